"""The strategies: small objects that choose how a computation is done and carry the
algorithm themselves (as optimistix's descents and searches do), passed where a
signature asks for one:

- how a sampled input is held between samples (`Replay`, `PredictionError`,
  `Innovations`, `LinearStart`, `ekf`): `ZeroOrderHold`, `FirstOrderHold`;
- when a zig-zag's rudder switches (`ZigZag.switch_at`): `SwitchAtCrossing`,
  `SwitchAtNearestStep`, `SwitchAtNextStep`;
- the covariance of a fit's residuals (`prediction_bands`, `calibrate_disturbance`):
  `RobustCovariance`, `WhiteCovariance`, `GivenCovariance`;
- the process noise of the innovations model (`Innovations.process`) and how its
  covariance is found (`Innovations.noise`): `ProcessNoise`, `EstimatedNoise`,
  `HeldNoise`;
- how Lu & Zhao's discrete models map to continuous ones (`DiscreteResponse`):
  `ExactDiscretisation`, `EulerDiscretisation`;
- the units of a written trial file (`write_trial_csv`): `DisplayUnits`, `SIUnits`;
- what is known of the coefficients before the data (`PredictionError.prior`,
  `Innovations.prior`, `ARMAX.prior`): `Prior`.

    import jaxship as js
    js.Replay(delta, dt=0.5, delta_hold=js.strategies.FirstOrderHold())

The steady-turn rule of `turning_indices` lives with it, in `jaxship.indices`.
"""

from ._estimate._bands import (
    GivenCovariance as GivenCovariance,
    RobustCovariance as RobustCovariance,
    WhiteCovariance as WhiteCovariance,
)
from ._estimate._discrete import (
    EulerDiscretisation as EulerDiscretisation,
    ExactDiscretisation as ExactDiscretisation,
)
from ._estimate._likelihood import (
    EstimatedNoise as EstimatedNoise,
    HeldNoise as HeldNoise,
    ProcessNoise as ProcessNoise,
)
from ._estimate._prior import Prior as Prior
from ._models._holds import FirstOrderHold as FirstOrderHold, ZeroOrderHold as ZeroOrderHold
from ._models._manoeuvres import (
    SwitchAtCrossing as SwitchAtCrossing,
    SwitchAtNearestStep as SwitchAtNearestStep,
    SwitchAtNextStep as SwitchAtNextStep,
)
from ._simulation._readers import DisplayUnits as DisplayUnits, SIUnits as SIUnits


__all__ = [
    # strategies: Holding a sampled input between samples
    "ZeroOrderHold",
    "FirstOrderHold",
    # strategies: When a zig-zag's rudder switches
    "SwitchAtCrossing",
    "SwitchAtNearestStep",
    "SwitchAtNextStep",
    # strategies: The covariance of a fit's residuals
    "RobustCovariance",
    "WhiteCovariance",
    "GivenCovariance",
    # strategies: The innovations model's process noise
    "ProcessNoise",
    "EstimatedNoise",
    "HeldNoise",
    # strategies: Discrete to continuous response models
    "ExactDiscretisation",
    "EulerDiscretisation",
    # strategies: The units of a written trial file
    "DisplayUnits",
    "SIUnits",
    # strategies: What is known of the coefficients before the data
    "Prior",
]
