"""The thesis vessel: a 3-DOF Ross-type model of the 4 m model of DTMB 5415.

The particulars are those of Table 4.1 of the identification thesis (Odegard 2009),
which are the SIMMAN 2008 DTMB 5415 model at scale 1:35.48 (simman2014.dk, "Geometry and
conditions, US Navy combatant"). The thesis' coefficients (Ross 2008) are not
published; every coefficient here is derived from documented empirical formulas. The
derivation, the sources and the tuning are in ``docs/thesis_vessel.md``.
"""

import functools

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._params import param
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, FossenWindLoads
from ._base import AbstractVessel


G = 9.81  # gravity [m/s^2]


class RossVessel(AbstractVessel):
    """3-DOF surge-sway-yaw model with Ross (2008) damping, propeller and stalling rudder.

    With $\\nu = (u, v, r)$ at midship, $M\\dot\\nu = -C_{RB}(\\nu)\\nu - C_A(\\nu)\\nu +
    \\tau_D(\\nu) + \\tau_P(u, n) + \\tau_R(\\nu, \\delta, n)$ (thesis eq. 2.13-2.20 in
    3 DOF). $M_A$ is the symmetrised added mass of thesis eq. 2.15 and $C_A$ the
    matching skew-symmetric added-mass Coriolis matrix (thesis eq. 2.18), so the
    Coriolis terms do no work. The damping $\\tau_D$ has Ross's terms:

    - surge: $X_{|u|u}|u|u + X_{uuu}u^3 + X_{vv}v^2\\sigma(u)$ with the smooth sign
      $\\sigma(u) = \\tanh(u/u_\\sigma)$ (the induced drag of the hull stays a drag astern);
    - sway: $Y_{uv}|u|v + Y_{ur}|u|r + Y_{uuv}u^2v + Y_{uur}u^2r + Y_{vvv}v^3 + Y_{rrr}r^3 +
      Y_{vvr}v^2r + Y_{rrv}r^2v + Y_{|v|v}|v|v + Y_{|r|v}|r|v + Y_{|v|r}|v|r +
      Y_{|r|r}|r|r$, and the same terms in yaw.

    Ross writes $u$ where we write $|u|$; the two agree ahead and $|u|$ keeps the
    lift terms dissipative astern. Propellers (`n_propellers` identical, thrust
    deduction $t$, wake $w$): $T = \\rho D^4 (k_0 n|n| + k_1 |n| u_a/D +
    k_2 u_a|u_a|/D^2)$, $u_a = (1 - w)u$, which is $\\rho D^4 n^2 K_T(J)$ with
    $K_T = k_0 + k_1 J + k_2 J^2$ ahead and pure drag at $n = 0$. Rudders (total
    area $A_R$ at $x_R$): normal force $F_N = \\tfrac12\\rho A_R U_R^2 C_N(\\alpha_R)$,
    $X = -F_N\\sin\\delta$, $Y = -F_N\\cos\\delta$, $N = x_R Y$, with the inflow
    $u_R = \\varepsilon[(1 - \\kappa)u_a + \\kappa\\sqrt{u_a^2 + 8T^+/(\\pi\\rho D^2)}]$
    (MMG propeller race, Yasukawa & Yoshimura 2015), $v_R = \\gamma_R(v + x_R r)$,
    $\\alpha_R = \\delta + \\mathrm{atan2}(v_R, u_R)$ and
    $C_N = \\sin\\alpha_R\\,[f_\\alpha(1 - s) + C_{N,90}\\, s]$,
    $s = \\tfrac12(1 + \\tanh((\\alpha_R^2 - \\alpha_s^2)/(2\\alpha_s\\Delta\\alpha)))$:
    Fujii's slope $f_\\alpha$ below the stall angle $\\alpha_s$, a flat-plate normal
    force above it. $\\alpha_s$ is the stall of the rudder where it works, i.e. in the
    propeller race for a rudder behind a running screw, which stalls much later than in
    open water (docs/thesis_vessel.md, sec. 16).

    Positive $\\delta$ turns to starboard ($r > 0$) as everywhere in jaxship; the
    model is port/starboard symmetric (no constant terms).
    """

    length: float = param(free=False, unit="m")  # L_pp, thesis Table 4.1
    rudder: RudderServo
    shaft: Shaft
    nominal_speed: float = param(free=False, unit="m/s")  # U_0, straight run at nominal_n
    nominal_n: float = param(free=False, unit="rev/s")  # n_0, 500 rpm (thesis sec. 4.1)
    frontal_wind_area: float = param(free=False, unit="m^2")  # A_F
    lateral_wind_area: float = param(free=False, unit="m^2")  # A_L
    rho: float = param(free=False, unit="kg/m^3")  # water density

    # rigid body and added mass (midship origin)
    mass: float = param(free=False, unit="kg")  # m, rho * displacement
    xg: float = param(free=False, unit="m")  # x_G
    iz: float = param(free=False, unit="kg m^2")  # I_z about midship
    x_udot: float = param(free=False, unit="kg")  # X_udot
    y_vdot: float = param(free=False, unit="kg")  # Y_vdot
    y_rdot: float = param(free=False, unit="kg m")  # Y_rdot = N_vdot (symmetrised, thesis eq. 2.15)
    n_rdot: float = param(free=False, unit="kg m^2")  # N_rdot

    # surge damping
    x_uu: float = param(free=True, unit="kg/m")  # X_|u|u
    x_uuu: float = param(free=False, unit="kg s/m^2")  # X_uuu
    x_vv: float = param(free=True, unit="kg/m")  # X_vv
    # u_sigma, width of the smooth sign of the X_vv term
    u_sigma: float = param(free=False, unit="m/s")

    # sway damping
    y_uv: float = param(free=True, unit="kg/m")  # Y_uv
    y_ur: float = param(free=True, unit="kg")  # Y_ur
    y_uuv: float = param(free=False, unit="kg s/m^2")  # Y_uuv
    y_uur: float = param(free=False, unit="kg s/m")  # Y_uur
    y_vvv: float = param(free=False, unit="kg s/m^2")  # Y_vvv
    y_rrr: float = param(free=False, unit="kg s m")  # Y_rrr
    y_vvr: float = param(free=False, unit="kg s/m")  # Y_vvr
    y_rrv: float = param(free=False, unit="kg s")  # Y_rrv
    y_absv_v: float = param(free=True, unit="kg/m")  # Y_|v|v
    y_absr_v: float = param(free=True, unit="kg")  # Y_|r|v
    y_absv_r: float = param(free=False, unit="kg")  # Y_|v|r
    y_absr_r: float = param(free=False, unit="kg m")  # Y_|r|r

    # yaw damping
    n_uv: float = param(free=True, unit="kg")  # N_uv
    n_ur: float = param(free=True, unit="kg m")  # N_ur
    n_uuv: float = param(free=False, unit="kg s/m")  # N_uuv
    n_uur: float = param(free=False, unit="kg s")  # N_uur
    n_vvv: float = param(free=False, unit="kg s/m")  # N_vvv
    n_rrr: float = param(free=False, unit="kg s m^2")  # N_rrr
    n_vvr: float = param(free=False, unit="kg s")  # N_vvr
    n_rrv: float = param(free=False, unit="kg s m")  # N_rrv
    n_absv_v: float = param(free=False, unit="kg")  # N_|v|v
    n_absr_v: float = param(free=False, unit="kg m")  # N_|r|v
    n_absv_r: float = param(free=True, unit="kg m")  # N_|v|r
    n_absr_r: float = param(free=True, unit="kg m^2")  # N_|r|r

    # propellers
    n_propellers: float = param(free=False, unit="-")  # number of identical propellers
    prop_diameter: float = param(free=False, unit="m")  # D
    kt0: float = param(free=False, unit="-")  # k_0, K_T(J) = k_0 + k_1 J + k_2 J^2
    kt1: float = param(free=False, unit="-")  # k_1
    kt2: float = param(free=False, unit="-")  # k_2, <= 0 so that a stopped propeller only drags
    wake: float = param(free=False, unit="-")  # w, Taylor wake fraction
    thrust_deduction: float = param(free=False, unit="-")  # t

    # rudders
    rudder_area: float = param(free=True, unit="m^2")  # A_R, total of all rudders
    # f_alpha, Fujii: 6.13 Lambda / (Lambda + 2.25)
    lift_slope: float = param(free=False, unit="1/rad")
    # C_N,90, post-stall normal force coefficient at 90 deg
    normal_force_90: float = param(free=False, unit="-")
    # alpha_s, effective angle of attack at mid-stall (s = 1/2)
    stall_angle: float = param(free=False, unit="rad")
    stall_width: float = param(free=False, unit="rad")  # Delta alpha, width of the stall transition
    x_rudder: float = param(free=False, unit="m")  # x_R
    flow_straightening: float = param(free=False, unit="-")  # gamma_R
    race_kappa: float = param(free=False, unit="-")  # kappa, MMG propeller-race factor
    race_epsilon: float = param(free=False, unit="-")  # epsilon, (1 - w_R) / (1 - w_P)
    wind_model: AbstractWindLoads = FossenWindLoads()  # wind loads on A_F, A_L

    def mass_matrix(self) -> Array:
        m, xg = self.mass, self.xg
        return jnp.array([
            [m - self.x_udot, 0.0, 0.0],
            [0.0, m - self.y_vdot, m * xg - self.y_rdot],
            [0.0, m * xg - self.y_rdot, self.iz - self.n_rdot],
        ])

    def thrust(self, u, n) -> Array:
        """Open-water thrust of one propeller [N] at surge speed `u` and rate `n` [rev/s]."""
        D = self.prop_diameter
        ua = (1.0 - self.wake) * u
        return self.rho * D**4 * (
            self.kt0 * n * jnp.abs(n) + self.kt1 * jnp.abs(n) * ua / D
            + self.kt2 * ua * jnp.abs(ua) / D**2
        )

    def normal_force_coefficient(self, alpha) -> Array:
        """Rudder normal-force coefficient $C_N(\\alpha)$: Fujii slope, smooth stall."""
        s = 0.5 * (1.0 + jnp.tanh(
            (alpha**2 - self.stall_angle**2) / (2.0 * self.stall_angle * self.stall_width)
        ))
        return jnp.sin(alpha) * (self.lift_slope * (1.0 - s) + self.normal_force_90 * s)

    def rudder_normal_force(self, u, v, r, delta, n) -> Array:
        """Total rudder normal force $F_N$ [N], positive for a starboard-turning force."""
        D = self.prop_diameter
        ua = (1.0 - self.wake) * u
        thrust = jnp.maximum(self.thrust(u, n), 0.0)
        race = jnp.sqrt(ua**2 + 8.0 * thrust / (jnp.pi * self.rho * D**2) + 1e-20)
        u_r = self.race_epsilon * ((1.0 - self.race_kappa) * ua + self.race_kappa * race)
        v_r = self.flow_straightening * (v + self.x_rudder * r)
        # atan2 with a guard against the undefined gradient at u_R = v_R = 0
        still = (u_r == 0.0) & (v_r == 0.0)
        alpha = delta + jnp.arctan2(v_r, jnp.where(still, 1.0, u_r))
        speed2 = u_r**2 + v_r**2
        return 0.5 * self.rho * self.rudder_area * speed2 * self.normal_force_coefficient(alpha)

    def forces(self, u, v, r, delta, n) -> Array:
        m, xg = self.mass, self.xg
        au, av, ar = jnp.abs(u), jnp.abs(v), jnp.abs(r)
        # -C_RB(nu) nu and -C_A(nu) nu (thesis eq. 2.17-2.18 in 3 DOF)
        X = m * (v * r + xg * r**2) - (self.y_vdot * v + self.y_rdot * r) * r
        Y = -m * u * r + self.x_udot * u * r
        N = -m * xg * u * r + (self.y_vdot - self.x_udot) * u * v + self.y_rdot * u * r
        # Ross damping (thesis eq. 2.20 in 3 DOF)
        X = X + (self.x_uu * au * u + self.x_uuu * u**3
                 + self.x_vv * v**2 * jnp.tanh(u / self.u_sigma))
        Y = Y + (
            self.y_uv * au * v + self.y_ur * au * r + self.y_uuv * u**2 * v
            + self.y_uur * u**2 * r + self.y_vvv * v**3 + self.y_rrr * r**3
            + self.y_vvr * v**2 * r + self.y_rrv * r**2 * v + self.y_absv_v * av * v
            + self.y_absr_v * ar * v + self.y_absv_r * av * r + self.y_absr_r * ar * r
        )
        N = N + (
            self.n_uv * au * v + self.n_ur * au * r + self.n_uuv * u**2 * v
            + self.n_uur * u**2 * r + self.n_vvv * v**3 + self.n_rrr * r**3
            + self.n_vvr * v**2 * r + self.n_rrv * r**2 * v + self.n_absv_v * av * v
            + self.n_absr_v * ar * v + self.n_absv_r * av * r + self.n_absr_r * ar * r
        )
        # propellers and rudders
        X = X + self.n_propellers * (1.0 - self.thrust_deduction) * self.thrust(u, n)
        fn = self.rudder_normal_force(u, v, r, delta, n)
        X = X - fn * jnp.sin(delta)
        Y = Y - fn * jnp.cos(delta)
        N = N - self.x_rudder * fn * jnp.cos(delta)
        return jnp.stack(jnp.broadcast_arrays(X, Y, N))


# --- derivation of the coefficients (docs/thesis_vessel.md) ---------------------------------


def clarke83(L, B, T, Cb):
    """Prime added masses and linear derivatives of Clarke, Gedling & Hine (1983).

    Returns a dict of $Y'_{\\dot v}, Y'_{\\dot r}, N'_{\\dot v}, N'_{\\dot r}, Y'_v, Y'_r,
    N'_v, N'_r$ (forces / (rho L^2 U^2 / 2), moments / (rho L^3 U^2 / 2), accelerations
    as in the prime system). The derivatives are hydrodynamic: they exclude the
    rigid-body centripetal terms and include the ideal-fluid (added-mass) loads.
    """
    S = np.pi * (T / L) ** 2
    return dict(
        y_vdot=-S * (1 + 0.16 * Cb * B / T - 5.1 * (B / L) ** 2),
        y_rdot=-S * (0.67 * B / L - 0.0033 * (B / T) ** 2),
        n_vdot=-S * (1.1 * B / L - 0.041 * B / T),
        n_rdot=-S * (1 / 12 + 0.017 * Cb * B / T - 0.33 * B / L),
        y_v=-S * (1 + 0.4 * Cb * B / T),
        y_r=-S * (-1 / 2 + 2.2 * B / L - 0.08 * B / T),
        n_v=-S * (1 / 2 + 2.4 * T / L),
        n_r=-S * (1 / 4 + 0.039 * B / T - 0.56 * B / L),
    )


# Hoerner's 2-D cross-flow drag coefficient against B/(2T) (MSS HYDRO/Hoerner.m, digitised
# from Leite et al. 1998); vessel-models.md sec. 1.11
HOERNER = np.array([
    [0.0108623, 1.96608], [0.176606, 1.96573], [0.353025, 1.89756], [0.451863, 1.78718],
    [0.472838, 1.58374], [0.492877, 1.27862], [0.493252, 1.21082], [0.558473, 1.08356],
    [0.646401, 0.998631], [0.833589, 0.87959], [0.988002, 0.828415], [1.30807, 0.759941],
    [1.63918, 0.691442], [1.85998, 0.657076], [2.31288, 0.630693], [2.59998, 0.596186],
    [3.00877, 0.586846], [3.45075, 0.585909], [3.7379, 0.559877], [4.00309, 0.559315],
])


def hoerner_cd(B, T):
    """2-D cross-flow drag coefficient of a ship section of beam B and draft T."""
    return float(np.interp(B / (2 * T), HOERNER[:, 0], HOERNER[:, 1]))


@functools.lru_cache
def crossflow_cross_terms(max_drift_deg=30.0, max_r_prime=1.0, num=41):
    """Constants $c_Y, c_N$ of the modulus expansion of the strip cross-flow integral.

    $\\int_{-L/2}^{L/2} |v + xr|(v + xr)dx \\approx L|v|v + c_Y L^2 |r|v$ and
    $\\int x|v + xr|(v + xr)dx \\approx c_N L^3|v|r + (L^4/32)|r|r$: the pure-sway and
    pure-yaw terms are exact; $c_Y$, $c_N$ are least-squares fits over drift angles up
    to `max_drift_deg` and $|r'| \\le$ `max_r_prime` (Blanke's bound
    $|v + xr| \\le |v| + |x||r|$ gives 1/4 and 1/12 instead). The integrals are
    evaluated by 2001-point trapezoidal quadrature at L = 1, U = 1.
    """
    x = np.linspace(-0.5, 0.5, 2001)
    beta = np.deg2rad(np.linspace(-max_drift_deg, max_drift_deg, num))
    rp = np.linspace(-max_r_prime, max_r_prime, num)
    v, r = np.meshgrid(-np.sin(beta), rp, indexing="ij")
    w = v[..., None] + x * r[..., None]
    y_int = np.trapezoid(np.abs(w) * w, x, axis=-1)
    n_int = np.trapezoid(x * np.abs(w) * w, x, axis=-1)
    ay, by = (np.abs(r) * v).ravel(), (y_int - np.abs(v) * v).ravel()
    an, bn = (np.abs(v) * r).ravel(), (n_int - np.abs(r) * r / 32).ravel()
    return float(ay @ by / (ay @ ay)), float(an @ bn / (an @ an))


def ittc57(speed, length, nu):
    """ITTC-1957 model-ship correlation line $C_F = 0.075/(\\log_{10}Re - 2)^2$."""
    return 0.075 / (np.log10(speed * length / nu) - 2.0) ** 2


def resistance_fit(L, S, rho, nu, form_factor, residuary, speeds):
    """$X_{|u|u}, X_{uuu}$ fitted to $R = \\tfrac12\\rho S U^2[(1+k)C_F + C_R(F_n)]$.

    $C_R = C_{R,0.25}(F_n/0.25)^4$ with $C_{R,0.25}$ = `residuary`; least squares of
    $-R(U) = X_{|u|u}U^2 + X_{uuu}U^3$ at `speeds`, relative to R (equal weight in %).
    """
    U = np.asarray(speeds, dtype=float)
    fn = U / np.sqrt(G * L)
    R = 0.5 * rho * S * U**2 * (form_factor * ittc57(U, L, nu) + residuary * (fn / 0.25) ** 4)
    A = np.stack([U**2, U**3], axis=1) / R[:, None]
    coef = np.linalg.lstsq(A, -np.ones_like(U), rcond=None)[0]
    return float(coef[0]), float(coef[1])


def thesis_vessel() -> RossVessel:
    """Thesis vessel: 4 m DTMB 5415 model, Ross-type 3-DOF model (Odegard 2009, Table 4.1).

    Particulars from the thesis (Lpp 4.002 m, B 0.538 m, T 0.172 m, 0.188 m^3,
    I_z = m (0.295 L)^2, rudder 45 deg at 15 deg/s) and SIMMAN 2008 (twin screws D =
    0.173 m, Z = 5, Ae/A0 = 0.58; twin spade rudders of 0.0122 m^2). Hydrodynamic
    coefficients derived from Clarke et al. (1983), Hoerner cross-flow drag, ITTC-57
    friction, a Wageningen B-series K_T fit and Fujii's rudder formula; see
    docs/thesis_vessel.md. 500 rpm gives about 1.55 m/s, 600 rpm about 1.8 m/s.
    """
    L, B = 4.002, 0.538  # thesis Table 4.1
    return RossVessel(
        length=L,
        rudder=RudderServo(
            max_angle=float(np.deg2rad(45.0)),  # thesis sec. 4.1
            max_rate=float(np.deg2rad(15.0)),  # thesis Table 4.1
            time_constant=1.0,  # T_delta [s], MSS convention
        ),
        shaft=Shaft(max_rate=10.0, time_constant=1.0),  # 600 rpm, T_n = 1 s (docs sec. 9)
        nominal_speed=1.5429721868551294,  # straight run at 500 rpm (tests/test_ross.py)
        nominal_n=500.0 / 60.0,  # thesis sec. 4.1
        frontal_wind_area=float(B * 0.2),  # bare hull, freeboard ~0.2 m (docs sec. 11)
        lateral_wind_area=float(L * 0.2),
        **_thesis_hull(L, B),
        **_thesis_propulsion(L),
    )


def _thesis_hull(L: float, B: float) -> dict:
    """The thesis vessel's mass, added mass and hull forces (`thesis_vessel`'s sources)."""
    rho, nu = 1000.0, 1.14e-6  # fresh water at 15 deg C (ITTC 7.5-02-01-03)
    T, disp = 0.172, 0.188  # thesis Table 4.1
    Cb = disp / (L * B * T)
    m = rho * disp
    xg = -0.018  # LCG [m], SIMMAN 5415 (MARIN model), midship origin
    izg = m * (0.295 * L) ** 2  # thesis Table 4.1 (about the CG)
    half = 0.5 * rho
    c = clarke83(L, B, T, Cb)

    # added mass: Soding (1982) in surge, Clarke (1983) in sway/yaw, symmetrised (eq. 2.15)
    x_udot = -2.7 * rho * disp ** (5 / 3) / L**2
    y_vdot = c["y_vdot"] * half * L**3
    y_rdot = 0.5 * (c["y_rdot"] + c["n_vdot"]) * half * L**4
    n_rdot = c["n_rdot"] * half * L**5

    # linear hydrodynamic derivatives per unit surge speed (Clarke 1983) less the
    # linear parts of -C_A(nu)nu, which the model carries separately
    y_uv = c["y_v"] * half * L**2
    y_ur = c["y_r"] * half * L**3 - x_udot
    n_uv = c["n_v"] * half * L**3 - (y_vdot - x_udot)
    n_ur = c["n_r"] * half * L**4 - y_rdot

    # cross-flow drag (strip theory, Hoerner C_D, constant T and C_D along the hull)
    kcf = half * T * hoerner_cd(B, T)
    cy, cn = crossflow_cross_terms()

    # resistance: ITTC-57 line, form factor and a residuary term (tuned, docs sec. 6, 12)
    S = 2.361  # wetted surface [m^2], SIMMAN 5415 model
    x_uu, x_uuu = resistance_fit(L, S, rho, nu, form_factor=1.10, residuary=1.0e-3,
                                 speeds=np.linspace(0.2, 2.0, 37))

    # induced drag of the hull lift as a wing of span 2T: X_vv = -Y_uv^2 / (2 pi rho T^2)
    x_vv = -(y_uv**2) / (2 * np.pi * rho * T**2)

    return dict(
        rho=rho,
        mass=float(m),
        xg=xg,
        iz=float(izg + m * xg**2),
        x_udot=float(x_udot),
        y_vdot=float(y_vdot),
        y_rdot=float(y_rdot),
        n_rdot=float(n_rdot),
        x_uu=x_uu,
        x_uuu=x_uuu,
        x_vv=float(x_vv),
        u_sigma=0.05,
        y_uv=float(y_uv),
        y_ur=float(y_ur),
        y_uuv=0.0, y_uur=0.0, y_vvv=0.0, y_rrr=0.0, y_vvr=0.0, y_rrv=0.0,
        y_absv_v=float(-kcf * L),
        y_absr_v=float(-kcf * cy * L**2),
        y_absv_r=0.0,  # zero by fore-aft symmetry of the strip model
        y_absr_r=0.0,
        n_uv=float(n_uv),
        n_ur=float(n_ur),
        n_uuv=0.0, n_uur=0.0, n_vvv=0.0, n_rrr=0.0, n_vvr=0.0, n_rrv=0.0,
        n_absv_v=0.0,  # zero by fore-aft symmetry of the strip model
        n_absr_v=0.0,
        n_absv_r=float(-kcf * cn * L**3),
        n_absr_r=float(-kcf * L**4 / 32),
    )


def _thesis_propulsion(L: float) -> dict:
    """The thesis vessel's propellers and rudders (`thesis_vessel`'s sources)."""
    aspect = 1.5  # rudder geometric aspect ratio Lambda (assumed, docs sec. 10)
    return dict(
        n_propellers=2.0,  # twin screws, SIMMAN 5415
        prop_diameter=0.173,  # SIMMAN 5415 model propeller
        kt0=0.5012,  # quadratic fit of B5-58, P/D = 1.15, J in [0, 1.2] (docs sec. 9)
        kt1=-0.2276,
        kt2=-0.1487,
        wake=0.045,  # Holtrop (1984) twin-screw formula (docs sec. 9)
        thrust_deduction=0.058,  # Holtrop (1984) twin-screw formula
        rudder_area=0.018,  # tuned: 74 % of the twin SIMMAN rudders' 2 x 0.0122 (docs sec. 12)
        lift_slope=6.13 * aspect / (aspect + 2.25),  # Fujii & Tuda (1961)
        normal_force_90=1.2,  # flat plate of low aspect ratio (Hoerner 1965)
        # stall in the propeller race (docs sec. 16): the rudders lie wholly in the race
        # (eta = 1), where stall is delayed to 35-45 deg effective incidence (Molland &
        # Turnock 2007, "Marine Rudders and Control Surfaces", ch. on rudder-propeller
        # interaction; Brix 1993); MMG has no stall up to 35 deg (Yasukawa & Yoshimura 2015).
        # alpha_s = 50 deg puts the C_N peak at 44.9 deg, the hard-over angle: the thesis'
        # vessel turns hardest at 45 deg (Odegard 2009, sec. 4.1, figs. 4.7, 4.16).
        stall_angle=float(np.deg2rad(50.0)),
        stall_width=float(np.deg2rad(4.0)),  # assumed (docs sec. 10)
        x_rudder=-0.5 * L,  # MMG x'_R = -0.5
        flow_straightening=0.5,  # gamma_R, MMG range 0.4-0.64
        race_kappa=0.5,  # MMG KVLCC2 value
        race_epsilon=1.0,  # open twin-screw stern: rudder wake = propeller wake
    )
