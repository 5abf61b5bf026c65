"""jaxship: differentiable ship-manoeuvring simulation and steering-model identification."""

from ._actuators import RudderServo as RudderServo, Shaft as Shaft
from ._batch import simulate_batch as simulate_batch, stack as stack
from ._data import (
    Dataset as Dataset,
    Experiment as Experiment,
    read_esso_osaka as read_esso_osaka,
    read_hsva_kvlcc2 as read_hsva_kvlcc2,
    read_marin_kvlcc2 as read_marin_kvlcc2,
    read_measured as read_measured,
    read_trial_csv as read_trial_csv,
    shared_data_dir as shared_data_dir,
    write_trial_csv as write_trial_csv,
)
from ._design import (
    excitation_order as excitation_order,
    fisher_information as fisher_information,
)
from ._environment import Current as Current, Environment as Environment, Wind as Wind
from ._estimate._armax import ARMAXResult as ARMAXResult, fit_armax as fit_armax
from ._estimate._discrete import fit_discrete_response as fit_discrete_response
from ._estimate._fit import (
    ConvergenceWarning as ConvergenceWarning,
    FitResult as FitResult,
    IdentifiabilityWarning as IdentifiabilityWarning,
    PredictionError as PredictionError,
    fit as fit,
)
from ._estimate._kalman import (
    KalmanFitResult as KalmanFitResult,
    KalmanOutput as KalmanOutput,
    SmoothedStates as SmoothedStates,
    ekf as ekf,
    fit_ml as fit_ml,
    rts_smoother as rts_smoother,
    smooth_states as smooth_states,
)
from ._estimate._linear import initial_estimate as initial_estimate
from ._estimate._lm import LevenbergMarquardt as LevenbergMarquardt
from ._estimate._params import Free as Free, param as param
from ._estimate._predict import predict as predict
from ._estimate._vessel_fit import default_free as default_free
from ._identify import IdentificationResult as IdentificationResult, identify as identify
from ._indices import (
    format_table as format_table,
    imo_criteria as imo_criteria,
    initial_turning_indices as initial_turning_indices,
    loop_width as loop_width,
    pull_out_indices as pull_out_indices,
    reverse_spiral_curve as reverse_spiral_curve,
    spiral_curve as spiral_curve,
    stopping_indices as stopping_indices,
    turning_indices as turning_indices,
    zigzag_indices as zigzag_indices,
)
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
from ._steering import (
    AbstractSteeringModel as AbstractSteeringModel,
    AuxInputs as AuxInputs,
    LinearSwayYaw as LinearSwayYaw,
    Nomoto1 as Nomoto1,
    Nomoto2 as Nomoto2,
    NonlinearNomoto as NonlinearNomoto,
    NorrbinCrossFlow as NorrbinCrossFlow,
    RossAutopilot as RossAutopilot,
    SteeringTrajectory as SteeringTrajectory,
    simulate_steering as simulate_steering,
)
from ._steering.nonlinear_nomoto2 import NonlinearNomoto2 as NonlinearNomoto2
from ._validate import (
    ValidationReport as ValidationReport,
    final_prediction_error as final_prediction_error,
    fit_percent as fit_percent,
    parameter_report as parameter_report,
    validate as validate,
)
from ._vessel._base import (
    AbstractVessel as AbstractVessel,
    state_derivative as state_derivative,
    straight_run as straight_run,
)
from ._vessel.catalogue import VESSELS as VESSELS, get_vessel as get_vessel
from ._vessel.esso_osaka import LowSpeedMMGVessel as LowSpeedMMGVessel
from ._vessel.mariner import Mariner as Mariner
from ._vessel.mmg import MMGVessel as MMGVessel
from ._vessel.nomoto import NomotoVessel as NomotoVessel
from ._vessel.ross import RossVessel as RossVessel
from ._vessel.sway_yaw import SwayYawVessel as SwayYawVessel


__version__ = "0.1.0"
