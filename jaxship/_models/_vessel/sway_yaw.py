"""Linear sway-yaw model with Norrbin's one-coefficient cross-flow drag (Astrom & Kallstrom 1979).

The presets are the full-scale identification results of K. J. Astrom and C. G. Kallstrom
(1979), *Determination of linear and nonlinear ship steering dynamics using system
identification*, final report STU project 77-5766, Lund Institute of Technology (Tables
2-4). The tables give the damping and rudder derivatives and the transfer-function
constants but not the mass terms; those are derived here from the transfer functions
(`_derive_mass_terms`).
"""

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._params import param
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, FossenWindLoads
from ._base import AbstractVessel


def _cross_flow_integrals(v, r, length):
    """$\\int_{-L/2}^{L/2} |w| w\\,dx$ and $\\int_{-L/2}^{L/2} x |w| w\\,dx$ for $w = v + x r$.

    Closed form, smooth in `(v, r)` and safe to differentiate at $r = 0$. When
    $|v| \\ge |r| L/2$ the local cross-flow $w$ has the sign of $v$ along the whole hull
    and the integrands are polynomials; otherwise $w$ changes sign at $x = -v/r$ inside
    the hull and, with $a = |r| L/2$ (so that $|r| > 0$ there),
    $\\int |w| w\\,dx = 2v(v^2 + 3a^2)/(3|r|)$,
    $\\int x|w|w\\,dx = \\mathrm{sgn}(r)(a^4/2 + v^2a^2 - v^4/6)/r^2$.
    """
    L = length
    crossing = jnp.abs(v) < 0.5 * L * jnp.abs(r)
    # the hull sees one sign of cross-flow
    i0_out = L * jnp.abs(v) * v + jnp.sign(v) * r**2 * L**3 / 12
    i1_out = jnp.abs(v) * r * L**3 / 6
    # the cross-flow changes sign along the hull; r is bounded away from 0 in this branch
    r_safe = jnp.where(crossing, r, 1.0)
    a2 = (0.5 * L * r_safe) ** 2
    i0_in = 2 * v * (v**2 + 3 * a2) / (3 * jnp.abs(r_safe))
    i1_in = jnp.sign(r_safe) * (0.5 * a2**2 + v**2 * a2 - v**4 / 6) / r_safe**2
    return jnp.where(crossing, i0_in, i0_out), jnp.where(crossing, i1_in, i1_out)


class SwayYawVessel(AbstractVessel):
    """Linear sway-yaw model of Astrom & Kallstrom (1979, eq. 3) with Norrbin's (1976)
    cross-flow drag.

    In the prime system (length $L$, time $L/V$, mass $\\rho L^3/2$):

    $\\begin{pmatrix} m' - Y'_{\\dot v} & m'x'_G - Y'_{\\dot r} \\\\
    m'x'_G - N'_{\\dot v} & I'_z - N'_{\\dot r}\\end{pmatrix}
    \\begin{pmatrix}\\dot v' \\\\ \\dot r'\\end{pmatrix} =
    \\begin{pmatrix} Y'_v & Y'_r - m' \\\\ N'_v & N'_r - m'x'_G\\end{pmatrix}
    \\begin{pmatrix} v' \\\\ r'\\end{pmatrix} +
    \\begin{pmatrix} Y'_\\delta \\\\ N'_\\delta\\end{pmatrix}\\delta + C\\,f(v, r)$,

    with the speed $V$ taken as the surge speed $u$, which stays constant ($X = 0$).
    The cross-flow drag with one effective coefficient $C$ and constant draught $T$ is
    $Y_{cf} = -\\tfrac12\\rho T C\\int_{-L/2}^{L/2}|v + xr|(v + xr)\\,dx$,
    $N_{cf} = -\\tfrac12\\rho T C\\int_{-L/2}^{L/2}x|v + xr|(v + xr)\\,dx$ (closed form in
    `_cross_flow_integrals`). $C = 0$ gives the linear model.

    The rudder derivatives here follow the jaxship sign (positive $\\delta$ turns to
    starboard): they are minus the published $Y'_\\delta > 0$, $N'_\\delta < 0$.
    """

    length: float = param(free=False, unit="m")  # L
    # T, constant along the hull (cross-flow drag only)
    draught: float = param(free=False, unit="m")
    rudder: RudderServo
    nominal_speed: float = param(free=False, unit="m/s")  # V, approach speed
    m22: float = param(free=False, unit="-")  # m' - Y'_vdot
    m23: float = param(free=False, unit="-")  # m'x'_G - Y'_rdot
    m32: float = param(free=False, unit="-")  # m'x'_G - N'_vdot
    m33: float = param(free=False, unit="-")  # I'_z - N'_rdot
    y_v: float = param(free=True, unit="-")  # Y'_v
    y_r: float = param(free=True, unit="-")  # Y'_r - m'
    n_v: float = param(free=True, unit="-")  # N'_v
    n_r: float = param(free=True, unit="-")  # N'_r - m'x'_G
    y_delta: float = param(free=True, unit="-")  # Y'_delta, jaxship sign (< 0 for a stern rudder)
    # N'_delta, jaxship sign (> 0: positive delta turns to starboard)
    n_delta: float = param(free=True, unit="-")
    # C, effective cross-flow drag coefficient (Norrbin 1976)
    cross_flow: float = param(0.0, free=False, unit="-")
    shaft: Shaft = Shaft()  # no propeller: surge speed is frozen
    nominal_n: float = param(0.0, free=False, unit="rev/s")
    frontal_wind_area: float = param(0.0, free=False, unit="m^2")  # A_F
    lateral_wind_area: float = param(0.0, free=False, unit="m^2")  # A_L
    rho: float = param(1025.0, free=False, unit="kg/m^3")  # water density
    wind_model: AbstractWindLoads = FossenWindLoads()  # wind loads on A_F, A_L

    def mass_matrix(self) -> Array:
        L = self.length
        # surge row: any nonzero mass, since X = 0 keeps u constant
        prime = jnp.array([
            [self.m22, 0.0, 0.0],
            [0.0, self.m22, L * self.m23],
            [0.0, L * self.m32, L**2 * self.m33],
        ])
        return 0.5 * self.rho * L**3 * prime

    def forces(self, u, v, r, delta, n) -> Array:
        del n
        L, V = self.length, u
        half = 0.5 * self.rho * L**2
        Y = half * (V * self.y_v * v + V * L * self.y_r * r + V**2 * self.y_delta * delta)
        N = half * L * (V * self.n_v * v + V * L * self.n_r * r + V**2 * self.n_delta * delta)
        i0, i1 = _cross_flow_integrals(v, r, L)
        drag = 0.5 * self.rho * self.draught * self.cross_flow
        X = jnp.zeros_like(Y)
        return jnp.stack(jnp.broadcast_arrays(X, Y - drag * i0, N - drag * i1))

    def prime_transfer_constants(self) -> dict:
        """Constants of the linear model's transfer functions in the prime system,
        Astrom & Kallstrom (1979, eq. 4-5):

        $r'/\\delta = K'(s' + 1/T'_3)/((s' + 1/T'_1)(s' + 1/T'_2))$,
        $v'/\\delta = K'_v(s' + 1/T'_{3v})/((s' + 1/T'_1)(s' + 1/T'_2))$,

        with $|T'_1| \\ge |T'_2|$ (NaN for complex poles) and the jaxship rudder sign
        ($K' > 0$; the published tables have $K' < 0$). Returns a dict with keys
        `K, T1, T2, T3, Kv, T3v`.
        """
        M = jnp.array([[self.m22, self.m23], [self.m32, self.m33]])
        A = jnp.array([[self.y_v, self.y_r], [self.n_v, self.n_r]])
        return _transfer_constants(M, A, jnp.array([self.y_delta, self.n_delta]))

    def transfer_constants(self, speed=None) -> dict:
        """`prime_transfer_constants` in SI units at `speed` [m/s] (default nominal):
        $K = K'V^2/L^2$ [1/s^2], $T_i = T'_i L/V$ [s], $K_v = K'_v V^2/L$ [m/s^2]."""
        V = self.nominal_speed if speed is None else speed
        L = self.length
        c = self.prime_transfer_constants()
        return dict(
            K=c["K"] * V**2 / L**2, T1=c["T1"] * L / V, T2=c["T2"] * L / V,
            T3=c["T3"] * L / V, Kv=c["Kv"] * V**2 / L, T3v=c["T3v"] * L / V,
        )


def _transfer_constants(M, A, b):
    """K, T1, T2, T3, Kv, T3v of $M\\dot x = Ax + b\\delta$, $x = (v, r)$ (eq. 4-5).

    With $s$ the Laplace variable, $\\det(sM - A) = \\det M\\,(s + 1/T_1)(s + 1/T_2)$, so
    $T_1T_2 = \\det M/\\det A$ and $T_1 + T_2 = -(m_{11}a_{22} + m_{22}a_{11} - m_{12}a_{21} -
    m_{21}a_{12})/\\det A$; the numerators give $K = (m_{11}b_2 - m_{21}b_1)/\\det M$,
    $K/T_3 = (a_{21}b_1 - a_{11}b_2)/\\det M$, $K_v = (m_{22}b_1 - m_{12}b_2)/\\det M$,
    $K_v/T_{3v} = (a_{12}b_2 - a_{22}b_1)/\\det M$.
    """
    xp = jnp if isinstance(M, jnp.ndarray) else np
    (m11, m12), (m21, m22) = M[0], M[1]
    (a11, a12), (a21, a22) = A[0], A[1]
    b1, b2 = b[0], b[1]
    det_m = m11 * m22 - m12 * m21
    det_a = a11 * a22 - a12 * a21
    total = -(m11 * a22 + m22 * a11 - m12 * a21 - m21 * a12) / det_a  # T1 + T2
    product = det_m / det_a  # T1 T2
    root = xp.sqrt(total**2 - 4 * product)  # NaN for complex poles
    ta, tb = (total + root) / 2, (total - root) / 2
    first = xp.abs(ta) >= xp.abs(tb)
    return dict(
        K=(m11 * b2 - m21 * b1) / det_m,
        T1=xp.where(first, ta, tb),
        T2=xp.where(first, tb, ta),
        T3=(m11 * b2 - m21 * b1) / (a21 * b1 - a11 * b2),
        Kv=(m22 * b1 - m12 * b2) / det_m,
        T3v=(m22 * b1 - m12 * b2) / (a12 * b2 - a22 * b1),
    )


def _derive_mass_terms(derivatives, constants, resolution=0.005):
    """Mass terms $(m' - Y'_{\\dot v}, m'x'_G - Y'_{\\dot r}, m'x'_G - N'_{\\dot v},
    I'_z - N'_{\\dot r})$ that reproduce published transfer-function constants.

    Arguments are the prime-system numbers of Astrom & Kallstrom (1979, Tables 2-4) in
    their sign convention. Six constants (`K, T1, T2, T3, Kv, T3v`, eq. 4-5) for four
    unknowns: the four equations for $K$, $T_1 + T_2$, $T_1T_2$ and $K_v$ (three linear
    in the mass terms, one bilinear: $\\det M = T_1T_2\\det A$) are solved exactly (the
    root with positive diagonal and the smaller coupling is taken), then Gauss-Newton
    refines a least-squares fit of all six constants in units of `resolution` (half the
    last published digit). With `n_delta=None` (missing in Table 3, linear column) it
    is estimated as a fifth unknown. `derivatives`: `(y_v, y_r, n_v, n_r, y_delta,
    n_delta)`; `constants`: `(K, T1, T2, T3, Kv, T3v)`. NumPy only; returns
    `(mass_terms, n_delta, residuals)` with the residuals (model minus published) of the
    six constants.
    """
    y_v, y_r, n_v, n_r, y_delta, n_delta = derivatives
    K, T1, T2, T3, Kv, T3v = constants
    A = np.array([[y_v, y_r], [n_v, n_r]], dtype=float)
    (a11, a12), (a21, a22) = A
    b1 = float(y_delta)
    det_a = np.linalg.det(A)
    free_b2 = n_delta is None
    # exact T3 relation K/T3 = (a21 b1 - a11 b2)/det M as the starting value of N'_delta
    b2 = (a21 * b1 - K * T1 * T2 * det_a / T3) / a11 if free_b2 else float(n_delta)
    det_m = det_a * T1 * T2
    lin = np.array([[a22, -a21, -a12, a11], [b2, 0.0, -b1, 0.0], [0.0, -b2, 0.0, b1]])
    rhs = np.array([-det_a * (T1 + T2), K * det_m, Kv * det_m])
    z0 = np.linalg.lstsq(lin, rhs, rcond=None)[0]
    null = np.linalg.svd(lin)[2][-1]
    quad = [
        null[0] * null[3] - null[1] * null[2],
        z0[0] * null[3] + z0[3] * null[0] - z0[1] * null[2] - z0[2] * null[1],
        z0[0] * z0[3] - z0[1] * z0[2] - det_m,
    ]
    roots = np.roots(quad)
    candidates = [z0 + t.real * null for t in roots if abs(t.imag) <= 1e-9 * abs(t)]
    candidates = [z for z in candidates if z[0] > 0 and z[3] > 0]
    if not candidates:
        raise ValueError("No positive-definite mass terms reproduce the given constants.")
    z = min(candidates, key=lambda z: (abs(z[1]) + abs(z[2])) / z[0])
    if free_b2:
        z = np.append(z, b2)
    target = np.array([K, T1, T2, T3, Kv, T3v], dtype=float)

    def residual(z):
        b = np.array([b1, z[4] if free_b2 else b2])
        c = _transfer_constants(z[:4].reshape(2, 2), A, b)
        return np.array([c[k] for k in ("K", "T1", "T2", "T3", "Kv", "T3v")]) - target

    scale = np.abs(z) + 1e-3 * abs(z[0])
    for _ in range(100):
        f = residual(z) / resolution
        jac = np.stack([
            (residual(z + h) - residual(z - h)) / (2 * h[j] * resolution)
            for j, h in enumerate(np.diag(1e-7 * scale))
        ], axis=1)
        step = np.linalg.lstsq(jac * scale, -f, rcond=None)[0] * scale
        z = z + step
        if np.max(np.abs(step / scale)) < 1e-12:
            break
    return z[:4], (z[4] if free_b2 else b2), residual(z)


def _tanker_servo():
    # typical tanker steering gear: 35 deg, 2.3 deg/s (SOLAS: 35 deg to 30 deg in 28 s)
    return RudderServo(float(np.deg2rad(35.0)), float(np.deg2rad(2.3)), 1.0)


def _mariner_servo():
    # Mariner steering gear as in MSS mariner.m (5 deg/s, T = 1 s), limited to 35 deg
    return RudderServo(float(np.deg2rad(35.0)), float(np.deg2rad(5.0)), 1.0)


def _published(y_v, y_r, n_v, n_r, y_delta, n_delta, masses, **kwargs):
    """A vessel from published prime numbers (their rudder sign) and derived mass terms."""
    m22, m23, m32, m33 = masses
    return SwayYawVessel(
        m22=m22, m23=m23, m32=m32, m33=m33, y_v=y_v, y_r=y_r, n_v=n_v, n_r=n_r,
        y_delta=-y_delta, n_delta=-n_delta,  # their positive delta turns to port
        **kwargs,
    )


# Particulars not in the source, used by the presets (reasons in each docstring):
_SEA_STRATUS = dict(length=350.0, draught=22.0, nominal_speed=8.0)
_SEA_SWIFT = dict(length=320.0, draught=19.5, nominal_speed=8.0)
_COMPASS_ISLAND = dict(length=160.93, draught=7.4, nominal_speed=7.7175)


def sea_stratus_linear() -> SwayYawVessel:
    """Tanker Sea Stratus, linear model (Astrom & Kallstrom (1979) Table 3).

    356 000 tdw tanker; prediction-error estimates (T_p = 60 s) from a 5/5 zig-zag
    (experiment E2), linear column: Y'_v = -0.02121, Y'_r - m' = -0.01010,
    N'_v = -0.00258, N'_r - m'x'_G = -0.00144, Y'_delta = 0.00203; K' = -1.01,
    T'_1 = 9.36, T'_2 = 0.37, T'_3 = 0.61, K'_v = 0.12, T'_3v = 0.15 (their rudder sign).
    N'_delta is missing from the scanned table; `_derive_mass_terms` estimates it with
    the mass terms (-0.000965, next to -0.00097 in the nonlinear column). The model
    reproduces the published constants to within 0.0015.

    Assumed particulars (not in the source; typical of a 1970s 356 000 tdw tanker):
    L = 350 m, draught 22 m, V = 8 m/s; steering gear 35 deg, 2.3 deg/s.
    """
    return _published(
        -0.02121, -0.01010, -0.00258, -0.00144, 0.00203, -0.000964751,
        masses=(0.0162179, -6.04553e-05, 1.84866e-05, 0.000957576),  # derived
        rudder=_tanker_servo(), **_SEA_STRATUS,
    )


def sea_stratus_nonlinear() -> SwayYawVessel:
    """Tanker Sea Stratus, cross-flow drag C = 0.63 (Astrom & Kallstrom (1979) Table 3).

    Nonlinear column of Table 3 (experiment E2, 5/5 zig-zag, T_p = 60 s):
    Y'_v = -0.02037, Y'_r - m' = -0.01065, N'_v = -0.00300, N'_r - m'x'_G = -0.00138,
    Y'_delta = 0.00206, N'_delta = -0.00097, C = 0.63; K' = -1.03, T'_1 = -11.08,
    T'_2 = 0.36, T'_3 = 0.61, K'_v = 0.13, T'_3v = 0.15 (course-unstable). Mass terms
    from `_derive_mass_terms` (constants reproduced to within 0.0007).

    Assumed particulars as `sea_stratus_linear`: L = 350 m, draught 22 m, V = 8 m/s.
    """
    return _published(
        -0.02037, -0.01065, -0.00300, -0.00138, 0.00206, -0.00097,
        masses=(0.0162197, 3.61292e-05, 3.66121e-05, 0.000946047),  # derived
        cross_flow=0.63, rudder=_tanker_servo(), **_SEA_STRATUS,
    )


def compass_island_linear() -> SwayYawVessel:
    """Compass Island, linear model (Astrom & Kallstrom (1979) Table 4, E1).

    Mariner-class hull; ML estimates (T_p = 6 s) from a 20/20 zig-zag digitised from
    Morse & Price (1961), experiment E1, linear column: Y'_v = -0.01313,
    Y'_r - m' = -0.00844, N'_v = -0.00009, N'_r - m'x'_G = -0.00106, Y'_delta = 0.00218,
    N'_delta = -0.00105; K' = -1.28, T'_1 = 1.15, T'_2 = 0.85, T'_3 = 1.18, K'_v = 0.17,
    T'_3v = 0.19. Mass terms from `_derive_mass_terms` (within 0.003).

    Particulars: Mariner hull L = 160.93 m at 15 kn as in MSS `mariner.m`; draught 7.4 m
    from the MSS Mariner mass (17 045 t) with B = 23.2 m and C_B = 0.6 (assumed); rudder
    35 deg at the 5 deg/s of MSS `mariner.m`.
    """
    return _published(
        -0.01313, -0.00844, -0.00009, -0.00106, 0.00218, -0.00105,
        masses=(0.0154584, 0.000314549, 0.000118003, 0.000835241),  # derived
        rudder=_mariner_servo(), **_COMPASS_ISLAND,
    )


def compass_island_nonlinear() -> SwayYawVessel:
    """Compass Island, cross-flow drag C = 0.35 (Astrom & Kallstrom (1979) Table 4, E1).

    Experiment E1, nonlinear column: Y'_v = -0.00892, Y'_r - m' = -0.00817,
    N'_v = -0.00075, N'_r - m'x'_G = -0.00100, Y'_delta = 0.00240, N'_delta = -0.00115,
    C = 0.35; K' = -1.42, T'_1 = 7.09, T'_2 = 0.64, T'_3 = 1.50, K'_v = 0.18,
    T'_3v = 0.19. Mass terms from `_derive_mass_terms` (within 0.0022).

    Particulars as `compass_island_linear`.
    """
    return _published(
        -0.00892, -0.00817, -0.00075, -0.00100, 0.00240, -0.00115,
        masses=(0.0154515, 0.000246337, 0.000126393, 0.000824968),  # derived
        cross_flow=0.35, rudder=_mariner_servo(), **_COMPASS_ISLAND,
    )


def sea_swift() -> SwayYawVessel:
    """Tanker Sea Swift, full draught, linear (Astrom & Kallstrom (1979) Table 2, E2).

    255 000 tdw sister of the Sea Scout; prediction-error estimates (T_p = 40 s),
    experiment E2: Y'_v = -0.01988, Y'_r - m' = -0.01507, N'_v = -0.00079,
    N'_r - m'x'_G = -0.00029, Y'_delta = 0.00147, N'_delta = -0.00069; K' = -0.41,
    T'_1 = -8.04, T'_2 = 1.04, T'_3 = 1.38, K'_v = 0.05, T'_3v = 0.23 (course-unstable).
    Mass terms from `_derive_mass_terms` (within 0.008 on K', 0.0032 on the others).

    Assumed particulars (not in the source; typical 255 000 tdw tanker): L = 320 m,
    full-load draught 19.5 m, V = 8 m/s; steering gear 35 deg, 2.3 deg/s.
    """
    return _published(
        -0.01988, -0.01507, -0.00079, -0.00029, 0.00147, -0.00069,
        masses=(0.0298380, -4.17839e-05, -1.40778e-05, 0.00171528),  # derived
        rudder=_tanker_servo(), **_SEA_SWIFT,
    )
