"""An MMG vessel from its main particulars by published empirical formulas.

Hull derivatives: Yoshimura & Masumoto (2012), *Hydrodynamic database and manoeuvring
prediction method with medium high-speed merchant ships and fishing vessels*, Proc.
MARSIM 2012 (their regression table; the linear terms are those of Kijima et al. 1990),
as compiled by Sukas, Kinaci & Bal (2019), *Theoretical background and application of
MANSIM for ship maneuvering simulations*, Ocean Eng. 192:106239, and as coded in the
Python package mmgdynamics (nikpau/mmgdynamics, `calibrate`, commit 6d38838, 2022).
Added masses: Zhou et al. (1983) regressions for m_y', J_z' and m_x' = 0.05 m', as
compiled by Sukas et al. (2019) and coded in mmgdynamics.
Propeller, rudder and their interaction: the MMG standard method of Yasukawa & Yoshimura
(2015), J. Mar. Sci. Technol. 20:37-52, with the empirical factors of Kijima, Katsuno,
Nakiri & Furukawa (1990), *On the manoeuvring performance of a ship with the parameter of
loading condition*, J. Soc. Nav. Arch. Japan 168:141-148 (as coded in mmgdynamics), and
Fujii's rudder lift gradient. Straight-run resistance: ITTC 1957 friction line with a
form factor and Denny-Mumford's wetted surface (below).

Notation: k = 2d/L (aspect ratio), C_b B/L = C_b/(L/B), m' = rho nabla/(rho L^2 d/2)
= 2 C_b B/L; derivatives non-dimensional as in `MMGVessel` (v' = v/U, r' = rL/U).
Validity: the regressions' ranges (YM 2012: merchant ships and fishing vessels, C_b
about 0.5-0.8, L/B about 4-7.5); beyond them the formulas extrapolate.
"""

import dataclasses
import math

from ..._foundation._params import param


@dataclasses.dataclass(frozen=True)
class MainParticulars:
    """A single-screw, single-rudder ship's main particulars (SI units, radians):
    what `MMGVessel.from_particulars` builds an MMG vessel from.

    `MMGVessel.from_particulars(particulars)` is the vessel; `save_vessel` writes the
    particulars as a vessel file's table [particulars], which `load_vessel` reads.
    `k_t` are the propeller's open-water coefficients, K_T = k_0 + k_1 J + k_2 J^2 (from
    the propeller's open-water test or a series chart); `speed` the approach speed U_0
    (the self-propulsion rate is solved for it, and it sets the Reynolds number of the
    resistance); `gyration_ratio` is k_zz/L; `viscosity` the water's kinematic
    viscosity (ITTC 2011 sea water at 15 deg C by default).
    """

    length: float = param(free=False, unit="m")  # L_pp
    breadth: float = param(free=False, unit="m")  # B
    draft: float = param(free=False, unit="m")  # d
    block_coefficient: float = param(free=False, lower=0.3, upper=1.0, unit="-")  # C_b
    speed: float = param(free=False, unit="m/s")  # U_0, approach speed
    propeller_diameter: float = param(free=False, unit="m")  # D_P
    rudder_area: float = param(free=False, unit="m^2")  # A_R, movable area
    rudder_span: float = param(free=False, unit="m")  # H_R
    rudder_rate: float = param(free=False, unit="rad/s")  # steering gear's rate limit
    k_t: tuple[float, float, float]  # (k_0, k_1, k_2) of K_T(J)
    x_g: float = param(0.0, free=False, unit="m")  # x_G, forward of midship
    gyration_ratio: float = param(0.25, free=False, lower=0.0, unit="-")  # k_zz / L
    rudder_max_angle: float = param(math.radians(35.0), free=False, unit="rad")  # delta_max
    rho: float = param(1025.0, free=False, unit="kg/m^3")
    viscosity: float = param(1.18831e-6, free=False, unit="m^2/s")  # nu, ITTC 7.5-02-01-03

    def volume(self) -> float:
        """Displacement volume nabla = C_b L B d [m^3]."""
        return self.block_coefficient * self.length * self.breadth * self.draft

    def coefficients(self) -> dict:
        """Every `MMGVessel` coefficient that the formulas give, non-dimensional, by field
        name (`particulars_coefficients`)."""
        return particulars_coefficients(self)


def added_masses(p: MainParticulars) -> dict:
    """m_x', m_y', J_z' (Zhou et al. 1983, via Sukas et al. 2019 and mmgdynamics)."""
    cb, l_b, d_b = p.block_coefficient, p.length / p.breadth, p.draft / p.breadth
    m = 2.0 * cb / l_b  # m' = rho nabla / (rho L^2 d / 2)
    m_y = m * (0.882 - 0.54 * cb * (1 - 1.6 * d_b) - 0.156 * (1 - 0.673 * cb) * l_b
               + 0.826 * d_b * l_b * (1 - 0.678 * d_b) - 0.638 * cb * d_b * l_b * (1 - 0.669 * d_b))
    # J_z = m (k L)^2 with k = (33 - 76.85 C_b (1 - 0.784 C_b) + 3.43 L/B (1 - 0.63 C_b))/100
    k = (33.0 - 76.85 * cb * (1 - 0.784 * cb) + 3.43 * l_b * (1 - 0.63 * cb)) / 100.0
    return {"m_x": 0.05 * m, "m_y": m_y, "j_z": m * k**2}


def hull_derivatives(p: MainParticulars, m_x: float, m_y: float) -> dict:
    """The 16 hull derivatives of Yoshimura & Masumoto (2012) (table of regressions; via
    Sukas et al. 2019 and mmgdynamics), in `MMGVessel`'s names."""
    cb, l_b = p.block_coefficient, p.length / p.breadth
    cbl = cb / l_b  # C_b B / L
    k = 2.0 * p.draft / p.length
    x_g = p.x_g / p.length
    return {
        "x_vv": 1.15 * cbl - 0.18,
        "x_vr": m_y - 1.91 * cbl + 0.08,  # X_vr' - m_y' = -1.91 C_b B/L + 0.08
        "x_rr": -0.085 * cbl + 0.008 - x_g * m_y,  # X_rr' + x_G' m_y' = -0.085 C_b B/L + 0.008
        "x_vvvv": -6.68 * cbl + 1.1,
        "y_v": -(0.5 * math.pi * k + 1.4 * cbl),  # Kijima et al. (1990), adopted by YM
        "y_r": m_x + 0.5 * cbl,  # Y_r' - m_x' = 0.5 C_b B/L
        "y_vvv": -0.185 * l_b + 0.48,
        "y_vvr": -0.75,
        "y_vrr": -(0.26 * (1 - cb) * l_b + 0.11),
        "y_rrr": -0.051,
        "n_v": -k,  # Kijima et al. (1990)
        # Kijima et al. (1990); the MANSIM compilation's -k(0.54 + k) differs in the sign
        # of k^2, mmgdynamics has Kijima's -0.54 k + k^2
        "n_r": -0.54 * k + k * k,
        "n_vvv": -(-0.69 * cb + 0.66),
        "n_vvr": 1.55 * cbl - 0.76,
        "n_vrr": -0.075 * (1 - cb) * l_b - 0.098,
        "n_rrr": 0.25 * cbl - 0.056,
    }


def resistance(p: MainParticulars) -> float:
    """R_0' = R_T / (rho L d U_0^2 / 2) at the approach speed: C_T = (1 + k) C_F, with
    ITTC 1957's C_F = 0.075/(log10 Re - 2)^2, Watanabe's form factor k = -0.095 +
    25.6 C_b/((L/B)^2 sqrt(B/d)) and Denny-Mumford's wetted surface S = 1.7 L d +
    nabla/d; wave resistance neglected (low Froude numbers)."""
    cb, length, d = p.block_coefficient, p.length, p.draft
    reynolds = p.speed * length / p.viscosity
    c_f = 0.075 / (math.log10(reynolds) - 2.0) ** 2
    form = -0.095 + 25.6 * cb / ((length / p.breadth) ** 2 * math.sqrt(p.breadth / d))
    wetted = 1.7 * length * d + p.volume() / d
    return (1.0 + form) * c_f * wetted / (length * d)


def propeller_rudder(p: MainParticulars) -> dict:
    """Propeller, rudder and interaction factors of the MMG standard method."""
    cb = p.block_coefficient
    cbl = cb * p.breadth / p.length
    w_p0 = 0.5 * cb - 0.05  # Taylor's wake fraction of single-screw ships (mmgdynamics' default)
    aspect = p.rudder_span**2 / p.rudder_area  # Lambda = H_R^2 / A_R
    gamma = 2.06 * cbl + 0.14  # gamma_R, Kijima et al. (1990) (mmgdynamics), both sides
    k_0, k_1, k_2 = p.k_t
    return {
        "w_p0": w_p0,
        # Schoenherr's t = k w with k = 0.5-0.7 for streamlined rudders (Principles of
        # Naval Architecture, 1967): the middle, k = 0.6
        "t_p": 0.6 * w_p0,
        "k_0": k_0, "k_1": k_1, "k_2": k_2,
        # x_P' ~ the propeller's position, -0.5 (Yasukawa & Yoshimura 2015, sec. 2.3);
        # C_2 = 1 (no formula for the wake's change with drift: w_P = w_P0)
        "x_p": -0.5, "c_1": 2.0, "c_2_plus": 1.0, "c_2_minus": 1.0,
        "t_r": 0.39,  # Yoshimura & Masumoto (2012)
        "a_h": 0.627 * cb - 0.153,  # Kijima et al. (1990) (mmgdynamics: via Quadvlieg 2013)
        "x_h": -(0.4 + 0.1 * cb),  # Kijima et al. (1990)
        "x_r": -0.5,  # rudder at the aft perpendicular (Yasukawa & Yoshimura 2015)
        "f_alpha": 6.13 * aspect / (aspect + 2.25),  # Fujii's formula
        "epsilon": -156.5 * cbl**2 + 41.6 * cbl - 1.76,  # Kijima et al. (1990)
        "kappa": 0.55 - 0.8 * cbl,  # Kijima et al. (1990) (mmgdynamics)
        "l_r": -0.9,  # Yoshimura & Masumoto (2012)
        "gamma_r_plus": gamma, "gamma_r_minus": gamma,
    }


def particulars_coefficients(p: MainParticulars) -> dict:
    """Every `MMGVessel` coefficient that the formulas give (non-dimensional, by field
    name): added masses, R_0', the hull derivatives and the propeller and rudder factors."""
    added = added_masses(p)
    return {**added, "r_0": resistance(p), **hull_derivatives(p, added["m_x"], added["m_y"]),
            **propeller_rudder(p)}
