"""The identification workflow behind the `identify` and `discover` commands: read
and check records (`data`), the registry of identifiable models with their start values
(`registry`, `starts`, `armax`), the output-error simulation of each model family
(`simulation`), the assessment on training and held-out records (`assessment`), the
report (`result`) and the workflow itself (`workflow`). Application layer: it uses the
library through `import jaxship as js`."""

from .assessment import Assessment as Assessment
from .data import read_experiments as read_experiments
from .registry import (
    MODELS as MODELS,
    ModelEntry as ModelEntry,
    get_model_entry as get_model_entry,
    model_key as model_key,
)
from .result import (
    IdentificationResult as IdentificationResult,
    model_from_report as model_from_report,
    read_result as read_result,
    unconverged_fit as unconverged_fit,
)
from .selection import linear_candidate as linear_candidate
from .simulation import (
    simulate_armax_records as simulate_armax_records,
    simulate_records as simulate_records,
)
from .starts import StartContext as StartContext
from .workflow import Progress as Progress, identify as identify
