"""Sway-yaw response model for low speed, where the propeller race and the wind steer
as much as the hull's speed does (model-basin manoeuvres at 0.1-0.5 m/s outdoors).

The linear sway-yaw model (`LinearSwayYaw`; Astrom & Kallstrom 1979, eq. 3) scales
every force with the speed: damping with $u$, the rudder with $u^2$. At low speed three
loads do not: the rudder's inflow from the propeller race, the cross-flow drag of a
hull drifting at tens of degrees, and the wind. Each equation here is written per unit
of its own inertia (the mass matrix folded into the coefficients), with the measured
surge speed u, propeller rate $n_+ = \\max(n, 0)$ and apparent wind (`AuxInputs`):

$$\\dot r = N_v u v + N_r u r + N_\\delta u_R^2\\delta - C_N\\!\\int x|w|w\\,dx
+ (2w_2u_{rw} + w_1V_{rw})v_{rw},$$
$$\\dot v = Y_v u v + Y_r u r + Y_\\delta u_R^2\\delta - C_Y\\!\\int |w|w\\,dx
+ w_Y V_{rw}v_{rw},$$

- $u_R^2 = u^2 + c_R n_+^2$: the rudder inflow behind a heavily loaded propeller (MMG,
  Yasukawa & Yoshimura 2015, eq. 23; as `PropellerRace`);
- $w = v + xr$ over $-L/2 \\le x \\le L/2$: Norrbin's (1976) cross-flow drag, as in
  `NorrbinCrossFlow` (closed form `_cross_flow_integrals`), with one effective
  coefficient per equation;
- the wind: lateral force $\\propto V_{rw}^2\\sin\\gamma$ and yaw moment
  $V_{rw}^2(c_2\\sin 2\\gamma + c_1\\sin\\gamma)$ (Fossen 2021, eqs. 10.9-10.10; Isherwood
  1972), $\\gamma$ the angle the apparent wind comes from (`ApparentWind`'s yaw term).
  Calm where no wind is logged or replayed.

A rudder offset is an effect (`augment(model, RudderOffset())`).
"""

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ..._foundation._params import param
from .._vessel.sway_yaw import _cross_flow_integrals
from ._base import AbstractSteeringModel, AuxInputs, WindowStart


class LowSpeedSwayYaw(AbstractSteeringModel):
    """The low-speed sway-yaw model of the module docstring: states `("r", "v")` (yaw
    rate [rad/s], sway velocity [m/s] at midship); needs the measured surge speed u
    and propeller rate n (a record without them steers with the race alone or not
    at all). Fit it with `PredictionError(wind=True)` on records with a wind log, on
    the channels r and v.

    Every coefficient is free by default; `length` $L$ [m] sets the cross-flow
    integrals; `speed` [m/s] and `propeller_rate` [rev/s] are the conditions of
    `initial_state` and `steady_turn`. Start values: a tanker model of L = 3 m at
    0.3 m/s (time constants of 5-15 s, race giving the rudder about its inflow at
    10 rev/s)."""

    n_v: float = param(0.0, scale=0.2, unit="1/m^2")  # N_v, yaw from drift
    n_r: float = param(-0.2, scale=0.2, unit="1/m")  # N_r, yaw damping (< 0)
    n_delta: float = param(0.04, scale=0.02, unit="1/m^2")  # N_delta (> 0: starboard)
    y_v: float = param(-0.6, scale=0.3, unit="1/m")  # Y_v, sway damping (< 0)
    y_r: float = param(-1.0, scale=0.5, unit="-")  # Y_r, sway from yaw
    y_delta: float = param(0.0, scale=0.05, unit="1/m")  # Y_delta
    race: float = param(1e-3, lower=0.0, scale=1e-3, unit="m^2")  # c_R, race inflow
    crossflow_y: float = param(0.1, lower=0.0, scale=0.1, unit="1/m^2")  # C_Y
    crossflow_n: float = param(0.01, lower=0.0, scale=0.01, unit="1/m^4")  # C_N
    wind_y: float = param(0.0, scale=1e-3, unit="1/m")  # w_Y, wind sway force
    wind_1: float = param(0.0, scale=1e-3, unit="1/m^2")  # w_1, wind yaw (sin gamma)
    wind_2: float = param(0.0, scale=1e-3, unit="1/m^2")  # w_2, wind yaw (sin 2 gamma)
    length: float = 3.0  # L [m]
    speed: float = 0.3  # u [m/s] of `initial_state`
    propeller_rate: float = 10.0  # n [rev/s] of `initial_state`

    state_names = ("r", "v")
    default_channels = ("psi", "r", "v")
    wind_loads = True
    built_in_effects = ("speed_dependent_rudder", "speed_dependent_damping", "propeller_race",
                        "crossflow_drag", "wind")

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        r, v = state[0], state[1]
        u = jnp.asarray(aux.u, float)
        n = jnp.maximum(jnp.asarray(aux.n, float), 0.0)
        rudder = (u**2 + self.race * n**2) * delta
        sway_drag, yaw_drag = _cross_flow_integrals(v, r, self.length)
        wind_sway = wind_yaw = 0.0
        if aux.wind_u is not None:
            wu, wv = jnp.asarray(aux.wind_u, float), jnp.asarray(aux.wind_v, float)
            speed = jnp.sqrt(wu**2 + wv**2)
            wind_sway = self.wind_y * speed * wv
            wind_yaw = (2.0 * self.wind_2 * wu + self.wind_1 * speed) * wv
        r_dot = (self.n_v * u * v + self.n_r * u * r + self.n_delta * rudder
                 - self.crossflow_n * yaw_drag + wind_yaw)
        v_dot = (self.y_v * u * v + self.y_r * u * r + self.y_delta * rudder
                 - self.crossflow_y * sway_drag + wind_sway)
        return jnp.stack([r_dot, v_dot])

    def output(self, state: Array) -> Array:
        return state[0]

    def steady_turn(self, r: ArrayLike):
        """`(v, delta)` [m/s, rad] of the calm steady turn at yaw rate `r` [rad/s],
        `speed` and `propeller_rate`: the root of $\\dot r = \\dot v = 0$ by Newton's
        method from the straight run."""
        aux = AuxInputs(self.speed, 0.0, self.propeller_rate)
        r = jnp.asarray(r, float)

        def residual(x):
            return self.rhs(jnp.stack([r, x[0]]), x[1], aux)

        x = jax.lax.fori_loop(  # one loop: written out, compiled twelve times
            0, 12, lambda _, x: x - jnp.linalg.solve(jax.jacfwd(residual)(x), residual(x)),
            jnp.zeros(2))
        return x[0], x[1]

    def initial_state(self, r: ArrayLike) -> Array:
        """State `(r, v)` of the steady turn at yaw rate `r` (`steady_turn`)."""
        return jnp.stack([jnp.asarray(r, float), self.steady_turn(r)[0]])

    def window_state(self, start: WindowStart) -> Array:
        # the measured r and sway velocity (zero where v is not logged)
        return jnp.stack([jnp.asarray(start.r, float), jnp.asarray(start.aux.v, float)])
