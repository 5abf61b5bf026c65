"""The identification workflow behind `jaxship.identify` and the `identify` and `discover`
commands: read and check records (`data`), the registry of identifiable models with their
start values (`registry`, `starts`, `armax`), a preset's fit settings (`settings`), the
output-error simulation of each model family (`simulation`), the assessment on training
and held-out records (`assessment`), the report (`result`), the loader (`load`) and the
workflow itself (`workflow`). Application layer: it uses the library through `import
jaxship as js`."""

from .assessment import Assessment as Assessment
from .data import (
    check_froude as check_froude,
    preset_length as preset_length,
    read_experiments as read_experiments,
    same_records as same_records,
)
from .load import load_model as load_model
from .registry import (
    MODELS as MODELS,
    ModelEntry as ModelEntry,
    get_model_entry as get_model_entry,
    model_key as model_key,
)
from .result import (
    Identification as Identification,
    model_from_report as model_from_report,
    read_report as read_report,
    read_result as read_result,
    unconverged_fit as unconverged_fit,
)
from .selection import (
    AUTO as AUTO,
    CANDIDATES as CANDIDATES,
    linear_candidate as linear_candidate,
)
from .settings import Settings as Settings, fit_settings as fit_settings
from .simulation import (
    simulate_armax_records as simulate_armax_records,
    simulate_records as simulate_records,
)
from .starts import StartContext as StartContext
from .workflow import (
    FitDivergedError as FitDivergedError,
    identify as identify,
    logs_wind as logs_wind,
)
