"""What `jaxship.identify` is built of, for a notebook that looks inside it or changes a
part: the catalogue of identifiable models (`MODELS`, `ModelEntry`), the candidates of
`"auto"` (`CANDIDATES`), a preset's fit settings (`fit_settings`), the reading and
checking of records (`read_experiments`, `check_froude`, `same_records`), the plausibility
of identified values and records (`implausible`, `propeller_rate_slip`, `rudder_in_rad`,
`wind_too_strong`), the assessment (`Assessment`) and the identification report read
back (`read_report`, `read_result`, `model_from_report`, `linear_candidate`,
`unconverged_fit`):

    import jaxship as js
    ident = js.identify("nomoto1", "zigzags/", horizon=10.0)
    js.identification.fit_settings("esso_osaka").horizon  # 30 s, the preset's own

The verbs themselves are top level: `identify`, `Identification`, `load_model`.
"""

from ._workflow._identify import (
    AUTO as AUTO,
    CANDIDATES as CANDIDATES,
    MODELS as MODELS,
    Assessment as Assessment,
    FitDivergedError as FitDivergedError,
    ModelEntry as ModelEntry,
    Settings as Settings,
    check_froude as check_froude,
    fit_settings as fit_settings,
    linear_candidate as linear_candidate,
    logs_wind as logs_wind,
    model_from_report as model_from_report,
    model_key as model_key,
    preset_length as preset_length,
    read_experiments as read_experiments,
    read_report as read_report,
    read_result as read_result,
    same_records as same_records,
    unconverged_fit as unconverged_fit,
)
from ._workflow._identify.plausibility import (
    implausible as implausible,
    nomoto_indices as nomoto_indices,
    propeller_rate_slip as propeller_rate_slip,
    rudder_in_rad as rudder_in_rad,
    wind_too_strong as wind_too_strong,
)


__all__ = [
    # analysis: Identification
    "MODELS",
    "ModelEntry",
    "model_key",
    "AUTO",
    "CANDIDATES",
    "fit_settings",
    "Settings",
    "read_experiments",
    "check_froude",
    "same_records",
    "implausible",
    "nomoto_indices",
    "rudder_in_rad",
    "propeller_rate_slip",
    "wind_too_strong",
    "preset_length",
    "logs_wind",
    "Assessment",
    "FitDivergedError",
    "read_report",
    "read_result",
    "model_from_report",
    "linear_candidate",
    "unconverged_fit",
]
