"""Uniform current and wind, both off by default; the wind-load models a vessel carries."""

import abc

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
    """Uniform wind; its loads come from the vessel's `wind_model`, by default
    `FossenWindLoads`: the simple load coefficients of Fossen (2021, eq. 10.7-10.10),

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

    def loads(self, u_ground, v_ground, psi, frontal_area, lateral_area, length, model=None):
        """Body-fixed wind force and moment `(X, Y, N)` [N, N, N m] on a moving ship, by
        the vessel's wind-load `model` (`FossenWindLoads()` if None: this wind's
        `cx`, `cy`, `cn`).

        The still-air load of the ship's own motion is taken as part of the vessel's
        calm-water resistance, so only the difference it makes is returned: zero
        when `speed` is zero, and straight runs stay in equilibrium in calm weather.
        """
        model = FossenWindLoads() if model is None else model
        # wind velocity (blowing towards) in body axes
        wn, we = -self.speed * jnp.cos(self.direction), -self.speed * jnp.sin(self.direction)
        uw, vw = earth_to_body(wn, we, psi)
        areas = (frontal_area, lateral_area)
        windy = model.pressure_loads(u_ground - uw, v_ground - vw, self, *areas)
        still = model.pressure_loads(u_ground, v_ground, self, *areas)
        scale = model.reference(frontal_area, lateral_area, length)
        return tuple(s * (a - b) for s, a, b in zip(scale, windy, still))


def _apparent(u_rw, v_rw):
    """Angle $\\gamma$ the relative wind `(u_rw, v_rw)` seen on board comes from (off the
    bow, + from starboard) [rad] and its dynamic pressure $q = \\tfrac12\\rho_a V_{rw}^2$ [Pa]."""
    return jnp.arctan2(v_rw, u_rw), 0.5 * RHO_AIR * (u_rw**2 + v_rw**2)


class AbstractWindLoads(eqx.Module):
    """How a vessel turns the relative wind into loads: the strategy a vessel carries
    in its `wind_model` field (`FossenWindLoads` by default, `FujiwaraWindLoads`).
    `Wind.loads` owns the kinematics (true to relative wind, still air)."""

    @abc.abstractmethod
    def pressure_loads(self, u_rw, v_rw, wind, frontal_area, lateral_area) -> tuple:
        """The loads per unit reference (`reference`) of the relative wind `(u_rw, v_rw)`
        [m/s] seen on board (the ship's velocity through the air), `wind` the `Wind`,
        on a vessel of these projected areas [m^2]."""

    @abc.abstractmethod
    def reference(self, frontal_area, lateral_area, length) -> tuple:
        """The reference area (X, Y) and area times length (N) [m^2, m^2, m^3] that
        `pressure_loads` multiplies, from the vessel's projected areas and length."""


class FossenWindLoads(AbstractWindLoads):
    """Fossen's (2021, eqs. 10.7-10.10) simple wind loads with the coefficients
    $c_x, c_y, c_n$ of the environment's `Wind`:
    $X = -c_x\\cos\\gamma\\, q A_F$, $Y = -c_y\\sin\\gamma\\, q A_L$,
    $N = -c_n\\sin 2\\gamma\\, q A_L L$ ($L$ the vessel's length). Every vessel's default."""

    def pressure_loads(self, u_rw, v_rw, wind, frontal_area, lateral_area):
        gamma, q = _apparent(u_rw, v_rw)
        return (
            -wind.cx * jnp.cos(gamma) * q,
            -wind.cy * jnp.sin(gamma) * q,
            -wind.cn * jnp.sin(2 * gamma) * q,
        )

    def reference(self, frontal_area, lateral_area, length):
        return frontal_area, lateral_area, lateral_area * length


class Environment(eqx.Module):
    """Current and wind acting on the vessel. `Environment()` is calm water."""

    current: Current = Current()
    wind: Wind = Wind()

    def ground_velocity(self, u, v, psi):
        """Earth-fixed track velocity (north, east) of a ship moving at `(u, v)` through water."""
        vn, ve = body_to_earth(u, v, psi)
        cn, ce = self.current.velocity()
        return vn + cn, ve + ce
