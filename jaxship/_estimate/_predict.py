"""`predict`: a model's prediction-error outputs on (new) data, for validation.

The same windows as `fit` with the same `PredictionError` (horizon, channels,
replayed rudder, wind): `horizon=None` is a free simulation of each experiment from
its first sample (output error); a finite horizon restarts from the measured state
every `horizon` seconds (k-step-ahead prediction). Works for steering models and
vessels alike.
"""

import dataclasses

import equinox as eqx
import numpy as np

from .._foundation._params import as_arrays
from .._foundation._validate import ValidationReport, validate
from ._fit import MAX_SUBSTEPS, PredictionError, _predict, _prepare, _stable_substeps
from ._windows import to_timeline


_predict_jit = eqx.filter_jit(lambda model, w: _predict(model, w))


@dataclasses.dataclass(frozen=True)
class Prediction:
    """Result of `predict`: `predictions` `{channel: (E, N)}` at the dataset's samples,
    `predicted` (E, N) mask of predicted samples, `metrics` `{channel:
    ValidationReport}` (fit %, loss, whiteness...), the estimator's `horizon` [s],
    `window_samples` per experiment and the `experiment_names`."""

    predictions: dict
    predicted: np.ndarray
    metrics: dict[str, ValidationReport]
    horizon: float | None
    window_samples: tuple[int, ...]
    experiment_names: tuple[str, ...]

    def fit_percent(self) -> dict[str, float]:
        """`{channel: fit %}` pooled over the experiments."""
        return {c: m.fit_percent for c, m in self.metrics.items()}

    def fit_per_experiment(self) -> dict[str, dict[str, float]]:
        """`{experiment: {channel: fit %}}`."""
        return {name: {c: float(m.fit_per_experiment[i]) for c, m in self.metrics.items()}
                for i, name in enumerate(self.experiment_names)}


def predict(model, dataset, *, estimator: PredictionError = PredictionError()) -> Prediction:
    """Predict the measured outputs of `dataset` with `model` (a steering model or a
    vessel) as `fit` does with `estimator`, and validate them (see `Prediction`); the
    integration step follows the model's fastest mode, as in `fit`.

    Raises `ValueError` for bad data as `fit` does.
    """
    if not isinstance(estimator, PredictionError):
        raise ValueError(f"`estimator` must be a PredictionError, got "
                         f"{type(estimator).__name__}.")
    ds, windows, layout = _prepare(model, dataset, estimator)
    model = as_arrays(model)
    needed = min(_stable_substeps(model, windows, refuse=False), MAX_SUBSTEPS)
    if needed > windows.substeps:  # the step follows the model's fastest mode, as in `fit`
        windows = dataclasses.replace(windows, substeps=needed)
    channels = windows.channels
    pred = _predict_jit(model, windows)
    pred = np.asarray(pred, dtype=np.float64)
    shape = (ds.num_experiments, ds.num_samples)
    u = np.asarray(getattr(ds, estimator.rudder), dtype=np.float64)
    predictions, metrics = {}, {}
    for c, name in enumerate(channels):
        timeline, hit = to_timeline(pred[c], layout, shape)
        predictions[name] = timeline
        metrics[name] = validate(np.asarray(getattr(ds, name), dtype=np.float64), timeline, hit,
                                 u=u, max_lag=estimator.max_lag, channel=name)
    return Prediction(predictions, hit, metrics, estimator.horizon, tuple(layout["lengths"]),
                      tuple(ds.names))
