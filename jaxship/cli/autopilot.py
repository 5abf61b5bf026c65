"""`jaxship autopilot`: design a heading autopilot from an identified model and run it
on a vessel preset."""

import json
import pathlib
import sys

import matplotlib.pyplot as plt
from tqdm import tqdm  # the terminal bar (tqdm.auto warns in a kernel without ipywidgets)

from .._workflow import _autopilot as autopilot_study
from .._workflow._autopilot import cell
from ..identification import (
    linear_candidate,
    model_from_report,
    read_result,
    unconverged_fit,
)
from ..plotting import plot_autopilot
from ._common import check_operating_point, check_out, numbers
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
    autopilot_study.Design.scaled(omega, step=step, damping=damping).check()
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
    by_rpm, values, auto, step, damping, omega = _numbers(args)
    vessel = read_vessel_option(args.vessel, vessel_only=True).model
    check_operating_point(vessel, args.vessel, [] if by_rpm else values,
                          values if by_rpm else [])
    model, report = read_result(args.model)
    linear, design_models = _design_models(model, report, args.model)
    fit = report.get("fit")  # none: parameters written by hand
    code = fit.get("code") if isinstance(fit, dict) else None
    unfit = unconverged_fit(report, args.model)
    check_out(args.out, inputs=[args.model], writes=("autopilot.json", "report.md", "figures/",
              *(f"figures/{_figure_name(v, by_rpm)}" for v in values)))
    basis = ""
    if auto:  # from the model's yaw time constant at the mean operating point of the runs
        u0, n0 = autopilot_study.operating_point(
            vessel, **{"rpm" if by_rpm else "speed": sum(values) / len(values)})
        omega, basis = autopilot_study.natural_frequency_for(design_models.feedback, vessel,
                                                             speed=u0, n=n0, step=step)
    design = autopilot_study.Design.scaled(omega, step=step, damping=damping, basis=basis)

    bar, progress = _stage_bar(args)
    kw = {"rpm": values} if by_rpm else {"speeds": values}
    evaluation = autopilot_study.evaluate(design_models, vessel, design=design, tune=args.tune,
                                          progress=progress, steady_turn=args.steady_turn, **kw)
    if evaluation.feedforward_at_step is None:  # --steady-turn model: measured for the report
        progress("the vessel's steady turn at the step's peak rate")
    at_step = _feedforward_at_step(evaluation, by_rpm, values)
    inverse = autopilot_study.feedforward_gain_text(at_step) + _chosen_text(report)
    bar.update(bar.total - bar.n)
    bar.close()

    names = list(evaluation.runs)
    loops = [evaluation.runs[n] for n in names]
    failure, saturation = _problems(evaluation.rows)
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
        result = {
            "model": {"file": str(args.model), "name": report["model"],
                      "class": type(model).__name__, "fit_code": code,
                      "selection": report.get("selection"),  # identify --model auto
                      "feedback": report["model"] if linear is None else linear["model"],
                      "parameters": {k: float(e["value"] if isinstance(e, dict) else e)
                                     for k, e in report["parameters"].items()}},
            "vessel": args.vessel,
            "feedforward_at_step": at_step,
            **evaluation.to_dict(),
            "figures": figures,
        }
        (stage / "autopilot.json").write_text(json.dumps(result, indent=2) + "\n")
        parameters = ", ".join(f"{k} = {float(v):.4g}"
                               for k, v in result["model"]["parameters"].items())
        page = evaluation_report(
            evaluation, title=f"Heading autopilot: {report['model']} on {args.vessel}",
            model_text=f"Model: {report['model']} ({type(model).__name__}) from "
            f"`{args.model}`: {parameters}. {inverse}", figures=figures)
        for sentence in (saturation, failure, unfit):  # first, under the title
            if sentence:
                title, _, rest = page.partition("\n")
                page = f"{title}\n\n**{sentence}**\n{rest}"
        (stage / "report.md").write_text(page)
    _print_summary(evaluation, inverse, f"{args.out}/autopilot.json, {args.out}/report.md, "
                   f"{args.out}/figures/ ({len(figures)} figures)", saturation)
    for sentence in (failure, unfit):
        if sentence:
            print(f"jaxship: {sentence}", file=sys.stderr)
    return 3 if failure or unfit else 0


def _design_models(model, report: dict, path) -> tuple:
    """`(linear, models)`: the linear candidate of the report's `selection` (its
    report form, or None) and the `DesignModels` pair `evaluate` designs on: `model`
    and the candidate, the poles placed on the candidate (none: `model` twice)."""
    linear = linear_candidate(report.get("selection"))
    if linear is None:
        return None, autopilot_study.DesignModels(model, model)
    try:
        return linear, autopilot_study.DesignModels(model, model_from_report(linear))
    except ValueError as error:
        raise ValueError(f"{path}: the linear candidate of its selection: {error}") from None


def _print_summary(evaluation, inverse: str, written: str, saturation: str) -> None:
    """The gains, the runs, the inverse's sentence and the tuning on stdout, what was
    `written`, and a rudder that saturated as a warning on stderr."""
    for text in (gains_table(evaluation.gains()), runs_table(evaluation.rows), inverse,
                 tuning_text(evaluation.tuning)):
        if text:
            print(text)
    print(f"wrote {written}")
    if saturation:
        print(f"jaxship: warning: {saturation}", file=sys.stderr)


def _chosen_text(report: dict) -> str:
    """How `identify --model auto` chose the model of the result `report`; "" for a
    model named by hand."""
    selection = report.get("selection")
    if not isinstance(selection, dict) or "candidates" not in selection:
        return ""
    number = lambda x: f"{x:.6g}" if isinstance(x, (int, float)) else str(x)  # "inf"
    scores = "; ".join(f"{name} {number(c['bic'])}" if "bic" in c else f"{name} not fitted"
                       for name, c in selection["candidates"].items())
    text = (f" `identify --model auto` chose {selection.get('chosen')} by the least BIC on "
            f"its training records ({scores}).")
    linear = linear_candidate(selection)
    if linear is not None:
        values = ", ".join(f"{k} = {float(e['value']):.4g}"
                           for k, e in linear["parameters"].items())
        text += (f" The PID's poles are placed on its linear candidate {linear['model']} "
                 f"({values}), fitted to the same records: pole placement needs a linear "
                 "yaw equation; this one is fitted over the records' yaw rates, while the "
                 "chosen model's tangent at r = 0 is an extrapolation.")
    return text


def _problems(rows) -> tuple[str, str]:
    """`(failure, saturation)`: the sentences on runs that blew up and on runs whose
    rudder sat on its limit (code rudder_saturated) among `rows`; "" where none."""
    where = lambda row: f"{row['controller']} at {row['rpm']:.4g} rpm, {row['speed']:.3g} m/s"
    failed = [where(row) for row in rows if not row["success"]]
    failure = (f"The closed loop blew up (not finite) for {'; '.join(failed)}: those runs "
               "have no metrics and say nothing about the autopilot." if failed else "")
    pinned = [where(row) for row in rows if row["code"] == "rudder_saturated"]
    saturation = (f"The rudder sat at its limit for more than half the window in "
                  f"{'; '.join(pinned)} (code rudder_saturated): the comparison there says "
                  "little about the controllers; try a lower --natural-frequency."
                  if pinned else "")
    return failure, saturation


def _feedforward_at_step(evaluation, by_rpm, values) -> dict:
    """The evaluation's `feedforward_at_step` (--steady-turn trial), or with the model's
    own steady turn the same numbers measured for the report, without a scale."""
    if evaluation.feedforward_at_step is not None:
        return evaluation.feedforward_at_step
    at_step = autopilot_study.steady_turn_trial(
        evaluation.model, evaluation.plant, evaluation.design, evaluation.controllers["pid"],
        **{"rpm" if by_rpm else "speed": sum(values) / len(values)})
    del at_step["steady_gain"]
    at_step.pop("trial_failed", None)  # not measured: the report just says nothing of it
    return at_step


def gains_table(gains: dict) -> str:
    """Markdown table of `Evaluation.gains()`."""
    lines = ["| controller | K_p [-] | K_i [1/s] | K_d [s] | reference omega [rad/s] | "
             "feed-forward | its gains (acceleration, steady turn) |",
             "|---|---|---|---|---|---|---|"]
    for name, g in gains.items():
        ff = g["feedforward"]
        weights = "-" if ff is None else f"{g['ff_gain']:.3g}, {g['ff_steady_gain']:.3g}"
        lines.append(f"| {name} | {g['kp']:.4g} | {g['ki']:.4g} | {g['kd']:.4g} | "
                     f"{g['reference_frequency']:.4g} | {ff or 'none'} | {weights} |")
    return "\n".join(lines) + "\n"


def runs_table(rows: list[dict]) -> str:
    """Markdown table of run rows (`RUN_KEYS`)."""
    lines = ["| controller | rpm | speed [m/s] | sum abs error [deg] | against the ordered "
             "heading [deg] | RMS error [deg] | overshoot [deg] | settling [s] | mean abs "
             "rudder [deg] | rudder travel [deg] | rate-limited [s] |", "|---" * 11 + "|"]
    for r in rows:
        settle = "never" if r["settling_time_s"] is None else f"{r['settling_time_s']:.1f}"
        lines.append(f"| {r['controller']} | {r['rpm']:.0f} | {r['speed']:.3f} | "
                     f"{cell(r['sum_abs_error_deg'])} | "
                     f"{cell(r.get('sum_abs_error_ordered_deg'))} | "
                     f"{cell(r['rms_error_deg'], 3)} | "
                     f"{cell(r['max_overshoot_deg'])} | {settle} | "
                     f"{cell(r['mean_abs_rudder_deg'])} | {cell(r['rudder_travel_deg'], 1)} | "
                     f"{cell(r['time_rate_limited_s'], 1)} |")
    return "\n".join(lines) + "\n"


def tuning_text(tuning: dict | None) -> str:
    """`Evaluation.tuning` (`--tune`) in words; "" without it."""
    if tuning is None:
        return ""
    before = tuning["ordered_objective_before"]
    after = tuning["ordered_objective_after"]
    versus = ("" if None in (before, after) else
              f", objective against the ordered heading {before:.4g} -> {after:.4g} rad^2 "
              "(with the tuned gains)")
    return (f"Tuned (--tune): the gains by tune_autopilot against the reference model's "
            f"heading, objective {tuning['objective_before']:.4g} -> "
            f"{tuning['objective_after']:.4g} rad^2 in {tuning['steps']} steps ("
            f"{'converged' if tuning['converged'] else 'NOT converged'}); then the reference "
            f"model's bandwidth omega {tuning['reference_frequency_before']:.4g} -> "
            f"{tuning['reference_frequency_after']:.4g} rad/s against the ordered heading, the "
            f"best of {tuning['reference_candidates']} on a log grid up to "
            f"{tuning['reference_frequency_top']:.4g} rad/s, each with the feed-forward of "
            f"the step within half the rudder's angle and rate limits (with the tuned "
            f"acceleration gain {tuning['ff_gain_before_reference']:.3g} up to "
            f"{tuning['reference_frequency_bound']:.4g} rad/s; at the chosen bandwidth "
            f"{tuning['ff_gain_after_reference']:.3g}){versus}.")


def feedforward_text(rows: list[dict]) -> str:
    """Whether the feed-forward helped, per operating point: pid+ff against pid (the same
    gains), summed and RMS error with their differences; where it is worse, why in
    words: with the vessel as its own model the feed-forward (eq. 5.2/5.6) leaves
    almost no error, so a worse pid+ff means the model's inverse orders a rudder the
    vessel does not need at these rudder angles."""
    by = {(r["controller"], r["rpm"], r["speed"]): r for r in rows}
    parts, worse = [], []
    for (controller, rpm, speed), ff in by.items():
        fb = by.get(("pid", rpm, speed))
        if controller != "pid+ff" or fb is None or None in (
                ff["sum_abs_error_deg"], fb["sum_abs_error_deg"]):
            continue
        a, b = ff["sum_abs_error_deg"], fb["sum_abs_error_deg"]
        where = f"{rpm:.4g} rpm, {speed:.3g} m/s"
        parts.append(f"at {where} pid+ff {a:.1f} against pid {b:.1f} deg (difference "
                     f"{a - b:+.1f} deg; RMS {cell(ff['rms_error_deg'], 3)} against "
                     f"{cell(fb['rms_error_deg'], 3)} deg)")
        if a > b:
            worse.append(f"{where} (mean |rudder| {cell(ff['mean_abs_rudder_deg'])} deg)")
    if not parts:
        return ""
    text = "Feed-forward against feedback only: " + "; ".join(parts) + "."
    if worse:
        text += (" **The feed-forward makes the tracking worse** at " + "; ".join(worse)
                 + ": the model's inverse orders a rudder that the vessel does not need "
                 "at these rudder angles (its gain or time constant differs from the "
                 "vessel's there, e.g. a model identified from larger rudder angles); the "
                 "gains are the same, so only the feed-forward differs.")
    return text


def evaluation_report(evaluation: autopilot_study.Evaluation, *, title: str = "Heading autopilot",
                      model_text: str = "", figures=()) -> str:
    """A markdown page: the design, the gains, the runs and the `figures` (paths
    relative to the page)."""
    d = evaluation.design
    limits = evaluation.to_dict()["design"]
    text = [f"# {title}\n"]
    if model_text:
        text.append(model_text + "\n")
    text.append(
        f"Pole placement (thesis eq. 5.3-5.5) with omega_n = {d.natural_frequency:g} rad/s, "
        f"zeta = {d.damping:g}, K_d = 2 zeta omega_n m"
        + (" - d" if d.subtract_damping else "") + f", K_i = omega_n K_p / 10, about the "
        f"straight run at {evaluation.design_speed:.3f} m/s ({evaluation.design_rpm:.0f} rpm). "
        f"Reference model (eq. 5.7): omega = {d.reference_frequency:g} rad/s, zeta = "
        f"{d.reference_damping:g}; heading step {d.step:g} deg at {d.step_time:g} s. Rudder "
        f"limits {limits['max_rudder_deg']:.0f} deg and {limits['max_rudder_rate_deg_s']:.0f} "
        f"deg/s; the controller updates every {d.interval:g} s. Chosen: {d.basis}.\n")
    text.append("## Gains\n\n" + gains_table(evaluation.gains()))
    text.append("## Closed-loop runs\n\n" + runs_table(evaluation.rows))
    for verdict in (feedforward_text(evaluation.rows), tuning_text(evaluation.tuning)):
        if verdict:
            text.append(verdict + "\n")
    text.append(autopilot_study.METRICS_TEXT.format(dt=d.sample_interval, start=d.window[0],
                                    end=d.window[1]) + "\n")
    if figures:
        text.append("## Figures\n")
        text += [f"![{f}]({f})\n" for f in figures]
    return "\n".join(text)
