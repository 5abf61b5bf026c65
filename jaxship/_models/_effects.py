"""Effects: named physical terms added to any vessel or steering model.

`augment(model, *effects)` returns the model with the effects' terms added: an
`AugmentedVessel` or an `AugmentedSteering`, which behave as their base model in
`simulate`, `simulate_batch`, `fit` and `predict`. An effect is an equinox Module
whose fields are its parameters (declared with `jaxship.param`: unit, plausible
range, free by default); with every parameter at zero it adds nothing, so the
augmented model equals its base bit for bit. Its parameters are fitted like any
other, by the name `"<effect id>.<field>"` (e.g. `"rudder_offset.delta0"`).

An effect says where it acts by the abstract classes it derives from, each one small
(one or two methods to write):

- `AbstractRudderEffect`, the actuator path, `rudder(delta, z, aux)`: the rudder angle
  the hydrodynamics see, with the effect's own states `z` (`state_names`,
  `initial_state`, `state_rate`: a lag, a delay or a rate limit; they travel in the
  simulated state after the model's own) and, on a steering model, its auxiliary
  inputs `aux` (`AuxInputs`: measured u, v, n; None on a vessel, whose effects see u,
  v, r, n in `loads`);
- `AbstractLoadEffect`, a vessel's loads, `loads(t, vessel, u, v, r, delta, n)`:
  body-fixed (X, Y, N) [N, N, N m] added to a vessel's (Fossen 2021, eq. 6.1:
  $M\\dot\\nu = \\tau + \\tau_{effect}$), `delta` the rudder after the actuator path;
- `AbstractYawTermEffect`, the yaw equation of a steering model, `yaw_term(model, x,
  delta, aux)`: a term $f$ added to its right-hand side where the rudder's moment
  enters (for Nomoto $T\\dot r + r = K\\delta + f$ [rad/s]; for models written as
  $\\dot r = \\dots$, [rad/s^2]), `delta` the logged rudder (before the actuator
  path); the model's `forcing(x)` says how it moves the state;
- `AbstractVesselPropertyEffect`, a vessel's mass matrix `mass(M)`, its environment
  (current and wind) in the equations of motion `environment(env)`, or its wind areas
  `wind_areas(frontal, lateral)` [m^2]: each returns the corrected value (override the
  ones the effect changes);
- `AbstractSensorEffect`, the measurement, `measure(channel, value)` and its inverse
  `unmeasure`: what a sensor reports.

An effect on vessels and steering models alike derives from both places (a yaw moment:
`AbstractLoadEffect` and `AbstractYawTermEffect`); a steering model refuses an effect
with no place it has (loads, mass), a vessel one with none of its own (a yaw term).

A parameter acting on several families has one unit per family ("family units",
e.g. `YawMomentBias.n0`: N m on a vessel, rad/s on a Nomoto model); such parameters
carry no bounds (no one range is plausible in all of them) and are scaled from the
Jacobian when a fit starts them at zero. The hull, rudder, propeller and environment
effects are in `_hydro_effects.py`. Adding an effect is writing one such Module;
discovery scores them by name.
"""

import abc
from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from .._foundation._contract import AbstractComposite
from .._foundation._params import param
from .._foundation._state import STATE_FIELDS
from ._steering._base import AbstractSteeringModel
from ._steering.nomoto import Nomoto2
from ._vessel._base import AbstractVessel


# Below this time constant [s] a rudder lag or delay is treated as absent: the default
# control step (0.1 s) of classical RK4 is stable for time constants above ~0.036 s,
# and a lag this short is not resolved by it anyway.
SHORTEST_TIME_CONSTANT = 0.05



def family_unit(unit: str, model) -> str:
    """The unit that a family unit (`"N m | rad/s | rad/s^2"`: vessel | steering model,
    the steering one split by the model's `yaw_term_unit` where it has two) takes on
    `model` (a vessel or a steering model, without its effects); other units as given."""
    parts = [p.strip() for p in unit.split("|")]
    if len(parts) == 1:
        return unit
    if not isinstance(model, AbstractSteeringModel):
        return parts[0]
    if len(parts) == 2:
        return parts[1]
    return parts[1] if model.yaw_term_unit == "rad/s" else parts[2]

class AbstractEffect(eqx.Module):
    """Base of all effects; `id` is the catalogue name (`"rudder_offset"`, ...). An
    effect derives from the abstract classes of the places it acts on (below)."""

    id: eqx.AbstractClassVar[str]
    state_names: ClassVar[tuple[str, ...]] = ()  # the effect's own states, if any
    uses_wind: ClassVar[bool] = False  # reads the replayed wind (`AuxInputs.wind_u`, ...)


class AbstractRudderEffect(AbstractEffect):
    """Acts on the actuator path, with states of its own where it has `state_names`."""

    @abc.abstractmethod
    def rudder(self, delta: ArrayLike, z, aux=None) -> ArrayLike:
        """The rudder angle [rad] the model sees for `delta`, with the effect's states
        `z` and a steering model's `AuxInputs` `aux` (None on a vessel)."""

    def initial_state(self, delta) -> Array:
        """The effect's states in a steady state at rudder `delta` [rad]."""
        return jnp.zeros((len(self.state_names),)) + 0.0 * delta

    def state_rate(self, z, delta) -> Array:
        """The time derivative of the effect's states `z` at the rudder `delta` it sees."""
        return jnp.zeros_like(z)


class AbstractLoadEffect(AbstractEffect):
    """Adds loads to a vessel's."""

    @abc.abstractmethod
    def loads(self, t, vessel, u, v, r, delta, n) -> ArrayLike:
        """Loads (X, Y, N) [N, N, N m] added to `vessel`'s at the rudder `delta` it sees."""


class AbstractYawTermEffect(AbstractEffect):
    """Adds a term to a steering model's yaw equation."""

    @abc.abstractmethod
    def yaw_term(self, model, x, delta, aux) -> ArrayLike:
        """The term added to steering `model`'s yaw equation at its state `x`."""


class AbstractVesselPropertyEffect(AbstractEffect):
    """Corrects a vessel's mass matrix, environment or wind areas (neutral by default:
    override what the effect changes)."""

    def mass(self, matrix: Array) -> Array:
        """A vessel's mass matrix $M$ [kg, kg m, kg m^2] with the effect's correction."""
        return matrix

    def environment(self, environment):
        """The `Environment` (current, wind) a vessel's equations of motion see."""
        return environment

    def wind_areas(self, frontal, lateral):
        """A vessel's frontal and lateral projected wind areas [m^2]."""
        return frontal, lateral


class AbstractSensorEffect(AbstractEffect):
    """Changes what a sensor reports."""

    @abc.abstractmethod
    def measure(self, channel: str, value: ArrayLike) -> ArrayLike:
        """The reading of `channel` whose true value is `value`."""

    @abc.abstractmethod
    def unmeasure(self, channel: str, value: ArrayLike) -> ArrayLike:
        """The true value behind a reading (the inverse of `measure`)."""


# the places each family has: an effect must act on at least one of them
VESSEL_PLACES = (AbstractRudderEffect, AbstractLoadEffect, AbstractVesselPropertyEffect,
                 AbstractSensorEffect)
STEERING_PLACES = (AbstractRudderEffect, AbstractYawTermEffect, AbstractSensorEffect)
PLACE_NAMES = {AbstractRudderEffect: "rudder", AbstractLoadEffect: "loads",
               AbstractYawTermEffect: "yaw equation",
               AbstractVesselPropertyEffect: "mass, environment and wind areas",
               AbstractSensorEffect: "sensors"}


def _of(effects, place):
    return [e for e in effects if isinstance(e, place)]


class RudderOffset(AbstractRudderEffect):
    """A rudder angle offset: the hydrodynamics see $\\delta + \\delta_0$ (a misaligned
    rudder indicator or a hull asymmetry; Lu & Zhao 2008, eq. 1)."""

    delta0: ArrayLike = param(0.0, lower=-0.1, upper=0.1, scale=0.01, unit="rad")
    id: ClassVar[str] = "rudder_offset"

    def rudder(self, delta, z, aux=None):
        return delta + self.delta0


class YawMomentBias(AbstractLoadEffect, AbstractYawTermEffect):
    """A constant yaw moment: $N_0$ [N m] on a vessel; on a steering model the term
    $N_0$ in its yaw equation (`yaw_term`: [rad/s] for Nomoto models, where it equals
    a rudder offset $N_0/K$; [rad/s^2] for models written as $\\dot r = \\dots$)."""

    n0: ArrayLike = param(0.0, unit="N m | rad/s | rad/s^2")
    id: ClassVar[str] = "yaw_moment_bias"

    def loads(self, t, vessel, u, v, r, delta, n):
        return jnp.stack([0.0 * u, 0.0 * u, self.n0 + 0.0 * u])

    def yaw_term(self, model, x, delta, aux):
        return self.n0


class YawCubicDamping(AbstractLoadEffect, AbstractYawTermEffect):
    """Cubic yaw damping, $\\beta > 0$ more damping in both families.

    - Steering models: $-\\beta r^3$ in the yaw equation. With `Nomoto2` it is the
      second-order nonlinear model of Lu & Zhao (2008, eq. 4),
      $T_1T_2\\ddot r + (T_1 + T_2)\\dot r + r + \\beta r^3 = K\\delta + KT_3\\dot\\delta$;
      with `Nomoto1` Norrbin's characteristic with $n_3 = \\beta$ (Norrbin 1963)
      [s^2/rad^2; s/rad^2 for models written as $\\dot r = \\dots$].
    - Vessels: $N \\mathrel{+}= -\\beta r^3$ [N m s^3/rad^3], i.e. $N_{rrr} = -\\beta$
      of an Abkowitz (1964) expansion, in addition to any the vessel has. In the
      prime system ($r' = rL/U$), $\\beta = -N'_{rrr}\\,\\tfrac12\\rho L^6/U$: about
      $10^{12}$ for the Mariner.

    Family units, hence no bounds; physically $\\beta \\ge 0$ (Norrbin's $n_3 > 0$).
    Typical sizes: 10^2-10^4 s^2/rad^2 on Nomoto models of ships ($n_3' = n_3
    (U/L)^2 \\approx 0.1$-$10$)."""

    beta: ArrayLike = param(0.0, unit="N m s^3/rad^3 | s^2/rad^2 | s/rad^2")
    id: ClassVar[str] = "yaw_cubic_damping"

    def loads(self, t, vessel, u, v, r, delta, n):
        return jnp.stack(jnp.broadcast_arrays(0.0 * u, 0.0 * u, -self.beta * r**3))

    def yaw_term(self, model, x, delta, aux):
        return -self.beta * model.output(x) ** 3


def _lag_gate(time_constant):
    """(active, safe time constant): a lag shorter than `SHORTEST_TIME_CONSTANT` is off."""
    active = time_constant > SHORTEST_TIME_CONSTANT
    return active, jnp.where(active, time_constant, 1.0)


class RudderLag(AbstractRudderEffect):
    """A first-order lag between the recorded and the acting rudder (a steering gear
    slower than logged, or a rudder angle read upstream of the gear):
    $T_l\\dot\\delta' = \\delta - \\delta'$ (Fossen 2021, eq. 9.8). Off (the base model
    exactly) for $T_l \\le$ `SHORTEST_TIME_CONSTANT`."""

    time_constant: ArrayLike = param(0.0, lower=0.0, upper=20.0, scale=0.5, unit="s")
    id: ClassVar[str] = "rudder_lag"
    state_names: ClassVar[tuple[str, ...]] = ("delta_lagged",)

    def initial_state(self, delta):
        return jnp.reshape(jnp.asarray(delta, float), (1,))

    def state_rate(self, z, delta):
        active, tau = _lag_gate(self.time_constant)
        return jnp.where(active, (delta - z) / tau, 0.0)

    def rudder(self, delta, z, aux=None):
        return jnp.where(_lag_gate(self.time_constant)[0], z[0], delta)


class RudderDelay(AbstractRudderEffect):
    """A pure delay $\\tau_d$ of the rudder, $\\delta'(t) = \\delta(t - \\tau_d)$, by its
    first-order Pade approximant $e^{-s\\tau_d} \\approx (1 - s\\tau_d/2)/(1 + s\\tau_d/2)$
    (Franklin, Powell & Emami-Naeini 2015, sec. 5.6): $\\delta' = 2z - \\delta$,
    $(\\tau_d/2)\\dot z = \\delta - z$. Off for $\\tau_d/2 \\le$ `SHORTEST_TIME_CONSTANT`."""

    delay: ArrayLike = param(0.0, lower=0.0, upper=10.0, scale=0.5, unit="s")
    id: ClassVar[str] = "rudder_delay"
    state_names: ClassVar[tuple[str, ...]] = ("delta_pade",)

    def initial_state(self, delta):
        return jnp.reshape(jnp.asarray(delta, float), (1,))

    def state_rate(self, z, delta):
        active, half = _lag_gate(self.delay / 2)
        return jnp.where(active, (delta - z) / half, 0.0)

    def rudder(self, delta, z, aux=None):
        return jnp.where(_lag_gate(self.delay / 2)[0], 2 * z[0] - delta, delta)


class RudderRateLimit(AbstractRudderEffect):
    """A steering gear slower than the recorded (commanded) rudder: the acting rudder
    follows it with time constant `tracking` (0.1 s) at no more than
    $\\dot\\delta_{max} = 1/s$ [rad/s] (Fossen 2021, sec. 9.3). Parametrised by the
    inverse rate $s$ [s/rad], so $s = 0$ (no limit) is the base model exactly."""

    inverse_rate: ArrayLike = param(0.0, lower=0.0, upper=100.0, scale=5.0, unit="s/rad")
    tracking: float = eqx.field(static=True, default=0.1)  # [s], not fitted
    id: ClassVar[str] = "rudder_rate_limit"
    state_names: ClassVar[tuple[str, ...]] = ("delta_limited",)

    def initial_state(self, delta):
        return jnp.reshape(jnp.asarray(delta, float), (1,))

    def state_rate(self, z, delta):
        active = self.inverse_rate > 0
        rate = 1.0 / jnp.where(active, self.inverse_rate, 1.0)
        return jnp.where(active, jnp.clip((delta - z) / self.tracking, -rate, rate), 0.0)

    def rudder(self, delta, z, aux=None):
        return jnp.where(self.inverse_rate > 0, z[0], delta)


class SwayForceBias(AbstractLoadEffect):
    """A constant body-fixed sway force $Y_0$ [N] (vessels only)."""

    y0: ArrayLike = param(0.0, unit="N")
    id: ClassVar[str] = "sway_force_bias"

    def loads(self, t, vessel, u, v, r, delta, n):
        return jnp.stack([0.0 * u, self.y0 + 0.0 * u, 0.0 * u])


class YawRateSensorBias(AbstractSensorEffect):
    """The yaw-rate sensor reads $r + b_r$ [rad/s] (a gyro bias)."""

    bias: ArrayLike = param(0.0, lower=-0.02, upper=0.02, scale=1e-3, unit="rad/s")
    id: ClassVar[str] = "yaw_rate_sensor_bias"

    def measure(self, channel, value):
        return value + self.bias if channel == "r" else value

    def unmeasure(self, channel, value):
        return value - self.bias if channel == "r" else value


class HeadingSensorBias(AbstractSensorEffect):
    """The compass reads $\\psi + b_\\psi$ [rad] (a misaligned heading reference)."""

    bias: ArrayLike = param(0.0, lower=-0.2, upper=0.2, scale=0.01, unit="rad")
    id: ClassVar[str] = "heading_sensor_bias"

    def measure(self, channel, value):
        return value + self.bias if channel == "psi" else value

    def unmeasure(self, channel, value):
        return value - self.bias if channel == "psi" else value


class RecordedDisturbance(AbstractLoadEffect):
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


class _Augmented(AbstractComposite):
    """What both augmented models share: the base, the effects (the parameter names
    `"<effect id>.<field>"` of `AbstractComposite`) and the effects' own states."""

    @property
    def effect_state_size(self) -> int:
        """How many states the effects add (after the base model's)."""
        return sum(len(e.state_names) for e in self.effects)

    def effect_initial(self, delta):
        """The effects' states in a steady state at the rudder `delta` [rad]."""
        return jnp.concatenate([jnp.zeros((0,))] + [
            e.initial_state(delta) for e in _of(self.effects, AbstractRudderEffect)])

    def rudder_path(self, delta, z, aux=None):
        """The rudder angle the base model sees, after every effect's actuator path in
        order, and the time derivative of the effects' states `z`; `aux`: a steering
        model's auxiliary inputs (None for a vessel)."""
        rates, i = [jnp.zeros((0,))], 0
        for effect in _of(self.effects, AbstractRudderEffect):
            k = len(effect.state_names)
            rates.append(effect.state_rate(z[i:i + k], delta))
            delta = effect.rudder(delta, z[i:i + k], aux)
            i += k
        return delta, jnp.concatenate(rates)

    def measure(self, channel: str, value):
        for effect in _of(self.effects, AbstractSensorEffect):
            value = effect.measure(channel, value)
        return value

    def true_start(self, start):
        """A window start with the true r and psi behind the readings (sensor effects
        removed)."""
        true = lambda channel, value: _unmeasure(self.effects, channel, value)
        return eqx.tree_at(lambda s: (s.r, s.psi, s.r_first, s.psi_first), start,
                           (true("r", start.r), true("psi", start.psi),
                            true("r", start.r_first), true("psi", start.psi_first)))


def _unmeasure(effects, channel, value):
    for effect in reversed(_of(effects, AbstractSensorEffect)):
        value = effect.unmeasure(channel, value)
    return value


def _check_effects(effects, places, family):
    ids = [e.id for e in effects]
    for e in effects:
        if not isinstance(e, AbstractEffect):
            raise ValueError(f"effects must be jaxship effects (AbstractEffect), got "
                             f"{type(e).__name__}.")
        if not isinstance(e, places):  # it would be a null parameter
            other = "steering model" if family == "vessel" else "vessel"
            raise ValueError(f"{type(e).__name__} acts on nothing a {family} has (its "
                             f"{', '.join(PLACE_NAMES[p] for p in places)}): augment a "
                             f"{other} instead.")
    if len(set(ids)) != len(ids):
        raise ValueError(f"each effect may appear once, got {ids}.")
    return tuple(effects)


class AugmentedVessel(_Augmented, AbstractVessel):
    """A vessel with effects: $\\tau = \\tau_{base}(u, v, r, \\delta', n) +
    \\sum_e \\tau_e(u, v, r, \\delta', n)$, $\\delta'$ the rudder after the effects'
    actuator path; the mass matrix, the environment and the wind areas after the
    effects' corrections (`mass`, `environment`, `wind_areas`), in order. The
    effects' states follow the eight of `ShipState` in the simulated state vector;
    `held` carries their values into `loads` during an evaluation (None: a steady
    state at the current rudder)."""

    base: AbstractVessel
    effects: tuple[AbstractEffect, ...]
    held: Array | None = None

    def __init__(self, base: AbstractVessel, effects=(), held=None):
        self.base, self.effects, self.held = base, _check_effects(effects, VESSEL_PLACES,
                                                                  "vessel"), held

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
        return self._wind_areas()[0]

    @property
    def wind_model(self):
        return self.base.wind_model

    @property
    def lateral_wind_area(self):
        return self._wind_areas()[1]

    def _wind_areas(self):
        areas = (self.base.frontal_wind_area, self.base.lateral_wind_area)
        for effect in _of(self.effects, AbstractVesselPropertyEffect):
            areas = effect.wind_areas(*areas)
        return areas

    def mass_matrix(self):
        matrix = self.base.mass_matrix()
        for effect in _of(self.effects, AbstractVesselPropertyEffect):
            matrix = effect.mass(matrix)
        return matrix

    def environment(self, environment):
        environment = self.base.environment(environment)
        for effect in _of(self.effects, AbstractVesselPropertyEffect):
            environment = effect.environment(environment)
        return environment

    def forces(self, u, v, r, delta, n):
        return self.loads(0.0, u, v, r, delta, n)

    def loads(self, t, u, v, r, delta, n):
        z = self.effect_initial(delta) if self.held is None else self.held
        seen = self.rudder_path(delta, z)[0]
        tau = self.base.loads(t, u, v, r, seen, n)
        for effect in _of(self.effects, AbstractLoadEffect):
            tau = tau + effect.loads(t, self.base, u, v, r, seen, n)
        return tau

    def holding(self, z) -> "AugmentedVessel":
        """This vessel with the effects' states `z` for its `loads`."""
        return AugmentedVessel(self.base, self.effects, z)

    def replay_state(self, start, servo: bool = False):
        y = self.base.replay_state(self.true_start(start), servo)
        return jnp.concatenate([y, self.effect_initial(y[6])])

    def replay_field(self, servo: bool = False):
        if not self.effect_state_size:
            return AbstractVessel.replay_field(self, servo)
        size = len(STATE_FIELDS)

        def field(t, y, inputs):
            z = y[size:]
            y_dot = AbstractVessel.replay_field(self.holding(z), servo)(t, y[:size], inputs)
            delta = y[STATE_FIELDS.index("delta")] if servo else inputs["delta"]
            return jnp.concatenate([y_dot, self.rudder_path(delta, z)[1]])

        return field


class AugmentedSteering(_Augmented, AbstractSteeringModel):
    """A steering model with effects: $\\dot x = f(x, \\delta', a) + b(x)\\sum_e f_e$,
    $\\delta'$ the rudder after the effects' actuator path, $f_e$ their terms in the
    yaw equation and $b$ the model's `forcing`; the effects' states follow the
    model's own (the heading stays last)."""

    base: AbstractSteeringModel
    effects: tuple[AbstractEffect, ...]

    def __init__(self, base: AbstractSteeringModel, effects=()):
        self.base, self.effects = base, _check_effects(effects, STEERING_PLACES,
                                                       "steering model")

    @property
    def wind_loads(self) -> bool:
        """Whether the base or an effect reads the replayed wind
        (`jaxship.effects.ApparentWind`)."""
        return self.base.wind_loads or any(e.uses_wind for e in self.effects)

    @property
    def default_channels(self) -> tuple[str, ...]:
        """The base's fitted outputs (a sway-yaw model's v as well)."""
        return self.base.default_channels

    @property
    def built_in_effects(self) -> tuple[str, ...]:
        return self.base.built_in_effects

    @property
    def state_names(self):
        return self.base.state_names + tuple(f"{e.id}.{name}" for e in self.effects
                                             for name in e.state_names)

    def _split(self, state):
        k = len(self.base.state_names)
        return state[:k], state[k:]

    def rhs(self, state, delta, aux):
        x, z = self._split(state)
        seen, z_dot = self.rudder_path(delta, z, aux)
        term = sum(jnp.asarray(e.yaw_term(self.base, x, delta, aux), float)
                   for e in _of(self.effects, AbstractYawTermEffect))
        x_dot = self.base.rhs(x, seen, aux) + self.base.forcing(x) * term
        return jnp.concatenate([x_dot, z_dot])

    def forcing(self, state):
        return jnp.concatenate([self.base.forcing(self._split(state)[0]),
                                jnp.zeros((self.effect_state_size,))])

    def output(self, state):
        return self.base.output(self._split(state)[0])

    def initial_state(self, r):
        """The base's steady state at yaw rate `r`, the effects' at zero rudder."""
        return jnp.concatenate([self.base.initial_state(r), self.effect_initial(0.0)])

    def window_state(self, start):
        """The base's window state, the effects' steady at the window's rudder."""
        return jnp.concatenate([self.base.window_state(start),
                                self.effect_initial(start.delta)])

    def replay_state(self, start, servo: bool = False):
        return AbstractSteeringModel.replay_state(self, self.true_start(start), servo)


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


def nonlinear_nomoto2(K, T1, T2, T3, beta1=0.0, delta0=0.0) -> AugmentedSteering:
    """The second-order nonlinear response model of Lu & Zhao (2008, eq. 4; seed 002),
    $T_1T_2\\ddot r + (T_1 + T_2)\\dot r + r + \\beta_1 r^3 = K(\\delta + \\delta_0) +
    KT_3\\dot\\delta$ ($\\alpha_1 = 1$, as they fix it): `Nomoto2` with the effect
    `YawCubicDamping` (its parameter `"yaw_cubic_damping.beta"` is $\\beta_1$)."""
    return AugmentedSteering(Nomoto2(K=K, T1=T1, T2=T2, T3=T3, delta0=delta0),
                             (YawCubicDamping(beta=beta1),))
