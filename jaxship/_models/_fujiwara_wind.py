"""Fujiwara, Ueno & Nimura's (1998) regression of the wind loads on a ship from its
projected areas and the places of their centroids.

T. Fujiwara, M. Ueno, T. Nimura (1998), "Estimation of wind forces and moments acting
on ships", J. Soc. Naval Architects of Japan 183, pp. 77-90: with the relative wind
from the angle $\\alpha$ off the bow and $q = \\tfrac12\\rho_a U_A^2$,

- $X_A = q A_T C_X$, $C_X = X_0 + X_1\\cos\\alpha + X_3\\cos3\\alpha + X_5\\cos5\\alpha$,
- $Y_A = q A_L C_Y$, $C_Y = Y_1\\sin\\alpha + Y_3\\sin3\\alpha + Y_5\\sin5\\alpha$,
- $N_A = q A_L L_{oa} C_N$, $C_N = N_1\\sin\\alpha + N_2\\sin2\\alpha + N_3\\sin3\\alpha$
  (about midship),

each of $X_0 \\dots N_3$ a constant plus coefficients times geometric ratios
(`TERMS`; the ship has a superstructure, "ss" = 1). The angle is read as
$\\alpha = -\\gamma$, jaxship's $\\gamma$ being + from starboard, as the Esso Osaka
lab's simulator (GitHub NAOE-5thLab/mmg-1p1r-simulator: angle of attack = 2 pi minus
the clockwise apparent-wind angle) and the public `wind_EO` function
($\\alpha$ = atan2(-v_rel, u_rel)) read it: with $Y_1 > 0$ a beam wind from starboard
then pushes to port, and a head wind on a ship moving ahead holds it back
(`tests/test_wind_loads.py`).
"""

import jax.numpy as jnp
from jaxtyping import ArrayLike

from .._foundation._params import param
from ._environment import AbstractWindLoads, _apparent


# {term: (constant, ((coefficient, ratio), ...))}: Fujiwara et al. (1998), the
# regression table (as in `shared/reference/fujiwara_wind.md` and `wind_EO`; the lab's
# Python code has x_AL z_AL/A_L for Y5's last ratio, 0.004 deg/s on its free runs)
TERMS = {
    "X0": (-0.330, ((0.293, "B H_BR/A_T"), (0.0193, "x_AL/z_AL"), (0.682, "A_OD/L^2"))),
    "X1": (-1.353, ((1.700, "A_L/(L B)"), (2.870, "L z_AL/A_L"), (-0.463, "L H_BR/A_L"),
                    (-0.570, "A_OD/A_L"), (-6.640, "A_T/(L B)"), (-0.0123, "L^2/A_T"),
                    (0.0202, "L/z_AL"))),
    "X3": (0.830, ((-0.413, "A_L/(L H_BR)"), (-0.0827, "A_L/A_T"), (-0.563, "L z_AL/A_L"),
                   (0.804, "A_OD/A_L"), (-5.670, "A_OD/L^2"), (0.0401, "x_AL/z_AL"),
                   (-0.132, "x_AOD/L"))),
    "X5": (0.0372, ((-0.0075, "A_L/A_OD"), (-0.103, "x_AOD/L"), (0.0921, "A_L/(L B)"))),
    "Y1": (0.684, ((0.717, "x_AOD/L"), (-3.220, "x_AL/L"), (0.0281, "A_L/A_OD"),
                   (0.0661, "x_AL/z_AL"), (0.298, "A_T/(B H_BR)"))),
    "Y3": (-0.400, ((0.282, "A_L/(L B)"), (0.307, "L z_AL/A_L"), (0.0519, "x_AOD/L"),
                    (0.0526, "B/H_BR"), (-0.0814, "A_OD/A_L"), (0.0582, "A_T/(B H_BR)"))),
    "Y5": (0.122, ((-0.166, "A_L/(L B)"), (-0.0054, "L/H_BR"), (-0.0481, "x_AOD/L"),
                   (-0.0136, "B^2/A_T"), (0.0864, "x_AL/L"), (-0.0297, "L z_AL/A_L"))),
    "N1": (0.299, ((1.710, "x_AL/L"), (0.183, "L z_AL/A_L"), (-1.090, "A_T/A_L"),
                   (-0.0442, "x_AL/z_AL"), (-0.289, "A_L/(L B)"), (4.240, "A_T/L^2"),
                   (-0.0646, "B^2/A_T"), (0.0306, "x_AOD/L"))),
    "N2": (0.117, ((0.123, "x_AOD/L"), (-0.323, "x_AL/L"), (0.0041, "A_L/A_OD"),
                   (-0.166, "A_T/B^2"), (-0.0109, "L/H_BR"), (0.174, "A_T/(B H_BR)"),
                   (0.214, "A_L/(L B)"), (-1.060, "A_L/L^2"))),
    "N3": (0.0230, ((0.0385, "x_AOD/L"), (-0.0339, "A_T/(B H_BR)"), (0.0023, "A_L/A_T"))),
}


def _ratios(loads, A_T, A_L) -> dict:
    """The geometric ratios of `TERMS`, by name, of a `FujiwaraWindLoads` and the
    projected areas $A_T$, $A_L$."""
    L, B, A_OD = loads.length_overall, loads.breadth, loads.superstructure_area
    x_AL, z_AL = loads.area_centre_x, loads.area_centre_height
    x_AOD, H_BR = loads.superstructure_x, loads.bridge_height
    return {
        "B H_BR/A_T": B * H_BR / A_T, "x_AL/z_AL": x_AL / z_AL, "A_OD/L^2": A_OD / L**2,
        "A_L/(L B)": A_L / (L * B), "L z_AL/A_L": L * z_AL / A_L,
        "L H_BR/A_L": L * H_BR / A_L, "A_OD/A_L": A_OD / A_L, "A_T/(L B)": A_T / (L * B),
        "L^2/A_T": L**2 / A_T, "L/z_AL": L / z_AL, "A_L/(L H_BR)": A_L / (L * H_BR),
        "A_L/A_T": A_L / A_T, "x_AOD/L": x_AOD / L, "A_L/A_OD": A_L / A_OD,
        "x_AL/L": x_AL / L, "A_T/(B H_BR)": A_T / (B * H_BR), "B/H_BR": B / H_BR,
        "L/H_BR": L / H_BR, "B^2/A_T": B**2 / A_T, "A_T/A_L": A_T / A_L,
        "A_T/L^2": A_T / L**2, "A_T/B^2": A_T / B**2, "A_L/L^2": A_L / L**2,
    }


class FujiwaraWindLoads(AbstractWindLoads):
    """Fujiwara, Ueno & Nimura's (1998) wind loads (module docstring) for the ship
    of this geometry; the projected areas $A_T$, $A_L$ are the vessel's
    `frontal_wind_area` and `lateral_wind_area`. Lengths in metres, x forward of
    midship, heights above the waterline. Give it to a vessel as its `wind_model`
    (`eqx.tree_at(lambda v: v.wind_model, vessel, FujiwaraWindLoads(...))`)."""

    length_overall: ArrayLike = param(free=False, unit="m")  # L_oa
    breadth: ArrayLike = param(free=False, unit="m")  # B
    superstructure_area: ArrayLike = param(free=False, unit="m^2")  # A_OD, lateral, over deck
    area_centre_x: ArrayLike = param(free=False, unit="m")  # x_AL, centroid of A_L
    area_centre_height: ArrayLike = param(free=False, unit="m")  # z_AL, centroid of A_L
    superstructure_x: ArrayLike = param(free=False, unit="m")  # x_AOD, centroid of A_OD
    bridge_height: ArrayLike = param(free=False, unit="m")  # H_BR, top of the bridge

    def coefficients(self, frontal_area, lateral_area) -> dict:
        """$X_0, X_1, X_3, X_5, Y_1, Y_3, Y_5, N_1, N_2, N_3$ [-] by name, for the
        vessel's transverse and lateral projected areas $A_T$, $A_L$ [m^2]."""
        ratios = _ratios(self, frontal_area, lateral_area)
        return {name: constant + sum(a * ratios[ratio] for a, ratio in terms)
                for name, (constant, terms) in TERMS.items()}

    def load_coefficients(self, alpha, frontal_area, lateral_area):
        """$(C_X, C_Y, C_N)$ [-] at the paper's wind angle `alpha` [rad] ($-\\gamma$)."""
        c = self.coefficients(frontal_area, lateral_area)
        return (
            c["X0"] + c["X1"] * jnp.cos(alpha) + c["X3"] * jnp.cos(3 * alpha)
            + c["X5"] * jnp.cos(5 * alpha),
            c["Y1"] * jnp.sin(alpha) + c["Y3"] * jnp.sin(3 * alpha) + c["Y5"] * jnp.sin(5 * alpha),
            c["N1"] * jnp.sin(alpha) + c["N2"] * jnp.sin(2 * alpha) + c["N3"] * jnp.sin(3 * alpha),
        )

    def pressure_loads(self, u_rw, v_rw, wind, frontal_area, lateral_area):
        gamma, q = _apparent(u_rw, v_rw)
        return tuple(c * q for c in self.load_coefficients(-gamma, frontal_area, lateral_area))

    def reference(self, frontal_area, lateral_area, length):
        return frontal_area, lateral_area, lateral_area * self.length_overall

    @classmethod
    def esso_osaka(cls) -> "FujiwaraWindLoads":
        """The Esso Osaka 3 m model as the lab's simulator has it (GitHub
        NAOE-5thLab/mmg-1p1r-simulator, `principal_particulars_EssoOsaka3m.csv` [PP],
        copied in `shared/data/esso_osaka_frt/reference/`), with the preset's
        $A_T = 0.13544$, $A_L = 0.52038$ m^2. $x_{AOD}$ is the file's LCBR, -0.06209 m,
        which the lab's simulator reads (its regression's loads then match the lab's
        published free-run scores); the `wind_EO` function's commented set has
        -1.23339 m, the bridge's place on a VLCC's poop, and gives $C_Y$ 24 % smaller."""
        return cls(
            length_overall=3.0,  # L_oa [m]: the lab uses L_pp, [PP] lpp
            breadth=0.48925,  # B [m], [PP] SBW (= breadth)
            superstructure_area=0.1423,  # A_OD [m^2], [PP] AOD
            area_centre_x=-0.01299,  # x_AL [m], [PP] LCW
            area_centre_height=0.10359,  # z_AL [m], [PP] HC
            superstructure_x=-0.06209,  # x_AOD [m], [PP] LCBR
            bridge_height=0.294,  # H_BR [m], [PP] HBR
        )
