"""The `jaxship` command: a thin layer over the public API (float64 is enabled here)."""

import argparse
import importlib.metadata
import json
import math
import pathlib
import sys
import tempfile

import jax
import matplotlib
from tqdm.auto import tqdm


matplotlib.use("Agg")  # the command writes files; it never opens a window

import matplotlib.pyplot as plt  # noqa: E402

from ._foundation._cache import enable_compilation_cache  # noqa: E402
from ._foundation._files import staged_folder  # noqa: E402
from ._models._vessel._base import surge_force  # noqa: E402
from ._models._vessel.catalogue import VESSELS, get_vessel  # noqa: E402
from ._trials import TrialSpec, simulate_to_folder  # noqa: E402
from .identification import (  # noqa: E402
    MODELS,
    get_model_entry,
    identify,
    read_experiments,
    read_result,
)
from .identification.discovery import run_discovery  # noqa: E402
from .identification.workflow import FitDivergedError  # noqa: E402
from .plotting import plot_autopilot, save_identification_figures  # noqa: E402
from .studies import autopilot as autopilot_study  # noqa: E402
from .studies.reproduce import reproduce  # noqa: E402


EXIT_STATUS = """exit status: 0 done; 2 bad input (arguments, records, an --out that cannot be
written: one line on stderr, nothing written); 1 a file-system failure while writing;
3 the fit did not converge, blew up, never moved, ended on a parameter bound, or a closed
loop blew up (results written, the reason on stderr) or diverged (nothing written); 130
interrupted. JAXSHIP_CACHE_DIR: where compiled programs are kept for later runs (default
~/.cache/jaxship/jax; "off" disables)."""

# the most samples `simulate` integrates (10 million samples hold gigabytes)
MAX_SAMPLES = 5_000_000


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="jaxship", description=__doc__, epilog=EXIT_STATUS,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version",
                        version=f"jaxship {importlib.metadata.version('jaxship')}")
    sub = parser.add_subparsers(dest="command", required=True)

    sub.add_parser("vessels", help="list the vessel presets and their sources")

    sim = sub.add_parser("simulate", help="simulate a standard trial")
    sim.add_argument("--vessel", required=True, help="preset name (see `jaxship vessels`)")
    sim.add_argument("--manoeuvre", required=True, help="e.g. turn:35, zigzag:-10/10, thesis")
    sim.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    sim.add_argument("--speed", type=float, help="approach speed [m/s]")
    sim.add_argument("--rpm", type=float, help="propeller rate [rpm]")
    sim.add_argument("--duration", type=float, help="duration [s]")
    sim.add_argument("--dt", type=float, help="sample interval [s]")

    rep = sub.add_parser("reproduce", help="the thesis pipeline on the built-in thesis vessel")
    rep.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/reproduce"))
    rep.add_argument("--quick", action="store_true", help="fewer trials (for smoke tests)")

    ident = sub.add_parser(
        "identify", help="estimate a steering model from measured trials and validate it",
        description="Estimate a steering model from training records (trial CSV files, "
        "measurement files or folders of them) and validate it; writes result.json and "
        "figures into --out.",
        epilog="models (--model):\n" + "\n".join(
            f"  {name:<24} {entry.description}" for name, entry in MODELS.items()),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ident.add_argument("train", nargs="+", type=pathlib.Path,
                       help="training records: trial CSV or measurement files, or folders")
    ident.add_argument("--model", required=True,
                       help="a registered model (listed below): a steering model, armax or a "
                       "vessel preset name")
    ident.add_argument("--horizon", default=None,
                       help="prediction horizon [s]; 'none' (default): output error, "
                       "0: equation error")
    ident.add_argument("--validate", nargs="+", type=pathlib.Path, default=None,
                       metavar="TEST", help="held-out records to validate on")
    ident.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    ident.add_argument("--rudder", default="delta", help="replayed rudder: delta or delta_c")
    ident.add_argument("--channels", default=None,
                       help="fitted outputs, e.g. psi,r or r, or psi,r,u,v,x,y to fit a "
                       "vessel's track (default: psi,r; psi,r,u,v for vessel presets; r for "
                       "armax)")
    ident.add_argument("--initial", default="auto",
                       help="window start states: measured, estimate or auto (default: "
                       "estimate for output error, else measured)")
    ident.add_argument("--max-steps", type=int, default=256, help="optimiser step limit")
    ident.add_argument("--no-figures", action="store_true", help="write result.json only")
    ident.add_argument("--quiet", action="store_true", help="no progress bar")

    auto = sub.add_parser(
        "autopilot", help="design a heading autopilot from an identified model and run it",
        description="Design a PID heading autopilot with reference feed-forward from the model "
        "of an `identify` result (pole placement, thesis eq. 5.1-5.7), run it on a vessel "
        "preset from straight runs at each --rpm or --speed with feed-forward (pid+ff), "
        "without (pid) and, with --tune, with gains tuned on the vessel (tuned); writes "
        "autopilot.json, report.md and figures/ into --out.")
    auto.add_argument("--model", required=True, type=pathlib.Path,
                      help="result.json written by `jaxship identify`")
    auto.add_argument("--vessel", required=True, help="the vessel steered (see `jaxship "
                      "vessels`)")
    auto.add_argument("--rpm", nargs="+", default=None, help="propeller rates of the runs")
    auto.add_argument("--speed", nargs="+", default=None, help="approach speeds [m/s]")
    auto.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    auto.add_argument("--step", default="45", help="heading step [deg] at 100 s (default 45)")
    auto.add_argument("--tune", action="store_true",
                      help="also tune the gains on the vessel at the given rpm/speeds")
    auto.add_argument("--natural-frequency", default="0.5",
                      help="the controller's omega_n [rad/s] (default 0.5)")
    auto.add_argument("--damping", default="1.0", help="the controller's zeta (default 1.0)")
    auto.add_argument("--quiet", action="store_true", help="no progress bar")

    disc = sub.add_parser(
        "discover", help="find, name and add the effect a model is missing",
        description="Fit a registered model to the training records (as `identify` does), "
        "score the catalogue of physically named effects at the fit, add those that pass "
        "calibrated tests and improve the held-out records, and report; writes "
        "discovery.json, report.md and figures/ into --out.")
    disc.add_argument("train", nargs="+", type=pathlib.Path,
                      help="training records: trial CSV or measurement files, or folders")
    disc.add_argument("--holdout", nargs="+", type=pathlib.Path, default=None, metavar="TEST",
                      help="held-out records (other manoeuvres) the effects must improve")
    disc.add_argument("--model", required=True, help="a registered model (see `jaxship "
                      "identify --help`)")
    disc.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    disc.add_argument("--max-effects", type=int, default=3, help="most effects added (3)")
    disc.add_argument("--alpha", type=float, default=0.01,
                      help="family-wise false-alarm rate (0.01)")
    disc.add_argument("--quiet", action="store_true", help="no progress messages")

    args = parser.parse_args(argv)
    jax.config.update("jax_enable_x64", True)
    enable_compilation_cache()  # second runs skip compilation ($JAXSHIP_CACHE_DIR moves it)
    commands = {"vessels": _vessels, "simulate": _simulate, "reproduce": _reproduce,
                "identify": _identify, "autopilot": _autopilot, "discover": _discover}
    try:
        return commands[args.command](args)
    except FitDivergedError as error:
        print(f"jaxship: error: {_one_line(error)}", file=sys.stderr)
        return 3
    except ValueError as error:
        print(f"jaxship: error: {_one_line(error)}", file=sys.stderr)
        return 2
    except OSError as error:  # the file system failed under us (disk full, a folder removed)
        where = f"{error.filename}: " if error.filename else ""
        print(f"jaxship: error: {where}{error.strerror or error}.", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("jaxship: interrupted.", file=sys.stderr)
        return 130


def _one_line(error) -> str:
    return " ".join(str(error).split())


def _vessels(args) -> int:
    width = max(map(len, VESSELS))
    print(f"{'name':<{width}}  {'L [m]':>7}  {'U [m/s]':>7}  {'n [rpm]':>7}  source")
    for name, entry in VESSELS.items():
        vessel = get_vessel(name)
        rpm = 60.0 * float(vessel.nominal_n)
        print(f"{name:<{width}}  {float(vessel.length):7.4g}  {float(vessel.nominal_speed):7.4g}"
              f"  {f'{rpm:7.4g}' if rpm else '      -'}  {entry.description}")
    return 0


def _simulate(args) -> int:
    # every check before the simulation; the files appear in --out only when all are written
    vessel = get_vessel(args.vessel)
    spec = TrialSpec.parse(args.manoeuvre)
    speed, rpm = _positive("--speed", args.speed), _positive("--rpm", args.rpm)
    duration, dt = _positive("--duration", args.duration), _positive("--dt", args.dt)
    limit = math.degrees(float(vessel.rudder.max_angle))
    for angle in spec.rudder_angles:
        if abs(angle) > limit * (1 + 1e-12):
            raise ValueError(f"--manoeuvre {args.manoeuvre}: the rudder angle {angle:g} deg is "
                             f"beyond the rudder limit of {args.vessel} ({limit:g} deg); give "
                             f"at most {limit:g}.")
    _check_operating_point(vessel, args.vessel, [speed] if speed else [], [rpm] if rpm else [])
    tau = float(vessel.length) / (speed or float(vessel.nominal_speed))  # time scale L/U [s]
    if dt is not None and dt > tau:
        raise ValueError(f"--dt {dt:g} s is longer than the time scale L/U = {tau:.3g} s of "
                         f"{args.vessel}, which the simulation could not resolve; give at most "
                         f"{tau:.3g} s (the default is about L/U / 20).")
    # a pull-out turns for 30 L/U before the release; a 3211 sequence lasts 7 L/U
    least = {"pullout": 30 * tau, "3211": 7 * tau}.get(spec.kind, 0.0)
    if duration is not None and duration <= least:
        raise ValueError(f"--duration {duration:g} s: a {spec.kind} needs more than "
                         f"{least:.4g} s on {args.vessel}; give a longer --duration or none.")
    if duration is not None and dt is not None and duration < 2 * dt:
        raise ValueError(f"--duration {duration:g} s is shorter than two samples of --dt "
                         f"{dt:g} s.")
    samples = (duration or 100 * tau) / (dt or tau / 20)
    if samples > MAX_SAMPLES:
        raise ValueError(f"--duration/--dt: {samples:.3g} samples ({duration or 100 * tau:.4g} s "
                         f"at {dt or tau / 20:.3g} s), more than {MAX_SAMPLES:.0e}; give a "
                         "larger --dt or a shorter --duration.")
    _check_out(args.out)
    with staged_folder(args.out) as stage:
        indices = simulate_to_folder(vessel, spec, stage, speed=speed, rpm=rpm,
                                     duration=duration, dt=dt,
                                     title=f"{args.vessel} {args.manoeuvre}")
        written = sorted(p.name for p in stage.iterdir())
    print(json.dumps(indices, indent=2))
    print(f"wrote {args.out}/" + f", {args.out}/".join(written))
    return 0


def _reproduce(args) -> int:
    _check_out(args.out)
    reproduce(args.out, quick=args.quick, progress=True)
    return 0


def _horizon(text):
    if text is None or text.strip().lower() in ("none", "oe", "output-error"):
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"--horizon {text!r}: the horizon must be a non-negative number of "
                         "seconds (e.g. 10; 0: equation error) or 'none' (output error).")
    return value


class _ProgressBar:
    """Turns `identify`'s `Progress` reports into tqdm bars on stderr."""

    def __init__(self, enabled):
        self.enabled, self.bar = enabled, None

    def __call__(self, event):
        if not self.enabled:
            return
        if event.stage != "fit":
            if not event.done:
                tqdm.write(f"jaxship: {event.message} ...", file=sys.stderr)
            return
        if self.bar is None:
            self.bar = tqdm(total=event.total, desc=event.message, unit="step", leave=False,
                            file=sys.stderr)
        self.bar.n = min(int(event.step), event.total)
        if event.cost is not None:
            self.bar.set_postfix(cost=f"{event.cost:.5g}", refresh=False)
        self.bar.refresh()
        if event.done:
            self.bar.close()
            self.bar = None
            tqdm.write(f"jaxship: {event.message}: {event.step} steps, cost {event.cost:.6g}",
                       file=sys.stderr)


def _note(sentence: str) -> None:
    print(f"jaxship: note: {sentence}", file=sys.stderr)


def _identify(args) -> int:
    # every check before the fit; the files appear in --out only when all are written
    get_model_entry(args.model)  # unknown models fail before reading any file
    horizon = _horizon(args.horizon)
    if args.max_steps < 1:
        raise ValueError(f"--max-steps {args.max_steps}: give a positive number of optimiser "
                         "steps (default 256).")
    _check_out(args.out)
    train = read_experiments(args.train, role="training", note=_note)
    held_out = None if args.validate is None else read_experiments(
        args.validate, role="validation", note=_note)
    bar = _ProgressBar(not args.quiet)
    result = identify(train, model=args.model, horizon=horizon, validate=held_out,
                      rudder=args.rudder, channels=args.channels, initial=args.initial,
                      max_steps=args.max_steps, progress=bar)
    written = ["result.json"]
    with staged_folder(args.out) as stage:
        if not args.no_figures:
            paths = save_identification_figures(result, stage / "figures")
            written.append(f"figures/ ({len(paths)} figures)")
        (stage / "result.json").write_text(result.to_json() + "\n")
    head, *lines = result.summary().splitlines()
    if not result.fit.success:  # the optimiser's own words are on stderr, in plain ones
        head = (f"{result.model_name}: {type(result.model).__name__}, NOT converged "
                f"({result.fit.code_name}, after {result.fit.num_steps} steps)")
    print("\n".join([head, *lines]))
    for note in result.notes:
        print(f"note: {note}")
    for message in dict.fromkeys(result.warnings):
        print(f"jaxship: warning: {_one_line(message)}", file=sys.stderr)
    print(f"wrote {args.out}/" + f", {args.out}/".join(written))
    if not result.fit.success:
        print(f"jaxship: the fit is not a converged estimate ({result.fit.code_name}: see "
              "the warnings above); the results were written for inspection.",
              file=sys.stderr)
        return 3
    return 0


def _check_operating_point(vessel, name, speeds, rpms):
    """Approach speeds [m/s] and propeller rates [rpm] a vessel can sail at: at most 10
    times its service speed and rate, and a rate only where it has a propeller model."""
    nominal = float(vessel.nominal_speed)
    for speed in speeds:
        if speed > 10 * nominal:
            raise ValueError(f"--speed {speed:g} m/s: more than 10 times the service speed "
                             f"of {name} ({nominal:.3g} m/s); give an approach speed in m/s.")
    if rpms and float(surge_force(vessel, nominal, 1.0)
                      - surge_force(vessel, nominal, 0.0)) == 0.0:
        raise ValueError(f"--rpm: {name} has no propeller model, so the propeller rate "
                         "does nothing; give --speed instead.")
    service = 60.0 * float(vessel.nominal_n)
    for rpm in rpms:
        if rpm > 10 * service:
            raise ValueError(f"--rpm {rpm:g}: more than 10 times the service propeller rate "
                             f"of {name} ({service:.4g} rpm).")


def _positive(option, value):
    """`value` (a float or None) checked: finite and positive."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise ValueError(f"{option} {value:g}: must be a positive number.")
    return value


def _numbers(option, texts) -> list[float]:
    values = []
    for text in texts:
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{option} {text!r}: not a number.") from None
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{option} {text!r}: must be a positive number.")
        values.append(value)
    return values


def _check_out(out: pathlib.Path):
    """`ValueError` unless `out` is (or can be made) a folder we can write into;
    writes nothing that stays."""
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} is a file, not a folder; give a folder (it is made if "
                         "need be).")
    parent = out
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"--out {out}: {parent} is a file, not a folder.")
    try:
        with tempfile.TemporaryFile(dir=parent):
            pass
    except OSError as error:
        raise ValueError(f"--out {out}: cannot write in {parent} "
                         f"({error.strerror or error}).") from None


def _point_name(row, by_rpm) -> str:
    return f"{row['rpm']:g}rpm" if by_rpm else f"{row['speed']:g}mps"


def _discover(args) -> int:
    _check_out(args.out)  # before any long work
    say = (lambda message: None) if args.quiet else (
        lambda message: tqdm.write(f"jaxship: {message} ...", file=sys.stderr))
    report = run_discovery(args.train, args.holdout, model=args.model, out=args.out,
                           max_effects=args.max_effects, alpha=args.alpha, progress=say)
    print(report.to_markdown())
    print(f"wrote {args.out}/discovery.json, {args.out}/report.md, {args.out}/figures/")
    return 0


def _autopilot(args) -> int:
    # every check before the long work; nothing is written until the runs are done
    if (args.rpm is None) == (args.speed is None):
        raise ValueError("give --rpm or --speed (one of them).")
    by_rpm = args.rpm is not None
    values = _numbers("--rpm" if by_rpm else "--speed", args.rpm if by_rpm else args.speed)
    try:
        step = float(args.step)
        design = autopilot_study.Design(step=step,
                                        natural_frequency=float(args.natural_frequency),
                                        damping=float(args.damping))
    except ValueError:
        raise ValueError("--step, --natural-frequency and --damping take numbers.") from None
    design.check()
    vessel = get_vessel(args.vessel)
    _check_operating_point(vessel, args.vessel, [] if by_rpm else values,
                           values if by_rpm else [])
    model, report = read_result(args.model)
    _check_out(args.out)

    bar = tqdm(total=2 + 2 * int(args.tune), desc="autopilot", unit="stage", leave=False,
               file=sys.stderr, disable=args.quiet)
    started = []

    def progress(message):  # a stage starts: the one before it is done
        if started:
            bar.update()
        started.append(message)
        bar.set_postfix_str(message)

    kw = {"rpm": values} if by_rpm else {"speeds": values}
    evaluation = autopilot_study.evaluate(model, vessel, design=design, tune=args.tune,
                                          progress=progress, **kw)
    bar.update(bar.total - bar.n)
    bar.close()

    names = list(evaluation.runs)
    loops = [evaluation.runs[n] for n in names]
    failed = [f"{row['controller']} at {row['rpm']:.4g} rpm, {row['speed']:.3g} m/s"
              for row in evaluation.rows if not row["success"]]
    failure = (f"The closed loop blew up (not finite) for {'; '.join(failed)}: those runs "
               "have no metrics and say nothing about the autopilot." if failed else "")
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
            name = f"figures/heading_{_point_name(row, by_rpm)}.png"
            fig.savefig(stage / name, dpi=100, format="png")
            plt.close(fig)
            figures.append(name)
        result = {
            "model": {"file": str(args.model), "name": report["model"],
                      "class": type(model).__name__,
                      "parameters": {k: e["value"] for k, e in report["parameters"].items()}},
            "vessel": args.vessel,
            **evaluation.to_dict(),
            "figures": figures,
        }
        (stage / "autopilot.json").write_text(json.dumps(result, indent=2) + "\n")
        parameters = ", ".join(f"{k} = {float(v):.4g}"
                               for k, v in result["model"]["parameters"].items())
        page = autopilot_study.evaluation_report(
            evaluation, title=f"Heading autopilot: {report['model']} on {args.vessel}",
            model_text=f"Model: {report['model']} ({type(model).__name__}) from "
            f"`{args.model}`: {parameters}.", figures=figures)
        if failure:  # first, under the title
            title, _, rest = page.partition("\n")
            page = f"{title}\n\n**{failure}**\n{rest}"
        (stage / "report.md").write_text(page)
    print(autopilot_study.gains_table(evaluation.gains()))
    print(autopilot_study.runs_table(evaluation.rows))
    print(f"wrote {args.out}/autopilot.json, {args.out}/report.md, {args.out}/figures/ "
          f"({len(figures)} figures)")
    if failure:
        print(f"jaxship: {failure}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
