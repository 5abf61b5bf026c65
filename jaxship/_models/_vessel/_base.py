"""The vessel interface: vessels return forces and a mass matrix, never integrate."""

import abc
from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._contract import AbstractModel
from ..._foundation._exported import persistent
from ..._foundation._state import (
    STATE_FIELDS,
    Command,
    ShipState,
    from_vector,
    straight_state,
    to_vector,
)
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, Environment, Wind


class AbstractVessel(AbstractModel):
    """A 3-DOF (surge, sway, yaw) vessel model.

    The equations of motion are $M \\dot\\nu = \\tau(\\nu, \\delta, n) + \\tau_{env}$ with
    $\\nu = (u, v, r)$ relative to the water at the vessel's reference point
    (Fossen 2021, eq. 6.1). Subclasses give the constant mass matrix $M$ (rigid body
    plus added mass) and the hydrodynamic, rudder, propeller and Coriolis loads
    $\\tau$; the simulator owns the numerics.

    Sign convention for every vessel: positive rudder angle turns the ship to
    starboard ($r > 0$); x forward, y to starboard, z down.
    """

    length: eqx.AbstractVar[float]  # L_pp [m]
    rudder: eqx.AbstractVar[RudderServo]
    shaft: eqx.AbstractVar[Shaft]
    nominal_speed: eqx.AbstractVar[float]  # approach speed U_0 [m/s]
    nominal_n: eqx.AbstractVar[float]  # propeller rate at U_0 in straight run [rev/s]
    frontal_wind_area: eqx.AbstractVar[float]  # A_F [m^2], 0 for no windage
    lateral_wind_area: eqx.AbstractVar[float]  # A_L [m^2]
    # how the wind on those areas makes loads (`jaxship.wind_loads.FossenWindLoads()` in every
    # class unless given another)
    wind_model: eqx.AbstractVar[AbstractWindLoads]

    # the model contract (`AbstractModel`): fitted outputs by default, channels every
    # window starts from, wind loads, a rudder servo; its coefficients are `param` fields
    default_channels: ClassVar[tuple[str, ...]] = ("psi", "r", "u", "v")
    start_channels: ClassVar[tuple[str, ...]] = ("u", "v")
    wind_loads: ClassVar[bool] = True
    has_servo: ClassVar[bool] = True
    # states of effects (a rudder lag, ...) after the eight of `ShipState`; see
    # `jaxship.effects.AugmentedVessel`
    effect_state_size: ClassVar[int] = 0

    @abc.abstractmethod
    def mass_matrix(self) -> Array:
        """The 3x3 matrix $M = M_{RB} + M_A$ in SI units [kg, kg m, kg m^2]."""

    def loads(self, t, u, v, r, delta, n) -> Array:
        """All loads at time `t` [s]: `forces` here; effects that vary in time add to
        them (`jaxship.effects.AugmentedVessel`)."""
        return self.forces(u, v, r, delta, n)

    def environment(self, environment: Environment) -> Environment:
        """The environment (current, wind) the equations of motion see for the given
        one: itself here; effects change it (`jaxship.effects.UniformCurrent`)."""
        return environment

    @abc.abstractmethod
    def forces(self, u, v, r, delta, n) -> Array:
        """Loads $\\tau = (X, Y, N)$ [N, N, N m] at velocities `u, v` [m/s], `r`
        [rad/s], rudder angle `delta` [rad] and propeller rate `n` [rev/s],
        including the Coriolis-centripetal terms, i.e. everything except $M\\dot\\nu$."""


    # -- the model contract shared with steering models (replay of measured records) --

    def channel_index(self, channel: str) -> int:
        """Where an output channel (`"psi"`, `"r"`, `"u"`, `"v"`, `"x"`, `"y"`) sits in the
        state vector."""
        return STATE_FIELDS.index(channel)

    def replay_state(self, start, servo: bool = False) -> Array:
        """The state vector at a window start (`WindowStart`) of a measured record:
        $(u, v, r, x, y, \\psi, \\delta, n)$ measured (x, y zero where not given: they
        do not enter the loads). The rudder is the replayed angle, or with
        `servo` the measured angle the servo starts from."""
        zero = jnp.zeros_like(start.r)
        delta = start.rudder_angle if servo else start.delta
        x, y = (zero, zero) if start.x is None else (start.x + zero, start.y + zero)
        return jnp.stack([start.aux.u, start.aux.v, start.r, x, y, start.psi, delta + zero,
                          start.aux.n + zero])

    def with_current(self, y, scale):
        """`y` with `scale` times the current of `environment` in body axes added to
        u, v: over ground $u_g = u + V_N\\cos\\psi + V_E\\sin\\psi$,
        $v_g = v - V_N\\sin\\psi + V_E\\cos\\psi$ (the current in body axes,
        $\\nu_c = R(\\psi)^\\top v_c^n$, Fossen 2021 ch. 10; `scale` 1); through the
        water from over ground (-1)."""
        north, east = self.environment(Environment()).current.velocity()
        psi = y[STATE_FIELDS.index("psi")]
        c, s = jnp.cos(psi), jnp.sin(psi)
        return y.at[0].add(scale * (north * c + east * s)).at[1].add(
            scale * (east * c - north * s))

    def replay_field(self, servo: bool = False):
        """`f(t, y, inputs)`: the state derivative with the measured rudder angle and
        propeller rate replayed (`inputs["delta"]`, `inputs["n"]`; their states do not
        move) or, with `servo`, the rudder command `inputs["delta"]` through the
        vessel's servo; with `inputs["wind_speed"]` and `["wind_dir"]` the wind loads
        of `jaxship.Wind` by the vessel's `wind_model`. The same `state_derivative` as
        `jaxship.simulate`."""
        mass_inverse = inverse3(self.mass_matrix())  # once per evaluation

        def field(t, y, inputs):
            state = from_vector(y)
            delta = state.delta if servo else inputs["delta"]
            state = eqx.tree_at(lambda s: (s.delta, s.n), state, (delta, inputs["n"]))
            wind = "wind_speed" in inputs
            environment = Environment(wind=Wind(inputs["wind_speed"], inputs["wind_dir"])
                                      ) if wind else Environment()
            d = _state_derivative(self, state, Command(inputs["delta"], inputs["n"]),
                                  environment, mass_inverse, wind=wind, t=t)
            still = jnp.zeros_like(d.n)
            return to_vector(eqx.tree_at(lambda s: (s.delta, s.n), d,
                                         (d.delta if servo else still, still)))

        return field


def state_derivative(
    vessel: AbstractVessel, state: ShipState, command: Command, environment: Environment
) -> ShipState:
    """Time derivative of the full state: dynamics, kinematics and actuators."""
    return _state_derivative(vessel, state, command, environment, inverse3(vessel.mass_matrix()))


def _state_derivative(
    vessel: AbstractVessel,
    state: ShipState,
    command: Command,
    environment: Environment,
    mass_inverse: Array,
    *,
    wind: bool = True,
    t=0.0,
    rudder_rate=None,
) -> ShipState:
    """`state_derivative` with $M^{-1}$ given (the simulator inverts $M$ once per run, not
    four times per step) and, with `wind=False`, without the wind loads (the simulator
    passes it when the wind speed is a static zero, where the loads vanish identically);
    `t` [s] for loads that vary in time; `rudder_rate` [rad/s]: a manoeuvre's limit on
    the rudder rate, $|\\dot\\delta| \\le$ min(servo's, `rudder_rate`) (None: the
    servo's own). The vessel's `environment` hook sees the environment first."""
    environment = vessel.environment(environment)
    tau = vessel.loads(t, state.u, state.v, state.r, state.delta, state.n)
    xdot, ydot = environment.ground_velocity(state.u, state.v, state.psi)
    if wind:
        cn, ce = environment.current.velocity()
        ug, vg = _ground_body_velocity(state, cn, ce)
        loads = environment.wind.loads(
            ug, vg, state.psi, vessel.frontal_wind_area, vessel.lateral_wind_area, vessel.length,
            vessel.wind_model,
        )
        tau = tau + jnp.stack(jnp.broadcast_arrays(*loads))
    # written out: a 3x3 `dot` is a library call per evaluation on CPU, this fuses
    nudot = mass_inverse[:, 0] * tau[0] + mass_inverse[:, 1] * tau[1] + mass_inverse[:, 2] * tau[2]
    return ShipState(
        u=nudot[0],
        v=nudot[1],
        r=nudot[2],
        x=xdot,
        y=ydot,
        psi=state.r,
        delta=_rudder_rate(vessel.rudder.rate(state.delta, command.delta), rudder_rate),
        n=vessel.shaft.rate(state.n, command.n),
    )


def _rudder_rate(rate, limit):
    """The servo's rudder rate, clipped to a manoeuvre's `limit` [rad/s] where given:
    the smaller of the two rate limits wins."""
    return rate if limit is None else jnp.clip(rate, -limit, limit)


def inverse3(m: Array) -> Array:
    """Inverse of a 3x3 matrix by its adjugate (no LAPACK call on the hot path)."""
    c0 = jnp.cross(m[:, 1], m[:, 2])
    c1 = jnp.cross(m[:, 2], m[:, 0])
    c2 = jnp.cross(m[:, 0], m[:, 1])
    return jnp.stack([c0, c1, c2]) / jnp.dot(m[:, 0], c0)


def solve3(m: Array, b: Array) -> Array:
    """Solve the 3x3 system `m x = b` by Cramer's rule (no LAPACK call on the hot path)."""
    c0 = jnp.cross(m[:, 1], m[:, 2])
    det = jnp.dot(m[:, 0], c0)
    return (
        jnp.stack(
            [
                jnp.dot(b, c0),
                jnp.dot(m[:, 0], jnp.cross(b, m[:, 2])),
                jnp.dot(m[:, 0], jnp.cross(m[:, 1], b)),
            ]
        )
        / det
    )


def _ground_body_velocity(state, current_north, current_east):
    c, s = jnp.cos(state.psi), jnp.sin(state.psi)
    return (
        state.u + current_north * c + current_east * s,
        state.v - current_north * s + current_east * c,
    )


def surge_force(vessel: AbstractVessel, u, n) -> Array:
    """Net surge force [N] in straight motion at speed `u` and propeller rate `n`."""
    zero = jnp.zeros_like(u)
    return vessel.forces(u, zero, zero, zero, n)[0]


def straight_run(vessel: AbstractVessel, *, speed=None, n=None, psi=0.0) -> ShipState:
    """Steady straight-run state (v = r = delta = 0, X = 0).

    Give `speed` [m/s] to solve for the self-propulsion rate `n`, or `n` [rev/s] to
    solve for the equilibrium speed; with neither, the vessel's nominal approach.
    Vessels without a propeller term keep `n` as given and `speed` as given.

    Arrays of `speed` or `n` give a batch of straight runs (a `ShipState` with their
    shape: a sweep's starts), solved by one compiled Newton iteration for all values.

    Raises `ValueError` where no such state exists: the surge force left at the state
    found exceeds $10^{-3}\\,m_{11} U^2/L$, $U$ the larger of u and the nominal speed
    (0.45 % off its nominal speed on the Mariner, whose surge equation has no propeller
    and balances only at that speed).
    """
    if speed is None and n is None:
        speed, n = vessel.nominal_speed, vessel.nominal_n
    if np.ndim(speed) or np.ndim(n):
        return _straight_runs(vessel, speed, n, psi)
    if n is None:
        n = _newton(lambda nn: _surge_and_slope(vessel, _f(speed), nn, "n"), vessel.nominal_n)
    elif speed is None:
        speed = _newton(lambda uu: _surge_and_slope(vessel, uu, _f(n), "u"),
                        vessel.nominal_speed)
    residual = float(_surge_and_slope(vessel, _f(speed), _f(n), "n")[0])
    reference = max(abs(float(speed)), float(vessel.nominal_speed))  # at rest too
    scale = float(_surge_mass(vessel)) * reference**2 / float(vessel.length)
    if not abs(residual) <= 1e-3 * scale:
        raise _no_straight_run(vessel, speed, n, f"a surge force of {residual:.4g} N is left")
    return straight_state(speed, n, psi)


def _no_straight_run(vessel, u, n, left: str) -> ValueError:
    """The error of `straight_run` where the surge force does not balance at u, n."""
    return ValueError(
        f"{type(vessel).__name__} has no straight run at u = {float(u):.4g} m/s, n = "
        f"{float(n):.4g} rev/s: {left} (its surge equation balances at "
        f"{float(vessel.nominal_speed):.4g} m/s"
        + (" only: it has no propeller term)." if not _has_propeller(vessel) else ")."))


def _straight_runs(vessel, speed, n, psi) -> ShipState:
    """`straight_run` for arrays of `speed` or `n` (the other None, or both given: nothing
    to solve), with the same check of the surge force left."""
    speed = None if speed is None else _f(speed)
    n = None if n is None else _f(n)
    dtype = jax.dtypes.canonicalize_dtype(np.float64)  # numbers traced, not static
    arrays = jax.tree.map(lambda x: np.asarray(x, dtype=dtype)
                          if isinstance(x, (float, int)) and not isinstance(x, bool) else x,
                          vessel)
    speed, n, residual = _solve_straight_runs(arrays, speed, n)
    reference = np.maximum(np.abs(np.asarray(speed)), float(vessel.nominal_speed))
    scale = float(_surge_mass(vessel)) * reference**2 / float(vessel.length)
    bad = ~(np.abs(np.asarray(residual)) <= 1e-3 * scale)
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        u_bad, n_bad = (float(np.ravel(np.asarray(x))[i]) for x in np.broadcast_arrays(speed, n))
        raise _no_straight_run(vessel, u_bad, n_bad,
                               f"({int(bad.sum())} of {bad.size} values) a surge force is left")
    return straight_state(speed, n, psi)


@persistent  # traced once per installation
@eqx.filter_jit
def _solve_straight_runs(vessel, speed, n, iterations=40):
    """Newton's iteration on the surge force X(u, n) = 0 for every value at once (a
    fixed count of steps, a guard where X does not depend on the unknown), and the force
    left."""
    def newton(f, x):
        def body(_, x):
            fx, dfx = jax.value_and_grad(f)(x)
            return jnp.where(jnp.abs(dfx) > 1e-300, x - fx / jnp.where(dfx == 0, 1.0, dfx), x)

        return jax.lax.fori_loop(0, iterations, body, x)

    if n is None:
        guess = jnp.asarray(vessel.nominal_n, dtype=float)
        n = jax.vmap(lambda uu: newton(lambda nn: surge_force(vessel, uu, nn), guess))(
            speed.ravel()).reshape(speed.shape)
    elif speed is None:
        guess = jnp.asarray(vessel.nominal_speed, dtype=float)
        speed = jax.vmap(lambda nn: newton(lambda uu: surge_force(vessel, uu, nn), guess))(
            n.ravel()).reshape(n.shape)
    speed, n = jnp.broadcast_arrays(speed, n)
    residual = jax.vmap(lambda uu, nn: surge_force(vessel, uu, nn))(speed.ravel(), n.ravel())
    return speed, n, residual.reshape(speed.shape)


def _has_propeller(vessel) -> bool:
    """Whether the surge force depends on the propeller rate at the nominal speed."""
    return float(_surge_and_slope(vessel, _f(vessel.nominal_speed),
                                  _f(vessel.nominal_n) + 1.0, "n")[1]) != 0.0


def _f(x):
    return jnp.asarray(x, dtype=float)


@persistent  # traced once per installation
@eqx.filter_jit
def _surge_and_slope(vessel, u, n, wrt: str):
    """`surge_force(vessel, u, n)` and its derivative with respect to `wrt` ("u" or
    "n"), as one compiled program (op by op, the trim compiled dozens of small ones in
    every new process)."""
    if wrt == "n":
        return jax.value_and_grad(lambda nn: surge_force(vessel, u, nn))(n)
    return jax.value_and_grad(lambda uu: surge_force(vessel, uu, n))(u)


_surge_mass = eqx.filter_jit(lambda vessel: vessel.mass_matrix()[0, 0])  # m_11 [kg]


def _newton(f, x0, iterations=50):
    """Scalar Newton iteration on `f(x) = (value, slope)`, with a guard for functions
    that do not depend on x."""
    x = _f(x0)
    for _ in range(iterations):
        fx, dfx = f(x)
        if float(abs(dfx)) < 1e-300:
            return x
        step = fx / dfx
        x = x - step
        if float(abs(step)) <= 1e-12 * max(1.0, float(abs(x))):
            break
    return x
