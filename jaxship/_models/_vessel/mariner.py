"""Mariner class cargo ship: the Chislett & Strom-Tejsen (1965) model as in Fossen's MSS.

Coefficients and equations follow MSS `CRAFT/SHIP/models/mariner.m` (Fossen; T. Lauvdal
1994), transcribed from Chislett & Strom-Tejsen (1965), *Planar Motion Mechanism Tests
and Full-Scale Steering and Maneuvering Predictions for a Mariner Class Vessel*, Hydro-
and Aerodynamics Laboratory, Lyngby, report Hy-5.
"""

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._params import param
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, FossenWindLoads
from ._base import AbstractVessel


class Mariner(AbstractVessel):
    """Mariner class cargo vessel, 3-DOF Abkowitz-type model (Chislett & Strom-Tejsen 1965).

    The forces are third-order Taylor expansions in the prime system of Fossen's MSS
    `mariner.m`: with the total speed $U = \\sqrt{u^2 + v^2}$,
    $u' = (u - U_0)/U$ (the *perturbation* of surge speed about $U_0$, which is
    `nominal_speed`), $v' = v/U$, $r' = rL/U$ and the source's rudder
    $\\delta_m = -\\delta$,

    $X' = X_u u' + X_{uu} u'^2 + X_{uuu} u'^3 + X_{vv} v'^2 + X_{rr} r'^2 +
    X_{rv} r'v' + X_{\\delta\\delta}\\delta_m^2 + X_{u\\delta\\delta} u'\\delta_m^2 +
    X_{v\\delta} v'\\delta_m + X_{uv\\delta} u'v'\\delta_m$,

    $Y' = Y_v v' + Y_r r' + Y_{vvv} v'^3 + Y_{vvr} v'^2 r' + Y_{vu} v'u' + Y_{ru} r'u' +
    Y_\\delta\\delta_m + Y_{\\delta\\delta\\delta}\\delta_m^3 + Y_{u\\delta} u'\\delta_m +
    Y_{uu\\delta} u'^2\\delta_m + Y_{v\\delta\\delta} v'\\delta_m^2 +
    Y_{vv\\delta} v'^2\\delta_m + Y_0 + Y_{0u} u' + Y_{0uu} u'^2$,

    and $N'$ with the same terms; $X = \\tfrac12\\rho L^2U^2 X'$, $Y = \\tfrac12\\rho L^2U^2 Y'$,
    $N = \\tfrac12\\rho L^3U^2 N'$. The rigid-body Coriolis terms are part of the
    coefficients ($X'_{rv} = m'$; $Y'_r$, $N'_r$ include $-m'$, $-m'x'_G$).

    The constant terms $Y_0, N_0, \\dots$ make the ship slowly turn at zero rudder and
    break port/starboard mirror symmetry, as in the source. The model has no propeller:
    the forces ignore `n`. MSS integrates the same equations; only the rudder sign
    differs (MSS `mariner.m` takes $u_i$ with $\\delta_c = -u_i$; here $\\delta = u_i$).
    """

    length: float = param(160.93, free=False, unit="m")  # L_pp, MSS mariner.m
    rudder: RudderServo = RudderServo(
        max_angle=float(np.deg2rad(40.0)),  # delta_max 40 deg, MSS mariner.m (2003 revision)
        max_rate=float(np.deg2rad(5.0)),  # delta_dot_max 5 deg/s, MSS mariner.m
        time_constant=1.0,  # T_delta [s], MSS mariner.m (delta_dot = delta_c - delta)
    )
    shaft: Shaft = Shaft()  # no propeller in the model; n is carried but ignored
    # U_0 (15 kn), MSS mariner.m default
    nominal_speed: float = param(7.7175, free=False, unit="m/s")
    nominal_n: float = param(0.0, free=False, unit="rev/s")  # no propeller
    frontal_wind_area: float = param(0.0, free=False, unit="m^2")  # A_F, no windage in the source
    lateral_wind_area: float = param(0.0, free=False, unit="m^2")  # A_L
    # water density used to dimensionalise the prime system
    rho: float = param(1025.0, free=False, unit="kg/m^3")

    # rigid body (prime system: mass / (rho L^3 / 2), inertia / (rho L^5 / 2), length / L)
    # m', MSS mariner.m (Chislett & Strom-Tejsen 1965)
    m: float = param(798e-5, free=False, unit="-")
    iz: float = param(39.2e-5, free=False, unit="-")  # I'_z, MSS mariner.m
    xg: float = param(-0.023, free=False, unit="-")  # x'_G, MSS mariner.m

    # surge, X' coefficients [-], MSS mariner.m
    x_udot: float = param(-42e-5, free=False, unit="-")  # X'_udot
    x_u: float = param(-184e-5, free=True, unit="-")  # X'_u
    x_uu: float = param(-110e-5, free=False, unit="-")  # X'_uu
    x_uuu: float = param(-215e-5, free=False, unit="-")  # X'_uuu
    x_vv: float = param(-899e-5, free=False, unit="-")  # X'_vv
    x_rr: float = param(18e-5, free=False, unit="-")  # X'_rr
    x_dd: float = param(-95e-5, free=False, unit="-")  # X'_deltadelta
    x_udd: float = param(-190e-5, free=False, unit="-")  # X'_udeltadelta
    x_rv: float = param(798e-5, free=False, unit="-")  # X'_rv (= m', the Coriolis term)
    x_vd: float = param(93e-5, free=False, unit="-")  # X'_vdelta
    x_uvd: float = param(93e-5, free=False, unit="-")  # X'_uvdelta

    # sway, Y' coefficients [-], MSS mariner.m
    y_vdot: float = param(-748e-5, free=False, unit="-")  # Y'_vdot
    y_rdot: float = param(-9.354e-5, free=False, unit="-")  # Y'_rdot
    y_v: float = param(-1160e-5, free=True, unit="-")  # Y'_v
    y_r: float = param(-499e-5, free=True, unit="-")  # Y'_r (includes -m')
    y_vvv: float = param(-8078e-5, free=False, unit="-")  # Y'_vvv
    y_vvr: float = param(15356e-5, free=False, unit="-")  # Y'_vvr
    y_vu: float = param(-1160e-5, free=False, unit="-")  # Y'_vu
    y_ru: float = param(-499e-5, free=False, unit="-")  # Y'_ru
    y_d: float = param(278e-5, free=True, unit="-")  # Y'_delta
    y_ddd: float = param(-90e-5, free=False, unit="-")  # Y'_deltadeltadelta
    y_ud: float = param(556e-5, free=False, unit="-")  # Y'_udelta
    y_uud: float = param(278e-5, free=False, unit="-")  # Y'_uudelta
    y_vdd: float = param(-4e-5, free=False, unit="-")  # Y'_vdeltadelta
    y_vvd: float = param(1190e-5, free=False, unit="-")  # Y'_vvdelta
    y_0: float = param(-4e-5, free=False, unit="-")  # Y'_0
    y_0u: float = param(-8e-5, free=False, unit="-")  # Y'_0u
    y_0uu: float = param(-4e-5, free=False, unit="-")  # Y'_0uu

    # yaw, N' coefficients [-], MSS mariner.m
    n_vdot: float = param(4.646e-5, free=False, unit="-")  # N'_vdot
    n_rdot: float = param(-43.8e-5, free=False, unit="-")  # N'_rdot
    n_v: float = param(-264e-5, free=True, unit="-")  # N'_v
    n_r: float = param(-166e-5, free=True, unit="-")  # N'_r (includes -m' x'_G)
    n_vvv: float = param(1636e-5, free=False, unit="-")  # N'_vvv
    n_vvr: float = param(-5483e-5, free=False, unit="-")  # N'_vvr
    n_vu: float = param(-264e-5, free=False, unit="-")  # N'_vu
    n_ru: float = param(-166e-5, free=False, unit="-")  # N'_ru
    n_d: float = param(-139e-5, free=True, unit="-")  # N'_delta
    n_ddd: float = param(45e-5, free=False, unit="-")  # N'_deltadeltadelta
    n_ud: float = param(-278e-5, free=False, unit="-")  # N'_udelta
    n_uud: float = param(-139e-5, free=False, unit="-")  # N'_uudelta
    n_vdd: float = param(13e-5, free=False, unit="-")  # N'_vdeltadelta
    n_vvd: float = param(-489e-5, free=False, unit="-")  # N'_vvdelta
    n_0: float = param(3e-5, free=False, unit="-")  # N'_0
    n_0u: float = param(6e-5, free=False, unit="-")  # N'_0u
    n_0uu: float = param(3e-5, free=False, unit="-")  # N'_0uu
    wind_model: AbstractWindLoads = FossenWindLoads()  # wind loads on A_F, A_L

    def mass_matrix(self) -> Array:
        L = self.length
        m11 = self.m - self.x_udot
        m22 = self.m - self.y_vdot
        m23 = self.m * self.xg - self.y_rdot
        m32 = self.m * self.xg - self.n_vdot
        m33 = self.iz - self.n_rdot
        prime = jnp.array([
            [m11, 0.0, 0.0],
            [0.0, m22, L * m23],
            [0.0, L * m32, L**2 * m33],
        ])
        return 0.5 * self.rho * L**3 * prime

    def forces(self, u, v, r, delta, n) -> Array:
        del n  # no propeller in the model
        L = self.length
        U = jnp.sqrt(u**2 + v**2)
        up = (u - self.nominal_speed) / U  # MSS's state is the perturbation u - U_0
        vp = v / U
        rp = r * L / U
        d = -delta  # MSS rudder: positive delta_m gives N < 0 (turn to port)
        X = (
            self.x_u * up + self.x_uu * up**2 + self.x_uuu * up**3 + self.x_vv * vp**2
            + self.x_rr * rp**2 + self.x_rv * rp * vp + self.x_dd * d**2
            + self.x_udd * up * d**2 + self.x_vd * vp * d + self.x_uvd * up * vp * d
        )
        Y = (
            self.y_v * vp + self.y_r * rp + self.y_vvv * vp**3 + self.y_vvr * vp**2 * rp
            + self.y_vu * vp * up + self.y_ru * rp * up + self.y_d * d + self.y_ddd * d**3
            + self.y_ud * up * d + self.y_uud * up**2 * d + self.y_vdd * vp * d**2
            + self.y_vvd * vp**2 * d + (self.y_0 + self.y_0u * up + self.y_0uu * up**2)
        )
        N = (
            self.n_v * vp + self.n_r * rp + self.n_vvv * vp**3 + self.n_vvr * vp**2 * rp
            + self.n_vu * vp * up + self.n_ru * rp * up + self.n_d * d + self.n_ddd * d**3
            + self.n_ud * up * d + self.n_uud * up**2 * d + self.n_vdd * vp * d**2
            + self.n_vvd * vp**2 * d + (self.n_0 + self.n_0u * up + self.n_0uu * up**2)
        )
        q = 0.5 * self.rho * L**2 * U**2
        return jnp.stack(jnp.broadcast_arrays(q * X, q * Y, q * L * N))


def mariner() -> Mariner:
    """Mariner class cargo ship at 15 kn (Chislett & Strom-Tejsen 1965; MSS `mariner.m`).

    L = 160.93 m, U_0 = 7.7175 m/s; Fossen's MSS `CRAFT/SHIP/models/mariner.m`
    coefficients and rudder servo (40 deg, 5 deg/s, 1 s), no propeller, rho = 1025 kg/m^3.
    """
    return Mariner()
