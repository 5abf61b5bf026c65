"""Heading-autopilot design: the linearised yaw equation of any model, PID gains by
pole placement (Odegard 2009, eq. 5.3-5.5; Fossen 2011, sec. 12.2; Fossen 2021,
sec. 15.3) and gradient tuning through the differentiable closed loop."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jaxtyping import Array

from .._foundation._kinematics import ssa
from .._foundation._results import RESULTS, as_code
from .._foundation._state import ShipState
from .._models._control import (
    Feedforward,
    HeadingAutopilot,
    HeadingSteps,
    ReferenceModel,
    yaw_acceleration,
)
from .._models._steering._base import AbstractSteeringModel
from .._models._vessel._base import AbstractVessel, straight_run
from .._simulation._batch import stack
from .._simulation._integrate import Simulator
from .._simulation._simulate import _as_arrays
from ._closed_loop import YawDisturbance, _closed_loop, _setup, tracking_objective


def operating_point(model, speed=None, n=None) -> ShipState:
    """The straight run the design linearises about: for a vessel `straight_run` at
    `speed` [m/s] or propeller rate `n` [rev/s] (neither: its nominal approach); for a
    steering model u = `speed`, v = 0, n = `n` (zero when not given)."""
    if isinstance(model, AbstractVessel):
        return straight_run(model, speed=speed, n=n)
    if not isinstance(model, AbstractSteeringModel):
        raise ValueError(f"`model` must be a vessel or a steering model, got "
                         f"{type(model).__name__}.")
    zero = jnp.zeros(())
    value = lambda x: zero if x is None else jnp.asarray(x, dtype=float)
    return ShipState(u=value(speed), v=zero, r=zero, x=zero, y=zero, psi=zero, delta=zero,
                     n=value(n))


def yaw_inertia(model, *, speed=None, n=None) -> tuple[Array, Array]:
    """`(m, d)` of the linearised yaw equation $m\\dot r + d r = \\delta$ of `model` (a
    vessel or a steering model) about the straight run `operating_point(model, speed,
    n)`, from $f(r, \\delta) = \\dot r$ (`yaw_acceleration`) by `jax.jacfwd` at
    $r = \\delta = 0$: $m = 1/f_\\delta$, $d = -f_r/f_\\delta$ (sway held at its
    straight-run value). For `Nomoto1` $m = T/K$, $d = 1/K$ exactly, the thesis' "m"
    of eq. 5.3-5.5. **Raises** `ValueError` where the rudder has no effect (e.g. a
    speed-dependent model at zero speed: give `speed`)."""
    state = operating_point(model, speed, n)
    zero = jnp.zeros(())
    f_r, f_delta = jax.jacfwd(lambda r, d: yaw_acceleration(model, r, d, state),
                              argnums=(0, 1))(zero, zero)
    if not float(f_delta) != 0:
        raise ValueError(f"the rudder of {type(model).__name__} has no yaw effect at u = "
                         f"{float(state.u)} m/s, n = {float(state.n)} rev/s: give `speed`/`n`.")
    return 1.0 / f_delta, -f_r / f_delta


def natural_frequency_of(bandwidth, damping):
    """$\\omega_n = \\omega_b/\\sqrt{1 - 2\\zeta^2 + \\sqrt{4\\zeta^4 - 4\\zeta^2 + 2}}$
    (thesis, after eq. 5.5; Fossen 2011, sec. 12.2)."""
    z2 = damping * damping
    return bandwidth / np.sqrt(1 - 2 * z2 + np.sqrt(4 * z2 * z2 - 4 * z2 + 2))


def design_autopilot(model, *, bandwidth=None, natural_frequency=None, damping=1.0,
                     feedforward=True, reference: ReferenceModel = ReferenceModel(),
                     steps: HeadingSteps = HeadingSteps(), max_angle=None, max_rate=None,
                     interval=0.1, speed=None, n=None, subtract_damping=True,
                     anti_windup=True, wave_filter=None) -> HeadingAutopilot:
    """A `HeadingAutopilot` for `model` (an identified steering model or a vessel) by
    pole placement (thesis eq. 5.3-5.5; Fossen 2011, sec. 12.2):

    $$K_p = m\\omega_n^2,\\quad K_d = 2\\zeta\\omega_n m - d,\\quad
    K_i = \\frac{\\omega_n}{10}K_p,$$

    with $(m, d)$ = `yaw_inertia(model, speed=speed, n=n)` and $\\omega_n$ given, or
    from the closed-loop `bandwidth` $\\omega_b$ (`natural_frequency_of`). The PD part
    places the closed-loop pair of $m\\dot r + dr = \\delta$ at $\\omega_n$, $\\zeta$
    exactly; the integral adds a pole near $-\\omega_n/10$ and moves the pair a little.
    `subtract_damping=False` uses the thesis' printed "simplified" $K_d =
    2\\zeta\\omega_n m$ (eq. 5.5), which damps the loop more by $d/(2m\\omega_n)$.

    `feedforward`: True (invert `model` itself), False/None, or another model (or
    a `Feedforward`) to invert. `max_angle`, `max_rate` [rad, rad/s]: default the
    vessel's servo limits, else 35 deg and no rate limit. `reference`, `steps`,
    `interval`, `anti_windup`, `wave_filter`: as `HeadingAutopilot`.
    """
    if (bandwidth is None) == (natural_frequency is None):
        raise ValueError("give exactly one of `bandwidth` and `natural_frequency` [rad/s].")
    w = natural_frequency if bandwidth is None else natural_frequency_of(bandwidth, damping)
    m, d = yaw_inertia(model, speed=speed, n=n)
    kp = m * w**2
    kd = 2 * damping * w * m - (d if subtract_damping else 0.0)
    if feedforward is True:
        feedforward = Feedforward(model)
    elif feedforward is False:
        feedforward = None
    elif feedforward is not None and not isinstance(feedforward, Feedforward):
        feedforward = Feedforward(feedforward)
    servo = model.rudder if isinstance(model, AbstractVessel) else None
    if max_angle is None:
        max_angle = servo.max_angle if servo is not None else float(np.deg2rad(35.0))
    if max_rate is None:
        max_rate = servo.max_rate if servo is not None else float("inf")
    return HeadingAutopilot(kp=kp, ki=w / 10 * kp, kd=kd, reference=reference, steps=steps,
                            feedforward=feedforward, max_angle=max_angle, max_rate=max_rate,
                            interval=interval, anti_windup=anti_windup,
                            wave_filter=wave_filter)


class TunedAutopilot(eqx.Module):
    """Result of `tune_autopilot`: the tuned `autopilot`, the objective
    (`tracking_objective`) of the start and of the result [rad^2] on the tuning runs,
    the optimiser's step count, its `RESULTS` code `result` (optimistix's, passed through)
    and `success`, `result == successful`; `reference`: with the reference bandwidth tuned
    after the gains (`jaxship.tune_autopilot(..., reference_bandwidth=True)`) its summary
    (the bandwidth before and after, its bounds, the objectives against the ordered
    heading), else None."""

    autopilot: HeadingAutopilot
    objective_before: Array
    objective_after: Array
    num_steps: Array
    result: RESULTS
    reference: dict | None = None

    @property
    def success(self) -> Array:
        return self.result == RESULTS.successful


def _tuned_values(autopilot):
    """Getter of the values `tune_autopilot` tunes: the PID gains and, with a
    feed-forward, its acceleration and steady-turn gains (`Feedforward`)."""
    if autopilot.feedforward is None:
        return lambda a: (a.kp, a.ki, a.kd)
    return lambda a: (a.kp, a.ki, a.kd, a.feedforward.gain, a.feedforward.steady_gain)


def _with_gains(autopilot, log_gains):
    gains = tuple(jnp.exp(log_gains))
    return eqx.tree_at(_tuned_values(autopilot), autopilot, gains)


def tune_autopilot(plant, autopilot: HeadingAutopilot, *, speeds=None, rpm=None,
                   duration: float = 300.0, dt: float = 1.0, rudder_weight: float = 0.1,
                   disturbance: YawDisturbance | None = None, max_steps: int = 30,
                   rtol: float = 1e-4, atol: float = 1e-8,
                   simulator: Simulator = Simulator(), throw: bool = False) -> TunedAutopilot:
    """Tune `kp`, `ki`, `kd` of `autopilot` on `plant` and, with a feed-forward, its
    `gain` and `steady_gain` (`Feedforward`: the model's inverse split into its
    acceleration and steady-turn parts), by minimising `tracking_objective` (mean
    squared heading error plus `rudder_weight` times the mean squared rudder command)
    over the closed-loop runs at all `speeds` (or `rpm`) at once, sampled every `dt`
    [s] for `duration` [s].

    Levenberg-Marquardt (optimistix) on the residuals $\\tilde\\psi_k/\\sqrt N$,
    $\\sqrt w\\,\\delta_{c,k}/\\sqrt N$, whose sum of squares is the objective, with the
    gains in log space (they stay positive; the start must be positive) and the
    Jacobian by forward mode through the simulation. One gain set for all speeds (no
    gain schedule). The reference model, the feed-forward's model and the limits stay
    as they are.
    `throw`: raise (optimistix's error) unless the optimiser converged; default False, the
    outcome in `TunedAutopilot.result`.
    """
    gains = np.array([np.asarray(g) for g in _tuned_values(autopilot)(autopilot)],
                     dtype=float)
    if gains.ndim != 1 or not np.all(gains > 0):
        raise ValueError(f"tune one autopilot with positive gains, got {gains}.")
    plant, x0, dt_, num, simulator, steps = _setup(plant, speeds, rpm, duration, dt,
                                                   disturbance, simulator)
    autopilot = _as_arrays(autopilot)

    def run(log_gains):
        batch = stack([_with_gains(autopilot, log_gains)])
        return _closed_loop(plant, batch, x0, dt_, num, simulator, steps)

    def residuals(log_gains, args):
        loop = run(log_gains)
        count = loop.psi.size
        error = ssa(loop.psi_d - loop.psi).ravel() / np.sqrt(count)
        effort = np.sqrt(rudder_weight / count) * loop.delta_c.ravel()
        return jnp.concatenate([error, effort])

    objective = lambda y: tracking_objective(run(y), rudder_weight)
    start = jnp.log(jnp.asarray(gains))
    solution = optx.least_squares(residuals, optx.LevenbergMarquardt(rtol=rtol, atol=atol),
                                  start, max_steps=max_steps, throw=throw)
    return TunedAutopilot(
        autopilot=_with_gains(autopilot, solution.value),
        objective_before=objective(start),
        objective_after=objective(solution.value),
        num_steps=solution.stats["num_steps"],
        result=as_code(solution.result),
    )
