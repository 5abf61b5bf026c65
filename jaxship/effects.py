"""The effects of the effect seam (docs/architecture.md): `jaxship.augment(model,
*effects)` adds them to any vessel or steering model, and an effect is exactly the base
model when its parameters are zero. A new effect derives from the small abstract class
of each place it acts on (`AbstractRudderEffect`, `AbstractLoadEffect`,
`AbstractYawTermEffect`, `AbstractVesselPropertyEffect`, `AbstractSensorEffect`).

    import jaxship as js
    model = js.augment(js.Nomoto1(K=0.06, T=25.0), js.effects.RudderOffset(delta0=0.01))

`DISCOVERY_CATALOGUE` is the catalogue of effects `jaxship.discover` tries, each a
`Candidate` (an effect with its family, bounds and what tells it apart); a catalogue of
one's own is a tuple of them.
"""

from ._analysis._discover._catalogue import (
    DISCOVERY_CATALOGUE as DISCOVERY_CATALOGUE,
    Candidate as Candidate,
)
from ._models._effects import (
    AbstractEffect as AbstractEffect,
    AbstractLoadEffect as AbstractLoadEffect,
    AbstractRudderEffect as AbstractRudderEffect,
    AbstractSensorEffect as AbstractSensorEffect,
    AbstractVesselPropertyEffect as AbstractVesselPropertyEffect,
    AbstractYawTermEffect as AbstractYawTermEffect,
    AugmentedSteering as AugmentedSteering,
    AugmentedVessel as AugmentedVessel,
    HeadingSensorBias as HeadingSensorBias,
    RecordedDisturbance as RecordedDisturbance,
    RudderDelay as RudderDelay,
    RudderLag as RudderLag,
    RudderOffset as RudderOffset,
    RudderRateLimit as RudderRateLimit,
    SwayForceBias as SwayForceBias,
    YawCubicDamping as YawCubicDamping,
    YawMomentBias as YawMomentBias,
    YawRateSensorBias as YawRateSensorBias,
    nonlinear_nomoto2 as nonlinear_nomoto2,
)
from ._models._hydro_effects import (
    AddedMassError as AddedMassError,
    ApparentWind as ApparentWind,
    CrossflowDrag as CrossflowDrag,
    PropellerAsymmetry as PropellerAsymmetry,
    PropellerRace as PropellerRace,
    RudderStall as RudderStall,
    SpeedDependentDamping as SpeedDependentDamping,
    SpeedDependentRudder as SpeedDependentRudder,
    SurgeTurnResistance as SurgeTurnResistance,
    UniformCurrent as UniformCurrent,
    Windage as Windage,
    YawQuadraticDamping as YawQuadraticDamping,
)


__all__ = [
    # effects: Augmenting a model
    "AbstractEffect",
    "AbstractRudderEffect",
    "AbstractLoadEffect",
    "AbstractYawTermEffect",
    "AbstractVesselPropertyEffect",
    "AbstractSensorEffect",
    "AugmentedVessel",
    "AugmentedSteering",
    # effects: Rudder and sensors
    "RudderOffset",
    "RudderLag",
    "RudderDelay",
    "RudderRateLimit",
    "RudderStall",
    "HeadingSensorBias",
    "YawRateSensorBias",
    # effects: Loads and yaw terms
    "YawMomentBias",
    "SwayForceBias",
    "YawCubicDamping",
    "YawQuadraticDamping",
    "SpeedDependentDamping",
    "SpeedDependentRudder",
    "PropellerRace",
    "PropellerAsymmetry",
    "CrossflowDrag",
    "SurgeTurnResistance",
    "AddedMassError",
    # steering: Steering models
    "nonlinear_nomoto2",
    # effects: Environment
    "UniformCurrent",
    "ApparentWind",
    "Windage",
    "RecordedDisturbance",
    # analysis: Discovery
    "Candidate",
    "DISCOVERY_CATALOGUE",
]
