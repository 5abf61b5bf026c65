"""Effects: named physical terms added to any vessel or steering model.

`augment(model, *effects)` returns the model with the effects' terms added: an
`AugmentedVessel` or an `AugmentedSteering`, which behave as their base model in
`simulate`, `simulate_steering`, `fit` and `predict`. An effect is an equinox Module
whose fields are its parameters (declared with `jaxship.param`: unit, plausible
range, free by default); with every parameter at zero it adds nothing, so the
augmented model equals its base bit for bit. Its parameters are fitted like any
other, by the name `"<effect id>.<field>"` (e.g. `"rudder_offset.delta0"`).

An effect may act on one or more of four places, each a method with a neutral
default:

- the actuator path, `rudder(delta)`: the rudder angle the hydrodynamics see;
- the loads, `loads(t, vessel, u, v, r, delta, n)`: body-fixed (X, Y, N) [N, N, N m]
  added to a vessel's (Fossen 2021, eq. 6.1: $M\\dot\\nu = \\tau + \\tau_{effect}$);
- the yaw equation of a steering model, `yaw_acceleration(t, model, x, delta)`:
  added to $\\dot r$ [rad/s^2];
- the measurement, `measure(channel, value)`: what a sensor reports.

Adding an effect is writing one such Module; discovery scores them by name.
"""

from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from .._foundation._params import param
from ._steering._base import AbstractSteeringModel
from ._vessel._base import AbstractVessel


class AbstractEffect(eqx.Module):
    """Base of all effects; `id` is the catalogue name (`"rudder_offset"`, ...)."""

    id: eqx.AbstractClassVar[str]

    def rudder(self, delta: ArrayLike) -> ArrayLike:
        return delta

    def loads(self, t, vessel, u, v, r, delta, n) -> ArrayLike:
        return 0.0

    def yaw_acceleration(self, t, model, x, delta) -> ArrayLike:
        return 0.0

    def measure(self, channel: str, value: ArrayLike) -> ArrayLike:
        return value

    def unmeasure(self, channel: str, value: ArrayLike) -> ArrayLike:
        """The true value behind a reading (the inverse of `measure`)."""
        return value


class RudderOffset(AbstractEffect):
    """A rudder angle offset: the hydrodynamics see $\\delta + \\delta_0$ (a misaligned
    rudder indicator or a hull asymmetry; Lu & Zhao 2008, eq. 1)."""

    delta0: ArrayLike = param(0.0, lower=-0.1, upper=0.1, scale=0.01, unit="rad")
    id: ClassVar[str] = "rudder_offset"

    def rudder(self, delta):
        return delta + self.delta0


class YawMomentBias(AbstractEffect):
    """A constant yaw moment: $N_0$ [N m] on a vessel; on a steering model the yaw
    acceleration $N_0$ [rad/s^2] it causes (moment over yaw inertia)."""

    n0: ArrayLike = param(0.0, unit="N m | rad/s^2")
    id: ClassVar[str] = "yaw_moment_bias"

    def loads(self, t, vessel, u, v, r, delta, n):
        return jnp.stack([0.0 * u, 0.0 * u, self.n0 + 0.0 * u])

    def yaw_acceleration(self, t, model, x, delta):
        return self.n0


class SwayForceBias(AbstractEffect):
    """A constant body-fixed sway force $Y_0$ [N] (vessels only)."""

    y0: ArrayLike = param(0.0, unit="N")
    id: ClassVar[str] = "sway_force_bias"

    def loads(self, t, vessel, u, v, r, delta, n):
        return jnp.stack([0.0 * u, self.y0 + 0.0 * u, 0.0 * u])


class YawRateSensorBias(AbstractEffect):
    """The yaw-rate sensor reads $r + b_r$ [rad/s] (a gyro bias)."""

    bias: ArrayLike = param(0.0, lower=-0.02, upper=0.02, scale=1e-3, unit="rad/s")
    id: ClassVar[str] = "yaw_rate_sensor_bias"

    def measure(self, channel, value):
        return value + self.bias if channel == "r" else value

    def unmeasure(self, channel, value):
        return value - self.bias if channel == "r" else value


class HeadingSensorBias(AbstractEffect):
    """The compass reads $\\psi + b_\\psi$ [rad] (a misaligned heading reference)."""

    bias: ArrayLike = param(0.0, lower=-0.2, upper=0.2, scale=0.01, unit="rad")
    id: ClassVar[str] = "heading_sensor_bias"

    def measure(self, channel, value):
        return value + self.bias if channel == "psi" else value

    def unmeasure(self, channel, value):
        return value - self.bias if channel == "psi" else value


class RecordedDisturbance(AbstractEffect):
    """A body-fixed sway force `sway_force[k]` [N] and yaw moment `yaw_moment[k]`
    [N m] held over $[t_0 + k\\,dt, t_0 + (k+1)\\,dt)$ (e.g. a wave moment from a
    disturbance model; Astrom & Kallstrom 1979, sec. 3). Not fitted: its arrays are
    data. Vessels only."""

    dt: ArrayLike
    yaw_moment: Array
    sway_force: Array
    start: ArrayLike = 0.0
    id: ClassVar[str] = "recorded_disturbance"

    def loads(self, t, vessel, u, v, r, delta, n):
        last = self.yaw_moment.shape[0] - 1
        k = jnp.clip(jnp.floor((t - self.start) / self.dt + 1e-9).astype(int), 0, last)
        return jnp.stack([0.0 * u, self.sway_force[k] + 0.0 * u, self.yaw_moment[k] + 0.0 * u])


class _Augmented(eqx.Module):
    """What both augmented models share: the base, the effects and the parameter names
    `"<effect id>.<field>"` of the effects."""

    base: eqx.AbstractVar[eqx.Module]
    effects: eqx.AbstractVar[tuple[AbstractEffect, ...]]

    def lookup(self, name: str):
        """The base's field `name`, or the effect with the id `name`."""
        for effect in self.effects:
            if effect.id == name:
                return effect
        return getattr(self.base, name)

    def _rudder(self, delta):
        for effect in self.effects:
            delta = effect.rudder(delta)
        return delta

    def measure(self, channel: str, value):
        for effect in self.effects:
            value = effect.measure(channel, value)
        return value

    def replay_state(self, start, servo: bool = False):
        """The base's state at a window start, from the true r and psi behind the
        readings (sensor effects removed)."""
        true = lambda channel, value: _unmeasure(self.effects, channel, value)
        start = eqx.tree_at(lambda s: (s.r, s.psi, s.r_first, s.psi_first), start,
                            (true("r", start.r), true("psi", start.psi),
                             true("r", start.r_first), true("psi", start.psi_first)))
        return self.base.replay_state(start, servo)


def _unmeasure(effects, channel, value):
    for effect in reversed(effects):
        value = effect.unmeasure(channel, value)
    return value


def _check_effects(effects):
    ids = [e.id for e in effects]
    for e in effects:
        if not isinstance(e, AbstractEffect):
            raise ValueError(f"effects must be jaxship effects (AbstractEffect), got "
                             f"{type(e).__name__}.")
    if len(set(ids)) != len(ids):
        raise ValueError(f"each effect may appear once, got {ids}.")
    return tuple(effects)


class AugmentedVessel(_Augmented, AbstractVessel):
    """A vessel with effects: $\\tau = \\tau_{base}(u, v, r, \\delta', n) +
    \\sum_e \\tau_e$, $\\delta'$ the rudder after the effects' actuator path."""

    base: AbstractVessel
    effects: tuple[AbstractEffect, ...]

    def __init__(self, base: AbstractVessel, effects=()):
        self.base, self.effects = base, _check_effects(effects)

    @property
    def length(self):
        return self.base.length

    @property
    def rudder(self):
        return self.base.rudder

    @property
    def shaft(self):
        return self.base.shaft

    @property
    def nominal_speed(self):
        return self.base.nominal_speed

    @property
    def nominal_n(self):
        return self.base.nominal_n

    @property
    def frontal_wind_area(self):
        return self.base.frontal_wind_area

    @property
    def lateral_wind_area(self):
        return self.base.lateral_wind_area

    @property
    def free_by_default(self):
        return self.base.free_by_default

    def mass_matrix(self):
        return self.base.mass_matrix()

    def forces(self, u, v, r, delta, n):
        return self.loads(0.0, u, v, r, delta, n)

    def loads(self, t, u, v, r, delta, n):
        tau = self.base.loads(t, u, v, r, self._rudder(delta), n)
        for effect in self.effects:
            tau = tau + effect.loads(t, self.base, u, v, r, delta, n)
        return tau


class AugmentedSteering(_Augmented, AbstractSteeringModel):
    """A steering model with effects: $\\dot x = f(x, \\delta', a) + e_r
    \\sum_e \\dot r_e$, with $\\delta'$ the rudder after the effects' actuator path and
    $e_r$ the yaw-rate state."""

    base: AbstractSteeringModel
    effects: tuple[AbstractEffect, ...]
    def __init__(self, base: AbstractSteeringModel, effects=()):
        self.base, self.effects = base, _check_effects(effects)

    @property
    def state_names(self):
        return self.base.state_names

    def rhs(self, state, delta, aux):
        x_dot = self.base.rhs(state, self._rudder(delta), aux)
        extra = sum(jnp.asarray(e.yaw_acceleration(0.0, self.base, state, delta), float)
                    for e in self.effects)
        return x_dot.at[0].add(extra)

    def output(self, state):
        return self.base.output(state)

    def initial_state(self, r):
        return self.base.initial_state(r)

    def window_state(self, start):
        return self.base.window_state(start)


def augment(model, *effects):
    """`model` (a vessel or a steering model) with `effects` added: an
    `AugmentedVessel` or an `AugmentedSteering`. With every effect parameter at zero
    it reproduces `model` exactly."""
    for base, augmented in ((AbstractVessel, AugmentedVessel),
                            (AbstractSteeringModel, AugmentedSteering)):
        if isinstance(model, base):
            return augmented(model, effects)
    raise ValueError(f"`model` must be a jaxship vessel or steering model, got "
                     f"{type(model).__name__}.")
