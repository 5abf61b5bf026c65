"""The reference model's bandwidth tuned on the vessel (issue 61, `jaxship autopilot --tune`).

A faster reference model (thesis eq. 5.7) brings the desired heading $\\psi_d$ sooner to
the ordered one $\\psi_{ref}$, the step; its feed-forward then asks for more rudder and
rudder rate. The bandwidth $\\omega$ is therefore chosen

- **within the rudder's limits**: the feed-forward rudder for the step (the tuned
  `Feedforward`, its gains included) and its rate stay within a share of the rudder's
  angle and rate limits (`RudderDemand`; half, `RUDDER_SHARE`: the rest is the
  feedback's), as the untuned design's omega_n does; a faster reference may take a
  smaller acceleration gain of the feed-forward to stay within them;
- **against the ordered heading**: the objective is $\\overline{\\mathrm{ssa}(\\psi_{ref}
  - \\psi)^2} + w\\,\\overline{\\delta_c^2}$ over the closed-loop runs on the vessel
  (`ordered_objective`). Against $\\psi_d$ a faster reference would never pay: the error
  to the reference says how well the loop follows it, not how soon the ship is on the
  ordered course.
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxship as js

from .._analysis._autopilot import tune_autopilot as tune_gains
from ._autopilot_steady_turn import operating_point


# the grid of the bandwidth search: log-spaced from the lower end to the rudder's bound
GRID_POINTS = 17
LOWEST_SHARE = 0.5  # the grid's lower end: half the untuned bandwidth (or the bound)


def reference_shape(damping: float, *, end: float = 30.0, num: int = 3001):
    """`(x, g1, g2)`: the unit step response of the reference model (eq. 5.7) at
    $\\omega = 1$ and `damping`, stepped by `ReferenceModel.step` to $x = \\omega t$ =
    `end`: $r_d = A\\omega\\,g_1(\\omega t)$ and $\\dot r_d = A\\omega^2 g_2(\\omega t)$ for
    a step $A$ at any $\\omega$ (the filter is linear and time-invariant)."""
    reference, h = js.ReferenceModel(natural_frequency=1.0, damping=float(damping)), \
        end / (num - 1)
    step = lambda state, _: (reference.step(state, 1.0, h),) * 2
    states = np.asarray(jax.lax.scan(step, jnp.zeros(3), length=num - 1)[1])
    states = np.vstack([np.zeros(3), states])
    return np.linspace(0.0, end, num), states[:, 1], states[:, 2]


@eqx.filter_jit
def _feedforward_peaks(feedforward, state, g1, g2, dx, w, step):
    """Peak |delta_ff| [rad] and |d delta_ff / dt| [rad/s] along the step at `w`."""
    rudder = jax.vmap(lambda r, a: feedforward(r, a, state))(step * w * g1, step * w * w * g2)
    return jnp.max(jnp.abs(rudder)), jnp.max(jnp.abs(jnp.diff(rudder))) / dx * w


class RudderDemand:
    """The feed-forward's demand on the rudder for a heading step of `step` [rad] at the
    measured straight-run `state`: `(feedforward, w)` -> the larger of its peak angle and
    peak rate along the reference (`reference_shape` at `damping`, bandwidth `w`
    [rad/s]), as shares of `share` times the rudder's limits `max_angle` [rad] and
    `max_rate` [rad/s] (an infinite rate limit: no rate bound). 1: exactly at the bound."""

    def __init__(self, state, step, max_angle, max_rate, *, damping=1.0, share=0.5):
        x, g1, g2 = reference_shape(damping)
        self.shape = (jnp.asarray(g1), jnp.asarray(g2), float(x[1] - x[0]))
        self.state, self.step = state, jnp.asarray(float(step))
        self.limits = (float(max_angle) * share, float(max_rate) * share)

    def __call__(self, feedforward, w: float) -> float:
        g1, g2, dx = self.shape
        angle, rate = _feedforward_peaks(feedforward, self.state, g1, g2, dx,
                                         jnp.asarray(float(w)), self.step)
        return max(float(angle) / self.limits[0], float(rate) / self.limits[1])

    def frequency_bound(self, feedforward) -> float:
        """The largest bandwidth [rad/s] with a demand of at most 1 (bisection on a log
        scale, 1e-6 to 1e2 rad/s to 1e-8 relative; both peaks grow with the bandwidth for
        a rudder monotonic in $r_d$, $\\dot r_d$)."""
        low, high = 1e-6, 1e2
        for _ in range(60):
            mid = math.sqrt(low * high)
            low, high = (mid, high) if self(feedforward, mid) <= 1.0 else (low, mid)
        return low

    def gain_bound(self, feedforward, w: float) -> float:
        """The largest acceleration gain $g_a$ (`Feedforward.gain`), at most the
        feed-forward's own, with a demand of at most 1 at bandwidth `w` (bisection; 0 where
        the steady-turn part alone asks for more)."""
        with_gain = lambda g: eqx.tree_at(lambda f: f.gain, feedforward, jnp.asarray(g))
        own = float(feedforward.gain)
        if self(with_gain(own), w) <= 1.0:
            return own
        low, high = 0.0, own
        for _ in range(40):
            mid = 0.5 * (low + high)
            low, high = (mid, high) if self(with_gain(mid), w) <= 1.0 else (low, mid)
        return low


def ordered_objective(run, rudder_weight: float) -> np.ndarray:
    """Per autopilot of `run` (a `ClosedLoop`): $\\overline{\\mathrm{ssa}(\\psi_{ref} -
    \\psi)^2} + w\\,\\overline{\\delta_c^2}$ [rad^2] over its speeds and samples, the
    objective of `tune_autopilot` with the ordered heading in place of the reference's."""
    error = np.angle(np.exp(1j * (np.asarray(run.psi_ref) - np.asarray(run.psi))))
    return (np.mean(error**2, axis=(1, 2))
            + rudder_weight * np.mean(np.asarray(run.delta_c) ** 2, axis=(1, 2)))


def ordered_error_deg(run, sample_interval: float, window) -> np.ndarray:
    """The summed |psi_ref - psi| [deg] (thesis eq. 3.19 against the ordered heading, the
    step, in place of the reference model's output), sampled every `sample_interval` [s]
    over `window` = (start, end) [s] as `closed_loop_metrics`: (autopilots, speeds)."""
    t = np.asarray(run.t)
    dt = float(t[1] - t[0])
    every = int(round(sample_interval / dt))
    inside = (t >= window[0] - 1e-9 * dt) & (t <= window[1] + 1e-9 * dt)
    sampled = np.zeros_like(inside)
    sampled[int(np.argmax(inside))::every] = True
    pick = np.flatnonzero(sampled & inside)
    error = np.angle(np.exp(1j * (np.asarray(run.psi_ref) - np.asarray(run.psi))))
    return np.degrees(np.sum(np.abs(error[..., pick]), axis=-1))


def tune_reference(plant, autopilot, demand: RudderDemand, *, duration: float, dt: float,
                   rudder_weight: float, run_kw: dict):
    """`(autopilot, summary)`: the reference bandwidth $\\omega$ of `autopilot` (its PID
    gains kept) that minimises `ordered_objective` on `plant` (closed loops of `duration`
    [s], output every `dt` [s], at the operating points `run_kw`) with its feed-forward's
    rudder for the step within the limits of `demand`. The bandwidth and the
    feed-forward's acceleration gain $g_a$ share the rudder: each candidate $\\omega$ takes
    the largest $g_a$ up to the autopilot's own within the limits (`gain_bound`). The
    candidates: a log grid of `GRID_POINTS` from `LOWEST_SHARE` times the smaller of its own
    bandwidth and the bound with its own $g_a$ up to the bound with $g_a$ at most 1 (the
    model's own inverse; `frequency_bound`), its own bandwidth added (compared, and chosen
    only where within the limits); all in one batched closed loop. `summary`: the
    bandwidth before and after, the bounds, the acceleration gain after, the objective at
    both (before: its own bandwidth, its gains where within the limits)."""
    ff = autopilot.feedforward
    own, g_own = float(autopilot.reference.natural_frequency), float(ff.gain)
    bound = demand.frequency_bound(ff)
    model_gain = eqx.tree_at(lambda f: f.gain, ff, jnp.asarray(min(g_own, 1.0)))
    top = max(bound, demand.frequency_bound(model_gain))
    grid = np.unique(np.append(np.geomspace(LOWEST_SHARE * min(own, bound), top, GRID_POINTS),
                               own))
    gains = [demand.gain_bound(ff, w) for w in grid]
    candidates = [eqx.tree_at(lambda a: (a.reference.natural_frequency, a.feedforward.gain),
                              autopilot, (jnp.asarray(float(w)), jnp.asarray(g)))
                  for w, g in zip(grid, gains)]
    runs = js.closed_loop(plant, candidates, duration=duration, dt=dt, **run_kw)
    objective = ordered_objective(runs, rudder_weight)
    ok = np.asarray(runs.success).all(axis=1) & np.isfinite(objective)
    at_own = int(np.flatnonzero(grid == own)[0])
    # its own bandwidth may lie beyond the limits even without acceleration gain (a
    # --natural-frequency given by hand): compared, never chosen
    within = np.array([demand(c.feedforward, w) <= 1.0 + 1e-9
                       for c, w in zip(candidates, grid)])
    best = (int(np.argmin(np.where(ok & within, objective, np.inf)))
            if (ok & within).any() else at_own)
    return candidates[best], {
        "reference_frequency_before": own, "reference_frequency_after": float(grid[best]),
        "reference_frequency_bound": float(bound), "reference_frequency_top": float(top),
        "ff_gain_before_reference": g_own, "ff_gain_after_reference": float(gains[best]),
        "ordered_objective_before": float(objective[at_own]) if ok[at_own] else None,
        "ordered_objective_after": float(objective[best]) if ok[best] else None,
        "reference_candidates": len(grid)}


# the share of the rudder's angle and rate limits the reference step's feed-forward may
# use (the rest is the feedback's)
RUDDER_SHARE = 0.5


def tune_autopilot(plant, autopilot, *, speeds=None, rpm=None,
                   reference_bandwidth: bool = False, progress=None, **options):
    """Tune `autopilot` on `plant` at `speeds` [m/s] or `rpm`: its gains (`kp`, `ki`,
    `kd` and the feed-forward's `gain`, `steady_gain`) by Levenberg-Marquardt on the
    objective $\\overline{\\mathrm{ssa}(\\psi_d - \\psi)^2} + w\\,\\overline{\\delta_c^2}$
    (`tracking_objective`; the `options` of the gains' tuning: `duration` [s] (300),
    `dt` [s] (1), `rudder_weight` $w$ (0.1), `disturbance`, `max_steps`, `rtol`, `atol`,
    `simulator`, `throw`); then, with
    `reference_bandwidth=True` (`jaxship autopilot --tune`), the reference model's
    bandwidth $\\omega$ (eq. 5.7) against the ordered heading (`tune_reference`): a log
    grid up to what keeps the feed-forward of the autopilot's one heading step within half
    (`RUDDER_SHARE`) of its rudder's angle and rate limits at the straight run of the mean
    operating point (`RudderDemand`), each bandwidth with the largest acceleration gain
    within them. `progress`: a callable taking a message, or None. **Returns** a
    `TunedAutopilot` (with `reference_bandwidth`: the autopilot of both steps and the
    bandwidth's summary in `reference`)."""
    say = progress or (lambda message: None)
    say("tuning the gains on the vessel")
    # the defaults of the gains' tuning (`jaxship._analysis`' `tune_autopilot`), which the
    # bandwidth's runs share
    options = {"duration": 300.0, "dt": 1.0, "rudder_weight": 0.1} | options
    tuned = tune_gains(plant, autopilot, speeds=speeds, rpm=rpm, **options)
    if not reference_bandwidth:
        return tuned
    headings = np.atleast_1d(np.asarray(autopilot.steps.headings, dtype=float))
    if headings.size != 1:
        raise ValueError("the reference bandwidth is tuned for one heading step; the "
                         f"autopilot orders {headings.size}.")
    say("tuning the reference model's bandwidth on the vessel")
    run_kw = {"rpm": rpm} if rpm is not None else {"speeds": speeds}
    demand = RudderDemand(_straight_run(plant, speeds, rpm), float(headings[0]),
                          float(autopilot.max_angle), float(autopilot.max_rate),
                          damping=float(autopilot.reference.damping), share=RUDDER_SHARE)
    better, summary = tune_reference(plant, tuned.autopilot, demand,
                                     duration=options["duration"], dt=options["dt"],
                                     rudder_weight=options["rudder_weight"], run_kw=run_kw)
    return dataclasses.replace(tuned, autopilot=better, reference=summary)


def _straight_run(plant, speeds, rpm):
    """The straight run at the mean of `speeds` or `rpm` (a vessel's, at the speed of its
    run at the mean rpm as `evaluate`'s design point; a steering model: u = the mean speed,
    n = the mean rpm / 60)."""
    if not isinstance(plant, js.AbstractVessel):
        mean = lambda x: 0.0 if x is None else float(np.mean(x))
        return js.ShipState(u=mean(speeds), v=0.0, r=0.0, x=0.0, y=0.0, psi=0.0, delta=0.0,
                            n=mean(rpm) / 60.0)
    key, values = ("rpm", rpm) if rpm is not None else ("speed", speeds)
    u0, _ = operating_point(plant, **{key: float(np.mean(values))})
    return js.straight_run(plant, speed=u0)
