"""Response (autopilot) models of ship steering and their simulation."""

from ._base import (
    AbstractSteeringModel as AbstractSteeringModel,
    AuxInputs as AuxInputs,
    SteeringTrajectory as SteeringTrajectory,
    WindowStart as WindowStart,
    simulate_steering as simulate_steering,
)
from .nomoto import Nomoto1 as Nomoto1, Nomoto2 as Nomoto2, NonlinearNomoto as NonlinearNomoto
