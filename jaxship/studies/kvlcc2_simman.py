"""KVLCC2: the MMG standard method (`kvlcc2()`) against the SIMMAN 2008 free-running tests.

Measured: the HSVA CPMC zig-zags (model scale, 13 runs) and the MARIN turning circles and
zig-zags (full scale, compared at model scale by Froude scaling, lambda = 45.714) in
`../shared/data`. Simulated: the same manoeuvres with `jaxship` from a straight run at the
measured approach speed, (a) at the measured propeller rate (HSVA 10.2295 rps; MARIN
about 10.3 rps at model scale), as in the tests, and (b) at the MMG model's own
self-propulsion rate for that speed (11.85 rps: the MMG parameter set has a 0.216 m
propeller, the tests used the 0.204 m INSEAN stock propeller).

Definitions (both sides alike, `jaxship.indices.zigzag_indices` and
`jaxship.indices.turning_indices`):
overshoot k = largest heading excursion beyond the switch heading after rudder execute
k + 1, relative to the heading at the first execute; advance, transfer and tactical
diameter from the midship track rotated into the initial-course frame at the rudder
execute, interpolated at 90 and 180 deg heading change, in units of L_pp.

The comparison that `benchmarks/kvlcc2_simman.py` prints and `notebooks/kvlcc2_simman.ipynb`
shows. Written against the public API; float64 is the caller's choice.
"""

import math

import numpy as np

import jaxship as js


LENGTH = 7.0  # L_pp of the model [m]
DT = 0.05  # sample interval of the simulations [s] (HSVA sampling), RK4 with 1 substep
ZIGZAG_DURATION = 240.0  # [s] model scale, one length for all zig-zags (one compilation)
TURN_DURATION = 150.0  # [s] model scale, past 180 deg heading change
EXECUTE_THRESHOLD = np.deg2rad(0.5)  # rudder leaves its approach value by this much [rad]


def execute_index(delta, lead=10):
    """First sample at which the rudder leaves its approach value (mean of the first
    `lead` samples) by more than 0.5 deg."""
    base = float(np.mean(delta[:lead]))
    moved = np.nonzero(np.abs(delta - base) > EXECUTE_THRESHOLD)[0]
    if moved.size == 0:
        raise ValueError("no rudder execute found in the record")
    return int(moved[0])


def zigzag_parameters(name):
    """Rudder angle and switch heading [deg] from an HSVA file name, e.g. ..._Z_10_05."""
    parts = name.split("_")
    z = parts.index("Z")
    return float(parts[z + 1]), float(parts[z + 2])


def measured_zigzag(exp, switch_deg):
    """Overshoots [deg], side (+1 starboard first), approach speed [m/s] and n [rev/s]."""
    k = execute_index(exp.delta)
    side = int(np.sign(exp.delta[min(k + 5, exp.num_samples - 1)] - exp.delta[0]))
    # no rudder history given: with a neutral-helm offset (MARIN: about 0.8 deg) the
    # rudder still has the approach sign at the execute; the side is then taken from the
    # heading, which first passes the switch angle on the side the rudder turns to
    z = js.indices.zigzag_indices(t=exp.t, psi=exp.psi, heading_switch=np.deg2rad(switch_deg),
                                  execute_times=[float(exp.t[k])])
    if z.side != side:
        raise ValueError(f"{exp.name}: heading and rudder disagree about the first side")
    return np.rad2deg(z.overshoots), side, float(np.hypot(exp.u[k], exp.v[k])), float(exp.n[k])


def simulate_zigzag(vessel, angle_deg, switch_deg, side, speed, n, duration=ZIGZAG_DURATION):
    """Overshoots [deg] of the simulated zig-zag from a straight run at `speed`, `n`."""
    x0 = js.straight_state(speed, n)
    manoeuvre = js.ZigZag(side * np.deg2rad(angle_deg), np.deg2rad(switch_deg),
                          duration=duration, dt=DT, n=n)
    traj = js.simulate(vessel, manoeuvre, x0, simulator=js.Simulator(substeps=1))
    z = js.indices.zigzag_indices(traj, np.deg2rad(switch_deg))
    return np.rad2deg(z.overshoots)


def measured_turn(exp):
    """Advance, transfer, tactical diameter [L], side, approach speed and n of a turn.

    From the printed positions and heading: their 3-significant-digit rounding
    (0.1 deg below 100 deg heading change, 1 deg above; 10 m at full scale) moves the
    indices by less than 0.02 L. (The printed earth-fixed velocities integrate to a
    track 2-4 % smaller than the printed positions during the turn, so they are not
    used.)"""
    k = execute_index(exp.delta)
    ti = js.indices.turning_indices(t=exp.t, x=exp.x, y=exp.y, psi=exp.psi, u=exp.u, v=exp.v,
                                    r=exp.r, execute_time=float(exp.t[k]))
    indices = np.array([ti.advance, ti.transfer, ti.tactical_diameter]) / LENGTH
    return indices, ti.side, float(np.hypot(exp.u[k], exp.v[k])), float(exp.n[k])


def simulate_turn(vessel, side, speed, n, angle_deg=35.0, duration=TURN_DURATION):
    """Advance, transfer, tactical diameter [L] of a simulated turn from a straight run."""
    x0 = js.straight_state(speed, n)
    traj = js.simulate(vessel, js.Turn(side * np.deg2rad(angle_deg), duration=duration, dt=DT, n=n),
                       x0, simulator=js.Simulator(substeps=1))
    ti = js.indices.turning_indices(traj)
    return np.array([ti.advance, ti.transfer, ti.tactical_diameter]) / LENGTH


def self_propulsion_n(vessel, speed):
    return float(js.straight_run(vessel, speed=speed).n)


def compare_hsva(path, vessel, *, self_propulsion=True):
    """Rows (run, quantity, measured, simulated at measured n, simulated at self-propulsion n)."""
    exp = js.read_measured(path)
    angle, switch = zigzag_parameters(exp.name)
    measured, side, speed, n = measured_zigzag(exp, switch)
    sim = simulate_zigzag(vessel, angle, switch, side, speed, n)
    sim_sp = (simulate_zigzag(vessel, angle, switch, side, speed, self_propulsion_n(vessel, speed))
              if self_propulsion else None)
    run = f"HSVA {angle:g}/{switch:g} {'stb' if side > 0 else 'port'}"
    rows = []
    for k, label in enumerate(("1st overshoot [deg]", "2nd overshoot [deg]")):
        pick = lambda a: float(a[k]) if a is not None and len(a) > k else math.nan
        rows.append((run, label, pick(measured), pick(sim), pick(sim_sp)))
    return rows


def compare_marin_turn(path, vessel, *, self_propulsion=True):
    exp = js.read_measured(path, model_scale=True)
    measured, side, speed, n = measured_turn(exp)
    sim = simulate_turn(vessel, side, speed, n)
    sim_sp = (simulate_turn(vessel, side, speed, self_propulsion_n(vessel, speed))
              if self_propulsion else np.full(3, math.nan))
    run = f"MARIN turn 35 {'stb' if side > 0 else 'port'}"
    labels = ("advance [L]", "transfer [L]", "tactical diameter [L]")
    return [(run, lab, float(measured[i]), float(sim[i]), float(sim_sp[i]))
            for i, lab in enumerate(labels)]


def compare_marin_zigzag(path, vessel, *, self_propulsion=True):
    exp = js.read_measured(path, model_scale=True)
    angle = abs(float(path.stem.split("_")[-2]))
    measured, side, speed, n = measured_zigzag(exp, angle)
    sim = simulate_zigzag(vessel, angle, angle, side, speed, n)
    sim_sp = (simulate_zigzag(vessel, angle, angle, side, speed, self_propulsion_n(vessel, speed))
              if self_propulsion else None)
    run = f"MARIN {angle:g}/{angle:g} {'stb' if side > 0 else 'port'}"
    rows = []
    for k, label in enumerate(("1st overshoot [deg]", "2nd overshoot [deg]")):
        pick = lambda a: float(a[k]) if a is not None and len(a) > k else math.nan
        rows.append((run, label, pick(measured), pick(sim), pick(sim_sp)))
    return rows


def percent(sim, measured):
    return 100.0 * (sim - measured) / measured


def markdown(rows):
    lines = [
        "| run | quantity | measured | MMG, measured n | diff % | MMG, self-prop. n | diff % |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for run, label, meas, sim, sim_sp in rows:
        lines.append(
            f"| {run} | {label} | {meas:.2f} | {sim:.2f} | {percent(sim, meas):+.0f} | "
            f"{sim_sp:.2f} | {percent(sim_sp, meas):+.0f} |"
        )
    return "\n".join(lines)
