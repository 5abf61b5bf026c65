"""The catalogue of candidate effects `jaxship.discover` scores: physically named
effects of `jaxship.augment`, each zero (absent) in the base model.

An entry says how to make the effect for a model (`make(model)`, None where it does
not apply: e.g. a sway force on a steering model), which of its parameters a probe
value differentiates (effects switched off below a threshold, such as a lag, have no
derivative at zero), and which experiment separates it from the effects it is often
confused with. Adding an effect to discovery is adding one entry here.
"""

import dataclasses
from collections.abc import Callable

import numpy as np

from ..._models._effects import (
    HeadingSensorBias,
    RudderDelay,
    RudderLag,
    RudderOffset,
    RudderRateLimit,
    SwayForceBias,
    YawCubicDamping,
    YawMomentBias,
    YawRateSensorBias,
)
from ..._models._hydro_effects import (
    AddedMassError,
    ApparentWind,
    CrossflowDrag,
    PropellerAsymmetry,
    PropellerRace,
    RudderStall,
    SpeedDependentDamping,
    SpeedDependentRudder,
    SurgeTurnResistance,
    UniformCurrent,
    Windage,
    YawQuadraticDamping,
)
from ..._models._steering._base import AbstractSteeringModel
from ..._models._vessel._base import AbstractVessel
from ._plausible import HARD_OVER


@dataclasses.dataclass(frozen=True)
class Candidate:
    """One catalogue entry: `id` (the effect's), `name` (what a naval architect calls
    it), `make(model, data)` the effect at zero for `model` and the training `data`
    (a `Dataset`), or None where it does not apply or the data cannot show it;
    `probes(model, data)` `{field: value}` for parameters scored by a secant to that
    value (parameters bounded at zero, or switched off below a threshold, have no
    useful derivative there); `separate`: the experiment that tells it apart from the
    effects it resembles; `rudder_range`: for effects whose parameters have family
    units (no bounds), the largest plausible rudder-equivalent angle [rad] of their
    loads (`rudder_equivalent`)."""

    id: str
    name: str
    make: Callable
    probes: Callable = lambda model, data: {}
    separate: str = ""
    rudder_range: float | None = None


def _is(model, family):
    return isinstance(model, {"vessel": AbstractVessel,
                              "steering": AbstractSteeringModel}[family])


def _measured(data, *channels) -> bool:
    return all(c in have for have in data.experiment_channels for c in channels)


def _simple(cls, *families):
    """`make` for an effect class acting on the given families of models."""
    return lambda model, data: cls() if any(_is(model, f) for f in families) else None


def _speed_dependent_rudder(model, data):
    if _is(model, "vessel"):
        return SpeedDependentRudder()
    if _measured(data, "u"):  # a steering model sees the measured u
        return SpeedDependentRudder(nominal_speed=float(np.mean(data.u[data.mask])))
    return None


def _speed_dependent_damping(model, data):
    if _is(model, "steering") and _measured(data, "u"):  # a vessel's damping scales already
        return SpeedDependentDamping(nominal_speed=float(np.mean(data.u[data.mask])))
    return None


def _propeller_asymmetry(model, data):
    return PropellerAsymmetry() if _is(model, "vessel") or _measured(data, "n") else None


def _propeller_race(model, data):
    """Steering models only (a vessel's rudder model carries the race), where n is logged."""
    return PropellerRace() if _is(model, "steering") and _measured(data, "n") else None


def _wind(model, data):
    """Windage on a vessel, the apparent wind's yaw term on a steering model (that
    needs u and v to make the apparent wind), where the wind is logged."""
    if not _measured(data, "wind_speed", "wind_dir"):
        return None
    if _is(model, "vessel"):
        return Windage()
    return ApparentWind() if _measured(data, "u", "v") else None


def _wind_probes(model, data):
    if _is(model, "vessel"):
        return {"lateral_area": 0.05 * float(model.length) ** 2,
                "frontal_area": 0.01 * float(model.length) ** 2}
    return {}


def _rate_probe(model, data):
    """A rate limit at half the fastest logged rudder rate [s/rad]."""
    rates = [np.max(np.abs(np.diff(data.delta[i, :n]) / data.dt[i]))
             for i, n in enumerate(data.lengths)]
    return {"inverse_rate": 2.0 / max(max(rates), 1e-6)}


BOTH, VESSEL, STEERING = ("vessel", "steering"), ("vessel",), ("steering",)
SPEEDS = ("runs at two speeds or rpm: a rudder offset's moment scales with the rudder "
          "inflow speed squared, a constant moment does not, a propeller moment with rpm")
STEADY_TURNS = ("steady turns over a wide range of yaw rate and rudder angle (turning "
                "circles at several angles) tell r|r| from r^3, and transients at peak "
                "rudder (stall) from those at peak yaw rate (damping)")
# a constant load needing more rudder than the rudder offset's range (5.7 deg) to hold
# a course is no hidden asymmetry; a damping, race or wind load beyond hard over would
# have left the ship unsteerable
BIAS_RANGE = 0.1
RUDDER_STEPS = ("rudder steps of different sizes and fast reversals: a lag's or delay's "
                "timing is the same for every step, a rate limit's grows with the step")

DISCOVERY_CATALOGUE = (
    Candidate("rudder_offset", "rudder zero offset (indicator error or hull asymmetry)",
              _simple(RudderOffset, *BOTH), separate=SPEEDS),
    Candidate("yaw_moment_bias", "constant yaw moment (hull or appendage asymmetry)",
              _simple(YawMomentBias, *BOTH), separate=SPEEDS, rudder_range=BIAS_RANGE),
    Candidate("propeller_asymmetry", "propeller-induced yaw moment (single screw)",
              _propeller_asymmetry, separate=SPEEDS, rudder_range=BIAS_RANGE),
    Candidate("propeller_race", "rudder in the propeller race (inflow from rpm)",
              _propeller_race,
              separate="runs at several rpm and at low or changing speed: the race's rudder "
                       "force grows with rpm squared, a rudder gain does not",
              rudder_range=HARD_OVER),
    Candidate("sway_force_bias", "constant sway force", _simple(SwayForceBias, *VESSEL),
              separate="measured sway velocity on straight legs", rudder_range=BIAS_RANGE),
    Candidate("current", "uniform current", _simple(UniformCurrent, *VESSEL),
              separate="GNSS tracks on several headings: a current drifts each the same "
                       "earth-fixed way, a compass bias sets it off to one side of the heading"),
    Candidate("wind", "wind loads (windage the model lacks)", _wind, probes=_wind_probes,
              separate="runs at several headings to the wind", rudder_range=HARD_OVER),
    Candidate("crossflow_drag", "cross-flow drag of the hull", _simple(CrossflowDrag, *VESSEL),
              probes=lambda model, data: {"coefficient": 0.02}, separate=STEADY_TURNS),
    Candidate("yaw_quadratic_damping", "quadratic yaw damping r|r|",
              _simple(YawQuadraticDamping, *BOTH), separate=STEADY_TURNS,
              rudder_range=HARD_OVER),
    Candidate("yaw_cubic_damping", "cubic yaw damping r^3 (Norrbin)",
              _simple(YawCubicDamping, *BOTH), separate=STEADY_TURNS,
              rudder_range=HARD_OVER),
    Candidate("speed_dependent_rudder", "rudder force changing with inflow speed",
              _speed_dependent_rudder,
              separate="turning circles (speed loss) or runs at several speeds"),
    Candidate("speed_dependent_damping", "yaw damping scaling with speed (Nomoto's T = T'L/U)",
              _speed_dependent_damping,
              separate="turning circles (speed loss) or runs at several speeds"),
    Candidate("rudder_stall", "rudder lift saturation (stall)", _simple(RudderStall, *BOTH),
              separate=STEADY_TURNS),
    Candidate("rudder_rate_limit", "rudder rate limit (slow steering gear)",
              _simple(RudderRateLimit, *BOTH), probes=_rate_probe, separate=RUDDER_STEPS),
    Candidate("rudder_delay", "rudder or time-stamp delay", _simple(RudderDelay, *BOTH),
              probes=lambda model, data: {"delay": 0.5}, separate=RUDDER_STEPS),
    Candidate("rudder_lag", "rudder (steering gear) lag", _simple(RudderLag, *BOTH),
              probes=lambda model, data: {"time_constant": 0.5}, separate=RUDDER_STEPS),
    Candidate("surge_turn_resistance", "added surge resistance in turns",
              _simple(SurgeTurnResistance, *VESSEL),
              separate="measured surge speed through turns"),
    Candidate("added_mass_error", "added mass (inertia) error",
              _simple(AddedMassError, *VESSEL), separate=RUDDER_STEPS),
    Candidate("yaw_rate_sensor_bias", "yaw-rate gyro bias", _simple(YawRateSensorBias, *BOTH),
              separate="the heading record: psi integrates the true r, not the reading"),
    Candidate("heading_sensor_bias", "heading (compass) bias",
              _simple(HeadingSensorBias, *BOTH),
              separate="an external heading reference (GNSS course on straight legs on "
                       "several headings: a current's drift angle changes with heading)"),
)


def applicable(model, data, catalogue=DISCOVERY_CATALOGUE, exclude=()) -> list:
    """The entries of `catalogue` that apply to `model` on `data` (a `Dataset`; not
    those in `exclude`), with their effects at zero and their probes: a list of
    `(Candidate, effect, probes)`."""
    out = []
    for entry in catalogue:
        if entry.id in exclude:
            continue
        effect = entry.make(model, data)
        if effect is not None:
            out.append((entry, effect, entry.probes(model, data)))
    return out
