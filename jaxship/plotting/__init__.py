"""Matplotlib figures of simulated and measured trials (degrees and rpm on the axes).

Every figure keeps its legends off the data (beside the axes or below the figure),
draws each quantity on its own axes, and writes display units (degrees, deg/s, ship
lengths and metres) at the edge; the functions take SI values and radians. Where a
figure is to be compared with a reference (a thesis, a model test), `reference=`
draws the reference's values or ranges on it.

- `_tracks`: time histories, tracks with ship outlines and indices, spirals, IMO table;
- `_fits`: measured against model, residual tests, parameter correlation;
- `_closed_loop`: heading autopilot runs;
- `_report`: the figures of `jaxship reproduce`.
"""

from ._closed_loop import plot_autopilot as plot_autopilot
from ._fits import (
    identification_figure_names as identification_figure_names,
    plot_comparison as plot_comparison,
    plot_parameter_correlation as plot_parameter_correlation,
    plot_residuals as plot_residuals,
    save_identification_figures as save_identification_figures,
)
from ._report import (
    plot_heading_tracking as plot_heading_tracking,
    plot_model_outputs as plot_model_outputs,
    plot_trial_vs_thesis as plot_trial_vs_thesis,
)
from ._tracks import (
    plot_imo_criteria as plot_imo_criteria,
    plot_spiral as plot_spiral,
    plot_trajectory as plot_trajectory,
)


# the figures by page section of the API reference (docs/api_pages.py)
__all__ = [
    # plotting: Trials
    "plot_trajectory",
    "plot_spiral",
    "plot_imo_criteria",
    # plotting: Fits
    "plot_comparison",
    "plot_residuals",
    "plot_parameter_correlation",
    "save_identification_figures",
    "identification_figure_names",
    # plotting: Autopilot
    "plot_autopilot",
    # plotting: The figures of `jaxship reproduce`
    "plot_trial_vs_thesis",
    "plot_model_outputs",
    "plot_heading_tracking",
]
