"""`jaxship autopilot`: design a heading autopilot from an identified model and run it
on a vessel preset (`jaxship.evaluate_autopilot`); this module parses, prints, draws and
writes the files."""

import json
import pathlib
import sys

from tqdm import tqdm  # the terminal bar (tqdm.auto warns in a kernel without ipywidgets)

import jaxship as js

from ..identification import implausible, read_result, unconverged_fit
from ..plotting import plot_autopilot
from ._common import check_out, numbers
from ._files import staged_folder
from ._vessel import VESSEL_HELP, read_vessel_option


def register(sub) -> None:
    auto = sub.add_parser(
        "autopilot", help="design a heading autopilot from an identified model and run it",
        description="Design a PID heading autopilot with reference feed-forward from the model "
        "of an `identify` result (pole placement, thesis eq. 5.1-5.7), run it on a vessel "
        "preset from straight runs at each --rpm or --speed with feed-forward (pid+ff), "
        "without (pid) and, with --tune, with the gains and the reference model's bandwidth "
        "tuned on the vessel (tuned); a --model from `identify --model auto` is the model "
        "it chose; writes "
        "autopilot.json, report.md and figures/ into --out.")
    auto.add_argument("--model", required=True, type=pathlib.Path,
                      help="result.json written by `jaxship identify`")
    auto.add_argument("--vessel", required=True, help="the vessel steered: " + VESSEL_HELP)
    auto.add_argument("--rpm", nargs="+", default=None, help="propeller rates of the runs")
    auto.add_argument("--speed", nargs="+", default=None, help="approach speeds [m/s]")
    auto.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    auto.add_argument("--step", default="45", help="heading step [deg], at 50 / omega_n "
                      "s (100 s for 0.5 rad/s)")
    auto.add_argument("--tune", action="store_true",
                      help="also tune on the vessel at the given rpm/speeds (controller "
                      "tuned): the gains, the PID's and the feed-forward's (its acceleration "
                      "and steady-turn parts), against the reference model's heading; then "
                      "the reference model's bandwidth omega (eq. 5.7) against the ordered "
                      "heading (the step), at most what keeps the tuned feed-forward of the "
                      "step within half the rudder's angle and rate limits")
    auto.add_argument("--natural-frequency", default="auto",
                      help="the controller's omega_n [rad/s]; auto: 1.25 / T from "
                      "the model's yaw time constant T, at most half the rudder servo's "
                      "bandwidth (0.5 rad/s on the thesis vessel) and at most what keeps the "
                      "step's feed-forward within half the rudder's limits; the reference "
                      "model, step "
                      "time and window follow it in the thesis' proportions")
    auto.add_argument("--damping", default="1.0", help="the controller's zeta")
    auto.add_argument("--steady-turn", choices=("trial", "model"), default="trial",
                      help="the feed-forward's steady-turn part: trial (default) scales the "
                      "model's to the rudder the vessel needs at the step's peak yaw rate, "
                      "measured first by a reverse-spiral point flown in closed loop (zig-zags "
                      "do not reach those small yaw rates, inside a course-unstable ship's "
                      "spiral loop); model: the model's own (thesis eq. 5.2/5.6)")
    auto.add_argument("--quiet", action="store_true", help="no progress bar")
    # --tune runs long gradient programs, which XLA's defaults compile to run faster
    auto.set_defaults(run=run, small_programs=lambda args: not args.tune)


def _figure_name(value, by_rpm) -> str:
    """The figure of the runs at `value` rpm (`by_rpm`) or m/s."""
    return f"heading_{value:g}{'rpm' if by_rpm else 'mps'}.png"


def _numbers(args):
    """`(by_rpm, values, auto, step, damping, omega)` of the options, checked: the run
    values (rpm or speeds), whether the natural frequency is `auto` (0.5 until chosen)."""
    if (args.rpm is None) == (args.speed is None):
        raise ValueError("give --rpm or --speed (one of them).")
    by_rpm = args.rpm is not None
    values = numbers("--rpm" if by_rpm else "--speed", args.rpm if by_rpm else args.speed)
    auto = args.natural_frequency.strip().lower() == "auto"
    try:
        step, damping = float(args.step), float(args.damping)
        omega = 0.5 if auto else float(args.natural_frequency)
    except ValueError:
        raise ValueError("--step, --natural-frequency (or auto) and --damping take "
                         "numbers.") from None
    js.AutopilotDesign.scaled(omega, step=step, damping=damping).check()
    return by_rpm, values, auto, step, damping, omega


def _stage_bar(args):
    """`(bar, progress)`: the stages' progress bar (none with --quiet) and the callable
    that says a stage starts (the one before it is done)."""
    bar = tqdm(total=3 + 3 * int(args.tune), desc="autopilot", unit="stage", leave=False,
               file=sys.stderr, disable=args.quiet)
    started = []

    def progress(message):
        if started:
            bar.update()
        started.append(message)
        bar.set_postfix_str(message)

    return bar, progress


def run(args) -> int:
    # every check before the long work; nothing is written until the runs are done
    import matplotlib.pyplot as plt  # with the figures only (issue 70)

    by_rpm, values, auto, step, damping, omega = _numbers(args)
    vessel = read_vessel_option(args.vessel, vessel_only=True).model
    js.check_operating_point(vessel, speeds=[] if by_rpm else values,
                             rpms=values if by_rpm else [], name=args.vessel)
    model, report = read_result(args.model)
    unfit = unconverged_fit(report, args.model)
    check_out(args.out, inputs=[args.model], writes=("autopilot.json", "report.md", "figures/",
              *(f"figures/{_figure_name(v, by_rpm)}" for v in values)))
    kw = {"rpm": values} if by_rpm else {"speeds": values}
    if auto:  # from the model's yaw time constant at the mean operating point of the runs
        design = js.AutopilotDesign.auto(report, vessel, step=step, damping=damping, **kw)
    else:
        design = js.AutopilotDesign.scaled(omega, step=step, damping=damping)

    bar, progress = _stage_bar(args)
    evaluation = js.evaluate_autopilot(report, vessel, design=design, tune=args.tune,
                                       progress=progress,
                                       steady_turn_trial=args.steady_turn == "trial", **kw)
    bar.update(bar.total - bar.n)
    bar.close()

    names = list(evaluation.runs)
    loops = [evaluation.runs[n] for n in names]
    failure, saturation = evaluation.problems()
    with staged_folder(args.out) as stage:  # the whole set appears, or none of it
        (stage / "figures").mkdir()
        figures = []
        for j, row in enumerate(evaluation.rows[:len(values)]):
            fig = plot_autopilot(
                loops[0], index=j, others=loops[1:], labels=names,
                max_angle=float(vessel.rudder.max_angle),
                window=(design.step_time - 10.0, design.duration),
                title=f"{report['model']} autopilot on {args.vessel} at {row['rpm']:.0f} rpm, "
                f"{row['speed']:.3g} m/s")
            name = f"figures/{_figure_name(values[j], by_rpm)}"
            fig.savefig(stage / name, dpi=100, format="png")
            plt.close(fig)
            figures.append(name)
        result = evaluation.to_dict()
        result = {"model": {"file": str(args.model), **result.pop("model")},
                  "vessel": args.vessel, **result, "figures": figures}
        (stage / "autopilot.json").write_text(json.dumps(result, indent=2) + "\n")
        (stage / "report.md").write_text(evaluation.report(
            vessel=args.vessel, file=str(args.model), figures=figures, unconverged=unfit))
    for text in (evaluation.summary(),
                 f"wrote {args.out}/autopilot.json, {args.out}/report.md, "
                 f"{args.out}/figures/ ({len(figures)} figures)"):
        print(text)
    # a value beyond what ships do, a hand edit too (identify warned of its own), against
    # the plant's length and service speed; after the runs, so that a refusal stays one line
    for sentence in implausible(model, length=float(vessel.length),
                                speed=float(vessel.nominal_speed)):
        print(f"jaxship: warning: {args.model}: {sentence}", file=sys.stderr)
    if saturation:
        print(f"jaxship: warning: {saturation}", file=sys.stderr)
    for sentence in (failure, unfit):
        if sentence:
            print(f"jaxship: {sentence}", file=sys.stderr)
    return 3 if failure or unfit else 0
