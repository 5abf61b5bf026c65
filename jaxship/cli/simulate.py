"""`jaxship simulate`: a standard trial of a vessel preset, its indices, records and
figure."""

import json
import math
import pathlib

from .._foundation._files import staged_folder
from .._models._vessel.catalogue import get_vessel
from .._simulation._froude import froude_scale
from ._common import check_operating_point, check_out, positive
from ._trials import TrialSpec, simulate_to_folder


# the most samples `simulate` integrates (10 million samples hold gigabytes)
MAX_SAMPLES = 5_000_000
LENGTHS = (1.0, 1000.0)  # [m] the lengths --length takes: a basin model to the longest ship


def register(sub) -> None:
    sim = sub.add_parser("simulate", help="simulate a standard trial")
    sim.add_argument("--vessel", required=True, help="preset name (see `jaxship vessels`)")
    sim.add_argument("--manoeuvre", required=True, help="e.g. turn:35, zigzag:-10/10, thesis")
    sim.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    sim.add_argument("--speed", type=float, help="approach speed [m/s]")
    sim.add_argument("--rpm", type=float, help="propeller rate [rpm]")
    sim.add_argument("--duration", type=float, help="duration [s]")
    sim.add_argument("--dt", type=float, help="sample interval [s]")
    sim.add_argument("--length", type=float, metavar="L", help="Froude-scale the preset to "
                     "this length between perpendiculars [m] (e.g. 320 for the KVLCC2 ship)")
    sim.set_defaults(run=run, small_programs=lambda args: True)


def run(args) -> int:
    # every check before the simulation; the files appear in --out only when all are written
    vessel = get_vessel(args.vessel)
    if positive("--length", args.length):
        if not LENGTHS[0] <= args.length <= LENGTHS[1]:
            raise ValueError(f"--length {args.length:g} m: give a ship or model length between "
                             f"{LENGTHS[0]:g} and {LENGTHS[1]:g} m ({args.vessel} is "
                             f"{float(vessel.length):.4g} m).")
        vessel = froude_scale(vessel, args.length / float(vessel.length))
    spec = TrialSpec.parse(args.manoeuvre)
    speed, rpm = positive("--speed", args.speed), positive("--rpm", args.rpm)
    duration, dt = positive("--duration", args.duration), positive("--dt", args.dt)
    limit = math.degrees(float(vessel.rudder.max_angle))
    for angle in spec.rudder_angles:
        if abs(angle) > limit * (1 + 1e-12):
            raise ValueError(f"--manoeuvre {args.manoeuvre}: the rudder angle {angle:g} deg is "
                             f"beyond the rudder limit of {args.vessel} ({limit:g} deg); give "
                             f"at most {limit:g}.")
    check_operating_point(vessel, args.vessel, [speed] if speed else [], [rpm] if rpm else [])
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
    check_out(args.out, writes=("trial.csv", "indices.json"))
    with staged_folder(args.out) as stage:
        indices = simulate_to_folder(vessel, spec, stage, speed=speed, rpm=rpm,
                                     duration=duration, dt=dt,
                                     title=f"{args.vessel} {args.manoeuvre}")
        written = sorted(p.name for p in stage.iterdir())
    print(json.dumps(indices, indent=2))
    print(f"wrote {args.out}/" + f", {args.out}/".join(written))
    return 0
