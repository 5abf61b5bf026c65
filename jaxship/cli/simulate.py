"""`jaxship simulate`: a standard trial (or the IMO set, `--manoeuvre imo`) of a vessel
preset, a vessel file or an identified model, its indices, records and figures."""

import json
import math
import pathlib
import sys

from .. import AbstractVessel, StandardTrial, check_operating_point, froude_scale
from ..identification import implausible, unconverged_fit
from ..indices import check_imo
from ..plotting import plot_imo_criteria, plot_trajectory
from ._common import check_out, note, positive
from ._files import staged_folder
from ._trial_files import simulate_steering_to_folder, simulate_to_folder
from ._vessel import VESSEL_HELP, read_vessel_option


# the most samples `simulate` integrates (10 million samples hold gigabytes)
MAX_SAMPLES = 5_000_000
LENGTHS = (1.0, 1000.0)  # [m] the lengths --length takes: a basin model to the longest ship


def register(sub) -> None:
    sim = sub.add_parser("simulate", help="simulate a standard trial")
    sim.add_argument("--vessel", required=True, help=VESSEL_HELP)
    sim.add_argument("--manoeuvre", required=True, help="e.g. turn:35, zigzag:-10/10, thesis; "
                     "imo: the IMO MSC.137(76) trials and criteria, with the band the "
                     "standard errors of an identified model give")
    sim.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    sim.add_argument("--speed", type=float, help="approach speed [m/s]")
    sim.add_argument("--rpm", type=float, help="propeller rate [rpm]")
    sim.add_argument("--duration", type=float, help="duration [s]")
    sim.add_argument("--dt", type=float, help="sample interval [s]")
    sim.add_argument("--length", type=float, metavar="L", help="Froude-scale the preset to "
                     "this length between perpendiculars [m] (e.g. 320 for the KVLCC2 ship)")
    sim.set_defaults(run=run, small_programs=lambda args: True)


def run(args) -> int:
    """A vessel's trial (`run_vessel`) or a steering model's (`run_steering`); exit 3,
    the reason said first, where `--vessel` is a result whose fit did not converge."""
    chosen = read_vessel_option(args.vessel)
    unfit = unconverged_fit(chosen.report, args.vessel) if chosen.report else ""
    if unfit:
        print(f"jaxship: {unfit}", file=sys.stderr)
    trial = run_vessel if isinstance(chosen.model, AbstractVessel) else run_steering
    # a value beyond what ships do, a hand edit too (identify warned of its own): said
    # after the trial, or in a refusal's one line, where it is the likely cause
    said = implausible(chosen.model) if chosen.report else ()
    try:
        status = trial(args, chosen)
    except ValueError as error:
        if not said:
            raise
        raise ValueError(f"{error} The model is beyond what ships do ({args.vessel}): "
                         f"{' '.join(said)}") from None
    for sentence in said:
        print(f"jaxship: warning: {args.vessel}: {sentence}", file=sys.stderr)
    return 3 if unfit else status


def run_vessel(args, chosen) -> int:
    # every check before the simulation; the files appear in --out only when all are written
    vessel, imo = chosen.model, args.manoeuvre.strip().lower() == "imo"
    if positive("--length", args.length):
        if not LENGTHS[0] <= args.length <= LENGTHS[1]:
            raise ValueError(f"--length {args.length:g} m: give a ship or model length between "
                             f"{LENGTHS[0]:g} and {LENGTHS[1]:g} m ({args.vessel} is "
                             f"{float(vessel.length):.4g} m).")
        vessel = froude_scale(vessel, args.length / float(vessel.length))
    spec = StandardTrial.parse("zigzag:20/20" if imo else args.manoeuvre)
    speed, rpm = positive("--speed", args.speed), positive("--rpm", args.rpm)
    if chosen.report is not None and speed is None and rpm is None and vessel.nominal_n:
        rpm = 60.0 * float(vessel.nominal_n)  # fitted: the speed its coefficients give
        note(f"the approach at the service propeller rate of {args.vessel}, {rpm:.4g} rpm "
             "(the fitted coefficients set the speed); give --speed or --rpm to choose.")
    duration, dt = positive("--duration", args.duration), positive("--dt", args.dt)
    limit = math.degrees(float(vessel.rudder.max_angle))
    trials = StandardTrial.imo(vessel) if imo else [spec]
    for angle in [a for trial in trials for a in trial.rudder_angles]:
        if abs(angle) > limit * (1 + 1e-12):
            raise ValueError(f"--manoeuvre {args.manoeuvre}: the rudder angle {angle:g} deg is "
                             f"beyond the rudder limit of {args.vessel} ({limit:g} deg); give "
                             f"at most {limit:g}.")
    check_operating_point(vessel, speeds=[speed] if speed else [],
                          rpms=[rpm] if rpm else [], name=args.vessel)
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
    if imo:
        return run_imo(args, chosen, vessel, speed=speed, rpm=rpm)
    check_out(args.out, writes=("trial.csv", "indices.json"))
    with staged_folder(args.out) as stage:
        indices = simulate_to_folder(vessel, spec, stage, speed=speed, rpm=rpm,
                                     duration=duration, dt=dt,
                                     title=f"{args.vessel} {args.manoeuvre}")
        written = sorted(p.name for p in stage.iterdir())
    print(json.dumps(indices, indent=2))
    print(f"wrote {args.out}/" + f", {args.out}/".join(written))
    return 0


def run_imo(args, chosen, vessel, *, speed, rpm) -> int:
    """`--manoeuvre imo`: the trials of `StandardTrial.imo`, the criteria with margins and bands
    (`jaxship.indices.check_imo`);
    writes `criteria.md`, `indices.json`, `imo_criteria.png` and one figure a trial."""
    import matplotlib.pyplot as plt  # with the figures only (issue 70)

    if args.duration is not None or args.dt is not None:
        raise ValueError("--manoeuvre imo runs each trial for its own duration and sample "
                         "interval; leave out --duration and --dt.")
    figures = [f"{spec.kind}{''.join(f'{v:g}' for v in spec.values[:1])}.png"
               for spec in StandardTrial.imo(vessel)]
    check_out(args.out, writes=("criteria.md", "indices.json", "imo_criteria.png", *figures))
    check = check_imo(vessel, identification=chosen.report, speed=speed, rpm=rpm)
    for text in check.notes:
        print(f"jaxship: warning: {text}", file=sys.stderr)
    with staged_folder(args.out) as stage:
        (stage / "criteria.md").write_text(check.to_markdown(chosen.label))
        (stage / "indices.json").write_text(json.dumps(check.to_dict(), indent=2) + "\n")
        fig = plot_imo_criteria(check.rows, bands=check.bands,
                                title=f"{chosen.label}: IMO MSC.137(76) criteria")
        fig.savefig(stage / "imo_criteria.png", dpi=110)
        plt.close(fig)
        for name, (text, (_, traj, marks)) in zip(figures, check.runs.items()):
            fig = plot_trajectory(traj, length=float(vessel.length), indices=marks,
                                  title=f"{chosen.label} {text}", labels=[text])
            fig.savefig(stage / name, dpi=110)
            plt.close(fig)
    print(check.table())
    print(f"band: {check.draws['from']} ({check.draws['used']} of {check.draws['draws']} "
          "draws ran)")
    if check.draws["draws"] and not check.draws["used"]:
        note("no parameter draw ran every trial: the standard errors reach values where the "
             "model has no straight run or blows up (see the result's identifiability flags); "
             "no band.")
    print(f"wrote {args.out}/criteria.md, {args.out}/indices.json, {args.out}/imo_criteria.png, "
          + ", ".join(f"{args.out}/{f}" for f in figures))
    return 0


def run_steering(args, chosen) -> int:
    """A steering model of an identify result through a closed-loop trial: its heading
    and yaw rate (no track, no speed); `--dt` and `--duration` default to its first
    training record's."""
    spec = StandardTrial.parse(args.manoeuvre) if args.manoeuvre.strip().lower() != "imo" \
        else None
    kinds = StandardTrial.steering_kinds
    if spec is None or spec.kind not in kinds:
        raise ValueError(f"--vessel {args.vessel}: a {type(chosen.model).__name__} steering "
                         "model has no track, speed or propeller, so it has no "
                         f"{args.manoeuvre} trial; give one of {', '.join(kinds)} "
                         "(the IMO check needs a vessel: identify a vessel preset).")
    for option in ("length", "speed", "rpm"):
        if getattr(args, option) is not None:
            raise ValueError(f"--{option}: a steering model has no length, speed or "
                             "propeller; leave it out.")
    records = (chosen.report.get("data") or {}).get("train") or [{}]
    dt = positive("--dt", args.dt) or positive("dt_s of the result", records[0].get("dt_s"))
    duration = positive("--duration", args.duration) or positive(
        "duration_s of the result", records[0].get("duration_s"))
    if dt is None or duration is None or duration < 2 * dt:
        raise ValueError("give --dt and --duration (longer than two samples): the result "
                         "names no training record to take them from.")
    if duration / dt > MAX_SAMPLES:
        given = "--duration/--dt" if args.dt and args.duration else \
            "--duration/--dt (default: the result's first training record)"
        raise ValueError(f"{given}: {duration / dt:.3g} samples ({duration:.4g} s at "
                         f"{dt:.3g} s), more than {MAX_SAMPLES:.0e}; give a larger --dt or a "
                         "shorter --duration.")
    check_out(args.out, writes=("trial.csv", "indices.json", "trial.png"))
    with staged_folder(args.out) as stage:
        indices = simulate_steering_to_folder(chosen.model, spec, stage, dt=dt,
                                              duration=duration,
                                              title=f"{chosen.label} {args.manoeuvre}")
    print(json.dumps(indices, indent=2))
    print(f"wrote {args.out}/trial.csv, {args.out}/indices.json, {args.out}/trial.png")
    return 0
