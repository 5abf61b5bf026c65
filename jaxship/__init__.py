"""jaxship: differentiable ship-manoeuvring simulation and steering-model identification.

The public API is `__all__` (grouped by layer as in docs/architecture.md; the API pages
of the documentation list the same names, tests/test_docs.py). The effects of the effect
seam are one namespace, `jaxship.effects`; the figures another, `jaxship.plotting`; the
strategy objects a third, `jaxship.strategies`.
"""

__version__ = "0.1.0"  # the one place of the version (pyproject.toml reads it)

import sys as _sys


# `python -m jaxship.cli` imports this package (seconds: jax's imports) before the
# command's module runs: there, and only there (`sys.argv[0]` is "-m" while Python
# locates the module to run), the command's entry installs its signal handlers first,
# as the console script does, so that Ctrl-C or SIGTERM during the imports ends with the
# command's line and status (issue 72). Any other import sets nothing global.
def _run_as_the_command() -> bool:
    argv = list(getattr(_sys, "orig_argv", ()))
    named = [argv[i + 1] for i, a in enumerate(argv[:-1]) if a == "-m"]
    named += [a[2:] for a in argv if a.startswith("-m") and len(a) > 2]
    return _sys.argv[:1] == ["-m"] and named[:1] == ["jaxship.cli"]


if _run_as_the_command():
    import _jaxship_cli

    _jaxship_cli.install()

# foundation: parameters, state, progress, the compilation cache
# analysis: manoeuvre indices, autopilot design and closed loops, experiment design,
# discovery
from ._analysis._autopilot import yaw_inertia as yaw_inertia
from ._analysis._closed_loop import (
    ClosedLoop as ClosedLoop,
    YawDisturbance as YawDisturbance,
    closed_loop as closed_loop,
    closed_loop_metrics as closed_loop_metrics,
)
from ._analysis._design import (
    excitation_order as excitation_order,
    fisher_information as fisher_information,
)
from ._analysis._discover._report import (
    DiscoveryReport as DiscoveryReport,
    Verdict as Verdict,
)
from ._analysis._discover._workflow import (
    DiscoveryOptions as DiscoveryOptions,
    discover as discover,
)

# estimate: fit and predict, the estimator strategies, bands, the Kalman filter
from ._estimate._armax import ARMAX as ARMAX
from ._estimate._bands import (
    Disturbance as Disturbance,
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
from ._estimate._kalman import ekf as ekf, smooth_states as smooth_states
from ._estimate._likelihood import (
    Innovations as Innovations,
    InnovationsLeastSquares as InnovationsLeastSquares,
    MaximumLikelihood as MaximumLikelihood,
)
from ._estimate._linear import LinearStart as LinearStart
from ._estimate._lm import RESULTS as RESULTS, LevenbergMarquardt as LevenbergMarquardt
from ._estimate._predict import predict as predict
from ._estimate._result import FitError as FitError, FitResult as FitResult
from ._foundation._cache import enable_compilation_cache as enable_compilation_cache
from ._foundation._compiler import compile_for_small_programs as compile_for_small_programs
from ._foundation._contract import AbstractModel as AbstractModel
from ._foundation._params import Free as Free, default_free as default_free, param as param
from ._foundation._progress import Progress as Progress
from ._foundation._state import (
    Command as Command,
    ShipState as ShipState,
    Trajectory as Trajectory,
    straight_state as straight_state,
)
from ._foundation._validate import fit_percent as fit_percent, validate as validate

# models: vessels, steering models, effects, environment, manoeuvres, controllers
from ._models._actuators import RudderServo as RudderServo, Shaft as Shaft
from ._models._armax_model import ARMAXModel as ARMAXModel
from ._models._control import (
    Feedforward as Feedforward,
    HeadingAutopilot as HeadingAutopilot,
    HeadingSteps as HeadingSteps,
    ReferenceModel as ReferenceModel,
    YawRateLevels as YawRateLevels,
)
from ._models._effects import augment as augment
from ._models._environment import Current as Current, Environment as Environment, Wind as Wind
from ._models._manoeuvres import (
    AbstractController as AbstractController,
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
from ._models._vessel.file import load_vessel as load_vessel, save_vessel as save_vessel
from ._models._vessel.mmg import MMGVessel as MMGVessel
from ._models._vessel.particulars import MainParticulars as MainParticulars
from ._models._vessel.ross import RossVessel as RossVessel

# simulate: the one time loop, batches, records and readers
from ._simulation._batch import (
    simulate_batch as simulate_batch,
    stack as stack,
)
from ._simulation._data import Dataset as Dataset, Experiment as Experiment
from ._simulation._froude import froude_scale as froude_scale
from ._simulation._integrate import RK4 as RK4, Simulator as Simulator
from ._simulation._measured import (
    measurement_files as measurement_files,
    read_measured as read_measured,
    shared_data_dir as shared_data_dir,
)
from ._simulation._readers import (
    read_trial_csv as read_trial_csv,
    write_trial_csv as write_trial_csv,
)
from ._simulation._simulate import simulate as simulate


# isort: split
# the namespaces: jaxship.effects.RudderOffset, jaxship.indices.turning_indices, ...
from . import (
    effects as effects,
    indices as indices,
    strategies as strategies,
    wind_loads as wind_loads,
)


# isort: split
# the workflow's verbs, last: their modules use the names above (`import jaxship as js`)
from . import identification as identification  # noqa: E402
from ._workflow._autopilot import AutopilotDesign as AutopilotDesign  # noqa: E402
from ._workflow._autopilot_evaluation import (  # noqa: E402
    AutopilotEvaluation as AutopilotEvaluation,
    design_autopilot as design_autopilot,
    evaluate_autopilot as evaluate_autopilot,
)
from ._workflow._autopilot_reference import tune_autopilot as tune_autopilot  # noqa: E402
from ._workflow._identify import (  # noqa: E402
    Identification as Identification,
    identify as identify,
    load_model as load_model,
)
from ._workflow._trials import (  # noqa: E402
    StandardTrial as StandardTrial,
    check_operating_point as check_operating_point,
)


# The public names, grouped by layer as in docs/architecture.md (`# -- layer`); a
# `# page: section` line puts the names after it in that section of docs/api/<page>.md
# (docs/api_pages.py generates the entries of the API pages from every `__all__`).
__all__ = [
    # -- foundation: the model contract, state, validation, progress, the cache
    # steering: The model contract
    "AbstractModel",
    "Free",
    "param",
    "default_free",
    # simulation: State
    "ShipState",
    "Command",
    "Trajectory",
    "straight_state",
    # estimation: Validation
    "validate",
    "fit_percent",
    # utilities: Progress
    "Progress",
    # utilities: Compilation cache
    "enable_compilation_cache",
    "compile_for_small_programs",
    # strategies: Strategy objects
    "strategies",
    # -- models: vessels, steering models, effects, manoeuvres and controllers
    # vessels: Presets
    "VESSELS",
    "get_vessel",
    # vessels: Vessel files
    "load_vessel",
    "save_vessel",
    # vessels: Vessels
    "AbstractVessel",
    "MMGVessel",
    "MainParticulars",
    "RossVessel",
    "straight_run",
    "state_derivative",
    # vessels: Actuators
    "RudderServo",
    "Shaft",
    # vessels: Environment
    "Environment",
    "Current",
    "Wind",
    # vessels: Wind loads
    "wind_loads",
    # steering: Steering models
    "AbstractSteeringModel",
    "AuxInputs",
    "Nomoto1",
    "Nomoto2",
    "NonlinearNomoto",
    "NorrbinCrossFlow",
    "RossAutopilot",
    "LinearSwayYaw",
    "LowSpeedSwayYaw",
    "ARMAXModel",
    # effects: Augmenting a model
    "effects",
    "augment",
    # manoeuvres: Manoeuvres
    "Turn",
    "ZigZag",
    "Stop",
    "pull_out",
    "spiral",
    "ReverseSpiral",
    "Schedule",
    "prbs",
    "multi_step_3211",
    "thesis_manoeuvre",
    "heading_perturbations",
    "Replay",
    # manoeuvres: Standard trials
    "StandardTrial",
    "check_operating_point",
    # manoeuvres: Controllers
    "AbstractController",
    "Controlled",
    "HeadingAutopilot",
    "Feedforward",
    "ReferenceModel",
    "HeadingSteps",
    "YawRateLevels",
    # -- simulate: the simulator, batches, records and their files
    # simulation: Simulating
    "simulate",
    "Simulator",
    "RK4",
    # simulation: Batches
    "simulate_batch",
    "stack",
    # simulation: Scaling
    "froude_scale",
    # data: Records
    "Experiment",
    "Dataset",
    # data: Trial CSV
    "read_trial_csv",
    "write_trial_csv",
    # data: Measured data
    "read_measured",
    "measurement_files",
    "shared_data_dir",
    # -- estimate: fit and predict, the estimator strategies, bands, the Kalman filter
    # estimation: Fitting and predicting
    "fit",
    "predict",
    "FitResult",
    "FitError",
    "RESULTS",
    # estimation: Estimators
    "AbstractEstimator",
    "PredictionError",
    "Innovations",
    "MaximumLikelihood",
    "InnovationsLeastSquares",
    "ARMAX",
    "DiscreteResponse",
    "LeastSquaresRegression",
    "SupportVectorRegression",
    "LinearStart",
    "MeasuredStates",
    "EstimatedStarts",
    "LevenbergMarquardt",
    # estimation: Prediction bands
    "prediction_bands",
    "calibrate_disturbance",
    "Disturbance",
    # estimation: Kalman filter
    "ekf",
    "smooth_states",
    # -- analysis: indices, autopilot design and closed loops, experiment design, discovery
    # analysis: Manoeuvre indices
    "indices",
    # analysis: Autopilot
    "design_autopilot",
    "tune_autopilot",
    "evaluate_autopilot",
    "AutopilotDesign",
    "AutopilotEvaluation",
    "yaw_inertia",
    "closed_loop",
    "ClosedLoop",
    "closed_loop_metrics",
    "YawDisturbance",
    # analysis: Experiment design
    "fisher_information",
    "excitation_order",
    # analysis: Discovery
    "discover",
    "DiscoveryOptions",
    "DiscoveryReport",
    "Verdict",
    # analysis: Identification
    "identify",
    "Identification",
    "load_model",
    "identification",
]
