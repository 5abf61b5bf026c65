"""Effects of hull, rudder, propeller and environment physics (see `_effects.py` for
the seam): terms a base model may lack, each zero (absent) by default, so that
`augment(model, effect)` equals `model` bit for bit until its parameter moves.

Vessel-only effects are parametrised without the vessel's size (prime system of
SNAME 1950 with the vessel's length $L$ and water density $\\rho$, or a ratio), so
that their bounds are a plausible range for any ship; effects acting on vessels and
steering models alike have family units and no bounds (see `_effects.py`).
"""

from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import ArrayLike

from .._foundation._params import param
from ._effects import (
    AbstractLoadEffect,
    AbstractRudderEffect,
    AbstractVesselPropertyEffect,
    AbstractYawTermEffect,
)
from ._environment import Current, Environment


RHO_WATER = 1025.0  # sea water [kg/m^3], for vessels that do not state their own `rho`

# two-point Gauss-Legendre rule on [0, 1] (weights 1/2): exact for cubics
_GAUSS2 = (0.5 - 0.5 / 3**0.5, 0.5 + 0.5 / 3**0.5)


def _density(vessel) -> float:
    """The vessel's water density [kg/m^3]: its `rho`, else sea water."""
    return getattr(vessel, "rho", RHO_WATER)


def _yaw_only(u, moment):
    return jnp.stack(jnp.broadcast_arrays(0.0 * u, 0.0 * u, moment))


class YawQuadraticDamping(AbstractLoadEffect, AbstractYawTermEffect):
    """Quadratic (modulus) yaw damping, $\\beta > 0$ more damping in both families
    (Norrbin 1970, $N_{r|r|}$; Blanke 1981, the second-order modulus model):

    - vessels: $N \\mathrel{+}= -\\beta\\,r|r|$ [N m s^2/rad^2], i.e. $N_{r|r|} = -\\beta$;
      independent of speed: $\\beta = -N'_{r|r|}\\tfrac12\\rho L^5$ in the prime system
      ($r' = rL/U$), about $10^{10}$-$10^{11}$ for the Mariner ($N'_{r|r|} \\sim 10^{-3}$);
    - steering models: $-\\beta\\,r|r|$ in the yaw equation, for Nomoto 1
      $T\\dot r + r + \\beta r|r| = K\\delta$ [s/rad; 1/rad for models written as
      $\\dot r = \\dots$]; $\\beta' = \\beta U/L \\sim 0.1$-$1$, 1-50 s/rad for ships.

    Family units, hence no bounds; physically $\\beta \\ge 0$. Odd in r like
    `YawCubicDamping`: the two differ only over a wide range of yaw rates."""

    beta: ArrayLike = param(0.0, unit="N m s^2/rad^2 | s/rad | 1/rad")
    id: ClassVar[str] = "yaw_quadratic_damping"

    def loads(self, t, vessel, u, v, r, delta, n):
        return _yaw_only(u, -self.beta * r * jnp.abs(r))

    def yaw_term(self, model, x, delta, aux):
        r = model.output(x)
        return -self.beta * r * jnp.abs(r)


def _crossflow_integrals(v, r, length):
    """$(\\int |w|w\\,dx, \\int x|w|w\\,dx)$ over $x \\in [-L/2, L/2]$, $w = v + xr$:
    exact (to rounding) by two-point Gauss-Legendre on either side of the section
    where $w$ changes sign, each side a polynomial of degree 2 or 3 in x."""
    half = 0.5 * length
    crosses = (jnp.abs(r) * half > jnp.abs(v)) & (jnp.abs(r) > 1e-100)
    split = jnp.where(crosses, -v / jnp.where(crosses, r, 1.0), half)
    sway, yaw = 0.0, 0.0
    for a, b in ((-half, split), (split, half)):
        for node in _GAUSS2:
            x = a + (b - a) * node
            w = v + x * r
            f = 0.5 * (b - a) * jnp.abs(w) * w
            sway, yaw = sway + f, yaw + x * f
    return sway, yaw


class CrossflowDrag(AbstractLoadEffect):
    """Cross-flow drag of the hull in sway and yaw by strip theory (the cross-flow
    drag principle: Hoerner 1965; Faltinsen 1990; Fossen 2021, ch. 6, as in MSS
    `crossFlowDrag.m`), with a constant sectional drag coefficient $C_D$ and draught
    $T$ over the length, $x$ from the body origin ($-L/2 \\dots L/2$, midship):

    $$Y \\mathrel{+}= -\\tfrac12\\rho\\,C_DT\\int_{-L/2}^{L/2}|v + xr|(v + xr)\\,dx,\\qquad
    N \\mathrel{+}= -\\tfrac12\\rho\\,C_DT\\int_{-L/2}^{L/2}x\\,|v + xr|(v + xr)\\,dx,$$

    integrated exactly. One parameter, $c = C_DT/L$ [-]: the vessels here do not all
    state a draught, and a ratio has a range for every ship. Hoerner's 2-D $C_D$ is
    0.56-1.97 for $B/2T$ = 4 to 0.01 (0.74 for the Mariner's $B/2T = 1.4$), $T/L$
    0.02-0.08: plausible $0 \\le c \\le 0.12$ (Mariner: $c \\approx 0.04$). Pure sway:
    $Y = -\\tfrac12\\rho cL^2 v|v|$, i.e. $Y_{v|v|}$; pure yaw: $N = -\\tfrac12\\rho cL
    \\cdot L^4 r|r|/32$. Vessels only; water density from the vessel's `rho`, else
    1025 kg/m^3."""

    coefficient: ArrayLike = param(0.0, lower=0.0, upper=0.12, scale=0.03, unit="-")
    id: ClassVar[str] = "crossflow_drag"

    def loads(self, t, vessel, u, v, r, delta, n):
        length = vessel.length
        sway, yaw = _crossflow_integrals(v, r, length)
        q = 0.5 * _density(vessel) * self.coefficient * length  # rho C_D T / 2 [kg/m^2]
        return jnp.stack(jnp.broadcast_arrays(0.0 * u, -q * sway, -q * yaw))


class SpeedDependentRudder(AbstractRudderEffect, AbstractLoadEffect):
    """Rudder effectiveness that changes with the inflow speed squared, by the factor
    $1 + \\kappa(u^2/U_0^2 - 1)$ ($\\kappa$ [-]; $u$ the surge speed through the
    water, $U_0$ `nominal_speed`):

    - vessels: the rudder's share of the base loads is scaled,
      $\\tau \\mathrel{+}= \\kappa(u^2/U_0^2 - 1)[\\tau(\\delta') - \\tau(0)]$, with
      $\\delta'$ the rudder the vessel sees and $U_0$ the vessel's `nominal_speed` by
      default. A vessel's rudder loads already scale with $U^2$ (every prime-system
      model), so $\\kappa$ is the inflow's departure from the hull's speed:
      $\\kappa \\approx -1$ a rudder in the propeller race at constant rpm, whose force
      hardly drops when the ship slows in a turn (MMG rudder inflow $u_R$,
      Yasukawa & Yoshimura 2015; Molland & Turnock 2007); $\\kappa > 0$ a rudder
      losing inflow faster than the hull (wake growing with drift);
    - steering models: the rudder angle is scaled, $\\delta' = \\delta(1 + \\kappa
      (u^2/U_0^2 - 1))$ with u the measured `AuxInputs.u`; `nominal_speed` must be
      given (the speed the model's K belongs to). $\\kappa = 1$: rudder moment
      $\\propto u^2$ at fixed K, T; $\\kappa = 1/2$: $K \\propto u$ to first order,
      as Nomoto's $K = K'U/L$.

    Plausible $-1 \\le \\kappa \\le 1.5$. At $u = U_0$ it is the base model exactly, so
    it is seen only where the speed changes (turning circles, the speed loss of
    large zig-zags, runs at several speeds); without measured u a steering model
    sees $u = 0$, i.e. a rudder gain $1 - \\kappa$ (confused with K)."""

    kappa: ArrayLike = param(0.0, lower=-1.0, upper=1.5, scale=0.5, unit="-")
    nominal_speed: float | None = eqx.field(static=True, default=None)  # U_0 [m/s]
    id: ClassVar[str] = "speed_dependent_rudder"

    def _gain(self, u, nominal):
        return self.kappa * (u**2 / nominal**2 - 1.0)

    def rudder(self, delta, z, aux=None):
        if aux is None:  # a vessel: the loads scale (`loads`)
            return delta
        if self.nominal_speed is None:
            raise ValueError("SpeedDependentRudder on a steering model needs "
                             "`nominal_speed` [m/s], the speed its K belongs to (e.g. the "
                             "mean measured u).")
        return delta * (1.0 + self._gain(aux.u, self.nominal_speed))

    def loads(self, t, vessel, u, v, r, delta, n):
        nominal = vessel.nominal_speed if self.nominal_speed is None else self.nominal_speed
        share = (vessel.forces(u, v, r, delta, n)
                 - vessel.forces(u, v, r, jnp.zeros_like(delta), n))
        return self._gain(u, nominal) * share


class SpeedDependentDamping(AbstractYawTermEffect):
    """Yaw damping that scales with the surge speed (steering models): $-\\kappa(u/U_0 -
    1)\\,r$ in the yaw equation, with u the measured `AuxInputs.u` and $U_0$
    `nominal_speed` (the speed the model's time constants belong to). Nomoto's
    dimensionless model, $K = K'U/L$ and $T = T'L/U$ (Nomoto 1957; Fossen 2021, sec.
    7.1), gives $T\\dot r + s r = K s^2 \\delta$ with $s = u/U_0$, that is $T\\dot r + r =
    K s^2\\delta - (s - 1) r$: this effect with $\\kappa = 1$ and `SpeedDependentRudder`
    with $\\kappa = 1$ together make a Nomoto model speed-scaled. $\\kappa$ [-] for Nomoto
    models ([1/s] for models written as $\\dot r = \\dots$); plausible $-1 \\le \\kappa
    \\le 2$. Seen only where the speed changes."""

    kappa: ArrayLike = param(0.0, lower=-1.0, upper=2.0, scale=0.5, unit="-")
    nominal_speed: float | None = eqx.field(static=True, default=None)  # U_0 [m/s]
    id: ClassVar[str] = "speed_dependent_damping"

    def yaw_term(self, model, x, delta, aux):
        if self.nominal_speed is None:
            raise ValueError("SpeedDependentDamping needs `nominal_speed` [m/s], the speed "
                             "the model's time constants belong to (e.g. the mean measured u).")
        return -self.kappa * (aux.u / self.nominal_speed - 1.0) * model.output(x)


class RudderStall(AbstractRudderEffect):
    """Lift saturation of the rudder as a third-order term linear in its parameter:
    the hydrodynamics see $\\delta' = \\delta - c\\,\\delta^3$ [c in 1/rad^2] (the
    Abkowitz $N_{\\delta\\delta\\delta}/N_\\delta$ form; Molland & Turnock 2007 for lift
    curves). $c > 0$: lift slope falling towards stall (free-stream stall at 30-40
    deg for aspect ratios 1-2); $c < 0$: the rising slope of low-aspect-ratio rudders
    (cross-flow lift, Whicker & Fehlner 1958). $\\delta'$ is monotonic while
    $3c\\delta^2 < 1$: $c \\le 0.5$ keeps it so up to 46.8 deg; plausible
    $-0.3 \\le c \\le 0.5$. Below 10 deg it changes the rudder by under 1.5 %: seen
    only in large rudder angles (20/20 zig-zags, 35 deg turns). Both families."""

    c: ArrayLike = param(0.0, lower=-0.3, upper=0.5, scale=0.1, unit="1/rad^2")
    id: ClassVar[str] = "rudder_stall"

    def rudder(self, delta, z, aux=None):
        return delta - self.c * delta**3


class PropellerAsymmetry(AbstractLoadEffect, AbstractYawTermEffect):
    """The yaw moment of a single screw (propeller walk: the asymmetric wake and the
    transverse force of the blades), proportional to the thrust, $\\propto n|n|$, with
    $n$ the propeller rate [rev/s] (Bech 1968: the offset of the reverse-spiral
    $r$-$\\delta$ curve; Norrbin's $n_0$):

    - vessels: $N \\mathrel{+}= N_p\\,n|n|$ [N m s^2] (n the shaft state);
    - steering models: $a_p\\,n|n|$ in the yaw equation, n the measured
      `AuxInputs.n` [rad s for Nomoto models: $T\\dot r + r = K\\delta + a_pn|n|$;
      rad for models written as $\\dot r = \\dots$].

    Positive: to starboard. Family units, hence no bounds; a walk worth a rudder
    offset $\\delta_e$ of 0.5-2 deg at the service rate $n_0$ is
    $N_p = N_\\delta\\delta_e/n_0^2$ ($\\sim 10^6$ N m s^2 for the Mariner at 1.5 rev/s)
    or $a_p = K\\delta_e/n_0^2$. At one rpm it is a constant moment: it is told from
    `RudderOffset` and `YawMomentBias` only by runs at several rpm (or reversing)."""

    moment: ArrayLike = param(0.0, unit="N m s^2 | rad s | rad")
    id: ClassVar[str] = "propeller_asymmetry"

    def loads(self, t, vessel, u, v, r, delta, n):
        return _yaw_only(u, self.moment * n * jnp.abs(n))

    def yaw_term(self, model, x, delta, aux):
        return self.moment * aux.n * jnp.abs(aux.n)


class PropellerRace(AbstractYawTermEffect):
    """The rudder's share of the propeller race, for steering models at low speed:
    the rudder inflow is $u_R^2 \\approx u^2 + c\\,(nD)^2$ (the MMG rudder inflow of
    Yasukawa & Yoshimura 2015, eq. 23, for a heavily loaded propeller, $u_P \\ll nD$;
    Molland & Turnock 2007), so a rudder behind a turning propeller keeps a force
    when the hull's speed does not give it one. A steering model whose rudder moment
    scales with $u$ (or not at all) lacks the $n^2$ part: this effect adds
    $b\\,n_+^2\\,\\delta$ to the yaw equation, with $n_+ = \\max(n, 0)$ the measured
    `AuxInputs.n` [rev/s] (an astern propeller throws its race forward, off the
    rudder) and $\\delta$ the logged rudder [for Nomoto models
    $T\\dot r + r = K\\delta + b n_+^2\\delta$, $b$ in s; for models written as
    $\\dot r = \\dots$, $b$ in -].

    Family units, hence no bounds; physically $b > 0$. At one rpm it is a rudder gain
    (confused with K): seen in runs at several rpm and at low or changing speed
    (accelerations from rest, speed loss in turns, manoeuvres in a harbour).
    Steering models only: vessels' rudder models carry the race already (MMG)."""

    gain: ArrayLike = param(0.0, unit="s | -")
    id: ClassVar[str] = "propeller_race"

    def yaw_term(self, model, x, delta, aux):
        n = jnp.maximum(jnp.asarray(aux.n, float), 0.0)
        return self.gain * n**2 * delta


class SurgeTurnResistance(AbstractLoadEffect):
    """Added surge resistance in turns (Norrbin 1970; Ross 2008; MMG $X'_{vr}$ of
    Yasukawa & Yoshimura 2015): $X \\mathrel{+}= X_{vr}\\,vr$ with
    $X_{vr} = X'_{vr}\\tfrac12\\rho L^3$ (prime system, speed-free), $X'_{vr}$ [-] the
    parameter. In a turn $vr < 0$ at midship (the hull drifts outward), so
    $X'_{vr} > 0$ slows the ship more. One term, not also $X_{rr}r^2$: in steady
    turns $v \\approx -c\\,rL$, so $vr$ and $r^2$ are nearly collinear and would be an
    unidentifiable pair; $vr$ carries the larger share (the added-mass coupling
    $(m + m_y)vr$ and the induced drag of the drifting hull). Plausible
    $|X'_{vr}| \\le 0.02$ (the Mariner's $m' + m'_y = 0.0155$). Vessels only; shows
    in u, and in r through the speed loss."""

    x_vr: ArrayLike = param(0.0, lower=-0.02, upper=0.02, scale=0.005, unit="-")
    id: ClassVar[str] = "surge_turn_resistance"

    def loads(self, t, vessel, u, v, r, delta, n):
        x = self.x_vr * 0.5 * _density(vessel) * vessel.length**3 * v * r
        return jnp.stack(jnp.broadcast_arrays(x, 0.0 * u, 0.0 * u))


class AddedMassError(AbstractVesselPropertyEffect):
    """An error in the sway and yaw entries of the mass matrix $M = M_{RB} + M_A$
    (Fossen 2021, eq. 6.1): $M_{22} \\to M_{22}(1 + s_v)$, $M_{33} \\to M_{33}(1 + s_r)$
    [-], the couplings $M_{23}, M_{32}$ unchanged. Added mass from slender-body or
    empirical formulas (e.g. Clarke et al. 1983) is uncertain by some 20-50 %, and
    $M_A$ is about half of $M_{22}$ and $M_{33}$: plausible $|s| \\le 0.3$. Acts on
    accelerations only, so it is seen in transients (zig-zags, rudder steps), not
    in steady turns. Vessels only."""

    s_v: ArrayLike = param(0.0, lower=-0.3, upper=0.3, scale=0.1, unit="-")
    s_r: ArrayLike = param(0.0, lower=-0.3, upper=0.3, scale=0.1, unit="-")
    id: ClassVar[str] = "added_mass_error"

    def mass(self, matrix):
        return matrix.at[1, 1].multiply(1.0 + self.s_v).at[2, 2].multiply(1.0 + self.s_r)


class _AddedCurrent(eqx.Module):
    """A `Current` with a north and east component [m/s] added to its velocity."""

    base: Current
    north: ArrayLike
    east: ArrayLike

    def velocity(self):
        north, east = self.base.velocity()
        return north + self.north, east + self.east


class UniformCurrent(AbstractVesselPropertyEffect):
    """A uniform, constant earth-fixed current $V_c = (V_N, V_E)$ [m/s] added to the
    environment's. jaxship's hydrodynamics use velocities through the water, so it
    leaves u, v, r and psi unchanged and drifts the track,
    $\\dot x = R(\\psi)\\nu + V_c$ (Fossen 2021, Property 10.1), and it changes the
    relative wind (where wind acts on wind areas).

    A record's u, v are through the water (a log, or the simulation's), where a
    current does not show, or over ground (`Experiment.over_ground`: GNSS, a basin's
    carriage; every measured data set), where `fit` predicts
    $u_g = u + V_N\\cos\\psi + V_E\\sin\\psi$,
    $v_g = v - V_N\\sin\\psi + V_E\\cos\\psi$ and starts each window through the
    water (`AbstractVessel.with_current`). It is also seen in the positions
    (`PredictionError(channels=(..., "x", "y"))`, which `discover` fits where every
    record logs them) and through wind on wind areas. Plausible $|V| \\le 3$ m/s per
    component (tidal streams). Vessels only."""

    north: ArrayLike = param(0.0, lower=-3.0, upper=3.0, scale=0.5, unit="m/s")
    east: ArrayLike = param(0.0, lower=-3.0, upper=3.0, scale=0.5, unit="m/s")
    id: ClassVar[str] = "current"

    def environment(self, environment):
        return Environment(current=_AddedCurrent(environment.current, self.north, self.east),
                           wind=environment.wind)


class Windage(AbstractVesselPropertyEffect):
    """Projected wind areas the base vessel lacks, frontal $A_F$ and lateral $A_L$
    [m^2], added to its `frontal_wind_area` and `lateral_wind_area`, so that the
    vessel's wind model (`jaxship.Wind`: Fossen 2021, eqs. 10.7-10.10, coefficients
    after Isherwood 1972) acts with them: $X_w = -c_x\\cos\\gamma\\,qA_F$,
    $Y_w = -c_y\\sin\\gamma\\,qA_L$, $N_w = -c_n\\sin2\\gamma\\,qA_LL$.

    It shows only where there is wind: in `simulate` with an `Environment` whose
    wind speed is not a static zero, and in `fit`/`predict` only with
    `PredictionError(wind=True)` on records with `wind_speed` and `wind_dir` (the
    default `wind=False` replays calm water, where the effect is exactly absent).
    Every vessel has `wind_loads` (zero areas give zero loads), so the base vessel
    with this effect equals the vessel with these areas. Areas scale with the ship
    (Mariner about 350 and 2000 m^2; $A_L/L^2$ 0.03-0.2 for merchant ships): bounded
    below by zero only. Vessels only."""

    frontal_area: ArrayLike = param(0.0, lower=0.0, unit="m^2")
    lateral_area: ArrayLike = param(0.0, lower=0.0, unit="m^2")
    id: ClassVar[str] = "wind"

    def wind_areas(self, frontal, lateral):
        return frontal + self.frontal_area, lateral + self.lateral_area


class ApparentWind(AbstractYawTermEffect):
    """Wind on a steering model, from the logged wind: the yaw term
    $f_w = V_{rw}^2(c_2\\sin 2\\gamma + c_1\\sin\\gamma)
    = 2c_2u_{rw}v_{rw} + c_1V_{rw}v_{rw}$ with $(u_{rw}, v_{rw})$ the apparent wind of
    `AuxInputs` (the ship's velocity through the air), $V_{rw}$ its speed and
    $\\gamma$ the angle it comes from off the bow. The $\\sin 2\\gamma$ shape is
    Fossen's (2021, eq. 10.10) yaw coefficient; $\\sin\\gamma$ is the lateral force
    (eq. 10.9) acting off midship (wind area ahead or aft of it), the first terms of
    Isherwood's (1972) series. $c_1, c_2$ [rad s/m^2 for Nomoto models, whose yaw
    term is a yaw rate; rad/m^2 for $\\dot r = \\dots$ models] scale with the
    windage over the rudder's moment: no ship-independent range. It shows only with
    `PredictionError(wind=True)` on records with `wind_speed` and `wind_dir`
    (`jaxship.discover` replays them where logged); vessels have `Windage`.
    Steering models only."""

    c2: ArrayLike = param(0.0, scale=1e-3, unit="rad s/m^2 | rad/m^2")
    c1: ArrayLike = param(0.0, scale=1e-3, unit="rad s/m^2 | rad/m^2")
    id: ClassVar[str] = "wind"
    uses_wind: ClassVar[bool] = True

    def yaw_term(self, model, x, delta, aux):
        if aux is None or aux.wind_u is None:  # no wind logged: calm
            return 0.0 * self.c2
        u, v = jnp.asarray(aux.wind_u, float), jnp.asarray(aux.wind_v, float)
        return (2.0 * self.c2 * u + self.c1 * jnp.sqrt(u**2 + v**2)) * v

