"""jaxship: differentiable ship-manoeuvring simulation and steering-model identification."""

from ._actuators import RudderServo as RudderServo, Shaft as Shaft
from ._environment import Current as Current, Environment as Environment, Wind as Wind
from ._kinematics import body_to_earth as body_to_earth, ssa as ssa
from ._manoeuvres import (
    AbstractManoeuvre as AbstractManoeuvre,
    HeadingAutopilot as HeadingAutopilot,
    Replay as Replay,
    ReverseSpiral as ReverseSpiral,
    Schedule as Schedule,
    Stop as Stop,
    Turn as Turn,
    ZigZag as ZigZag,
    multi_step_3211 as multi_step_3211,
    prbs as prbs,
    pull_out as pull_out,
    spiral as spiral,
    thesis_manoeuvre as thesis_manoeuvre,
)
from ._simulate import Simulator as Simulator, simulate as simulate
from ._state import (
    Command as Command,
    ShipState as ShipState,
    Trajectory as Trajectory,
    straight_state as straight_state,
)
from ._vessel._base import (
    AbstractVessel as AbstractVessel,
    state_derivative as state_derivative,
    straight_run as straight_run,
)


__version__ = "0.1.0"
