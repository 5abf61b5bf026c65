"""The catalogue of candidate effects `jaxship.discover` scores: physically named
effects of `jaxship.augment`, each zero (absent) in the base model.

An entry names the effect class (its id names the candidate) and says how to make it
for a model (the kinds of model it acts on, or `make(model, data)`; None where it does not
apply: e.g. a sway force on a steering model), which of its parameters a probe
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
    """One catalogue entry: the `effect` class (or classes with one id: the wind on a
    vessel and on a steering model), whose `id` names the candidate; `name` (what a
    naval architect calls it); `acts_on` the model classes it acts on (vessels and
    steering models by default); `make(model, data)` the effect at zero for `model` and
    the training `data` (a `Dataset`), or None where it does not apply or the data cannot
    show it (default: `effect()` on the models of `acts_on`); `probes(model, data)`
    `{field: value}` for parameters scored by a secant to that value (parameters bounded
    at zero, or switched off below a threshold, have no useful derivative there);
    `separate`: the experiment that tells it apart from the effects it resembles;
    `rudder_range`: for effects whose parameters have family units (no bounds), the
    largest plausible rudder-equivalent angle [rad] of their loads
    (`rudder_equivalent`)."""

    effect: type | tuple[type, ...]
    name: str
    acts_on: tuple[type, ...] = (AbstractVessel, AbstractSteeringModel)
    make: Callable | None = None
    probes: Callable = lambda model, data: {}
    separate: str = ""
    rudder_range: float | None = None

    def __post_init__(self):
        classes = self.effect if isinstance(self.effect, tuple) else (self.effect,)
        if len({c.id for c in classes}) != 1:
            raise ValueError(f"a candidate's effect classes must share one id, got "
                             f"{', '.join(c.id for c in classes)}.")

    @property
    def id(self) -> str:
        return (self.effect if isinstance(self.effect, type) else self.effect[0]).id

    def build(self, model, data):
        """The effect at zero for `model` on `data`, or None (see `make`)."""
        if self.make is not None:
            effect = self.make(model, data)
        else:
            effect = self.effect() if isinstance(model, self.acts_on) else None
        if effect is not None and not isinstance(effect, self.effect):
            raise TypeError(f"candidate {self.id!r} made a {type(effect).__name__}.")
        return effect


def _measured(data, *channels) -> bool:
    return all(c in have for have in data.experiment_channels for c in channels)


def _speed_dependent_rudder(model, data):
    if isinstance(model, AbstractVessel):
        return SpeedDependentRudder()
    if _measured(data, "u"):  # a steering model sees the measured u
        return SpeedDependentRudder(nominal_speed=float(np.mean(data.u[data.mask])))
    return None


def _speed_dependent_damping(model, data):
    # a vessel's damping scales with speed already
    if isinstance(model, AbstractSteeringModel) and _measured(data, "u"):
        return SpeedDependentDamping(nominal_speed=float(np.mean(data.u[data.mask])))
    return None


def _propeller_asymmetry(model, data):
    applies = isinstance(model, AbstractVessel) or _measured(data, "n")
    return PropellerAsymmetry() if applies else None


def _propeller_race(model, data):
    """Steering models only (a vessel's rudder model carries the race), where n is logged."""
    applies = isinstance(model, AbstractSteeringModel) and _measured(data, "n")
    return PropellerRace() if applies else None


def _wind(model, data):
    """Windage on a vessel, the apparent wind's yaw term on a steering model (that
    needs u and v to make the apparent wind), where the wind is logged."""
    if not _measured(data, "wind_speed", "wind_dir"):
        return None
    if isinstance(model, AbstractVessel):
        return Windage()
    return ApparentWind() if _measured(data, "u", "v") else None


def _wind_probes(model, data):
    if isinstance(model, AbstractVessel):
        return {"lateral_area": 0.05 * float(model.length) ** 2,
                "frontal_area": 0.01 * float(model.length) ** 2}
    return {}


def _rate_probe(model, data):
    """A rate limit at half the fastest logged rudder rate [s/rad]."""
    rates = [np.max(np.abs(np.diff(data.delta[i, :n]) / data.dt[i]))
             for i, n in enumerate(data.lengths)]
    return {"inverse_rate": 2.0 / max(max(rates), 1e-6)}


VESSEL = (AbstractVessel,)  # `acts_on` of the entries that act on vessels only
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
    Candidate(RudderOffset, "rudder zero offset (indicator error or hull asymmetry)",
              separate=SPEEDS),
    Candidate(YawMomentBias, "constant yaw moment (hull or appendage asymmetry)",
              separate=SPEEDS, rudder_range=BIAS_RANGE),
    Candidate(PropellerAsymmetry, "propeller-induced yaw moment (single screw)",
              make=_propeller_asymmetry, separate=SPEEDS, rudder_range=BIAS_RANGE),
    Candidate(PropellerRace, "rudder in the propeller race (inflow from rpm)",
              make=_propeller_race,
              separate="runs at several rpm and at low or changing speed: the race's rudder "
                       "force grows with rpm squared, a rudder gain does not",
              rudder_range=HARD_OVER),
    Candidate(SwayForceBias, "constant sway force", VESSEL,
              separate="measured sway velocity on straight legs", rudder_range=BIAS_RANGE),
    Candidate(UniformCurrent, "uniform current", VESSEL,
              separate="GNSS tracks on several headings: a current drifts each the same "
                       "earth-fixed way, a compass bias sets it off to one side of the heading"),
    Candidate((Windage, ApparentWind), "wind loads (windage the model lacks)", make=_wind,
              probes=_wind_probes, separate="runs at several headings to the wind",
              rudder_range=HARD_OVER),
    Candidate(CrossflowDrag, "cross-flow drag of the hull", VESSEL,
              probes=lambda model, data: {"coefficient": 0.02}, separate=STEADY_TURNS),
    Candidate(YawQuadraticDamping, "quadratic yaw damping r|r|", separate=STEADY_TURNS,
              rudder_range=HARD_OVER),
    Candidate(YawCubicDamping, "cubic yaw damping r^3 (Norrbin)", separate=STEADY_TURNS,
              rudder_range=HARD_OVER),
    Candidate(SpeedDependentRudder, "rudder force changing with inflow speed",
              make=_speed_dependent_rudder,
              separate="turning circles (speed loss) or runs at several speeds"),
    Candidate(SpeedDependentDamping, "yaw damping scaling with speed (Nomoto's T = T'L/U)",
              make=_speed_dependent_damping,
              separate="turning circles (speed loss) or runs at several speeds"),
    Candidate(RudderStall, "rudder lift saturation (stall)", separate=STEADY_TURNS),
    Candidate(RudderRateLimit, "rudder rate limit (slow steering gear)", probes=_rate_probe,
              separate=RUDDER_STEPS),
    Candidate(RudderDelay, "rudder or time-stamp delay",
              probes=lambda model, data: {"delay": 0.5}, separate=RUDDER_STEPS),
    Candidate(RudderLag, "rudder (steering gear) lag",
              probes=lambda model, data: {"time_constant": 0.5}, separate=RUDDER_STEPS),
    Candidate(SurgeTurnResistance, "added surge resistance in turns", VESSEL,
              separate="measured surge speed through turns"),
    Candidate(AddedMassError, "added mass (inertia) error", VESSEL, separate=RUDDER_STEPS),
    Candidate(YawRateSensorBias, "yaw-rate gyro bias",
              separate="the heading record: psi integrates the true r, not the reading"),
    Candidate(HeadingSensorBias, "heading (compass) bias",
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
        effect = entry.build(model, data)
        if effect is not None:
            out.append((entry, effect, entry.probes(model, data)))
    return out
