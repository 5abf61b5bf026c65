"""Uniform current and wind, both off by default."""

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from .._foundation._kinematics import body_to_earth, earth_to_body


RHO_AIR = 1.225  # air density [kg/m^3], ISA sea level


class Current(eqx.Module):
    """Uniform, irrotational earth-fixed current.

    With the hydrodynamics written in velocities relative to the water, a constant
    current only drifts the track (Fossen 2021, Property 10.1).
    """

    speed: ArrayLike = 0.0  # V_c [m/s]
    direction: ArrayLike = 0.0  # beta_c [rad], direction the current flows *towards*, from north

    def velocity(self) -> tuple[Array, Array]:
        """North and east components of the current [m/s]."""
        return self.speed * jnp.cos(self.direction), self.speed * jnp.sin(self.direction)


class Wind(eqx.Module):
    """Uniform wind with the simple load coefficients of Fossen (2021, eq. 10.7-10.10).

    $X = -c_x \\cos\\gamma\\, q A_F$, $Y = -c_y \\sin\\gamma\\, q A_L$,
    $N = -c_n \\sin 2\\gamma\\, q A_L L$, with $q = \\tfrac12 \\rho_a V_{rw}^2$ and
    $\\gamma$ the angle of the relative wind *coming from*, measured from the bow,
    positive from starboard (a beam wind from starboard
    pushes the ship to port, $Y < 0$). Coefficient ranges from Fossen's table 10.1
    (merchant ships: $c_x \\in [0.50, 0.90]$, $c_y \\in [0.70, 0.95]$,
    $c_n \\in [0.05, 0.20]$); defaults are mid-range.
    """

    speed: ArrayLike = 0.0  # V_w [m/s], true wind speed
    direction: ArrayLike = 0.0  # beta_w [rad], direction the wind comes *from*, from north
    cx: ArrayLike = 0.70  # c_x [-]
    cy: ArrayLike = 0.825  # c_y [-]
    cn: ArrayLike = 0.125  # c_n [-]

    def loads(self, u_ground, v_ground, psi, frontal_area, lateral_area, length):
        """Body-fixed wind force and moment `(X, Y, N)` [N, N, N m] on a moving ship.

        The still-air load of the ship's own motion is taken as part of the vessel's
        calm-water resistance, so only the difference it makes is returned: zero
        when `speed` is zero, and straight runs stay in equilibrium in calm weather.
        """
        # wind velocity (blowing towards) in body axes
        wn, we = -self.speed * jnp.cos(self.direction), -self.speed * jnp.sin(self.direction)
        uw, vw = earth_to_body(wn, we, psi)
        windy = self._coefficient_loads(u_ground - uw, v_ground - vw)
        still = self._coefficient_loads(u_ground, v_ground)
        scale = (frontal_area, lateral_area, lateral_area * length)
        return tuple(s * (a - b) for s, a, b in zip(scale, windy, still))

    def _coefficient_loads(self, u_rw, v_rw):
        """Loads per unit area (and length) for a relative wind `(u_rw, v_rw)` seen on board."""
        gamma = jnp.arctan2(v_rw, u_rw)  # angle the relative wind comes from, + from starboard
        q = 0.5 * RHO_AIR * (u_rw**2 + v_rw**2)
        return (
            -self.cx * jnp.cos(gamma) * q,
            -self.cy * jnp.sin(gamma) * q,
            -self.cn * jnp.sin(2 * gamma) * q,
        )


class Environment(eqx.Module):
    """Current and wind acting on the vessel. `Environment()` is calm water."""

    current: Current = Current()
    wind: Wind = Wind()

    def ground_velocity(self, u, v, psi):
        """Earth-fixed track velocity (north, east) of a ship moving at `(u, v)` through water."""
        vn, ve = body_to_earth(u, v, psi)
        cn, ce = self.current.velocity()
        return vn + cn, ve + ce
