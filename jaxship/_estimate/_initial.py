"""Where each prediction window of `PredictionError` starts (`initial`): from the
measured states as they are, or with corrections of the start r and psi estimated; a
list of `SmoothedStates` (`jaxship.smooth_states`) is the third choice. Each strategy
says what it adds to the estimated vector: nothing, or two scaled corrections per
window."""

import math

import equinox as eqx
import numpy as np


class MeasuredStates(eqx.Module):
    """`PredictionError(initial=MeasuredStates())` (the default): every window starts from
    the measured r and psi (and a vessel's u and v) as they are."""

    def check(self, lengths) -> None:
        """Any window length will do."""

    def start_parameters(self, ds, num_windows: int):
        """`(offset_scale, z0)` of the start corrections: none (`None`, an empty start)."""
        return None, np.zeros(0)

    def start_columns(self, mask) -> np.ndarray:
        """Indices, within the corrections' block of the Jacobian, of those estimated for
        windows that exist: none."""
        return np.zeros(0, dtype=int)


class EstimatedStarts(eqx.Module):
    """`PredictionError(initial=EstimatedStarts())`: corrections of the start r and psi of
    every window join the estimated parameters (nuisance parameters, reported in no table
    but counted in the FPE), which removes the errors-in-variables bias of a noisy start
    sample: output error on noisy data (MATLAB's `InitialState='estimate'`). Costs two
    parameters per window."""

    def check(self, lengths) -> None:
        """`ValueError` for a window of one sample (its correction explains it all)."""
        if min(lengths) < 2:
            raise ValueError("`initial=EstimatedStarts()` needs windows of at least 2 samples "
                             "(with one sample the estimated start explains every residual); "
                             "use a longer `horizon` or MeasuredStates().")

    def start_parameters(self, ds, num_windows: int):
        """`(offset_scale, z0)`: the corrections (r, psi) of each of `num_windows` windows
        are estimated in units of 1 % of each channel's spread in `ds` (1e-3 where it has
        none), starting at zero."""
        mask = np.asarray(ds.mask)
        scales = []
        for name in ("r", "psi"):
            y = np.asarray(getattr(ds, name), dtype=np.float64)
            mean = np.sum(np.where(mask, y, 0.0), axis=1, keepdims=True) / mask.sum(
                axis=1, keepdims=True)
            spread = math.sqrt(np.sum(np.where(mask, (y - mean) ** 2, 0.0)) / mask.sum())
            scales.append(0.01 * spread if spread > 0 else 1e-3)
        return np.array(scales), np.zeros(num_windows * 2)

    def start_columns(self, mask) -> np.ndarray:
        """Indices, within the corrections' block of the Jacobian, of the corrections of
        windows that exist (`mask` (E, W, L) of predicted samples): two per window."""
        return np.nonzero(np.repeat(mask.any(axis=-1).reshape(-1), 2))[0]
