"""The autopilot model of Ross (thesis eq. 3.6-3.7) restricted to yaw, driven by the
measured surge and sway velocities, with a linear least-squares start.

Source: Odegard (2009), *Identification of Manoeuvring Characteristics* (seed 000),
sec. 3.2.2, eq. 3.6-3.7, after Ross (2008), *Nonlinear Manoeuvering Models for Ships:
a Lagrangian Approach* (NTNU), whose lift and cross-flow damping terms are those of
the thesis' damping matrix (eq. 2.20). Without roll ($p = 0$) eq. 3.6 reads

$$(I_z - N_{\\dot r})\\dot r = N_{uv}uv + N_{uuv}u^2v + N_{vvv}v^3 + N_{rrv}r^2v
+ N_{|v|v}|v|v + N_{|r|v}|r|v + N_{ur}ur + N_{uur}u^2r + N_{rrr}r^3 + N_{vvr}v^2r
+ N_{|v|r}|v|r + N_{|r|r}|r|r + N_R(u, n, \\delta), \\qquad \\dot\\psi = r,$$

where the Munk moment $(X_{\\dot u} - Y_{\\dot v})uv$ and the added-mass term
$\\tfrac12(N_{\\dot v} + Y_{\\dot r})ur$ of eq. 3.6 have the regressors $uv$ and $ur$
and are merged into $N_{uv}$ and $N_{ur}$ (they cannot be told apart from the lift
terms), and $N_R$ is the rudder moment, the right-hand side "N" of eq. 3.6.
"""

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ..._foundation._params import param
from ._base import AbstractSteeringModel, AuxInputs, WindowStart


# (field, regressor description) of the hull terms, in field order; the exponents
# (u, v, r) give the conversion to Ross's dimensional coefficients (`dimensional`)
HULL_TERMS = (
    ("n_uv", (1, 1, 0)),
    ("n_uuv", (2, 1, 0)),
    ("n_vvv", (0, 3, 0)),
    ("n_rrv", (0, 1, 2)),
    ("n_absv_v", (0, 2, 0)),
    ("n_absr_v", (0, 1, 1)),
    ("n_ur", (1, 0, 1)),
    ("n_uur", (2, 0, 1)),
    ("n_rrr", (0, 0, 3)),
    ("n_vvr", (0, 2, 1)),
    ("n_absv_r", (0, 1, 1)),
    ("n_absr_r", (0, 0, 2)),
)
RUDDER_TERMS = ("n_delta", "n_delta_nn", "n_delta3", "n_delta3_nn")
# the parameters of the speed-dependent rudder variant: `fit(model, data, free=SPEED_RUDDER)`
ROSS_FREE = tuple(name for name, _ in HULL_TERMS) + ("n_delta",)
SPEED_RUDDER = ROSS_FREE + ("n_delta_nn", "n_delta3", "n_delta3_nn")


class RossAutopilot(AbstractSteeringModel):
    """Ross' autopilot model (thesis eq. 3.6-3.7, Ross 2008) without roll: a
    nonlinear, time-varying first-order yaw model driven by the rudder and the
    measured surge `u`, sway `v` and propeller rate `n` (`AuxInputs` of each sample).

    **Scaled form.** The equation is homogeneous in $(I_z - N_{\\dot r})$ and the $N$
    coefficients, so only their ratios are identifiable; they are estimated as
    non-dimensional coefficients $a$ of the primed variables
    $u' = u/U_0$, $v' = v/U_0$, $r' = rL/U_0$, $n' = n/n_0$ with the reference
    length `length` $L$, speed `speed` $U_0$ and propeller rate `rate` $n_0$
    (frozen constants, not estimated):

    $$\\dot r = \\frac{U_0^2}{L^2}\\Big[a_{uv}u'v' + a_{uuv}u'^2v' + a_{vvv}v'^3
    + a_{rrv}r'^2v' + a_{|v|v}|v'|v' + a_{|r|v}|r'|v' + a_{ur}u'r' + a_{uur}u'^2r'
    + a_{rrr}r'^3 + a_{vvr}v'^2r' + a_{|v|r}|v'|r' + a_{|r|r}|r'|r'
    + (a_{\\delta}u'^2 + a_{\\delta nn}n'^2)\\delta
    + (a_{\\delta^3}u'^2 + a_{\\delta^3 nn}n'^2)\\delta^3\\Big].$$

    This is eq. 3.6 exactly (the map is one to one), with every coefficient of order
    one for a ship near its reference speed, which is what makes the least-squares
    start and the Levenberg-Marquardt steps well conditioned.
    Ross' dimensional ratio of a hull term with regressor $u^iv^jr^k$ is
    $N/(I_z - N_{\\dot r}) = a\\,U_0^{2-i-j-k}L^{k-2}$ (`dimensional`).

    **Rudder moment** $N_R$ (the right-hand side of eq. 3.6). Ross' model: a lift
    moment linear in the rudder angle and in the square of the speed,
    $N_\\delta u^2\\delta$ (`n_delta`; free by default with the 12 hull terms,
    `ROSS_FREE`). The *speed-dependent rudder effectiveness* variant
    (`SPEED_RUDDER`: free also `n_delta_nn`, `n_delta3`, `n_delta3_nn`) lets the
    rudder inflow depend on the propeller race, $u_R^2 \\approx c_1u^2 + c_2n^2$ (the
    momentum-theory race of a rudder behind a propeller, $u_R^2 = u_a^2 +
    8T/(\\pi\\rho D^2)$ with thrust $T \\propto n^2$; MMG, Yasukawa & Yoshimura 2015,
    eq. 38), and the lift saturate at large angles (the odd cubic $\\delta^3$ of an
    expansion of $C_N(\\delta)$, e.g. Fossen 2021, sec. 6.7 on stall). The extra terms
    are frozen at 0 by default, so the default model is Ross' own.

    All terms are linear in the parameters: `LinearStart` gives start
    values by linear least squares. The model is port/starboard symmetric (every
    term is odd in $(v, r, \\delta)$).
    """

    length: float = 1.0  # L [m], reference length (e.g. L_pp), not estimated
    speed: float = 1.0  # U_0 [m/s], reference speed, not estimated
    rate: float = 1.0  # n_0 [rev/s], reference propeller rate, not estimated
    # hull terms of eq. 3.6 (Ross 2008 lift and cross-flow damping), scaled as above
    n_uv: float = param(0.0, unit="-")  # a_uv [-]: N^L_uv u v (+ Munk (X_udot - Y_vdot) u v)
    n_uuv: float = param(0.0, unit="-")  # a_uuv [-]: N^L_uuv u^2 v
    n_vvv: float = param(0.0, unit="-")  # a_vvv [-]: N^L_vvv v^3
    n_rrv: float = param(0.0, unit="-")  # a_rrv [-]: N^L_rrv r^2 v
    n_absv_v: float = param(0.0, unit="-")  # a_|v|v [-]: N_|v|v |v| v (cross-flow)
    n_absr_v: float = param(0.0, unit="-")  # a_|r|v [-]: N_|r|v |r| v (cross-flow)
    n_ur: float = param(0.0, unit="-")  # a_ur [-]: N^L_ur u r (+ (N_vdot + Y_rdot) u r / 2)
    n_uur: float = param(0.0, unit="-")  # a_uur [-]: N^L_uur u^2 r
    n_rrr: float = param(0.0, unit="-")  # a_rrr [-]: N^L_rrr r^3
    n_vvr: float = param(0.0, unit="-")  # a_vvr [-]: N^L_vvr v^2 r
    n_absv_r: float = param(0.0, unit="-")  # a_|v|r [-]: N_|v|r |v| r (cross-flow)
    n_absr_r: float = param(0.0, unit="-")  # a_|r|r [-]: N_|r|r |r| r (cross-flow)
    # rudder moment N (right-hand side of eq. 3.6)
    n_delta: float = param(0.0, unit="1/rad")  # a_delta [1/rad]: N_delta u^2 delta (Ross)
    n_delta_nn: float = param(0.0, free=False, unit="1/rad")  # a_delta,nn: n^2 delta (race)
    n_delta3: float = param(0.0, free=False, unit="1/rad^3")  # a_delta3: u^2 delta^3 (stall)
    n_delta3_nn: float = param(0.0, free=False, unit="1/rad^3")  # a_delta3,nn: n^2 delta^3

    state_names = ("r",)

    def __check_init__(self):
        for name in ("length", "speed", "rate"):
            value = getattr(self, name)
            if isinstance(value, (int, float)) and not value > 0:
                raise ValueError(f"RossAutopilot.{name} (a reference scale) must be positive, "
                                 f"got {value}.")

    def regressors(self, r: ArrayLike, delta: ArrayLike, aux: AuxInputs) -> Array:
        """The regressors of the bracket of the scaled equation, in the order of
        `HULL_TERMS` + `RUDDER_TERMS`, stacked on the last axis: $\\dot r =
        (U_0/L)^2\\,\\phi\\cdot a$."""
        u = jnp.asarray(aux.u) / self.speed
        v = jnp.asarray(aux.v) / self.speed
        rp = jnp.asarray(r) * self.length / self.speed
        n2 = (jnp.asarray(aux.n) / self.rate) ** 2
        u2 = u * u
        d = jnp.asarray(delta)
        av, ar = jnp.abs(v), jnp.abs(rp)
        terms = [
            u * v, u2 * v, v**3, rp**2 * v, av * v, ar * v,  # eq. 3.6, v terms
            u * rp, u2 * rp, rp**3, v**2 * rp, av * rp, ar * rp,  # eq. 3.6, r terms
            u2 * d, n2 * d, u2 * d**3, n2 * d**3,  # rudder moment N_R
        ]
        return jnp.stack(jnp.broadcast_arrays(*terms), axis=-1)

    def coefficients(self) -> Array:
        """The scaled coefficients $a$ in the order of `regressors`."""
        return jnp.stack([jnp.asarray(getattr(self, n), dtype=float)
                          for n in (*(h for h, _ in HULL_TERMS), *RUDDER_TERMS)])

    def yaw_acceleration(self, r: ArrayLike, delta: ArrayLike, aux: AuxInputs) -> Array:
        """$\\dot r$ [rad/s^2] of eq. 3.6."""
        return (self.speed / self.length) ** 2 * (
            self.regressors(r, delta, aux) @ self.coefficients())

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        return jnp.reshape(self.yaw_acceleration(state[0], delta, aux), (1,))

    def output(self, state: Array) -> Array:
        return state[0]

    def initial_state(self, r: ArrayLike) -> Array:
        return jnp.reshape(jnp.asarray(r, dtype=float), (1,))

    def window_state(self, start: WindowStart) -> Array:
        return self.initial_state(start.r)

    def dimensional(self) -> dict[str, float]:
        """Ross' hull coefficients divided by the yaw inertia, $N/(I_z - N_{\\dot r})$,
        in SI units (e.g. `n_uv` [1/m^2], `n_ur` [1/m], `n_absr_r` [-]), and the
        rudder terms per unit inertia: `n_delta` [1/m^2] of $u^2\\delta$, `n_delta_nn`
        [-] of $n^2\\delta$ (n in rev/s), and the same for the $\\delta^3$ terms."""
        L, U, n0 = float(self.length), float(self.speed), float(self.rate)
        out = {}
        for name, (i, j, k) in HULL_TERMS:
            out[name] = float(getattr(self, name)) * U ** (2 - i - j - k) * L ** (k - 2)
        out["n_delta"] = float(self.n_delta) / L**2
        out["n_delta_nn"] = float(self.n_delta_nn) * (U / (L * n0)) ** 2
        out["n_delta3"] = float(self.n_delta3) / L**2
        out["n_delta3_nn"] = float(self.n_delta3_nn) * (U / (L * n0)) ** 2
        return out


def reference_scales(vessel) -> dict:
    """Reference scales `dict(length=, speed=, rate=)` of a vessel: $L_{pp}$, the
    nominal speed and the nominal propeller rate."""
    return dict(length=float(vessel.length), speed=float(vessel.nominal_speed),
                rate=float(vessel.nominal_n))


__all__ = ["RossAutopilot", "ROSS_FREE", "SPEED_RUDDER",
           "HULL_TERMS", "RUDDER_TERMS", "reference_scales"]
