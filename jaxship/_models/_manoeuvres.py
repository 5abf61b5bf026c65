"""Standard trials as rudder/propeller command generators.

A manoeuvre is a controller (its `init` and `command`) plus a duration and an output
sampling. The simulator calls `command(t, state, memory, h)` at the start of every
control step of `h` seconds (at most `Simulator.max_step`, 0.1 s by default, whatever
the output interval `dt`): closed-loop logic such as zig-zag switching or a heading
controller sees the state there and returns the command for the step; its memory
(an integrator, the zig-zag side) travels in the simulated state. Angles are radians
and propeller rates rev/s; degrees and rpm belong to the CLI and the file formats.
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import ArrayLike

from .._foundation._state import Command, Switched
from ._control import AbstractController, HeadingAutopilot, HeadingSteps, YawRateLevels
from ._holds import FirstOrderHold, ZeroOrderHold, check_hold


class AbstractManoeuvre(AbstractController):
    """A controller run for a duration with an output sampling: what `simulate` takes.

    Every manoeuvre has `duration` [s], a sample interval `dt` [s], the time `start`
    [s] of its first sample, a propeller command `n` [rev/s] (`None`: hold the
    initial rate) and `num_samples` (static; by default `round(duration/dt) + 1`,
    larger to pad a batch of manoeuvres to one length).
    """

    duration: eqx.AbstractVar[ArrayLike]
    dt: eqx.AbstractVar[ArrayLike]
    start: eqx.AbstractVar[ArrayLike]
    n: eqx.AbstractVar[ArrayLike | None]
    num_samples: eqx.AbstractVar[int | None]

    def __post_init__(self):
        if self.num_samples is None:
            self.num_samples = int(round(float(self.duration) / float(self.dt))) + 1
        if self.num_samples < 2:
            raise ValueError(f"`duration` ({self.duration} s) must cover at least one `dt`.")

    @property
    def rudder_rate(self) -> ArrayLike | None:
        """The manoeuvre's limit on the rudder rate [rad/s] (None: none beyond a
        vessel's servo); `Turn`, `ZigZag` and `Schedule` take it as an argument."""
        return None


class Controlled(AbstractManoeuvre):
    """Any `AbstractController` run for `duration` [s] with output every `dt` [s]."""

    controller: AbstractController
    duration: ArrayLike
    dt: ArrayLike = 0.1
    start: ArrayLike = 0.0
    n: None = None
    num_samples: int | None = eqx.field(static=True, default=None)

    def init(self, x0):
        return self.controller.init(x0)

    def command(self, t, state, memory, h):
        return self.controller.command(t, state, memory, h)


class AbstractTrial(AbstractManoeuvre):
    """The standard trials: a rudder law (`rudder`) and a propeller order, with the
    initial heading and propeller rate kept in the memory."""

    def init(self, x0):
        """Controller memory at the first sample: initial rpm, initial heading, own state."""
        return (x0.n, x0.psi, self.init_memory(x0))

    def command(self, t, state, memory, h):
        """The command for the control step `[t, t + h]` and the new memory."""
        n0, psi0, own = memory
        delta, own = self.rudder(t - self.start, state, psi0, own, h)
        n = n0 if self.n is None else self.n
        return Command(delta, self.propeller(t - self.start, n)), (n0, psi0, own)

    def propeller(self, tau, n):
        """Propeller command at time `tau` since the start; constant unless overridden."""
        del tau
        return n

    @abc.abstractmethod
    def init_memory(self, x0):
        """Initial controller memory (a pytree; `None` for open-loop manoeuvres)."""

    @abc.abstractmethod
    def rudder(self, tau, state, psi0, memory, h):
        """Rudder command [rad] at `tau` seconds after the start, held for the control
        step of `h` seconds, and the new memory."""


def _step(tau, execute):
    return jnp.where(tau >= execute, 1.0, 0.0)


def _check_rate(rate):
    """A rudder rate [rad/s] must be positive (or None); traced values are not checked."""
    if rate is None or isinstance(rate, jax.core.Tracer):
        return
    if not np.all(np.asarray(rate, dtype=float) > 0):
        raise ValueError(f"`rudder_rate` must be positive [rad/s] or None, got {rate}.")


class Turn(AbstractTrial):
    """Turning circle: rudder `angle` ordered at `execute` and held (ITTC 7.5-04-02-01
    2.2.1). `rudder_rate` [rad/s]: the steering gear's rate limit for the trial (a
    vessel's servo rate too applies, the smaller wins; None: the servo's alone)."""

    angle: ArrayLike  # delta [rad]; positive turns to starboard
    duration: ArrayLike
    dt: ArrayLike = 0.1
    execute: ArrayLike = 0.0  # time of the rudder order after `start` [s]
    start: ArrayLike = 0.0
    n: ArrayLike | None = None
    num_samples: int | None = eqx.field(static=True, default=None)
    rudder_rate: ArrayLike | None = None  # |d delta/dt| limit [rad/s]; None: none

    def __check_init__(self):
        _check_rate(self.rudder_rate)

    def init_memory(self, x0):
        return None

    def rudder(self, tau, state, psi0, memory, h):
        return self.angle * _step(tau, self.execute), memory


class SwitchAtCrossing(eqx.Module):
    """`ZigZag(switch_at=SwitchAtCrossing())` (the default): the rudder is reversed at the
    crossing itself, the time in the control step where the heading change extrapolated
    over the step, $\\Delta\\psi + r\\tau + \\dot r\\tau^2/2 = \\pm\\psi_s$, reaches
    the switch angle; the step is integrated in two parts (`Switched`), so the overshoots
    do not depend on the control step."""

    def memory(self, side, x0):
        """The side and the yaw rate of the last step (for $\\dot r$)."""
        return side, x0.r

    def sampled(self):
        """The rule where the rudder moves once per control step: the nearest step."""
        return SwitchAtNearestStep()

    def command(self, zigzag, sampled, t, state, memory, h):
        """A `Switched` command at the crossing (`sampled`, the trial's per-step command,
        is not used)."""
        n0, psi0, (side, r_last) = memory
        tau = t - zigzag.start
        a = state.psi - psi0 - side * zigzag.heading
        b, c = state.r, 0.5 * (state.r - r_last) / h
        crossed = (side * (a + b * h + c * h * h) >= 0) & (tau >= zigzag.execute)
        disc = b * b - 4 * a * c  # the root of a + b s + c s^2 nearest zero, stable as c -> 0
        root = jnp.where(disc > 0, jnp.sqrt(jnp.where(disc > 0, disc, 1.0)), 0.0)
        q = b + jnp.where(b >= 0, 1.0, -1.0) * root
        at = jnp.clip(-2 * a / jnp.where(q == 0, 1.0, q), 0.0, h)
        new = jnp.where(crossed, -side, side)
        n = n0 if zigzag.n is None else zigzag.n
        size = jnp.abs(zigzag.angle) * _step(tau, zigzag.execute)
        switched = Switched(Command(side * size, n), Command(new * size, n),
                            jnp.where(crossed, at, h))
        return switched, (n0, psi0, (new, state.r))

    def lookahead(self, h, r):
        return 0.0 * r


class _SwitchAtAStep(eqx.Module):
    """A rule that reverses the rudder at a control step: the memory is the side, the
    command the trial's per-step one; `lookahead` says which step."""

    def memory(self, side, x0):
        return side

    def sampled(self):
        return self

    def command(self, zigzag, sampled, t, state, memory, h):
        """The trial's per-step command `sampled()`."""
        return sampled()


class SwitchAtNearestStep(_SwitchAtAStep):
    """`ZigZag(switch_at=SwitchAtNearestStep())`: the rudder is reversed at the control step
    nearest to the crossing (within half a step): the heading change half a step ahead,
    $\\Delta\\psi + r h/2$, is compared with the switch angle."""

    def lookahead(self, h, r):
        """The heading change half a control step ahead."""
        return 0.5 * h * r


class SwitchAtNextStep(_SwitchAtAStep):
    """`ZigZag(switch_at=SwitchAtNextStep())`: the rudder is reversed at the first control
    step after the crossing (as MSS `zigzag.m` and sampled-logic implementations do, late
    by up to one step)."""

    def lookahead(self, h, r):
        return 0.0 * r


SWITCHES = (SwitchAtCrossing, SwitchAtNearestStep, SwitchAtNextStep)


class ZigZag(AbstractTrial):
    """Kempf zig-zag `angle`/`heading` (IMO MSC.137(76) 4.2.7; ITTC 2.2.2).

    The rudder goes to `angle` at `execute` (negative `angle`: port first) and is
    reversed whenever the heading change from the initial heading passes
    `heading` on the side the rudder is turning the ship to, as `switch_at` says: at the
    crossing itself (`SwitchAtCrossing()`, the default), at the control step nearest to
    it (`SwitchAtNearestStep()`) or at the first control step after it
    (`SwitchAtNextStep()`). A steering model's rudder moves once per control step, so
    the crossing acts there as the nearest step. `rudder_rate` [rad/s]: the steering
    gear's rate limit for the trial (a vessel's servo rate too applies, the smaller
    wins; None: the servo's alone).
    """

    angle: ArrayLike  # delta_0 [rad], sign gives the first side
    heading: ArrayLike  # psi_switch [rad] > 0
    duration: ArrayLike
    dt: ArrayLike = 0.1
    execute: ArrayLike = 0.0
    start: ArrayLike = 0.0
    n: ArrayLike | None = None
    num_samples: int | None = eqx.field(static=True, default=None)
    switch_at: SwitchAtCrossing | SwitchAtNearestStep | SwitchAtNextStep = eqx.field(
        static=True, default=SwitchAtCrossing())
    rudder_rate: ArrayLike | None = None  # |d delta/dt| limit [rad/s]; None: none

    def __check_init__(self):
        if not isinstance(self.switch_at, SWITCHES):
            raise ValueError(f"`switch_at` must be SwitchAtCrossing(), SwitchAtNearestStep() "
                             f"or SwitchAtNextStep(), got {self.switch_at!r}.")
        _check_rate(self.rudder_rate)

    def init_memory(self, x0):
        side = jnp.sign(jnp.asarray(self.angle, dtype=float))
        return self.switch_at.memory(side, x0)

    def command(self, t, state, memory, h):
        """The command for the control step `[t, t + h]`, as the `switch_at` rule gives it
        (the trial's per-step command, or one switched inside the step)."""
        sampled = lambda: super(ZigZag, self).command(t, state, memory, h)
        return self.switch_at.command(self, sampled, t, state, memory, h)

    def rudder(self, tau, state, psi0, side, h):
        change = state.psi - psi0
        change = change + self.switch_at.lookahead(h, state.r)
        side = jnp.where((side > 0) & (change >= self.heading), -1.0, side)
        side = jnp.where((side < 0) & (change <= -self.heading), 1.0, side)
        side = jnp.where(tau >= self.execute, side, jnp.sign(self.angle))
        return side * jnp.abs(self.angle) * _step(tau, self.execute), side


class Schedule(AbstractTrial):
    """Open-loop piecewise-linear rudder schedule through the points `(times, angles)`.

    The building block of the direct spiral, pull-out, 3-2-1-1, PRBS and the thesis
    manoeuvre; before the first time the first angle holds, after the last the last.
    Steps are written as two points at the same time. `rudder_rate` [rad/s]: the
    steering gear's rate limit (as `Turn`'s; None: none beyond a vessel's servo).
    """

    times: ArrayLike  # [s] after start, non-decreasing
    angles: ArrayLike  # [rad]
    duration: ArrayLike
    dt: ArrayLike = 0.1
    start: ArrayLike = 0.0
    n: ArrayLike | None = None
    num_samples: int | None = eqx.field(static=True, default=None)
    rudder_rate: ArrayLike | None = None  # |d delta/dt| limit [rad/s]; None: none

    def __check_init__(self):
        _check_rate(self.rudder_rate)

    def init_memory(self, x0):
        return None

    def rudder(self, tau, state, psi0, memory, h):
        times, angles = jnp.asarray(self.times), jnp.asarray(self.angles)
        # right-continuous interpolation so that a step at t_k is already taken at t_k
        k = jnp.clip(jnp.searchsorted(times, tau, side="right") - 1, 0, times.shape[0] - 2)
        t_a, t_b, a_a, a_b = times[k], times[k + 1], angles[k], angles[k + 1]
        w = jnp.where(
            t_b > t_a, jnp.clip((tau - t_a) / jnp.where(t_b > t_a, t_b - t_a, 1.0), 0, 1), 1.0
        )
        value = a_a + w * (a_b - a_a)
        value = jnp.where(tau < times[0], angles[0], value)
        return jnp.where(tau >= times[-1], angles[-1], value), memory


def _staircase(levels, durations):
    """Knots of a staircase from t = 0: `levels[i]` held for `durations[i]` seconds."""
    levels = np.asarray(levels, dtype=float)
    edges = np.concatenate([[0.0], np.cumsum(np.broadcast_to(durations, levels.shape))])
    return np.repeat(edges, 2)[1:-1], np.repeat(levels, 2)


# direct spiral levels [rad]: 25 deg to either side in 5 deg steps, finer near midships
# where the loop of a course-unstable ship lies (MSC/Circ.1053 app. 4 2.1.5)
SPIRAL_LEVELS = tuple(np.deg2rad((25.0, 20.0, 15.0, 10.0, 5.0, 2.0, 1.0)).tolist())


def spiral(hold=300.0, *, levels=SPIRAL_LEVELS, dt=0.1, n=None):
    """Direct (Dieudonne) spiral (MSC/Circ.1053 app. 4 2.1; ITTC 7.5-04-02-01 2.2.4): the
    rudder at each of `levels` [rad] (the positive ones; default 25, 20, 15, 10, 5, 2 and
    1 deg) to starboard, then midships, the same to port and back up, each held `hold`
    [s] (the steady yaw rate is read at the end of each). `jaxship simulate --manoeuvre
    spiral` holds each level 30 L/U (`StandardTrial`)."""
    side = np.asarray(levels, dtype=float)
    side = np.sort(side[side > 0])[::-1]
    down = np.concatenate([side, [0.0], -side[::-1]])
    steps = np.concatenate([down, down[::-1][1:]])
    edges = hold * np.arange(steps.size + 1)
    times = np.repeat(edges, 2)[1:-1]
    return Schedule(times, np.repeat(steps, 2), duration=float(edges[-1]), dt=dt, n=n)


def pull_out(angle=np.deg2rad(20), turn_time=300.0, release_time=300.0, *, dt=0.1, n=None):
    """Pull-out (ITTC 2.2.6): steady turn at `angle`, rudder to midships at `turn_time`."""
    times = np.array([0.0, 0.0, turn_time, turn_time])
    angles = np.array([0.0, angle, angle, 0.0])
    return Schedule(times, angles, duration=turn_time + release_time, dt=dt, n=n)


def multi_step_3211(amplitude=np.deg2rad(10), unit=5.0, *, settle=None, dt=0.1, n=None):
    """3-2-1-1 multi-step: +A for 3 units, -A for 2, +A for 1, -A for 1, then midships."""
    levels = [amplitude, -amplitude, amplitude, -amplitude, 0.0]
    settle = 10 * unit if settle is None else settle
    times, angles = _staircase(levels, np.array([3, 2, 1, 1, settle / unit]) * unit)
    return Schedule(times, angles, duration=7 * unit + settle, dt=dt, n=n)


def prbs(
    amplitude=np.deg2rad(10), bit_time=5.0, duration=600.0, *, order=7, seed=1, dt=0.1, n=None
):
    """Pseudo-random binary rudder sequence of +-`amplitude`, one bit every `bit_time` s.

    A maximum-length linear-feedback shift register of `order` bits (period
    $2^{order} - 1$) drawn from the nonzero `seed` state; Ljung (1999, sec. 13.3).
    """
    taps = {5: (5, 3), 6: (6, 5), 7: (7, 6), 8: (8, 6, 5, 4), 9: (9, 5), 10: (10, 7)}
    if order not in taps:
        raise ValueError(f"`order` must be one of {sorted(taps)}, got {order}.")
    if not 0 < seed < 2**order:
        raise ValueError(f"`seed` must be in [1, {2**order - 1}], got {seed}.")
    state, bits = seed, []
    for _ in range(int(np.ceil(duration / bit_time))):
        bits.append(state & 1)
        feedback = 0
        for tap in taps[order]:
            feedback ^= (state >> (order - tap)) & 1
        state = (state >> 1) | (feedback << (order - 1))
    times, angles = _staircase(amplitude * (2.0 * np.array(bits) - 1.0), bit_time)
    return Schedule(times, angles, duration=duration, dt=dt, n=n)


def thesis_manoeuvre(
    steps_deg=(5, 10, 20, 40, 45),
    hold_per_deg=2.0,
    ramp_deg_per_s=0.3,
    end_hold=300.0,
    *,
    dt=0.1,
    n=None,
):
    """The identification manoeuvre of the thesis (Table 3.1, Fig. 3.4).

    For each step angle a (5, 10, 20, 40, 45 deg), first to starboard, then to port:
    rudder ordered to a, held 2 s per degree, then reduced to zero at 0.3 deg/s;
    finally midships for `end_hold` s. The order "to either side" of each step is
    our reading of Fig. 3.4 (about 1600 s of manoeuvre).
    """
    times, angles, t = [0.0], [0.0], 0.0
    for a in steps_deg:
        for side in (1.0, -1.0):
            hold, ramp = hold_per_deg * a, a / ramp_deg_per_s
            times += [t, t + hold, t + hold + ramp]
            angles += [np.deg2rad(side * a)] * 2 + [0.0]
            t += hold + ramp
    times.append(t + end_hold)
    angles.append(0.0)
    return Schedule(np.array(times), np.array(angles), duration=t + end_hold, dt=dt, n=n)


class Stop(AbstractTrial):
    """Crash stop (ITTC 7.5-04-02-01 2.2.7; IMO MSC.137(76) 4.2.4): propeller to
    `astern_n` [rev/s] at `execute`, rudder midships.

    The trial ends when the ship is stopped in the water (the surge velocity through
    the water falls to zero): with `until_stopped` (the default) the propeller is
    then ordered to zero, so that the ship is not driven astern (and, with a
    single-screw ship's asymmetric astern forces, into a turn) for the rest of the
    run; the stop is latched in the controller memory. `until_stopped=False` keeps
    the astern order to the end (the astern run after a stop)."""

    astern_n: ArrayLike  # n_astern [rev/s], negative
    duration: ArrayLike
    dt: ArrayLike = 0.1
    execute: ArrayLike = 0.0
    start: ArrayLike = 0.0
    n: ArrayLike | None = None
    num_samples: int | None = eqx.field(static=True, default=None)
    until_stopped: bool = eqx.field(static=True, default=True)

    def init_memory(self, x0):
        return jnp.zeros_like(jnp.asarray(x0.u, dtype=float))  # 1 once stopped

    def rudder(self, tau, state, psi0, memory, h):
        return jnp.zeros_like(tau), memory

    def command(self, t, state, memory, h):
        """Astern from `execute` until the surge velocity reaches zero (then stop)."""
        n0, psi0, stopped = memory
        tau = t - self.start
        ordered = tau >= self.execute
        if self.until_stopped:
            stopped = jnp.where(ordered & (state.u <= 0.0), 1.0, stopped)
        ahead = n0 if self.n is None else self.n
        astern = jnp.where(stopped > 0, 0.0, self.astern_n)
        n = jnp.where(ordered, astern, ahead)
        return Command(jnp.zeros_like(tau), n), (n0, psi0, stopped)

    def propeller(self, tau, n):
        return jnp.where(tau >= self.execute, self.astern_n, n)


class ReverseSpiral(AbstractManoeuvre):
    """Bech's reverse spiral (Bech 1968, "The reversed spiral test as applied to large
    ships", Shipping World and Shipbuilder; MSC/Circ.1053 app. 4 2.2): the heading
    autopilot (`HeadingAutopilot`, no reference model) tracks a heading that turns at
    each rate of `rates` [rad/s] for `hold` s (`YawRateLevels`); the mean rudder needed
    gives the delta(r) curve, S-shaped through an unstable ship's loop, which the
    direct spiral cannot hold.

    Rudder law: $\\delta_c = K_p\\tilde\\psi + K_d\\tilde r + K_i\\int\\tilde\\psi\\,dt$,
    $\\tilde\\psi = \\psi_{ref} - \\psi$, $\\tilde r = r_{ref} - r$, clipped to
    `max_angle` with conditional-integration anti-windup. Since
    $\\tilde\\psi = \\int\\tilde r\\,dt$, with $K_i = 0$ it is a PI controller on the
    yaw rate (gains $K_d$, $K_p$), the rate-of-turn controller of Bech's trial; on
    $\\dot r = -a r + b\\delta$ its closed loop is $s^2 + (a + bK_d)s + bK_p$.
    `jaxship simulate` places those poles from the vessel's linearised yaw dynamics
    and sizes the rates from its steady turn at the direct spiral's largest rudder
    angle (`jaxship.StandardTrial`).
    """

    rates: ArrayLike  # r_ref levels [rad/s]
    hold: ArrayLike  # [s] per level
    kp: ArrayLike  # K_p [rad rudder / rad heading]
    kd: ArrayLike  # K_d [s]
    duration: ArrayLike
    ki: ArrayLike = 0.0  # K_i [1/s]
    dt: ArrayLike = 0.1
    start: ArrayLike = 0.0
    max_angle: ArrayLike = float(np.deg2rad(35))  # rudder limit of the autopilot [rad]
    n: None = None
    num_samples: int | None = eqx.field(static=True, default=None)

    @property
    def autopilot(self) -> HeadingAutopilot:
        """The heading autopilot flying the levels (time from `start`)."""
        return HeadingAutopilot(kp=self.kp, ki=self.ki, kd=self.kd, reference=None,
                                steps=YawRateLevels(self.rates, self.hold),
                                max_angle=self.max_angle)

    def init(self, x0):
        return self.autopilot.init(x0)

    def command(self, t, state, memory, h):
        return self.autopilot.command(t - self.start, state, memory, h)


def heading_perturbations(amplitude, period, kp, ki, kd, duration, *, dt=0.1,
                          max_angle=np.deg2rad(35)) -> Controlled:
    """Heading-reference perturbations under the heading autopilot (the closed-loop
    identification experiments of Astrom & Kallstrom 1979, sec. 4): the ordered
    heading is the initial one plus a square wave of `amplitude` [rad] and `period`
    [s], taken without a reference model; the rudder law is `HeadingAutopilot`'s PID,
    $\\delta_c = k_p e + k_i\\int e\\,dt - k_d r$, $e = \\mathrm{ssa}(\\psi_{ref} - \\psi)$,
    with `kp` [-], `ki` [1/s], `kd` [s], clipped to `max_angle` [rad] with
    conditional-integration anti-windup. Returns the manoeuvre (`Controlled`)."""
    count = int(np.ceil(float(duration) / (0.5 * float(period)))) + 1
    times = 0.5 * float(period) * np.arange(count)
    headings = float(amplitude) * (1.0 - 2.0 * (np.arange(count) % 2))
    pilot = HeadingAutopilot(kp=kp, ki=ki, kd=kd, reference=None,
                             steps=HeadingSteps(tuple(times), tuple(headings)),
                             max_angle=max_angle)
    return Controlled(pilot, duration=duration, dt=dt)


def interpolate(record, dt, tau, hold):
    """Value and slope of a record sampled every `dt` at `tau` seconds after its first
    sample, as `hold` (`ZeroOrderHold()` or `FirstOrderHold()`) interpolates it."""
    return hold.interpolate(record, dt, tau)


class Replay(AbstractTrial):
    """Open-loop replay of recorded rudder and propeller commands.

    `delta_record` [rad] and `n_record` [rev/s] are sampled every `dt` from `start`.
    Between samples each channel is held (`ZeroOrderHold()`: right for a commanded,
    piecewise-constant signal) or interpolated linearly (`FirstOrderHold()`: right for a
    measured, continuous signal such as a logged rudder angle or shaft speed), as
    MATLAB's `InterSample`. Commands default to `ZeroOrderHold()`.
    `n_record=None` holds the initial propeller rate (and is what a steering model,
    which takes no propeller order, needs); `dt` is keyword-only.
    """

    delta_record: ArrayLike
    n_record: ArrayLike | None = None
    dt: ArrayLike = eqx.field(kw_only=True)
    start: ArrayLike = 0.0
    duration: ArrayLike | None = None
    n: None = None
    num_samples: int | None = eqx.field(static=True, default=None)
    delta_hold: ZeroOrderHold | FirstOrderHold = eqx.field(static=True,
                                                           default=ZeroOrderHold())
    n_hold: ZeroOrderHold | FirstOrderHold = eqx.field(static=True, default=ZeroOrderHold())

    def __post_init__(self):
        length = np.shape(self.delta_record)[0]
        if self.n_record is not None and np.shape(self.n_record)[0] != length:
            raise ValueError("`delta_record` and `n_record` must have the same length.")
        for name in ("delta_hold", "n_hold"):
            check_hold(getattr(self, name), name)
        if self.duration is None:
            self.duration = (length - 1) * float(self.dt)
        if self.num_samples is None:
            self.num_samples = length

    def init_memory(self, x0):
        return None

    def rudder(self, tau, state, psi0, memory, h):
        return interpolate(self.delta_record, self.dt, tau, self.delta_hold)[0], memory

    def command(self, t, state, memory, h):
        tau = t - self.start
        delta, delta_rate = interpolate(self.delta_record, self.dt, tau, self.delta_hold)
        if self.n_record is None:  # the initial propeller rate held
            return Command(delta, memory[0], delta_rate, None), memory
        n, n_rate = interpolate(self.n_record, self.dt, tau, self.n_hold)
        return Command(delta, n, delta_rate, n_rate), memory
