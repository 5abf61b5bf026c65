"""The feed-forward's steady turn where the heading step steers (issue 61): the straight
run of a vessel at a propeller rate or speed (`operating_point`), the step's peak desired
yaw rate, the rudder the vessel itself needs there (two points of Bech's reverse spiral
flown in closed loop, `vessel_steady_rudder`), the model's own rudder there
(`feedforward_at_step`), the steady-turn gain between them (`steady_turn_trial`) and the
choice between two models by it (`nearest_steady_turn`). `design` is the autopilot
study's `AutopilotDesign` (its step, reference frequency, run length and output interval)."""

import math

import numpy as np

import jaxship as js


def operating_point(plant, *, rpm=None, speed=None) -> tuple[float, float]:
    """(u [m/s], n [rev/s]) of the straight run of the vessel `plant` at `rpm` or
    `speed` (one number)."""
    if rpm is not None:
        state = js.straight_run(plant, n=float(rpm) / 60.0)
    else:
        state = js.straight_run(plant, speed=float(speed))
    return float(state.u), float(state.n)


def peak_reference_rate(design) -> float:
    """The step's peak desired yaw rate $r_p = A\\omega\\,2e^{-2}$ [rad/s]: the peak of
    $\\dot\\psi_d$ of eq. 5.7 at damping 1 for a step $A$ (`reference_rudder_frequency`)."""
    return math.radians(abs(design.step)) * design.reference_frequency * 2 * math.exp(-2)


def vessel_steady_rudder(plant, pid, design, *, rpm=None, speed=None) -> float:
    """The rudder [rad] the vessel `plant` itself needs to turn steadily at the step's
    peak desired yaw rate $r_p$ (`peak_reference_rate`), at `rpm` or `speed`: two
    points of Bech's reverse spiral (MSC/Circ.1053, app. 4, 2.2), flown in closed loop
    at $+r_p$ and $-r_p$ (`YawRateLevels`, each for the design's run length) by the
    gains and limits of the `pid` autopilot (the design's feedback, no feed-forward),
    the mean rudder over the last quarter of each level; half their difference (a
    rudder offset of the vessel drops out). **Raises** `ValueError` where the vessel
    did not settle on the levels (mean yaw rate of a last quarter more than 10 % off
    its level, or the run not finite). For a course-unstable vessel at small
    $r_p$ this is a point inside its spiral loop, where zig-zags at 10-20 deg do not
    steer."""
    r_p, hold = peak_reference_rate(design), design.duration
    pilot = js.HeadingAutopilot(kp=pid.kp, ki=pid.ki, kd=pid.kd, reference=None,
                                steps=js.YawRateLevels(rates=(r_p, -r_p), hold=hold),
                                max_angle=pid.max_angle, max_rate=pid.max_rate,
                                interval=pid.interval)
    run = js.closed_loop(plant, pilot, duration=2 * hold, dt=design.dt,
                         **({"rpm": [rpm]} if rpm is not None else {"speeds": [speed]}))
    t, delta, r = np.asarray(run.t), np.asarray(run.delta)[0, 0], np.asarray(run.r)[0, 0]
    last = [(t > (k + 0.75) * hold) & (t <= (k + 1) * hold) for k in (0, 1)]
    rates = [float(np.mean(r[part])) for part in last]
    # a steady turn: the mean yaw rate of each last quarter within 10 % of its level
    if not (bool(np.asarray(run.success)[0, 0]) and abs(rates[0] - r_p) <= 0.1 * r_p
            and abs(rates[1] + r_p) <= 0.1 * r_p):
        raise ValueError(f"the vessel did not settle on the reverse-spiral trial's yaw rates "
                         f"+-{math.degrees(r_p):.3g} deg/s (mean "
                         f"{math.degrees(rates[0]):.3g}, {math.degrees(rates[1]):.3g} "
                         "deg/s).")
    return float(np.mean(delta[last[0]]) - np.mean(delta[last[1]])) / 2


def feedforward_at_step(model, plant, design, *, speed: float, n: float) -> dict:
    """Which model the feed-forward inverts and how it steers where the step steers
    (JSON-ready, degrees and 1/s): at the step's peak desired yaw rate $r_p$
    (`peak_reference_rate`) the model's steady-turn rudder $\\delta_s$
    (`Feedforward.inverse` with $\\dot r_d = 0$) and its gain $r_p/\\delta_s$,
    against the linear gain $1/d$ of `yaw_inertia` about the straight run (K for
    Nomoto models)."""
    state = js.straight_run(plant, speed=speed)  # the measured u, v, n the inverse uses
    r_peak = peak_reference_rate(design)
    steady = float(js.Feedforward(model).inverse(r_peak, 0.0, state))
    return {"model": type(model).__name__, "peak_rate_deg_s": math.degrees(r_peak),
            "model_rudder_deg": math.degrees(steady),
            "model_gain_1_s": r_peak / steady if steady != 0 else None,
            "linear_gain_1_s": 1.0 / float(js.yaw_inertia(model, speed=speed, n=n)[1])}


# the least steady-turn gain a trial sets: a point measured inside a spiral loop can be
# at or below zero rudder; the feed-forward then orders (almost) no steady rudder, and
# `tune_autopilot` (log-space gains) can still start from it
LEAST_STEADY_GAIN = 0.01


def steady_turn_trial(model, plant, design, pid, *, rpm=None, speed=None) -> dict:
    """`feedforward_at_step` at the operating point `rpm` or `speed` with the rudder
    the vessel `plant` needs there ("vessel_rudder_deg", `vessel_steady_rudder` flown by
    `pid`) and the feed-forward's steady-turn gain from them, "steady_gain"
    $g_s = \\delta_{vessel}(r_p)/\\delta_s(r_p)$ (at least `LEAST_STEADY_GAIN`): the
    model's steady-turn characteristic corrected at the one yaw rate where the step
    steers. Zig-zags at 10-20 deg do not reach the small yaw rates of a heading step,
    where a course-unstable ship is inside its spiral loop (Bech 1966; MSC/Circ.1053
    app. 4); the reverse spiral is the trial that measures the steady turn there. The
    acceleration part ($T\\dot r_d/K$, the yaw inertia per rudder angle) stays the
    model's. Where the vessel does not settle on the trial's yaw rates (a step faster than
    it can turn steadily) "vessel_rudder_deg" is None, "steady_gain" 1 and
    "trial_failed" says why."""
    key, value = ("rpm", rpm) if rpm is not None else ("speed", speed)
    u, n = operating_point(plant, **{key: value})
    at_step = feedforward_at_step(model, plant, design, speed=u, n=n)
    try:
        vessel = math.degrees(vessel_steady_rudder(plant, pid, design, rpm=rpm, speed=speed))
    except ValueError as error:  # not measured: the model's own steady turn, said so
        return at_step | {"vessel_rudder_deg": None, "steady_gain": 1.0,
                          "trial_failed": str(error)}
    return _scaled(at_step, vessel)


def _scaled(at_step: dict, vessel: float) -> dict:
    """`at_step` (`feedforward_at_step`) with the vessel's rudder [deg] there and the
    steady-turn gain to it (`steady_turn_trial`)."""
    ratio = vessel / at_step["model_rudder_deg"] if at_step["model_rudder_deg"] else 1.0
    return at_step | {"vessel_rudder_deg": vessel,
                      "steady_gain": max(ratio, LEAST_STEADY_GAIN)}


def nearest_steady_turn(models, plant, design, pid, *, rpm=None,
                        speed=None) -> tuple:
    """`(model, trial)`: of `models` (the feed-forward's model, then the poles' one), the
    one whose steady-turn rudder at the step's peak desired yaw rate is nearest the one
    the vessel `plant` needs there, and its `steady_turn_trial`: the least
    $|\\log(\\delta_s/\\delta_{vessel})|$, a rudder of the other sign (or zero) never
    nearer, the first model on a tie or where none is near (or the trial failed). The
    trial then also has "candidates" {class: steady-turn rudder [deg]}. The model that
    fits the step it steers (issue 61): the Norrbin model of the KVLCC2's zig-zags turns
    steadily there, inside its spiral loop, with -0.73 deg where the `kvlcc2` preset
    needs +0.03 deg; the linear Nomoto 1 of the same records, +1.31 deg."""
    first = steady_turn_trial(models[0], plant, design, pid, rpm=rpm, speed=speed)
    vessel = first["vessel_rudder_deg"]
    if not vessel or models[1] is models[0]:
        return models[0], first
    u, n = operating_point(plant, **({"rpm": rpm} if rpm is not None else {"speed": speed}))
    trials = [first, _scaled(feedforward_at_step(models[1], plant, design, speed=u, n=n),
                             vessel)]

    def distance(trial):
        steady = trial["model_rudder_deg"]
        return abs(math.log(steady / vessel)) if steady * vessel > 0 else math.inf

    k = min((0, 1), key=lambda i: distance(trials[i]))
    return models[k], trials[k] | {"candidates": {type(m).__name__: t["model_rudder_deg"]
                                                  for m, t in zip(models, trials)}}


def feedforward_gain_text(at_step: dict) -> str:
    """`feedforward_at_step` (with, where measured, the vessel's own rudder
    "vessel_rudder_deg", `vessel_steady_rudder`) in words."""
    gain = at_step["model_gain_1_s"]
    text = (f"The feed-forward inverts the {at_step['model']} model. At the step's peak "
            f"desired yaw rate {at_step['peak_rate_deg_s']:.3g} deg/s its steady-turn rudder "
            f"is {at_step['model_rudder_deg']:.3g} deg: a gain r/delta = "
            f"{math.inf if gain is None else gain:.4g} 1/s where the autopilot steers, "
            f"against the identified model's linear gain 1/d = "
            f"{at_step['linear_gain_1_s']:.4g} 1/s at r = 0.")
    vessel = at_step.get("vessel_rudder_deg")
    if vessel:  # measured and not zero
        text += (f" The vessel steered needs {vessel:.3g} deg there (a reverse-spiral point "
                 f"flown in closed loop): the model's steady-turn rudder is "
                 f"{at_step['model_rudder_deg'] / vessel:.3g} times the vessel's.")
    if "candidates" in at_step:  # `nearest_steady_turn`
        rudders = ", ".join(f"{name} {x:.3g} deg" for name, x in at_step["candidates"].items())
        text += (f" Of the candidates' steady-turn rudders there ({rudders}) the "
                 f"{at_step['model']}'s is the nearest to the vessel's (a rudder of the other "
                 "sign is never near), so the feed-forward inverts it.")
    if at_step.get("trial_failed"):
        text += (f" The reverse-spiral trial failed ({at_step['trial_failed']}): the "
                 "feed-forward's steady-turn part stays the model's.")
    elif "steady_gain" in at_step:
        text += (f" The feed-forward's steady-turn part is scaled by g_s = "
                 f"{at_step['steady_gain']:.3g} to the vessel's (--steady-turn trial).")
    return text
