"""jaxship: differentiable ship-manoeuvring simulation and steering-model identification."""

__version__ = "0.1.0"  # the one place of the version (pyproject.toml reads it)

from ._analysis._autopilot import (
    TunedAutopilot as TunedAutopilot,
    design_autopilot as design_autopilot,
    tune_autopilot as tune_autopilot,
    yaw_inertia as yaw_inertia,
)
from ._analysis._closed_loop import (
    ClosedLoop as ClosedLoop,
    ClosedLoopMetrics as ClosedLoopMetrics,
    YawDisturbance as YawDisturbance,
    closed_loop as closed_loop,
    closed_loop_metrics as closed_loop_metrics,
    tracking_objective as tracking_objective,
)
from ._analysis._design import (
    excitation_order as excitation_order,
    fisher_information as fisher_information,
)
from ._analysis._discover._catalogue import (
    DISCOVERY_CATALOGUE as DISCOVERY_CATALOGUE,
    Candidate as Candidate,
)
from ._analysis._discover._locate import locate_disagreement as locate_disagreement
from ._analysis._discover._report import (
    CandidateOutcome as CandidateOutcome,
    CandidateScore as CandidateScore,
    DiscoveryReport as DiscoveryReport,
    EffectParameter as EffectParameter,
)
from ._analysis._discover._workflow import (
    DiscoveryOptions as DiscoveryOptions,
    discover as discover,
)
from ._analysis._indices import (
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
from ._estimate._armax import ARMAX as ARMAX
from ._estimate._bands import (
    Disturbance as Disturbance,
    PredictionBands as PredictionBands,
    calibrate_disturbance as calibrate_disturbance,
    prediction_bands as prediction_bands,
)
from ._estimate._discrete_estimator import (
    DiscreteResponse as DiscreteResponse,
    LeastSquaresRegression as LeastSquaresRegression,
    SupportVectorRegression as SupportVectorRegression,
)
from ._estimate._fit import (
    AbstractEstimator as AbstractEstimator,
    PredictionError as PredictionError,
    fit as fit,
)
from ._estimate._initial import (
    EstimatedStarts as EstimatedStarts,
    MeasuredStates as MeasuredStates,
)
from ._estimate._kalman import (
    KalmanOutput as KalmanOutput,
    SmoothedStates as SmoothedStates,
    ekf as ekf,
    rts_smoother as rts_smoother,
    smooth_states as smooth_states,
)
from ._estimate._likelihood import (
    Innovations as Innovations,
    InnovationsLeastSquares as InnovationsLeastSquares,
    MaximumLikelihood as MaximumLikelihood,
)
from ._estimate._linear import LinearStart as LinearStart
from ._estimate._lm import RESULTS as RESULTS, LevenbergMarquardt as LevenbergMarquardt
from ._estimate._predict import predict as predict
from ._estimate._result import (
    FitError as FitError,
    FitResult as FitResult,
    Prediction as Prediction,
)
from ._foundation._cache import (
    compilation_cache_dir as compilation_cache_dir,
    enable_compilation_cache as enable_compilation_cache,
)
from ._foundation._contract import AbstractModel as AbstractModel
from ._foundation._covariance import parameter_report as parameter_report
from ._foundation._kinematics import body_to_earth as body_to_earth, ssa as ssa
from ._foundation._params import Free as Free, default_free as default_free, param as param
from ._foundation._progress import Progress as Progress
from ._foundation._state import (
    Command as Command,
    ShipState as ShipState,
    Trajectory as Trajectory,
    straight_state as straight_state,
)
from ._foundation._validate import (
    ValidationReport as ValidationReport,
    final_prediction_error as final_prediction_error,
    fit_percent as fit_percent,
    validate as validate,
)
from ._models._actuators import RudderServo as RudderServo, Shaft as Shaft
from ._models._control import (
    Feedforward as Feedforward,
    HeadingAutopilot as HeadingAutopilot,
    HeadingSteps as HeadingSteps,
    ReferenceModel as ReferenceModel,
    YawRateLevels as YawRateLevels,
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
    augment as augment,
    nonlinear_nomoto2 as nonlinear_nomoto2,
)
from ._models._environment import Current as Current, Environment as Environment, Wind as Wind
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
from ._models._manoeuvres import (
    AbstractController as AbstractController,
    AbstractManoeuvre as AbstractManoeuvre,
    Controlled as Controlled,
    Replay as Replay,
    ReverseSpiral as ReverseSpiral,
    Schedule as Schedule,
    Stop as Stop,
    Turn as Turn,
    ZigZag as ZigZag,
    heading_perturbations as heading_perturbations,
    multi_step_3211 as multi_step_3211,
    prbs as prbs,
    pull_out as pull_out,
    spiral as spiral,
    thesis_manoeuvre as thesis_manoeuvre,
)
from ._models._steering import (
    AbstractSteeringModel as AbstractSteeringModel,
    AuxInputs as AuxInputs,
    LinearSwayYaw as LinearSwayYaw,
    LowSpeedSwayYaw as LowSpeedSwayYaw,
    Nomoto1 as Nomoto1,
    Nomoto2 as Nomoto2,
    NonlinearNomoto as NonlinearNomoto,
    NorrbinCrossFlow as NorrbinCrossFlow,
    RossAutopilot as RossAutopilot,
)
from ._models._vessel._base import (
    AbstractVessel as AbstractVessel,
    state_derivative as state_derivative,
    straight_run as straight_run,
)
from ._models._vessel.catalogue import VESSELS as VESSELS, get_vessel as get_vessel
from ._models._vessel.esso_osaka import LowSpeedMMGVessel as LowSpeedMMGVessel
from ._models._vessel.file import load_vessel as load_vessel, save_vessel as save_vessel
from ._models._vessel.mariner import Mariner as Mariner
from ._models._vessel.mmg import MMGVessel as MMGVessel
from ._models._vessel.nomoto import NomotoVessel as NomotoVessel
from ._models._vessel.ross import RossVessel as RossVessel
from ._models._vessel.sway_yaw import SwayYawVessel as SwayYawVessel
from ._simulation._batch import simulate_batch as simulate_batch, stack as stack
from ._simulation._data import Dataset as Dataset, Experiment as Experiment
from ._simulation._froude import froude_scale as froude_scale
from ._simulation._integrate import RK4 as RK4, Simulator as Simulator
from ._simulation._measured import (
    read_esso_osaka as read_esso_osaka,
    read_hsva_kvlcc2 as read_hsva_kvlcc2,
    read_marin_kvlcc2 as read_marin_kvlcc2,
    read_measured as read_measured,
    shared_data_dir as shared_data_dir,
)
from ._simulation._readers import (
    read_trial_csv as read_trial_csv,
    write_trial_csv as write_trial_csv,
)
from ._simulation._simulate import simulate as simulate


# isort: split
# helpers of the application (jaxship.cli) and the notebooks
from ._models._armax_model import ARMAXModel as ARMAXModel
from ._models._steering.ross import (
    ROSS_FREE as ROSS_FREE,
    SPEED_RUDDER as SPEED_RUDDER,
)
from ._simulation._batch import (
    batch_turning_indices as batch_turning_indices,
    straight_run_batch as straight_run_batch,
)


vessel = get_vessel  # js.vessel("mariner"): a fresh instance of a preset (VESSELS)
