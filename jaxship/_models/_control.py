"""The heading autopilot: a third-order reference model and a PID controller with
reference feed-forward (Odegard 2009, ch. 5, eq. 5.1-5.7; Fossen 2011, ch. 12), run
inside the simulation as an `AbstractController`.

Sign convention of jaxship: a positive rudder angle turns the ship to starboard
($r > 0$), so the feedback terms carry a plus sign on the errors $\\tilde\\psi =
\\mathrm{ssa}(\\psi_d - \\psi)$, $\\tilde r = r_d - r$ (the thesis, after Fossen, writes
$\\tau_N = \\tau_{FF} - K_p\\tilde\\psi - K_d\\tilde r - K_i\\int\\tilde\\psi$ with the
errors the other way round, $\\tilde\\psi = \\psi - \\psi_d$: the same law).
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike

from .._foundation._kinematics import ssa
from .._foundation._state import Command, ShipState
from ._steering._base import AbstractSteeringModel, AuxInputs
from ._vessel._base import AbstractVessel, inverse3


def _floats(x):
    """Numbers and sequences as float NumPy arrays (cast to JAX's default float when
    traced); JAX arrays and tracers as they are."""
    return x if isinstance(x, jax.Array) else np.asarray(x, dtype=float)



class AbstractController(eqx.Module):
    """The controller seam. `init(x0)` gives the controller's memory (a pytree) at the
    initial state; `command(t, state, memory, h)` the `Command` for the control step
    $[t, t + h]$ and the new memory. The simulator calls it at every control step
    (`Simulator.max_step`, 0.1 s by default, whatever the output interval) and carries
    the memory in its scan state, so a closed loop is differentiable (tune gains by
    gradient) and vmappable (over gains, speeds, seeds)."""

    @abc.abstractmethod
    def init(self, x0):
        """The controller's memory at the initial `ShipState` `x0`."""

    @abc.abstractmethod
    def command(self, t, state, memory, h):
        """The command for the control step `[t, t + h]` and the new memory."""


class ReferenceModel(eqx.Module):
    """Third-order reference model (thesis eq. 5.7, after Fossen 2011, ch. 10)

    $$\\frac{\\psi_d}{\\psi_{ref}}(s) = \\frac{\\omega^3}{(s + \\omega)(s^2 + 2\\zeta\\omega s
    + \\omega^2)},\\quad \\psi_d^{(3)} + (2\\zeta + 1)\\omega\\ddot\\psi_d + (2\\zeta + 1)
    \\omega^2\\dot\\psi_d + \\omega^3\\psi_d = \\omega^3\\psi_{ref},$$

    with the state $(\\psi_d, r_d, a_d) = (\\psi_d, \\dot\\psi_d, \\ddot\\psi_d)$. `step`
    advances it over a control step of `h` seconds with $\\psi_{ref}$ held, by the
    classical RK4 (relative error $(\\omega h)^5/120$ per step, 3e-11 at the defaults
    and h = 0.1 s), then saturates the rate at `max_rate` and the acceleration at
    `max_acceleration` (the velocity saturation of Fossen's MSS `refModel3`); while the
    rate is at its limit the acceleration pushing past it is set to zero, so the filter
    does not wind up.
    """

    natural_frequency: ArrayLike = 0.2  # omega [rad/s], thesis Table 5.1
    damping: ArrayLike = 1.0  # zeta [-], thesis Table 5.1
    max_rate: ArrayLike = float("inf")  # |r_d| limit [rad/s]
    max_acceleration: ArrayLike = float("inf")  # |a_d| limit [rad/s^2]

    def derivative(self, state: Array, psi_ref: ArrayLike) -> Array:
        """$(\\dot\\psi_d, \\dot r_d, \\dot a_d)$ of eq. 5.7 at `state`."""
        w, z = self.natural_frequency, self.damping
        psi_d, r_d, a_d = state[0], state[1], state[2]
        jerk = w**3 * (psi_ref - psi_d) - (2 * z + 1) * w**2 * r_d - (2 * z + 1) * w * a_d
        return jnp.stack([r_d, a_d, jerk])

    def step(self, state: Array, psi_ref: ArrayLike, h: ArrayLike) -> Array:
        """The state `h` seconds later with `psi_ref` [rad] held (RK4, then the limits)."""
        k1 = self.derivative(state, psi_ref)
        k2 = self.derivative(state + 0.5 * h * k1, psi_ref)
        k3 = self.derivative(state + 0.5 * h * k2, psi_ref)
        k4 = self.derivative(state + h * k3, psi_ref)
        psi_d, r_d, a_d = state + h * (k1 + 2 * k2 + 2 * k3 + k4) / 6
        r_d = jnp.clip(r_d, -self.max_rate, self.max_rate)
        a_d = jnp.clip(a_d, -self.max_acceleration, self.max_acceleration)
        at_limit = (jnp.abs(r_d) >= self.max_rate) & (a_d * r_d > 0)
        return jnp.stack([psi_d, r_d, jnp.where(at_limit, 0.0, a_d)])


class HeadingSteps(eqx.Module):
    """The ordered heading: $\\psi_{ref}(t) = \\psi_0 +$ `headings[k]` from `times[k]`
    on (the last step taken), $\\psi_0$ before the first step; relative to the initial
    heading $\\psi_0$. Default: thesis Table 5.1, a 45 deg step at 100 s."""

    times: ArrayLike = eqx.field(converter=_floats, default=(100.0,))  # [s], ascending
    headings: ArrayLike = eqx.field(converter=_floats, default=(np.pi / 4,))  # [rad]

    def __check_init__(self):
        if np.shape(self.times) != np.shape(self.headings) or np.ndim(self.times) < 1:
            raise ValueError(f"`times` and `headings` must be 1-D of one length, got shapes "
                             f"{np.shape(self.times)} and {np.shape(self.headings)}.")

    def __call__(self, t: ArrayLike) -> Array:
        """The heading change ordered at time `t` [s] [rad]."""
        taken = jnp.searchsorted(jnp.asarray(self.times), t, side="right")
        values = jnp.concatenate([jnp.zeros((1,)), jnp.asarray(self.headings, dtype=float)])
        return values[taken]

    def rate(self, t: ArrayLike) -> Array:
        """The yaw rate ordered at time `t`: zero between steps [rad/s]."""
        return jnp.zeros_like(jnp.asarray(t, dtype=float))


class YawRateLevels(eqx.Module):
    """An ordered heading that turns at constant rates: `rates[k]` [rad/s] from
    `k hold` to `(k + 1) hold` [s] (the last held after), so $\\psi_{ref}(t) = \\psi_0 +
    \\int_0^t r_{ref}\\,dt$ and $r_{ref}$ is the ordered yaw rate (Bech's reverse spiral
    flown by a heading autopilot; MSC/Circ.1053 app. 4 2.2)."""

    rates: ArrayLike = eqx.field(converter=_floats)  # [rad/s]
    hold: ArrayLike = eqx.field(converter=_floats)  # [s] per level

    def rate(self, t: ArrayLike) -> Array:
        """$r_{ref}(t)$ [rad/s]."""
        rates = jnp.asarray(self.rates, dtype=float)
        k = jnp.clip(jnp.floor(t / self.hold).astype(int), 0, rates.shape[0] - 1)
        return rates[k]

    def __call__(self, t: ArrayLike) -> Array:
        """The heading change ordered at time `t` [s], $\\int_0^t r_{ref}\\,dt$ [rad]."""
        rates = jnp.asarray(self.rates, dtype=float)
        t = jnp.maximum(t, 0.0)
        k = jnp.clip(jnp.floor(t / self.hold).astype(int), 0, rates.shape[0] - 1)
        before = jnp.concatenate([jnp.zeros((1,)), jnp.cumsum(rates) * self.hold])
        return before[k] + rates[k] * (t - k * self.hold)


def yaw_acceleration(model, r: ArrayLike, delta: ArrayLike, state: ShipState) -> Array:
    """$\\dot r$ [rad/s^2] of `model` at yaw rate `r`, rudder angle `delta` and the
    measured surge, sway and propeller rate of `state`.

    - a vessel: the yaw row of $M^{-1}\\tau(u, v, r, \\delta, n)$ (Fossen 2021, eq. 6.1),
      with `forces` (time-invariant loads; give the model without disturbances);
    - a steering model: $\\dot r = h'(x)f(x, \\delta, a)$ at the state of a steady turn
      $x =$ `initial_state(r)` with $a =$ `AuxInputs(u, v, n)`. For models with
      more than one state (Nomoto 2, sway-yaw) the hidden states are taken at their
      steady-turn values for `r`, an approximation while the yaw rate changes (for
      Nomoto 2 it gives $\\delta = r/K + T_1T_2\\dot r/(KT_3)$, large for small
      $T_3$, and no feed-forward at $T_3 = 0$ where $\\dot r$ does not depend on
      $\\delta$).
    """
    if isinstance(model, AbstractVessel):
        tau = model.forces(state.u, state.v, r, delta, state.n)
        return inverse3(model.mass_matrix())[2] @ tau
    if isinstance(model, AbstractSteeringModel):
        x = model.initial_state(r)
        x_dot = model.rhs(x, delta, AuxInputs(state.u, state.v, state.n))
        return jax.jvp(model.output, (x,), (x_dot,))[1]
    raise ValueError(f"the feed-forward model must be a jaxship vessel or steering model, got "
                     f"{type(model).__name__}.")


class Feedforward(eqx.Module):
    """Reference feed-forward by inverting the yaw equation of `model` (a vessel or a
    steering model) along the reference: the rudder $\\delta_{ff}$ with
    $\\dot r(r_d, \\delta_{ff}; u, v, n) = \\dot r_d$ (see `yaw_acceleration`).

    Solved by `newton_steps` Newton steps in $\\delta$ from 0 (derivative by
    `jax.jvp`), each iterate kept within the rudder limit; exact after one step for
    models linear in $\\delta$. For `Nomoto1` it is thesis eq. 5.2,
    $\\delta_{ff} = (T\\dot r_d + r_d)/K$ (less the offset $\\delta_0$); for
    `RossAutopilot` thesis eq. 5.6 (the hull moment along the reference, divided by
    the rudder's moment per angle). Where the rudder has no effect (zero speed) it
    returns 0.

    **Gains.** The inverse splits into the steady-turn rudder $\\delta_s = \\delta_{ff}(r_d,
    0)$ (the manoeuvring characteristic, Norrbin's $H(r_d)/K$ for `NonlinearNomoto`;
    Astrom & Kallstrom 1979, sec. 2) and the acceleration part $\\delta_{ff}(r_d,
    \\dot r_d) - \\delta_s$ ($T\\dot r_d/K$ for Nomoto models), weighted by `gain` $g_a$
    and `steady_gain` $g_s$:

    $$\\delta = g_a\\,[\\delta_{ff}(r_d, \\dot r_d) - \\delta_s] + g_s\\,\\delta_s.$$

    Both 1 (default): the model's inverse itself. The acceleration part rests on the
    yaw inertia per rudder angle $T/K$, which zig-zags determine well; the steady part
    on the characteristic at the small yaw rates of an autopilot's turn, which they
    barely excite (a course-unstable ship's spiral loop lies inside it), so
    `tune_autopilot` tunes both on the vessel.
    """

    model: AbstractVessel | AbstractSteeringModel
    newton_steps: int = eqx.field(static=True, default=2)
    gain: ArrayLike = 1.0  # g_a [-] on the acceleration part
    steady_gain: ArrayLike = 1.0  # g_s [-] on the steady-turn part

    def inverse(self, r_d: ArrayLike, r_dot_d: ArrayLike, state: ShipState,
                limit: ArrayLike = np.pi / 2) -> Array:
        """The model's rudder $\\delta_{ff}$ [rad] with $\\dot r(r_d, \\delta_{ff}) =
        \\dot r_d$ at the measured `state`, within $\\pm$`limit` (Newton, class text)."""
        def residual(delta):
            return yaw_acceleration(self.model, r_d, delta, state) - r_dot_d

        delta = jnp.zeros_like(jnp.asarray(r_d, dtype=float))
        for _ in range(self.newton_steps):
            value, slope = jax.jvp(residual, (delta,), (jnp.ones_like(delta),))
            usable = jnp.abs(slope) > 1e-300
            delta = delta - jnp.where(usable, value / jnp.where(usable, slope, 1.0), 0.0)
            delta = jnp.clip(delta, -limit, limit)
        return delta

    def __call__(self, r_d: ArrayLike, r_dot_d: ArrayLike, state: ShipState,
                 limit: ArrayLike = np.pi / 2) -> Array:
        """$\\delta$ [rad] of the class text for the desired yaw rate `r_d` and
        acceleration `r_dot_d` at the measured `state`."""
        full = self.inverse(r_d, r_dot_d, state, limit)
        steady = self.inverse(r_d, jnp.zeros_like(jnp.asarray(r_dot_d, dtype=float)), state,
                              limit)
        return self.gain * (full - steady) + self.steady_gain * steady


class AutopilotMemory(eqx.Module):
    """The autopilot's memory, carried in the simulated state: the reference model's
    state (psi_d, r_d, a_d) at the step's start, the integral of the heading error
    [rad s], the command held [rad], the time of the next update [s] (-inf before the
    first) and the initial heading the steps are relative to [rad]."""

    reference: Array
    integral: Array
    command: Array
    next_update: Array
    origin: Array
    filtered: Array  # the wave filter's (psi, r) estimate [rad, rad/s]


class HeadingAutopilot(AbstractController):
    """PID heading autopilot with reference feed-forward (thesis eq. 5.1):

    $$\\delta_c = \\delta_{ff}(r_d, \\dot r_d) + K_p\\tilde\\psi + K_d\\tilde r
    + K_i\\int\\tilde\\psi\\,dt,\\qquad \\tilde\\psi = \\mathrm{ssa}(\\psi_d - \\psi),
    \\quad \\tilde r = r_d - r,$$

    with $(\\psi_d, r_d, \\dot r_d)$ from `reference` (eq. 5.7) driven by `steps`
    (relative to the initial heading), and $\\delta_{ff}$ from `feedforward` (None: no
    feed-forward) clipped to `max_angle`. With `reference=None` the ordered heading is
    tracked as it is, $(\\psi_d, r_d, \\dot r_d) = (\\psi_{ref}, r_{ref}, 0)$, where
    `steps` may order a yaw rate too (`YawRateLevels`).

    **Sampling.** The controller updates at its own `interval` [s]: at the first
    control step whose start is within half a step of the scheduled time (a fixed grid,
    so the mean rate is exact; every step when `interval` <= h), and holds its command
    in between. The integral advances by $\\tilde\\psi\\,T_u$, $T_u = \\max$(`interval`,
    h) (backward rectangle). The reference model advances every control step.

    **Limits.** The command is rate-limited to `max_rate` $T_u$ per update from the
    last command and clipped to `max_angle`. Anti-windup (`anti_windup=True`) by
    conditional integration: the integral is frozen while the command saturates (in
    angle or rate) and the error would drive it further into saturation. Chosen over
    back-calculation because it needs no tracking time constant, leaves the
    integrator exactly the pole-placement design when nothing saturates, and handles
    the rate limit as well as the angle limit.

    **Wave filter.** With `wave_filter` $= T_f$ [s] the PID sees the measured heading
    and yaw rate through a first-order low pass, $\\dot{\\hat x} = (x - \\hat x)/T_f$
    (exact discretisation every control step), so that wave-frequency yaw motion does
    not drive the rudder (Fossen 2011, sec. 11.3, in its simplest form; $T_f$ well
    below the closed-loop time constant and above the wave periods).

    The gains `kp` [-], `ki` [1/s], `kd` [s] are arrays: differentiable and vmappable.
    """

    kp: ArrayLike  # K_p [rad rudder / rad heading]
    ki: ArrayLike  # K_i [1/s]
    kd: ArrayLike  # K_d [s]
    reference: ReferenceModel | None = ReferenceModel()  # None: track the steps as they are
    steps: HeadingSteps | YawRateLevels = HeadingSteps()
    feedforward: Feedforward | None = None
    max_angle: ArrayLike = float(np.deg2rad(35.0))  # delta_max [rad]
    max_rate: ArrayLike = float("inf")  # delta_dot_max [rad/s]
    interval: ArrayLike = 0.1  # control interval [s]
    anti_windup: bool = eqx.field(static=True, default=True)
    wave_filter: ArrayLike | None = None  # T_f [s] of the wave filter; None: none

    def __check_init__(self):
        for name in ("max_angle", "max_rate", "interval"):
            value = getattr(self, name)
            if isinstance(value, (int, float)) and not value > 0:
                raise ValueError(f"HeadingAutopilot.{name} must be positive, got {value}.")

    def __repr__(self):  # the gains' values, not `kp=f64[]`
        return eqx.tree_pformat(self, short_arrays=False)

    def init(self, x0: ShipState) -> AutopilotMemory:
        psi0 = jnp.asarray(x0.psi, dtype=float)
        zero = jnp.zeros_like(psi0)
        return AutopilotMemory(reference=jnp.stack([psi0, zero, zero]), integral=zero,
                               command=zero + x0.delta, next_update=zero - jnp.inf,
                               origin=psi0, filtered=jnp.stack([psi0, zero + x0.r]))

    def command(self, t, state: ShipState, memory: AutopilotMemory, h):
        psi_ref = memory.origin + self.steps(t + 0.5 * h)
        if self.reference is None:  # the ordered heading and yaw rate themselves
            r_ref = self.steps.rate(t + 0.5 * h) + 0.0 * psi_ref
            memory = eqx.tree_at(lambda m: m.reference, memory,
                                 jnp.stack([psi_ref, r_ref, 0.0 * psi_ref]))
        psi_d, r_d, a_d = memory.reference[0], memory.reference[1], memory.reference[2]
        period = jnp.maximum(self.interval, h)
        update = t >= memory.next_update - 0.5 * h
        psi, r = state.psi, state.r
        filtered = memory.filtered
        if self.wave_filter is not None:  # first-order low pass, exact over the step
            a = jnp.exp(-h / self.wave_filter)
            filtered = jnp.stack([memory.filtered[0] + (1 - a) * ssa(psi - memory.filtered[0]),
                                  a * memory.filtered[1] + (1 - a) * r])
            psi, r = filtered[0], filtered[1]
        error = ssa(psi_d - psi)
        fixed = self.kp * error + self.kd * (r_d - r)  # all but the integral term
        if self.feedforward is not None:
            fixed = fixed + jnp.clip(self.feedforward(r_d, a_d, state, self.max_angle),
                                           -self.max_angle, self.max_angle)
        move = self.max_rate * period

        def saturate(integral):
            wanted = fixed + self.ki * integral
            limited = jnp.clip(wanted, memory.command - move, memory.command + move)
            return wanted, jnp.clip(limited, -self.max_angle, self.max_angle)

        integral = memory.integral + error * period
        wanted, delta = saturate(integral)
        if self.anti_windup:
            excess = wanted - delta
            winding = (excess != 0) & (excess * self.ki * error > 0)
            integral = jnp.where(winding, memory.integral, integral)
            delta = saturate(integral)[1]
        scheduled = jnp.where(jnp.isfinite(memory.next_update),
                              jnp.maximum(memory.next_update + self.interval, t + 0.5 * h),
                              t + self.interval)
        memory = AutopilotMemory(
            reference=memory.reference if self.reference is None
            else self.reference.step(memory.reference, psi_ref, h),
            integral=jnp.where(update, integral, memory.integral),
            command=jnp.where(update, delta, memory.command),
            next_update=jnp.where(update, scheduled, memory.next_update),
            origin=memory.origin,
            filtered=filtered,
        )
        return Command(memory.command, state.n), memory
