"""Hidden-effect data for `jaxship.discover`: the records its tests, its Monte-Carlo
benchmark and its notebook use.

A truth model (a steering model with or without effects) is run through 10/10 and
20/20 zig-zags to both sides (training) and +-20 deg turning circles (held out), with
a rudder rate limit of 2.3 deg/s, integrated more finely than any fit (0.02 s control
steps against one RK4 step per 0.5 s sample) and with the rudder logged at the sample
rate, as a real log would be. Measurement noise: heading 0.1 deg, yaw rate 0.05 deg/s.
Optionally a slowly varying yaw moment that is not in any log: an Ornstein-Uhlenbeck
equivalent rudder angle (20 s correlation time), the kind of disturbance waves and
gusts cause, which colours the residuals without being physics to name.
"""

import dataclasses
import functools
import math
import time

import numpy as np

import jaxship as js


DEG = np.pi / 180
FINE = js.Simulator(max_step=0.02)
TRAIN = tuple((a, s) for a in (10, 20) for s in (1, -1))  # zig-zag angle [deg], side
HOLDOUT = (20, -20)  # turning-circle rudder angles [deg]


def disturbance(t, std, seed, correlation_time=20.0) -> np.ndarray:
    """An Ornstein-Uhlenbeck series at the times `t` (uniform), standard deviation
    `std` and correlation time [s]: exact discretisation $w_k = a w_{k-1} +
    \\sqrt{1 - a^2}\\,\\sigma\\xi_k$, $a = e^{-\\Delta t/\\tau}$, from zero."""
    rng = np.random.default_rng(seed)
    a = np.exp(-(t[1] - t[0]) / correlation_time)
    w = np.zeros(t.size)
    for k in range(1, t.size):
        w[k] = a * w[k - 1] + np.sqrt(1 - a * a) * std * rng.normal()
    return w


def record(truth, manoeuvre, name, rng, *, disturbance_std=0.0, noise=(0.1, 0.05)):
    """One noisy record of `truth` through `manoeuvre` (see the module text)."""
    out = js.simulate(truth, dataclasses.replace(manoeuvre, rudder_rate=2.3 * DEG), simulator=FINE)
    t, delta = np.asarray(out.t), np.asarray(out.state.delta)
    psi, r = np.asarray(out.state.psi), np.asarray(out.state.r)
    if disturbance_std:
        w = disturbance(t, disturbance_std, int(rng.integers(2**31)))
        replay = js.Replay(delta + w, dt=float(t[1] - t[0]),
                           delta_hold=js.strategies.FirstOrderHold())
        out = js.simulate(truth, replay,
                          simulator=js.Simulator(max_step=math.inf, substeps=25))
        psi, r = np.asarray(out.state.psi), np.asarray(out.state.r)
    psi, r = np.asarray(truth.measure("psi", psi)), np.asarray(truth.measure("r", r))  # sensors
    return js.Experiment(t, delta, psi=psi + rng.normal(0, noise[0] * DEG, t.size),
                         r=r + rng.normal(0, noise[1] * DEG, t.size), name=name)


def hidden_effect_records(truth, seed, *, disturbance_std=0.0):
    """`(train, holdout)` records of `truth` (see the module text)."""
    rng = np.random.default_rng(seed)
    train = [record(truth, js.ZigZag(a * DEG, s * a * DEG, duration=400.0, dt=0.5),
                    f"zigzag {a}/{a} {'starboard' if s > 0 else 'port'}", rng,
                    disturbance_std=disturbance_std) for a, s in TRAIN]
    holdout = [record(truth, js.Turn(a * DEG, duration=300.0, dt=0.5), f"turn {a:+d}", rng,
                      disturbance_std=disturbance_std) for a in HOLDOUT]
    return train, holdout


def condition_records(at, seed, *, channel="n", values=(1.0, 2.0), held=None):
    """`(train, holdout)` of a steering truth that changes with a logged condition
    held constant in each run: the propeller rate (`channel="n"`, [rev/s]) or the
    surge speed (`"u"`, [m/s]). `at(value)` is the truth at that value, exact where
    the effect is a gain, time constant or moment constant at a constant rate or
    speed (a steering model's closed loop has no logged inputs). 10/10 and 20/20 zig-zags to
    starboard at each of `values` to train, +-20 deg turns at `held` (default their
    mean) held out, run as `record` does."""
    rng = np.random.default_rng(seed)
    unit = {"n": "rev/s", "u": "m/s"}[channel]

    def one(manoeuvre, value, name):
        out = record(at(value), manoeuvre, name, rng)
        return js.Experiment(out.t, out.delta, psi=out.psi, r=out.r, name=name,
                             **{channel: np.full(out.t.size, value)})

    train = [one(js.ZigZag(a * DEG, a * DEG, duration=400.0, dt=0.5), value,
                 f"zigzag {a}/{a} at {value} {unit}") for a in (10, 20) for value in values]
    held = float(np.mean(values)) if held is None else held
    holdout = [one(js.Turn(a * DEG, duration=300.0, dt=0.5), held,
                   f"turn {a:+d} at {held} {unit}") for a in HOLDOUT]
    return train, holdout


def race_records(K, T, gain, seed, *, rpms=(1.0, 2.0)):
    """`condition_records` of Nomoto 1 ($K$ [1/s], $T$ [s]) whose rudder sits in the
    propeller race (`PropellerRace(gain)`) at the propeller rates `rpms` [rev/s]: at
    a constant rate the race is a rudder gain, so each record is Nomoto 1 with
    $K + b n^2$."""
    return condition_records(lambda n: js.Nomoto1(K=K + gain * n**2, T=T), seed, values=rpms)


def wind_records(truth, seed, *, speed=7.0, wind=(15.0, 60.0 * DEG), noise=(0.1, 0.05)):
    """`(train, holdout)` of a steering `truth` that feels the wind (`ApparentWind`):
    10/10 zig-zags to starboard on four headings (N, E, S, W) to train, +-20 deg turns
    held out, at a logged constant surge speed `speed` [m/s] (v = 0) in a steady true
    wind `(speed [m/s], direction it comes from [rad])` that is logged. The wind the
    ship feels follows the heading it steers, so each record is the fixed point of
    replaying the logged rudder through `truth` (output error, 10 substeps per
    sample, 8 passes) from the calm-water record turned to its heading."""
    rng = np.random.default_rng(seed)
    replay = js.PredictionError(horizon=None, wind=True,
                                simulator=js.Simulator(max_step=math.inf, substeps=10))

    def one(manoeuvre, heading, name):
        calm = js.simulate(truth, dataclasses.replace(manoeuvre, rudder_rate=2.3 * DEG),
                           simulator=FINE)
        t, delta = np.asarray(calm.t), np.asarray(calm.state.delta)
        logged = dict(u=np.full(t.size, speed), v=np.zeros(t.size),
                      wind_speed=np.full(t.size, wind[0]), wind_dir=np.full(t.size, wind[1]))
        psi, r = np.asarray(calm.state.psi) + heading, np.asarray(calm.state.r)
        for _ in range(8):
            out = js.predict(truth, js.Experiment(t, delta, psi=psi, r=r, **logged),
                             estimator=replay)
            hit = np.asarray(out.predicted[0])
            psi = np.where(hit, np.asarray(out.predictions["psi"][0]), psi)
            r = np.where(hit, np.asarray(out.predictions["r"][0]), r)
        return js.Experiment(t, delta, psi=psi + rng.normal(0, noise[0] * DEG, t.size),
                             r=r + rng.normal(0, noise[1] * DEG, t.size), name=name, **logged)

    train = [one(js.ZigZag(10 * DEG, 10 * DEG, duration=400.0, dt=0.5), h * DEG,
                 f"zigzag 10/10 heading {h}") for h in (0, 90, 180, 270)]
    holdout = [one(js.Turn(a * DEG, duration=300.0, dt=0.5), 0.0, f"turn {a:+d}")
               for a in HOLDOUT]
    return train, holdout


def run_case(effects, seed, *, base=None, disturbance_std=0.0, records=None, **options):
    """Discovery on records of `base` (default Nomoto 1, K = 0.06 1/s, T = 25 s) with
    `effects` hidden, made by `records(truth, seed)` (default `hidden_effect_records`;
    e.g. `wind_records`); returns `(report, seconds)`."""
    base = js.Nomoto1(K=0.06, T=25.0) if base is None else base
    truth = js.augment(base, *effects) if effects else base
    if records is None:
        train, holdout = hidden_effect_records(truth, seed, disturbance_std=disturbance_std)
    else:
        train, holdout = records(truth, seed)
    start = js.Nomoto1(K=0.05, T=20.0) if isinstance(base, js.Nomoto1) else base
    began = time.perf_counter()
    report = js.discover(start, train, holdout, **options)
    return report, time.perf_counter() - began


def outcome(report, hidden_ids) -> str:
    """`"correct"` (every hidden effect named or in a named class, nothing else),
    `"missed"` (something hidden not named, nothing wrong named), `"wrong"` (a
    named effect whose class holds no hidden one) or `"nothing"` (null data,
    nothing named)."""
    classes = report.names_or_classes()
    if any(not (c & set(hidden_ids)) for c in classes):
        return "wrong"
    if not hidden_ids:
        return "nothing"
    found = {h for h in hidden_ids if any(h in c for c in classes)}
    return "correct" if found == set(hidden_ids) else "missed"


def vessel_records(truth, seed, *, duration=800.0, noise=(0.1, 0.05, 0.02, 0.02, 1.0),
                   wind=None, over_ground=False):
    """`(train, holdout)` of a 3-DOF `truth` vessel (e.g. the Mariner with an effect):
    10/10 and 20/20 zig-zags to both sides to train, +-35 deg turning circles and a
    15/15 zig-zag held out, `duration` s at 2 Hz from the nominal straight run, with
    the servo's rudder logged at the samples and noise on psi [deg], r [deg/s], u, v
    [m/s] and the positions x, y [m] (GNSS; rudder and rpm exact): 8 channels per
    record. With a steady true `wind` (`jaxship.Wind`) the ship sails in it and the
    records log it (10 channels). With `over_ground` the logged u, v are over ground (GNSS:
    `Experiment.over_ground`), the through-water ones plus the truth's current in body
    axes (`AbstractVessel.with_current`)."""
    rng = np.random.default_rng(seed)
    x0 = js.straight_run(truth)
    environment = js.Environment() if wind is None else js.Environment(wind=wind)

    def one(manoeuvre, name):
        traj = js.simulate(truth, manoeuvre, x0, environment=environment, simulator=FINE)
        e = js.Experiment.from_trajectory(traj, name=name)
        u, v = e.u, e.v
        if over_ground:  # u_g = u + V_N cos psi + V_E sin psi, v_g = v - V_N sin psi + V_E cos psi
            north, east = (float(c) for c in truth.environment(environment).current.velocity())
            u = u + north * np.cos(e.psi) + east * np.sin(e.psi)
            v = v - north * np.sin(e.psi) + east * np.cos(e.psi)
        scale = {"psi": noise[0] * DEG, "r": noise[1] * DEG, "u": noise[2], "v": noise[3],
                 "x": noise[4], "y": noise[4]}
        clean = {"psi": e.psi, "r": e.r, "u": u, "v": v, "x": e.x, "y": e.y}
        noisy = {c: clean[c] + rng.normal(0, s, e.t.size) for c, s in scale.items()}
        logged = {} if wind is None else {
            "wind_speed": np.full(e.t.size, float(wind.speed)),
            "wind_dir": np.full(e.t.size, float(wind.direction))}
        return js.Experiment(e.t, e.delta, psi=truth.measure("psi", noisy["psi"]),
                             r=truth.measure("r", noisy["r"]), u=noisy["u"], v=noisy["v"],
                             x=noisy["x"], y=noisy["y"], n=e.n, name=name, **logged,
                             metadata=(("velocities", "over ground"),) if over_ground else ())

    # the helm reverses the rudder at the control step nearest to the crossing (10 Hz), as
    # a sampled autopilot does, not inside a step (the default)
    zigzag = functools.partial(js.ZigZag, duration=duration, dt=0.5,
                               switch_at=js.strategies.SwitchAtNearestStep())
    train = [one(zigzag(a * DEG, s * a * DEG),
                 f"zigzag {a}/{a} {'starboard' if s > 0 else 'port'}") for a, s in TRAIN]
    holdout = [one(js.Turn(a * DEG, duration=duration, dt=0.5), f"turn {a:+d}")
               for a in (35, -35)]
    holdout.append(one(zigzag(15 * DEG, 15 * DEG), "zigzag 15/15"))
    return train, holdout


def run_vessel_case(effects, seed, *, duration=400.0, over_ground=True, **options):
    """Discovery from the Mariner preset on `vessel_records` of the Mariner with `effects`
    hidden (u, v over ground by default, as GNSS logs them); returns `(report, seconds)`."""
    truth = js.augment(js.get_vessel("mariner"), *effects)
    train, holdout = vessel_records(truth, seed, duration=duration, over_ground=over_ground)
    began = time.perf_counter()
    report = js.discover(js.get_vessel("mariner"), train, holdout, **options)
    return report, time.perf_counter() - began


def covered(report, truth: dict) -> bool | None:
    """Whether every named estimate of a parameter in `truth` `{name: value}` holds the
    true value within its interval (`EffectParameter.covers`: 3 standard errors); None
    where no named parameter is in `truth` (an effect named through its class)."""
    checks = [p.covers(truth[n]) for e in report.effects for n, p in e.parameters.items()
              if n in truth]
    return all(checks) if checks else None
