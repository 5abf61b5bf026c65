"""MMG standard method (Yasukawa & Yoshimura 2015) and the KVLCC2 model-scale preset.

H. Yasukawa & Y. Yoshimura (2015), *Introduction of MMG standard method for ship
maneuvering predictions*, J. Mar. Sci. Technol. 20:37-52, doi:10.1007/s00773-014-0293-y.
Parameter values of the KVLCC2 L7 model: the paper's Tables 1-4 as transcribed in the
project notes `reference/vessel-models.md` sec. 2.2 (cross-checked there against
`ShipMMG/shipmmg` and other public implementations).
"""


import dataclasses

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._params import param
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, FossenWindLoads
from ._base import AbstractVessel, straight_run
from .particulars import MainParticulars, particulars_coefficients


GRAVITY = 9.80665  # g [m/s^2]
# U is regularised as sqrt(u^2 + v^2 + (SPEED_FLOOR sqrt(g L))^2) where it divides:
# a Froude number of 1e-4 (8e-4 m/s for a 7 m model), far below any manoeuvring speed.
SPEED_FLOOR = 1e-4
# Width [rad] of the smooth switches between the port and starboard values of
# gamma_R and C_2 and of the smoothed |beta_P|; small enough that the switch is
# invisible in manoeuvres, large enough that the forces have continuous derivatives.
SWITCH_WIDTH = 1e-3


def safe_sqrt(x):
    """$\\sqrt{\\max(x, 0)}$ with a zero (not NaN) derivative at and below zero."""
    positive = x > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, x, 1.0)), 0.0)


def safe_atan2(y, x):
    """`arctan2(y, x)`, 0 with zero derivative at the origin instead of NaN."""
    ok = (x * x + y * y) > 0
    return jnp.where(ok, jnp.arctan2(jnp.where(ok, y, 0.0), jnp.where(ok, x, 1.0)), 0.0)


def smooth_abs(x, width):
    """$\\sqrt{x^2 + w^2} - w$: equals $|x|$ to within $w$, 0 at 0, smooth."""
    return jnp.sqrt(x * x + width * width) - width


def side_value(x, negative, positive, width):
    """`negative` for $x \\ll -w$, `positive` for $x \\gg w$, a tanh blend in between."""
    return 0.5 * (positive + negative) + 0.5 * (positive - negative) * jnp.tanh(x / width)


class MMGVessel(AbstractVessel):
    """3-DOF MMG standard method of Yasukawa & Yoshimura (2015), single screw, single rudder.

    Midship origin, x forward, y to starboard; positive rudder angle turns the ship to
    starboard (the paper's convention, no sign change). With $U = \\sqrt{u^2+v^2}$,
    $v' = v/U$, $r' = rL/U$, $\\beta = \\mathrm{atan2}(-v, u)$:

    - hull: $X_H = \\tfrac12\\rho L d U^2 (-R_0' + X_{vv}'v'^2 + X_{vr}'v'r' + X_{rr}'r'^2 +
      X_{vvvv}'v'^4)$, $Y_H = \\tfrac12\\rho L d U^2 (Y_v'v' + Y_r'r' + Y_{vvv}'v'^3 +
      Y_{vvr}'v'^2r' + Y_{vrr}'v'r'^2 + Y_{rrr}'r'^3)$, $N_H$ likewise with $L^2$;
    - propeller: $X_P = (1-t_P)\\rho n^2 D_P^4 K_T(J_P)$, $K_T = k_0 + k_1 J_P + k_2 J_P^2$,
      $J_P = u(1-w_P)/(nD_P)$, $1 - w_P = (1-w_{P0})[1 + (1 - e^{-C_1|\\beta_P|})(C_2 - 1)]$,
      $\\beta_P = \\beta - x_P' r'$, $C_2$ by the sign of $\\beta_P$;
    - rudder: $F_N = \\tfrac12\\rho A_R f_\\alpha U_R^2 \\sin\\alpha_R$,
      $\\alpha_R = \\delta - \\mathrm{atan}(v_R/u_R)$, $v_R = U\\gamma_R\\beta_R$,
      $\\beta_R = \\beta - \\ell_R' r'$, $\\gamma_R$ by the sign of $\\beta_R$,
      $u_R = \\varepsilon u(1-w_P)\\sqrt{\\eta\\{1 + \\kappa[\\sqrt{1 + 8K_T/(\\pi J_P^2)} -
      1]\\}^2 + 1 - \\eta}$, $\\eta = D_P/H_R$; $X_R = -(1-t_R)F_N\\sin\\delta$,
      $Y_R = -(1+a_H)F_N\\cos\\delta$, $N_R = -(x_R + a_H x_H)F_N\\cos\\delta$.

    The paper's equations at the centre of gravity become, at midship,
    $M\\dot\\nu = \\tau$ with $M = [[m+m_x, 0, 0], [0, m+m_y, x_G m],
    [0, x_G m, I_{zG} + x_G^2 m + J_z]]$ and Coriolis terms
    $(m+m_y)vr + x_G m r^2$, $-(m+m_x)ur$, $-x_G m u r$ in $\\tau$.

    Numerically robust forms (identical to the paper for $u > 0$, $n > 0$):
    $n^2K_T = k_0 n|n| + k_1|n|u_P/D_P + k_2 u_P|u_P|/D_P^2$ with $u_P = u(1-w_P)$ (no
    division by $n$); $u(1-w_P)\\sqrt{1 + 8K_T/(\\pi J_P^2)} = \\sqrt{u_P^2 + 8 n^2K_T
    D_P^2/\\pi}$ (no division by $J_P$); $U_R^2\\sin\\alpha_R = U_R(u_R\\sin\\delta -
    v_R\\cos\\delta)$ (no division by $u_R$); $U$ is floored at a Froude number of 1e-4
    where it divides; the sign switches of $\\gamma_R$ and $C_2$ and $|\\beta_P|$ are
    smoothed over `SWITCH_WIDTH` = 1e-3 rad, so the forces are continuously differentiable.

    Validity: ahead motion with a running propeller ($u > 0$, $n > 0$, drift angles up to
    about 30 deg), as in the paper. For $u \\le 0$ or $n \\le 0$ the forces and their
    derivatives stay finite but are not physical (no four-quadrant propeller model; the
    resistance $-R_0'U^2$ keeps its sign astern).
    """

    length: float = param(free=False, unit="m")  # L_pp
    rudder: RudderServo
    shaft: Shaft
    nominal_speed: float = param(free=False, unit="m/s")  # U_0
    nominal_n: float = param(free=False, unit="rev/s")  # self-propulsion n_P at U_0
    frontal_wind_area: float = param(free=False, unit="m^2")  # A_F
    lateral_wind_area: float = param(free=False, unit="m^2")  # A_L
    draft: float = param(free=False, unit="m")  # d
    volume: float = param(free=False, unit="m^3")  # displacement volume nabla; m = rho nabla
    x_g: float = param(free=False, unit="m")  # x_G, centre of gravity forward of midship
    radius_of_gyration: float = param(free=False, unit="m")  # k_zz; I_zG = m k_zz^2
    m_x: float = param(free=False, unit="-")  # m_x', added mass in surge / (rho L^2 d / 2)
    m_y: float = param(free=False, unit="-")  # m_y', added mass in sway / (rho L^2 d / 2)
    j_z: float = param(free=False, unit="-")  # J_z', added yaw inertia / (rho L^4 d / 2)
    r_0: float = param(free=True, unit="-")  # R_0', straight-run resistance coefficient
    x_vv: float = param(free=False, unit="-")  # X_vv'
    x_vr: float = param(free=False, unit="-")  # X_vr'
    x_rr: float = param(free=False, unit="-")  # X_rr'
    x_vvvv: float = param(free=False, unit="-")  # X_vvvv'
    y_v: float = param(free=True, unit="-")  # Y_v'
    y_r: float = param(free=True, unit="-")  # Y_r'
    y_vvv: float = param(free=True, unit="-")  # Y_vvv'
    y_vvr: float = param(free=False, unit="-")  # Y_vvr'
    y_vrr: float = param(free=False, unit="-")  # Y_vrr'
    y_rrr: float = param(free=False, unit="-")  # Y_rrr'
    n_v: float = param(free=True, unit="-")  # N_v'
    n_r: float = param(free=True, unit="-")  # N_r'
    n_vvv: float = param(free=False, unit="-")  # N_vvv'
    n_vvr: float = param(free=False, unit="-")  # N_vvr'
    n_vrr: float = param(free=False, unit="-")  # N_vrr'
    n_rrr: float = param(free=True, unit="-")  # N_rrr'
    propeller_diameter: float = param(free=False, unit="m")  # D_P
    t_p: float = param(free=False, unit="-")  # t_P, thrust deduction
    w_p0: float = param(free=False, unit="-")  # w_P0, wake fraction in straight motion
    k_0: float = param(free=False, unit="-")  # k_0, K_T = k_0 + k_1 J + k_2 J^2
    k_1: float = param(free=False, unit="-")  # k_1
    k_2: float = param(free=False, unit="-")  # k_2
    x_p: float = param(free=False, unit="-")  # x_P', effective propeller position in beta_P
    c_1: float = param(free=False, unit="-")  # C_1, wake change with beta_P
    c_2_plus: float = param(free=False, unit="-")  # C_2 for beta_P > 0
    c_2_minus: float = param(free=False, unit="-")  # C_2 for beta_P < 0
    rudder_area: float = param(free=False, unit="m^2")  # A_R
    rudder_span: float = param(free=False, unit="m")  # H_R
    t_r: float = param(free=False, unit="-")  # t_R, steering resistance deduction
    a_h: float = param(free=False, unit="-")  # a_H, rudder force increase factor
    # x_H', acting point of the hull force induced by steering
    x_h: float = param(free=False, unit="-")
    x_r: float = param(free=False, unit="-")  # x_R', rudder position
    f_alpha: float = param(free=False, unit="-")  # f_alpha, rudder lift gradient
    epsilon: float = param(free=True, unit="-")  # epsilon, (1 - w_R)/(1 - w_P)
    kappa: float = param(free=False, unit="-")  # kappa, propeller-race factor in u_R
    l_r: float = param(free=False, unit="-")  # l_R', effective rudder position in beta_R
    gamma_r_plus: float = param(free=False, unit="-")  # gamma_R for beta_R > 0 (flow straightening)
    gamma_r_minus: float = param(free=False, unit="-")  # gamma_R for beta_R < 0
    rho: float = param(1025.0, free=False, unit="kg/m^3")  # water density
    wind_model: AbstractWindLoads = FossenWindLoads()  # wind loads on A_F, A_L

    @classmethod
    def from_particulars(cls, particulars: MainParticulars) -> "MMGVessel":
        """The MMG vessel of a ship's main particulars (`jaxship.MainParticulars`) by
        published empirical formulas (`particulars_coefficients`): the hull derivatives of
        Yoshimura & Masumoto (2012), Zhou et al.'s (1983) added masses, Kijima et al.'s
        (1990) and Yoshimura & Masumoto's interaction factors, Fujii's f_alpha, an ITTC
        1957 resistance; `nominal_n` is the self-propulsion rate at the particulars'
        speed (`straight_run`, X = 0). Each formula and its source are in
        `jaxship/_models/_vessel/particulars.py`. A first estimate where there are no
        captive tests: on the KVLCC2 see `benchmarks/results/particulars.md`."""
        p = particulars
        coefficients = particulars_coefficients(p)
        # start of the self-propulsion Newton iteration: J_P = 0.5
        n_start = p.speed * (1.0 - coefficients["w_p0"]) / (0.5 * p.propeller_diameter)
        vessel = cls(
            length=p.length,
            rudder=RudderServo(max_angle=p.rudder_max_angle, max_rate=p.rudder_rate,
                               time_constant=0.1),  # T_delta: practically a pure rate limit
            shaft=Shaft(max_rate=float("inf"), time_constant=1.0),  # as the kvlcc2 preset
            nominal_speed=p.speed, nominal_n=n_start, frontal_wind_area=0.0,
            lateral_wind_area=0.0, draft=p.draft, volume=p.volume(), x_g=p.x_g,
            radius_of_gyration=p.gyration_ratio * p.length,
            propeller_diameter=p.propeller_diameter, rudder_area=p.rudder_area,
            rudder_span=p.rudder_span, rho=p.rho, **coefficients)
        n = float(np.asarray(straight_run(vessel, speed=p.speed).n))
        return dataclasses.replace(vessel, nominal_n=n)

    def mass(self) -> Array:
        """Displacement mass $m = \\rho\\nabla$ [kg]."""
        return self.rho * self.volume

    def mass_matrix(self) -> Array:
        L, d, m = self.length, self.draft, self.mass()
        half = 0.5 * self.rho * L**2 * d
        m_x, m_y, j_z = self.m_x * half, self.m_y * half, self.j_z * half * L**2
        i_zg = m * self.radius_of_gyration**2
        xm = self.x_g * m
        return jnp.array(
            [[m + m_x, 0.0, 0.0], [0.0, m + m_y, xm], [0.0, xm, i_zg + self.x_g**2 * m + j_z]]
        )

    def propeller(self, u, v, r, n):
        """Effective propeller inflow $u_P = u(1-w_P)$ [m/s] and $n^2K_T$ [1/s^2]."""
        L, D = self.length, self.propeller_diameter
        big_u = jnp.sqrt(u * u + v * v + (SPEED_FLOOR**2) * GRAVITY * L)
        beta = safe_atan2(-v, u)
        beta_p = beta - self.x_p * r * L / big_u
        c_2 = side_value(beta_p, self.c_2_minus, self.c_2_plus, SWITCH_WIDTH)
        wake_change = (1.0 - jnp.exp(-self.c_1 * smooth_abs(beta_p, SWITCH_WIDTH))) * (c_2 - 1.0)
        u_p = u * (1.0 - self.w_p0) * (1.0 + wake_change)
        n2_kt = (self.k_0 * n * jnp.abs(n) + self.k_1 * jnp.abs(n) * u_p / D
                 + self.k_2 * u_p * jnp.abs(u_p) / D**2)
        return u_p, n2_kt

    def forces(self, u, v, r, delta, n) -> Array:
        L, d, rho, D = self.length, self.draft, self.rho, self.propeller_diameter
        m = self.mass()
        big_u = jnp.sqrt(u * u + v * v + (SPEED_FLOOR**2) * GRAVITY * L)
        rl = r * L  # r' U [m/s]

        # hull, written dimensionally: U^2 v' = U v, U^2 v'^3 = v^3/U, ...
        q = 0.5 * rho * L * d
        x_h = q * (-self.r_0 * (u * u + v * v) + self.x_vv * v * v + self.x_vr * v * rl
                   + self.x_rr * rl * rl + self.x_vvvv * v**4 / big_u**2)
        y_h = q * (self.y_v * big_u * v + self.y_r * big_u * rl
                   + (self.y_vvv * v**3 + self.y_vvr * v * v * rl + self.y_vrr * v * rl * rl
                      + self.y_rrr * rl**3) / big_u)
        n_h = q * L * (self.n_v * big_u * v + self.n_r * big_u * rl
                       + (self.n_vvv * v**3 + self.n_vvr * v * v * rl + self.n_vrr * v * rl * rl
                          + self.n_rrr * rl**3) / big_u)

        # propeller
        u_p, n2_kt = self.propeller(u, v, r, n)
        x_p = (1.0 - self.t_p) * rho * D**4 * n2_kt

        # rudder
        eta = D / self.rudder_span
        race = safe_sqrt(u_p * u_p + 8.0 / jnp.pi * D**2 * n2_kt)  # u_P sqrt(1 + 8K_T/(pi J^2))
        u_race = (1.0 - self.kappa) * u_p + self.kappa * race
        u_r = self.epsilon * safe_sqrt(eta * u_race**2 + (1.0 - eta) * u_p**2)
        beta = safe_atan2(-v, u)
        u_beta_r = big_u * beta - self.l_r * rl  # U beta_R [m/s]
        gamma = side_value(u_beta_r / big_u, self.gamma_r_minus, self.gamma_r_plus, SWITCH_WIDTH)
        v_r = gamma * u_beta_r
        big_u_r = safe_sqrt(u_r * u_r + v_r * v_r)
        sin_d, cos_d = jnp.sin(delta), jnp.cos(delta)
        f_n = 0.5 * rho * self.rudder_area * self.f_alpha * big_u_r * (u_r * sin_d - v_r * cos_d)
        x_r = -(1.0 - self.t_r) * f_n * sin_d
        y_r = -(1.0 + self.a_h) * f_n * cos_d
        n_r = -(self.x_r + self.a_h * self.x_h) * L * f_n * cos_d

        # rigid-body Coriolis-centripetal terms at midship (added mass included)
        half = 0.5 * rho * L**2 * d
        m_x, m_y = self.m_x * half, self.m_y * half
        xm = self.x_g * m
        X = x_h + x_p + x_r + (m + m_y) * v * r + xm * r * r
        Y = y_h + y_r - (m + m_x) * u * r
        N = n_h + n_r - xm * u * r
        return jnp.stack(jnp.broadcast_arrays(X, Y, N))


def kvlcc2() -> MMGVessel:
    """KVLCC2 tanker, 7 m model (1:45.714), MMG standard method (Yasukawa & Yoshimura 2015).

    Hull, propeller and rudder parameters of the paper's Tables 1-4 (project notes
    `reference/vessel-models.md` sec. 2.1-2.2, with the paper's wake model: x_P' = -0.48,
    C_1 = 2.0, C_2 = 1.6/1.1). Approach speed 1.179 m/s (Fn 0.142, 15.5 kn full scale);
    `nominal_n` is the model self-propulsion rate at that speed from X = 0 (11.85 rps; the
    SIMMAN 2008 free-running tests ran at 10.23 rps with a 0.204 m stock propeller,
    the MMG parameter set has D_P = 0.216 m). Rudder rate 15.8 deg/s (SIMMAN test
    report, HSVA), 35 deg maximum.
    """
    return MMGVessel(
        length=7.0,  # L_pp [m], Yasukawa & Yoshimura (2015) Table 1
        rudder=RudderServo(
            max_angle=float(np.deg2rad(35.0)),  # delta_max [rad]
            max_rate=float(np.deg2rad(15.8)),  # [rad/s], model helm rate (SIMMAN 2008, HSVA report)
            # T_delta [s]: not in the source; 0.1 s makes the servo practically a pure
            # rate limit (the command is reached within 0.1 deg of the rate-limited ramp)
            time_constant=0.1,
        ),
        # no shaft data in the source; manoeuvres hold n constant. 1 s model-scale lag.
        shaft=Shaft(max_rate=float("inf"), time_constant=1.0),
        nominal_speed=1.179,  # U_0 [m/s], Fn = 0.142 (paper; SIMMAN 2008)
        nominal_n=11.85159,  # n_P [rev/s], solved here from X(U_0, n_P) = 0 (notes sec. 6: 11.85)
        frontal_wind_area=0.0,  # A_F [m^2], no windage in the source
        lateral_wind_area=0.0,  # A_L [m^2]
        draft=0.46,  # d [m], Table 1
        volume=3.27,  # nabla [m^3], Table 1
        x_g=0.25,  # x_G [m], Table 1
        radius_of_gyration=0.25 * 7.0,  # k_zz = 0.25 L_pp [m], Table 1
        m_x=0.022,  # m_x' [-], Table 2
        m_y=0.223,  # m_y' [-], Table 2
        j_z=0.011,  # J_z' [-], Table 2
        r_0=0.022,  # R_0' [-], Table 3
        x_vv=-0.040,  # X_vv' [-], Table 3
        x_vr=0.002,  # X_vr' [-], Table 3
        x_rr=0.011,  # X_rr' [-], Table 3
        x_vvvv=0.771,  # X_vvvv' [-], Table 3
        y_v=-0.315,  # Y_v' [-], Table 3
        y_r=0.083,  # Y_r' [-], Table 3
        y_vvv=-1.607,  # Y_vvv' [-], Table 3
        y_vvr=0.379,  # Y_vvr' [-], Table 3
        y_vrr=-0.391,  # Y_vrr' [-], Table 3
        y_rrr=0.008,  # Y_rrr' [-], Table 3
        n_v=-0.137,  # N_v' [-], Table 3
        n_r=-0.049,  # N_r' [-], Table 3
        n_vvv=-0.030,  # N_vvv' [-], Table 3
        n_vvr=-0.294,  # N_vvr' [-], Table 3
        n_vrr=0.055,  # N_vrr' [-], Table 3
        n_rrr=-0.013,  # N_rrr' [-], Table 3
        propeller_diameter=0.216,  # D_P [m], Table 1
        t_p=0.220,  # t_P [-], Table 4
        w_p0=0.40,  # w_P0 [-], Table 4
        k_0=0.2931,  # k_0 [-], Table 4
        k_1=-0.2753,  # k_1 [-], Table 4
        k_2=-0.1385,  # k_2 [-], Table 4
        # x_P' [-], Table 4 (notes sec. 2.2 flag it [recall]; shipmmg: -0.69, another wake model)
        x_p=-0.48,
        c_1=2.0,  # C_1 [-], Table 4
        c_2_plus=1.6,  # C_2 (beta_P > 0) [-], Table 4
        c_2_minus=1.1,  # C_2 (beta_P < 0) [-], Table 4
        rudder_area=0.0539,  # A_R [m^2], Table 1
        rudder_span=0.345,  # H_R [m], Table 1
        t_r=0.387,  # t_R [-], Table 4
        a_h=0.312,  # a_H [-], Table 4
        x_h=-0.464,  # x_H' [-], Table 4
        x_r=-0.500,  # x_R' [-], Table 4
        f_alpha=2.747,  # f_alpha [-], Table 4
        epsilon=1.09,  # epsilon [-], Table 4
        kappa=0.50,  # kappa [-], Table 4
        l_r=-0.710,  # l_R' [-], Table 4
        gamma_r_plus=0.640,  # gamma_R (beta_R > 0) [-], Table 4
        gamma_r_minus=0.395,  # gamma_R (beta_R < 0) [-], Table 4
        rho=1025.0,  # [kg/m^3], m = rho nabla = 3351.75 kg as in the notes
    )

