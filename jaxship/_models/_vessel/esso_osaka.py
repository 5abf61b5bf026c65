"""Low-speed MMG model (cross-flow hull, four-quadrant propeller) and the Esso Osaka 3 m preset.

The model structure is the "MMG low-speed model" of Osaka University's NAOE 5th lab
(GitHub `NAOE-5thLab/mmg-1p1r-simulator`, `pyshipsim/obj_ship_mmg/mmg_esso_3m`), used
with the free-running data set FRT-DS-ESSO in Wakita et al. (2022), J. Mar. Sci.
Technol. 27:772-785, and Miyauchi et al. (2022), J. Mar. Sci. Technol. 27:1065-1083.
Its parts: the hull cross-flow model of Yoshimura (low-speed MMG), the propeller
side force of Hachii and of Ueno's *Seiun-maru* tests for astern quadrants,
Kitagawa's rudder inflow for reversed propeller. Equations are rewritten here
from the upstream code's structure; parameter values are those of the upstream files
`MMG_params_EssoOsaka3m.csv` and `principal_particulars_EssoOsaka3m.csv`
(copies in `shared/data/esso_osaka_frt/reference/`), hard-coded below.
"""


import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._params import param
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, FossenWindLoads
from ._base import AbstractVessel
from .mmg import GRAVITY, SPEED_FLOOR, SWITCH_WIDTH, safe_atan2, safe_sqrt, side_value, smooth_abs


def cross_flow_integrals(a, b):
    """$I_1 = \\int_{-1/2}^{1/2} |a + bx|(a + bx)\\,dx$ and $I_2 = \\int x|a + bx|(a + bx)\\,dx$.

    Closed form of the cross-flow drag integrals (the upstream code integrates them
    with a 200-interval trapezoidal rule). Without a sign change along the hull
    ($|b| \\le 2|a|$) the integrand is $\\pm(a + bx)^2$, giving
    $I_1 = \\mathrm{sgn}(a)(a^2 + b^2/12)$ and $I_2 = \\mathrm{sgn}(a)\\,ab/6$; otherwise
    $I_1 = [F(w_+) - F(w_-)]/(3b)$ and $I_2 = [(G(w_+) - G(w_-))/4 - a(F(w_+) - F(w_-))/3]/b^2$
    with $w_\\pm = a \\pm b/2$, $F(w) = |w|w^2$, $G(w) = |w|w^3$.
    """
    same_sign = jnp.abs(b) <= 2.0 * jnp.abs(a)
    s = jnp.sign(a)
    b_safe = jnp.where(same_sign, 1.0, b)
    w_plus, w_minus = a + 0.5 * b_safe, a - 0.5 * b_safe
    df = jnp.abs(w_plus) * w_plus**2 - jnp.abs(w_minus) * w_minus**2
    dg = jnp.abs(w_plus) * w_plus**3 - jnp.abs(w_minus) * w_minus**3
    i_1 = jnp.where(same_sign, s * (a * a + b * b / 12.0), df / (3.0 * b_safe))
    i_2 = jnp.where(same_sign, s * a * b / 6.0, (dg / 4.0 - a * df / 3.0) / b_safe**2)
    return i_1, i_2


class LowSpeedMMGVessel(AbstractVessel):
    """MMG low-speed model of the NAOE lab (Osaka Univ.): cross-flow hull, four-quadrant propeller.

    Midship origin, positive rudder turns to starboard (the source's convention, no sign
    change); u, v at midship. With $U = \\sqrt{u^2 + v^2}$, $\\hat\\beta = \\mathrm{atan2}(v, u)$,
    $v' = v/U$, $r' = rL/U$, all coefficients primed as in the source:

    - hull: $X_H = \\tfrac12\\rho L d\\,[(X_{0F} + (X_{0A} - X_{0F})|\\hat\\beta|/\\pi)\\,uU +
      X_{vr} v r L]$, $Y_H = \\tfrac12\\rho L d\\,[Y_v v|u| + Y_r rLu - C_D I_1(v, C_{rY}rL)]$,
      $N_H = \\tfrac12\\rho L^2 d\\,[N_v vu + N_r rL|u| - C_D I_2(v, C_{rN}rL)]$ with the
      cross-flow integrals of `cross_flow_integrals`;
    - propeller: $w_P = w_{P0} - \\tau_P|v' + x_P'r'| - C_P'(v' + x_P'r')^2$,
      $1 - w_P$ clipped to $(0, 1]$ ahead and 1 astern ($u \\le 0$), $u_P = u(1 - w_P)$;
      for $n \\ge 0$: $X_P = (1 - t_P)\\rho D^4 n^2 K_T(J)$, $K_T = k_0 + k_1J + k_2J^2$,
      $J = u_P/(nD)$; for $n < 0$: $X_P = \\rho D^4n^2(C_6 + C_7J_s)$ if $J_s \\ge C_{10}$
      else $\\rho D^4 n^2 C_3$, $J_s = u/(nD)$. Side force and moment: 0 ahead;
      for $n \\ge 0$, $u < 0$: $\\tfrac12\\rho L d (nP)^2(A_6J_s^2 + A_7J_s + A_8)$ (N: $B_i$,
      $L^2$); for $n < 0$: $\\tfrac12\\rho L d (nD)^2$ times $A_3 + A_4J_s$ ($J_s < -0.35$),
      $A_1 + A_2J_s$ ($-0.35 \\le J_s \\le -0.06$), $A_5$ ($J_s > -0.06$);
    - rudder: $F_N = \\tfrac12\\rho A_R f_\\alpha U_R^2\\sin\\alpha_R$,
      $f_\\alpha = 6.13\\Lambda/(\\Lambda + 2.25)$,
      $\\alpha_R = \\delta - \\mathrm{atan2}(v_R, u_R)$,
      $v_R = -\\gamma_R(v + \\ell_R r)$ with $\\gamma_R = \\gamma_P$ if $v + x_R r \\ge 0$ else
      $\\gamma_N$; $u_R = \\varepsilon\\sqrt{\\eta[u_P + \\kappa(\\sqrt{u_P^2 + 8K_Tn^2D^2/\\pi} -
      u_P)]^2 + (1 - \\eta)u_P^2}$ if $n \\ge 0$ and $K_T > 0$ ($\\kappa = k_x/\\varepsilon$,
      $\\eta = D/H_R$, $H_R = \\sqrt{A_R\\Lambda}$); otherwise $u_R = u$ astern and, ahead,
      Kitagawa's $u_R = \\mathrm{sgn}(s)\\sqrt{|s|}$, $s = \\eta\\,\\mathrm{sgn}(a)a^2 +
      (1 - \\eta)(\\varepsilon u_P)^2 + c_{PR}u^2$, $a = \\varepsilon u_P +
      \\mathrm{sgn}(n) D k_{x,rev}\\sqrt{8|n^2K_T|/\\pi}$; $X_R, Y_R, N_R$ as in the MMG
      standard method with $t_R$, $a_H$, $x_H$, $x_R$.

    Mass matrix and Coriolis terms as in `MMGVessel` ($m$, $m_x$, $m_y$ from the primes,
    $I_{zG} + J_z$ given together).

    Differences from the upstream code, all outside ahead manoeuvring: the thrust is
    written as $n^2K_T$ multiplied out (continuous at $n = 0$, where the upstream sets
    $J = 10^4$ and gets exactly zero force), likewise the second-quadrant side force;
    $|\\hat\\beta|$, $|v' + x_P'r'|$ and the $\\gamma_N/\\gamma_P$ switch are smoothed over
    1e-3 (rad or $v'$); the cross-flow integrals are exact instead of a trapezoidal sum;
    $U$ is floored at a Froude number of 1e-4 where it divides. The source model
    itself is discontinuous where the $u_R$ branches and propeller quadrants meet
    ($n = 0$ or $u = 0$); this implementation keeps those switches (finite forces, but
    derivatives there are one-sided). The upstream bow/stern thrusters are left out
    (no thruster signal is logged in the data set). Its wind loads are Fujiwara et al.'s
    (1998) regression, `jaxship.wind_loads.FujiwaraWindLoads.esso_osaka()` as the `wind_model`;
    the preset keeps every vessel's default, `FossenWindLoads` on the given areas.
    """

    length: float = param(free=False, unit="m")  # L_pp
    rudder: RudderServo
    shaft: Shaft
    nominal_speed: float = param(free=False, unit="m/s")  # U_0
    nominal_n: float = param(free=False, unit="rev/s")  # n giving U_0 in straight run
    frontal_wind_area: float = param(free=False, unit="m^2")  # A_T, transverse projected area
    lateral_wind_area: float = param(free=False, unit="m^2")  # A_L, lateral projected area
    draft: float = param(free=False, unit="m")  # d
    mass_nd: float = param(free=False, unit="-")  # m' = m / (rho L^2 d / 2)
    x_g: float = param(free=False, unit="-")  # x_G' = x_G / L, forward of midship
    m_x: float = param(free=False, unit="-")  # m_x', / (rho L^2 d / 2)
    m_y: float = param(free=False, unit="-")  # m_y'
    i_zz_j_zz: float = param(free=False, unit="-")  # (I_zG + J_z)', / (rho L^4 d / 2)
    x_0f: float = param(free=True, unit="-")  # X_0F', resistance coefficient ahead
    x_0a: float = param(free=False, unit="-")  # X_0A', resistance coefficient astern
    x_vr: float = param(free=False, unit="-")  # X_vr'
    y_v: float = param(free=True, unit="-")  # Y_v'
    y_r: float = param(free=True, unit="-")  # Y_r'
    n_v: float = param(free=True, unit="-")  # N_v'
    n_r: float = param(free=True, unit="-")  # N_r'
    c_d: float = param(free=True, unit="-")  # C_D, cross-flow drag coefficient
    # C_rY, yaw-rate factor in the sway cross-flow integral
    c_ry: float = param(free=True, unit="-")
    c_rn: float = param(free=True, unit="-")  # C_rN, yaw-rate factor in the yaw cross-flow integral
    propeller_diameter: float = param(free=False, unit="m")  # D
    pitch_ratio: float = param(free=False, unit="-")  # P/D
    t_p: float = param(free=False, unit="-")  # t_P
    w_p0: float = param(free=False, unit="-")  # w_P0
    tau_p: float = param(free=False, unit="-")  # tau_P, wake change with |v' + x_P' r'|
    c_p: float = param(free=False, unit="-")  # C_P', wake change with (v' + x_P' r')^2
    x_p: float = param(free=False, unit="-")  # x_P'
    k_0: float = param(free=False, unit="-")  # k_0
    k_1: float = param(free=False, unit="-")  # k_1
    k_2: float = param(free=False, unit="-")  # k_2
    a_coeffs: tuple  # A_1..A_8 [-], propeller side force (astern quadrants)
    b_coeffs: tuple  # B_1..B_8 [-], propeller yaw moment (astern quadrants)
    c_3: float = param(free=False, unit="-")  # C_3, X_P/(rho n^2 D^4) for n < 0, J_s < C_10
    c_6: float = param(free=False, unit="-")  # C_6, for n < 0, J_s >= C_10: C_6 + C_7 J_s
    c_7: float = param(free=False, unit="-")  # C_7
    c_10: float = param(free=False, unit="-")  # C_10, switch advance ratio
    # J_syn, side-force switch advance ratio (upstream constant)
    j_syn: float = param(free=False, unit="-")
    j_syn0: float = param(free=False, unit="-")  # J_syn0, (upstream constant)
    rudder_area: float = param(free=False, unit="m^2")  # A_R
    rudder_aspect_ratio: float = param(free=False, unit="-")  # Lambda
    x_r: float = param(free=False, unit="-")  # x_R', rudder position
    t_r: float = param(free=False, unit="-")  # t_R
    a_h: float = param(free=False, unit="-")  # a_H
    x_h: float = param(free=False, unit="-")  # x_H'
    l_r: float = param(free=False, unit="-")  # l_R'
    k_x: float = param(free=False, unit="-")  # k_x, kappa = k_x / epsilon
    k_x_reverse: float = param(free=False, unit="-")  # k_x for reversed propeller, Kitagawa
    epsilon: float = param(free=True, unit="-")  # epsilon
    c_pr: float = param(free=False, unit="-")  # c_PR, Kitagawa's u_R term in u^2
    gamma_n: float = param(free=True, unit="-")  # gamma_N, flow straightening for v + x_R r < 0
    gamma_p: float = param(free=True, unit="-")  # gamma_P, for v + x_R r >= 0
    rho: float = param(998.0, free=False, unit="kg/m^3")  # fresh water
    wind_model: AbstractWindLoads = FossenWindLoads()  # wind loads on A_F, A_L

    def _scales(self):
        L, d = self.length, self.draft
        half = 0.5 * self.rho * L**2 * d
        return half, self.mass_nd * half

    def mass(self) -> Array:
        """Mass $m = m'\\,\\rho L^2 d/2$ [kg]."""
        return self._scales()[1]

    def mass_matrix(self) -> Array:
        L = self.length
        half, m = self._scales()
        xm = self.x_g * L * m
        i_total = self.i_zz_j_zz * half * L**2 + (self.x_g * L) ** 2 * m
        return jnp.array(
            [[m + self.m_x * half, 0.0, 0.0], [0.0, m + self.m_y * half, xm], [0.0, xm, i_total]]
        )

    def forces(self, u, v, r, delta, n) -> Array:
        L, d, rho, D = self.length, self.draft, self.rho, self.propeller_diameter
        half, m = self._scales()
        q = 0.5 * rho * L * d
        big_u = jnp.sqrt(u * u + v * v + (SPEED_FLOOR**2) * GRAVITY * L)
        rl = r * L

        # hull: linear terms + cross-flow drag
        beta_hat = safe_atan2(v, u)
        x_0 = self.x_0f + (self.x_0a - self.x_0f) * smooth_abs(beta_hat, SWITCH_WIDTH) / jnp.pi
        i_y, _ = cross_flow_integrals(v, self.c_ry * rl)
        _, i_n = cross_flow_integrals(v, self.c_rn * rl)
        x_h = q * (x_0 * u * safe_sqrt(u * u + v * v) + self.x_vr * v * rl)
        y_h = q * (self.y_v * v * jnp.abs(u) + self.y_r * rl * u - self.c_d * i_y)
        n_h = q * L * (self.n_v * v * u + self.n_r * rl * jnp.abs(u) - self.c_d * i_n)

        # propeller
        s = (v + self.x_p * rl) / big_u  # v' + x_P' r'
        w_p = self.w_p0 - self.tau_p * smooth_abs(s, SWITCH_WIDTH) - self.c_p * s * s
        one_minus_w = jnp.where(u > 0, jnp.clip(1.0 - w_p, 1e-12, 1.0), 1.0)
        u_p = u * one_minus_w
        ahead = n >= 0
        n_neg = jnp.where(ahead, -1.0, n)  # n < 0 in the astern branch
        j_s = u / (n_neg * D)
        nd = n * D
        # n^2 K_T: ahead (1st/2nd quadrant) with the quadratic K_T(J), astern (n < 0) per C_i
        n2_kt_ahead = self.k_0 * n * n + self.k_1 * n * u_p / D + self.k_2 * u_p * u_p / D**2
        n2_kt_astern = jnp.where(
            j_s >= self.c_10, self.c_6 * n * n + self.c_7 * n * u / D, self.c_3 * n * n
        )
        n2_kt = jnp.where(ahead, n2_kt_ahead, n2_kt_astern)
        x_p = rho * D**4 * jnp.where(ahead, (1.0 - self.t_p) * n2_kt, n2_kt)
        a, b = self.a_coeffs, self.b_coeffs
        pd2 = self.pitch_ratio**2
        side_2nd = lambda c6, c7, c8: pd2 * (c6 * u * u + c7 * u * nd + c8 * nd * nd)
        side_astern = lambda c1, c2, c3, c4, c5: jnp.where(
            j_s < self.j_syn, c3 * nd * nd + c4 * nd * u,
            jnp.where(j_s > self.j_syn0, c5 * nd * nd, c1 * nd * nd + c2 * nd * u),
        )
        y_p_nd = jnp.where(ahead, jnp.where(u >= 0, 0.0, side_2nd(*a[5:8])), side_astern(*a[:5]))
        n_p_nd = jnp.where(ahead, jnp.where(u >= 0, 0.0, side_2nd(*b[5:8])), side_astern(*b[:5]))
        y_p, n_p = q * y_p_nd, q * L * n_p_nd

        # rudder
        span = jnp.sqrt(self.rudder_area * self.rudder_aspect_ratio)
        eta = D / span
        f_alpha = 6.13 * self.rudder_aspect_ratio / (2.25 + self.rudder_aspect_ratio)
        kappa = self.k_x / self.epsilon
        race = safe_sqrt(u_p * u_p + 8.0 / jnp.pi * D**2 * n2_kt)
        u_r_mmg = self.epsilon * safe_sqrt(
            eta * (u_p + kappa * (race - u_p)) ** 2 + (1.0 - eta) * u_p * u_p
        )
        a_1 = self.epsilon * u_p + jnp.sign(n) * D * self.k_x_reverse * safe_sqrt(
            8.0 * jnp.abs(n2_kt) / jnp.pi
        )
        a_2 = self.epsilon * u_p
        s_r = eta * jnp.sign(a_1) * a_1**2 + (1.0 - eta) * a_2**2 + self.c_pr * u * u
        u_r_kitagawa = jnp.sign(s_r) * safe_sqrt(jnp.abs(s_r))
        u_r = jnp.where(ahead & (n2_kt > 0), u_r_mmg, jnp.where(u < 0, u, u_r_kitagawa))
        gamma = side_value((v + self.x_r * rl) / big_u, self.gamma_n, self.gamma_p, SWITCH_WIDTH)
        v_r = -gamma * (v + self.l_r * rl)
        big_u_r = safe_sqrt(u_r * u_r + v_r * v_r)
        sin_d, cos_d = jnp.sin(delta), jnp.cos(delta)
        f_n = 0.5 * rho * self.rudder_area * f_alpha * big_u_r * (u_r * sin_d - v_r * cos_d)
        x_r = -(1.0 - self.t_r) * f_n * sin_d
        y_r = -(1.0 + self.a_h) * f_n * cos_d
        n_r = -(self.x_r + self.a_h * self.x_h) * L * f_n * cos_d

        m_x, m_y = self.m_x * half, self.m_y * half
        xm = self.x_g * L * m
        X = x_h + x_p + x_r + (m + m_y) * v * r + xm * r * r
        Y = y_h + y_p + y_r - (m + m_x) * u * r
        N = n_h + n_p + n_r - xm * u * r
        return jnp.stack(jnp.broadcast_arrays(X, Y, N))


def esso_osaka() -> LowSpeedMMGVessel:
    """Esso Osaka VLCC 3 m model, low-speed MMG model (Osaka Univ., NAOE-5thLab/mmg-1p1r-simulator).

    Parameters from `MMG_params_EssoOsaka3m.csv` [P] and
    `principal_particulars_EssoOsaka3m.csv` [PP] of GitHub
    `NAOE-5thLab/mmg-1p1r-simulator`, `pyshipsim/obj_ship_mmg/mmg_esso_3m/f2py/inputfile/`
    (the model used with the FRT-DS-ESSO free-running data, Wakita et al. 2022).
    Nominal straight run: n = 10 rps (the most common rate in the data) and the
    equilibrium speed this model gives there. Actuators as in the upstream simulator's
    defaults (rudder 35 deg, 20 deg/s, T = 0.1 s; shaft T = 0.1 s, 20 rps).
    """
    return LowSpeedMMGVessel(
        length=3.0,  # L_pp [m], [PP] lpp
        rudder=RudderServo(
            max_angle=float(np.deg2rad(35.0)),  # [rad], upstream Rudder actuator limits
            max_rate=float(np.deg2rad(20.0)),  # [rad/s], upstream Rudder actuator K = 20 deg/s
            time_constant=0.1,  # T [s], upstream Rudder actuator
        ),
        # upstream Propeller actuator: |n| <= 20 rps, T = 0.1 s
        shaft=Shaft(max_rate=20.0, time_constant=0.1),
        nominal_speed=0.39826,  # U_0 [m/s], straight-run equilibrium at n = 10 rps (solved here)
        nominal_n=10.0,  # [rev/s], the data set's usual propeller rate
        frontal_wind_area=0.13544,  # A_T [m^2], [PP] area_projected_trans
        lateral_wind_area=0.52038,  # A_L [m^2], [PP] area_projected_lateral
        draft=0.20114,  # d [m], [PP] draft
        mass_nd=0.27078,  # m' [-], [PP] mass_nd (m = 244.6 kg with rho = 998)
        x_g=0.03119,  # x_G' [-], [PP] x_lcg (x_G = 0.094 m)
        m_x=0.0467,  # m_x' [-], [P] massx_nd
        m_y=0.2579,  # m_y' [-], [P] massy_nd
        i_zz_j_zz=0.0286,  # (I_zG + J_z)' [-], [P] IzzJzz_nd
        x_0f=-0.02139,  # X_0F' [-], [P] xuu_nd
        x_0a=-0.03189,  # X_0A' [-], [P] coeff_drag_aft
        x_vr=-0.0081,  # X_vr' [-], [P] xvr_nd
        y_v=-0.3728,  # Y_v' [-], [P] yv_nd
        y_r=0.116,  # Y_r' [-], [P] yr_nd
        n_v=-0.1458,  # N_v' [-], [P] nv_nd
        n_r=-0.04849,  # N_r' [-], [P] nr_nd
        c_d=0.9665,  # C_D [-], [P] coeff_drag_sway
        c_ry=2.217,  # C_rY [-], [P] cry_cross_flow
        c_rn=0.8097,  # C_rN [-], [P] crn_cross_flow
        propeller_diameter=0.084,  # D [m], [PP] dia_prop
        pitch_ratio=0.7151,  # P/D [-], [PP] pitchr
        t_p=0.22,  # t_P [-], [P] t_prop
        w_p0=0.614,  # w_P0 [-], [P] w_prop_zero
        tau_p=0.871,  # tau_P [-], [P] tau_prop
        c_p=-0.359,  # C_P' [-], [P] coeff_cp_prop
        x_p=-0.517,  # x_P' [-], [P] xp_prop_nd
        k_0=0.3278,  # k_0 [-], [P] kt_coeff0
        k_1=-0.3223,  # k_1 [-], [P] kt_coeff1
        k_2=-0.156,  # k_2 [-], [P] kt_coeff2
        # A_1..A_8 [-], [P] ai_coeff_prop0..7 (A_1-A_5 Hachii, A_6-A_8 Seiun-maru)
        a_coeffs=(-7.90e-05, 7.99e-03, -4.93e-03, -5.87e-03, -5.58e-04,
                  5.08e-03, 1.702e-03, 9.16e-04),
        # B_1..B_8 [-], [P] bi_coeff_prop0..7
        b_coeffs=(3.50e-05, -3.17e-03, 1.96e-03, 2.33e-03, 2.25e-04, -2.16e-03, 6.27e-05, 6.25e-05),
        c_3=-0.251,  # C_3 [-], [P] ci_coeff_prop0
        c_6=-0.175,  # C_6 [-], [P] ci_coeff_prop1
        c_7=0.330,  # C_7 [-], [P] ci_coeff_prop2
        c_10=-0.233,  # C_10 [-], [P] ci_coeff_prop3
        j_syn=-0.35,  # J_syn [-], constant in the upstream model code
        j_syn0=-0.06,  # J_syn0 [-], constant in the upstream model code
        rudder_area=0.01063,  # A_R [m^2], [PP] area_rudder
        rudder_aspect_ratio=1.539,  # Lambda [-], [PP] lambda_rudder
        x_r=-0.5,  # x_R' [-], [PP] x_location_rudder = -1.5 m
        t_r=0.19,  # t_R [-], [P] t_rudder
        a_h=0.393,  # a_H [-], [P] ah_rudder
        x_h=-0.45,  # x_H' [-], [P] xh_rudder_nd
        l_r=-1.08,  # l_R' [-], [P] lr_rudder_nd
        k_x=0.288,  # k_x [-], [P] kx_rudder
        k_x_reverse=0.144,  # k_x,rev [-], [P] kx_rudder_reverse
        epsilon=1.42,  # epsilon [-], [P] epsilon_rudder
        c_pr=-0.176,  # c_PR [-], [P] cpr_rudder
        gamma_n=0.4406,  # gamma_N [-], [P] gammaN_rudder
        gamma_p=0.3506,  # gamma_P [-], [P] gammaP_rudder
        rho=998.0,  # [kg/m^3]; upstream uses 998/g in kgf units, same motion
    )
