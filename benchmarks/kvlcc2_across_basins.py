"""KVLCC2 across basins (issue 32.3): models identified on HSVA's zig-zags predicting
MARIN's free-running tests, the SIMMAN 2008 question.

Training: HSVA's 11 zig-zags other than the two 10/10 runs (5 Hz); those two are
`discover`'s held-out runs. MARIN's runs (full scale, Froude-scaled to the 7 m model,
lambda = 45.714) take no part in any fit or decision. Columns:

- `preset`: the `kvlcc2` MMG coefficients (Yasukawa & Yoshimura 2015), unfitted;
- `HSVA-identified`: `discover`'s base fit (the preset's free coefficients fitted on the
  HSVA zig-zags, started from `identify`, as the discovery notebook does);
- `+ discovered`: `discover`'s model, its named effects fitted on HSVA;
- `+ discovered, hull`: the same without the effects that belong to a basin's
  instruments or water, not to the hull (`BASIN_SPECIFIC`: a rudder zero offset, sensor
  biases, a current), which should not travel to another basin: the hull coefficients
  fitted together with those effects.

Rows: the MARIN 35 deg turning circles (advance and tactical diameter [L], steady speed
[m/s] and yaw rate [deg/s], means over 360-720 deg of heading change) and the four
zig-zags' first and second overshoots [deg]. Every simulation starts from a straight run
at the measured approach speed and propeller rate (`kvlcc2_simman.py`'s definitions).

Run: `python benchmarks/kvlcc2_across_basins.py`; prints markdown tables and whether the
HSVA-identified hull improves every MARIN index over the preset (the issue's goal).
"""

import math
import sys
import time

import jax


jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402
from jaxship.studies.kvlcc2_simman import (  # noqa: E402
    DT,
    LENGTH,
    execute_index,
    measured_zigzag,
    simulate_zigzag,
)
from jaxship.studies.real_data import kvlcc2_discovery_split  # noqa: E402


BASIN_SPECIFIC = ("rudder_offset", "heading_sensor_bias", "yaw_rate_sensor_bias", "current")
TURN_DURATION = 320.0  # [s] model scale: MARIN's turns run to about 740 deg in 305-315 s
STEADY = (2 * math.pi, 4 * math.pi)  # heading change [rad] over which the turn is steady


def turn_indices(t, x, y, psi, u, v, r, execute_time):
    """(advance, tactical diameter [L], steady speed [m/s], steady |yaw rate| [deg/s]),
    and the side of the turn."""
    ti = js.indices.turning_indices(t=t, x=x, y=y, psi=psi, u=u, v=v, r=r,
                                    execute_time=execute_time)
    change = np.abs(psi - psi[int(np.searchsorted(t, execute_time))])
    steady = (change >= STEADY[0]) & (change <= STEADY[1])
    mean = lambda a: float(np.mean(a[steady])) if steady.any() else math.nan
    return (ti.advance / LENGTH, ti.tactical_diameter / LENGTH, mean(np.hypot(u, v)),
            np.degrees(mean(np.abs(r)))), ti.side


def marin_turn(exp):
    """The measured indices, the side, the approach speed and propeller rate."""
    k = execute_index(exp.delta)
    indices, side = turn_indices(exp.t, exp.x, exp.y, exp.psi, exp.u, exp.v, exp.r,
                                 float(exp.t[k]))
    return indices, side, float(np.hypot(exp.u[k], exp.v[k])), float(exp.n[k])


def simulated_turn(vessel, side, speed, n):
    traj = js.simulate(vessel, js.Turn(side * np.deg2rad(35.0), duration=TURN_DURATION,
                                       dt=DT, n=n), js.straight_state(speed, n),
                       simulator=js.Simulator(substeps=1))
    s = traj.state
    return turn_indices(*(np.asarray(a) for a in (traj.t, s.x, s.y, s.psi, s.u, s.v, s.r)),
                        0.0)[0]


def hull_only(model):
    """`model` without its basin-specific effects."""
    effects = [e for e in getattr(model, "effects", ()) if e.id not in BASIN_SPECIFIC]
    base = getattr(model, "base", model)
    return js.augment(base, *effects) if effects else base


def main():
    data = js.shared_data_dir()
    if data is None:
        raise SystemExit("measured data not found (set JAXSHIP_DATA)")
    js.enable_compilation_cache()
    began = time.perf_counter()
    train, holdout = kvlcc2_discovery_split(marin=False)
    start = js.identify("kvlcc2", train).model
    report = js.discover(start, train, holdout)
    named = [e.id for e in report.effects]
    print(f"discover on HSVA ({time.perf_counter() - began:.0f} s): named {named or 'nothing'}",
          file=sys.stderr)
    columns = {"preset": js.get_vessel("kvlcc2"), "HSVA-identified": report.model_before,
               "+ discovered": report.model_after,
               "+ discovered, hull": hull_only(report.model_after)}
    rows = []  # (run, quantity, measured, {column: simulated})
    marin = data / "kvlcc2_simman2008_marin"
    labels = ("advance [L]", "tactical diameter [L]", "steady speed [m/s]",
              "steady yaw rate [deg/s]")
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_tc_*.dat")):
        exp = js.read_measured(path, model_scale=True)
        measured, side, speed, n = marin_turn(exp)
        sims = {k: simulated_turn(m, side, speed, n) for k, m in columns.items()}
        run = f"MARIN turn 35 {'stb' if side > 0 else 'port'}"
        rows += [(run, lab, measured[i], {k: s[i] for k, s in sims.items()})
                 for i, lab in enumerate(labels)]
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_zz_*.dat")):
        exp = js.read_measured(path, model_scale=True)
        angle = abs(float(path.stem.split("_")[-2]))
        measured, side, speed, n = measured_zigzag(exp, angle)
        sims = {k: simulate_zigzag(m, angle, angle, side, speed, n) for k, m in columns.items()}
        run = f"MARIN {angle:g}/{angle:g} {'stb' if side > 0 else 'port'}"
        for i, lab in enumerate(("1st overshoot [deg]", "2nd overshoot [deg]")):
            pick = lambda a: float(a[i]) if len(a) > i else math.nan
            rows.append((run, lab, pick(measured), {k: pick(s) for k, s in sims.items()}))

    print("| run | quantity | measured | " + " | ".join(columns) + " |")
    print("|---|---|---:|" + "---:|" * len(columns))
    for run, label, meas, sims in rows:
        cells = " | ".join(f"{v:.2f} ({100 * (v - meas) / meas:+.0f} %)" for v in sims.values())
        print(f"| {run} | {label} | {meas:.2f} | {cells} |")
    for column in ("HSVA-identified", "+ discovered, hull"):
        better = [abs(s[column] - m) < abs(s["preset"] - m) for _, _, m, s in rows
                  if math.isfinite(s[column]) and math.isfinite(m)]
        print(f"\n{column}: closer to MARIN than the preset on {sum(better)} of {len(better)} "
              f"indices; goal (every index) {'met' if all(better) else 'not met'}.")


if __name__ == "__main__":
    main()
