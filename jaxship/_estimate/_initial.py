"""Where each prediction window of `PredictionError` starts (`initial`): from the
measured states as they are, or with corrections of the start r and psi estimated; a
list of `SmoothedStates` (`jaxship.smooth_states`) is the third choice."""

import equinox as eqx


class MeasuredStates(eqx.Module):
    """`PredictionError(initial=MeasuredStates())` (the default): every window starts from
    the measured r and psi (and a vessel's u and v) as they are."""


class EstimatedStarts(eqx.Module):
    """`PredictionError(initial=EstimatedStarts())`: corrections of the start r and psi of
    every window join the estimated parameters (nuisance parameters, reported in no table
    but counted in the FPE), which removes the errors-in-variables bias of a noisy start
    sample: output error on noisy data (MATLAB's `InitialState='estimate'`). Costs two
    parameters per window."""
