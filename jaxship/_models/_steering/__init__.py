"""Response (autopilot) models of ship steering and their simulation."""

from ._base import (
    AbstractSteeringModel as AbstractSteeringModel,
    AuxInputs as AuxInputs,
    WindowStart as WindowStart,
)
from .low_speed import LowSpeedSwayYaw as LowSpeedSwayYaw
from .nomoto import Nomoto1 as Nomoto1, Nomoto2 as Nomoto2, NonlinearNomoto as NonlinearNomoto
from .ross import (
    ROSS_FREE as ROSS_FREE,
    SPEED_RUDDER as SPEED_RUDDER,
    RossAutopilot as RossAutopilot,
)
from .sway_yaw import (
    AbstractSwayYaw as AbstractSwayYaw,
    LinearSwayYaw as LinearSwayYaw,
    NorrbinCrossFlow as NorrbinCrossFlow,
)
