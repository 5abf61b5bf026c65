"""Linear sway-yaw steering model in prime derivatives and Norrbin's cross-flow model
(Astrom & Kallstrom 1979, eq. 3 and the "Nonlinear Models" paragraph of section 2).

Both are the sway and yaw equations of `SwayYawVessel` (the simulator vessel of
the same report) as response models: the states are $(r, v)$, the rudder angle is the
input and the surge speed is a *measured* input, $V = u$ at each sample (`AuxInputs.u`),
as Astrom & Kallstrom did ("By using the measured value of the ship speed V at each
sampling event instead of the mean value the influences of the speed variations can be
reduced"). The forces are computed by `SwayYawVessel.forces` and its mass matrix, so the
physics is written once (`jaxship/_vessel/sway_yaw.py`).

In the prime system (length $L$, time $L/V$, mass $\\rho L^3/2$; eq. 3):

$$\\begin{pmatrix} m' - Y'_{\\dot v} & L(m'x'_G - Y'_{\\dot r}) \\\\
m'x'_G - N'_{\\dot v} & L(I'_z - N'_{\\dot r})\\end{pmatrix}
\\begin{pmatrix}\\dot v \\\\ \\dot r\\end{pmatrix} =
\\begin{pmatrix} \\tfrac VL Y'_v & V(Y'_r - m') \\\\
\\tfrac VL N'_v & V(N'_r - m'x'_G)\\end{pmatrix}
\\begin{pmatrix} v \\\\ r\\end{pmatrix} +
\\begin{pmatrix} \\tfrac{V^2}{L} Y'_\\delta \\\\ \\tfrac{V^2}{L} N'_\\delta\\end{pmatrix}\\delta
\\; [+\\, C f(v, r)],$$

with Norrbin's (1976) cross-flow drag $C f$ in `NorrbinCrossFlow` (one effective
coefficient $C$; $f$ the integral of $-\\tfrac12\\rho T|v + xr|(v + xr)$ over the hull,
`jaxship._models._vessel.sway_yaw._cross_flow_integrals`). The rudder sign is jaxship's
(positive $\\delta$ turns to starboard): $Y'_\\delta$, $N'_\\delta$ are minus the
published values.

The mass terms are frozen by default, as in the report (Tables 2-4 estimate the six
damping and rudder derivatives and C, not the mass terms).
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ..._foundation._params import param
from .._actuators import RudderServo
from .._vessel.sway_yaw import SwayYawVessel
from ._base import AbstractSteeringModel, AuxInputs, WindowStart


# the steering model is driven by the measured rudder angle: no servo dynamics
_NO_SERVO = RudderServo(float("inf"), float("inf"), 1.0)
_DERIVATIVES = ("y_v", "y_r", "n_v", "n_r", "y_delta", "n_delta")
_MASSES = ("m22", "m23", "m32", "m33")


class AbstractSwayYaw(AbstractSteeringModel):
    """Shared equations of `LinearSwayYaw` and `NorrbinCrossFlow` (see the module
    docstring): states `("r", "v")` (yaw rate [rad/s], sway velocity [m/s] at midship),
    speed $V$ = the measured surge speed `aux.u` when it is positive, else the
    model's `speed` (records without a speed log: `Experiment` fills a missing u
    with zeros).

    **Window starts** (`window_state`): the measured r and the measured sway velocity
    `start.aux.v` at the first sample of the window. A record without a sway
    measurement has v = 0 there, which is right for output error
    (`PredictionError(horizon=None)`) from a straight run but biases prediction-error
    windows that start mid-manoeuvre: such records need a measured (or
    log-derived) v for finite horizons.
    """

    length: eqx.AbstractVar[float]
    draught: eqx.AbstractVar[float]
    speed: eqx.AbstractVar[float]
    m22: eqx.AbstractVar[float]
    m23: eqx.AbstractVar[float]
    m32: eqx.AbstractVar[float]
    m33: eqx.AbstractVar[float]
    y_v: eqx.AbstractVar[float]
    y_r: eqx.AbstractVar[float]
    n_v: eqx.AbstractVar[float]
    n_r: eqx.AbstractVar[float]
    y_delta: eqx.AbstractVar[float]
    n_delta: eqx.AbstractVar[float]

    state_names = ("r", "v")

    @abc.abstractmethod
    def cross_flow_coefficient(self):
        """Norrbin's effective cross-flow drag coefficient C [-] (0: linear)."""

    def vessel(self) -> SwayYawVessel:
        """The `SwayYawVessel` with these coefficients (no rudder servo, nominal
        speed `speed`): the force model the steering model evaluates."""
        values = {k: getattr(self, k) for k in _DERIVATIVES + _MASSES}
        return SwayYawVessel(length=self.length, draught=self.draught, rudder=_NO_SERVO,
                             nominal_speed=self.speed,
                             cross_flow=self.cross_flow_coefficient(), **values)

    def _speed(self, aux: AuxInputs):
        u = jnp.asarray(aux.u, dtype=float)
        return jnp.where(u > 0, u, self.speed)

    def _accelerations(self, vessel, V, v, r, delta):
        """(v_dot, r_dot) from the vessel's sway and yaw rows: $M\\dot\\nu = \\tau$."""
        tau = vessel.forces(V, v, r, delta, 0.0)
        m = vessel.mass_matrix()
        a, b, c, d = m[1, 1], m[1, 2], m[2, 1], m[2, 2]
        det = a * d - b * c
        return (d * tau[1] - b * tau[2]) / det, (a * tau[2] - c * tau[1]) / det

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        r, v = state[0], state[1]
        v_dot, r_dot = self._accelerations(self.vessel(), self._speed(aux), v, r, delta)
        return jnp.stack([r_dot, v_dot])

    def output(self, state: Array) -> Array:
        return state[0]

    def steady_turn(self, r: ArrayLike, speed: ArrayLike | None = None):
        """`(v, delta)` [m/s, rad] of the steady turn at yaw rate `r` [rad/s] and
        `speed` [m/s] (default `speed`): the root of the sway and yaw equations with
        $\\dot v = \\dot r = 0$ by Newton's method from the linear solution (exact for
        `LinearSwayYaw`; 12 iterations for the cross-flow drag)."""
        V = self.speed if speed is None else speed
        return _steady_turn(self.vessel(), jnp.asarray(r, dtype=float),
                            jnp.asarray(V, dtype=float))

    def initial_state(self, r: ArrayLike) -> Array:
        """State `(r, v)` of the steady turn at yaw rate `r` (v from `steady_turn`);
        `(0, 0)` for a straight run."""
        v, _ = self.steady_turn(r)
        return jnp.stack([jnp.asarray(r, dtype=float), v])

    def window_state(self, start: WindowStart) -> Array:
        # measured r and measured sway velocity (see the class docstring)
        return jnp.stack([jnp.asarray(start.r, dtype=float),
                          jnp.asarray(start.aux.v, dtype=float)])


class LinearSwayYaw(AbstractSwayYaw):
    """Linear sway-yaw model in prime derivatives (Astrom & Kallstrom 1979, eq. 3),
    driven by the measured rudder angle with the measured surge speed as $V$.

    Free by default: the six damping and rudder derivatives, as estimated in the
    report's Tables 2-4; frozen: the mass terms, `length` $L$ [m], `draught` $T$
    [m] (unused here) and `speed` (the fallback V [m/s]). Build it from a vessel with
    `LinearSwayYaw.from_vessel(jaxship.get_vessel("sea_stratus_linear"))`.
    """

    length: float  # L [m], the unit of length of the prime system
    y_v: float = param(unit="-")  # Y'_v [-], eq. 3
    y_r: float = param(unit="-")  # Y'_r - m' [-], eq. 3
    n_v: float = param(unit="-")  # N'_v [-], eq. 3
    n_r: float = param(unit="-")  # N'_r - m'x'_G [-], eq. 3
    y_delta: float = param(unit="-")  # Y'_delta [-], eq. 3, jaxship sign (< 0)
    n_delta: float = param(unit="-")  # N'_delta [-], eq. 3, jaxship sign (> 0)
    m22: float = param(free=False, unit="-")  # m' - Y'_vdot [-], eq. 3 (frozen)
    m23: float = param(free=False, unit="-")  # m'x'_G - Y'_rdot [-], eq. 3 (frozen)
    m32: float = param(free=False, unit="-")  # m'x'_G - N'_vdot [-], eq. 3 (frozen)
    m33: float = param(free=False, unit="-")  # I'_z - N'_rdot [-], eq. 3 (frozen)
    speed: float  # V [m/s] when the record has no measured surge speed
    draught: float = 0.0  # T [m], unused by the linear model

    def cross_flow_coefficient(self):
        return 0.0

    @classmethod
    def from_vessel(cls, vessel: SwayYawVessel) -> "LinearSwayYaw":
        """The linear model with a `SwayYawVessel`'s coefficients; a cross-flow drag of
        the vessel is dropped (use `NorrbinCrossFlow.from_vessel` to keep it)."""
        return cls(**_vessel_fields(vessel))


class NorrbinCrossFlow(AbstractSwayYaw):
    """Norrbin's (1976) cross-flow model: the linear model (eq. 3) plus the cross-flow
    drag $C f_Y(v, r)$, $C f_N(v, r)$ with one effective coefficient $C$ (Astrom &
    Kallstrom 1979, section 2, "Nonlinear Models"; C = 0.63 for the Sea Stratus,
    Table 3, "approximately 0.7 for a tanker"):

    $Y_{cf} = -\\tfrac12\\rho T C\\int_{-L/2}^{L/2}|v + xr|(v + xr)\\,dx$,
    $N_{cf} = -\\tfrac12\\rho T C\\int_{-L/2}^{L/2}x|v + xr|(v + xr)\\,dx$,

    with the constant draught $T$ (`draught`, frozen). Free by default: the six
    derivatives and `cross_flow` ($C \\ge 0$).
    """

    length: float  # L [m], the unit of length of the prime system
    draught: float  # T [m], constant along the hull (cross-flow drag)
    y_v: float = param(unit="-")  # Y'_v [-], eq. 3
    y_r: float = param(unit="-")  # Y'_r - m' [-], eq. 3
    n_v: float = param(unit="-")  # N'_v [-], eq. 3
    n_r: float = param(unit="-")  # N'_r - m'x'_G [-], eq. 3
    y_delta: float = param(unit="-")  # Y'_delta [-], eq. 3, jaxship sign (< 0)
    n_delta: float = param(unit="-")  # N'_delta [-], eq. 3, jaxship sign (> 0)
    cross_flow: float = param(lower=0.0, unit="-")  # C [-], Norrbin (1976) cross-flow drag
    m22: float = param(free=False, unit="-")  # m' - Y'_vdot [-], eq. 3 (frozen)
    m23: float = param(free=False, unit="-")  # m'x'_G - Y'_rdot [-], eq. 3 (frozen)
    m32: float = param(free=False, unit="-")  # m'x'_G - N'_vdot [-], eq. 3 (frozen)
    m33: float = param(free=False, unit="-")  # I'_z - N'_rdot [-], eq. 3 (frozen)
    speed: float  # V [m/s] when the record has no measured surge speed

    def cross_flow_coefficient(self):
        return self.cross_flow

    @classmethod
    def from_vessel(cls, vessel: SwayYawVessel, cross_flow: float | None = None
                    ) -> "NorrbinCrossFlow":
        """The cross-flow model with a `SwayYawVessel`'s coefficients (its `cross_flow`,
        or `cross_flow` if given, e.g. a start value for a linear vessel)."""
        fields = _vessel_fields(vessel)
        c = vessel.cross_flow if cross_flow is None else cross_flow
        return cls(cross_flow=c, **fields)


@jax.jit
def _steady_turn(vessel, r, V):
    def residual(x):
        return vessel.forces(V, x[0], r, x[1], 0.0)[1:]

    # the linear part is affine in (v, delta): one Newton step solves it exactly
    linear = eqx.tree_at(lambda s: s.cross_flow, vessel, 0.0)
    jac = jax.jacfwd(lambda x: linear.forces(V, x[0], r, x[1], 0.0)[1:])(jnp.zeros(2))
    x = -jnp.linalg.solve(jac, linear.forces(V, 0.0, r, 0.0, 0.0)[1:])
    # the iterations in one loop: written out, they were compiled twelve times
    x = jax.lax.fori_loop(
        0, 12, lambda _, x: x - jnp.linalg.solve(jax.jacfwd(residual)(x), residual(x)), x)
    return x[0], x[1]


def _vessel_fields(vessel: SwayYawVessel) -> dict:
    if not isinstance(vessel, SwayYawVessel):
        raise ValueError(f"`vessel` must be a jaxship SwayYawVessel (e.g. "
                         f"get_vessel('sea_stratus_nonlinear')), got {type(vessel).__name__}.")
    out = {k: getattr(vessel, k) for k in _DERIVATIVES + _MASSES}
    return dict(out, length=vessel.length, draught=vessel.draught, speed=vessel.nominal_speed)
