"""`predict`: a model's outputs on (new) data as an estimator predicts them, validated.

Each estimator brings its own predictor (`AbstractEstimator.predict`): `PredictionError`
the windows of `fit` (`horizon=None`: a free simulation of each record from its first
sample; a finite horizon restarts from the measured state every `horizon` seconds),
`Innovations` the Kalman filter's one-step-ahead predictions at given noise variances,
`ARMAX` and `DiscreteResponse` one-step-ahead predictions of the yaw rate. Works for
steering models and vessels alike, and for the result of any `fit`.
"""

import dataclasses

from ._fit import AbstractEstimator, PredictionError
from ._likelihood import Innovations
from ._result import FitResult, Prediction


def predict(model, dataset, *, estimator: AbstractEstimator = PredictionError()
            ) -> Prediction:
    """Predict the measured outputs of `dataset` with `model` (a steering model, a
    vessel, or a `FitResult`, whose model is used) as `estimator` does, and validate
    them (see `Prediction`). An `Innovations` estimator without given noise variances
    takes those a `FitResult` estimated. A `FitResult`'s d estimated parameters (its
    `names`) are counted in FPE, AIC and BIC (FPE = V (1 + d/N) / (1 - d/N), thesis
    eq. 3.21; a model alone counts none).

    Raises `ValueError` for bad data as `fit` does, and for an estimator that cannot
    predict without what it lacks (the noise variances of `Innovations`).
    """
    if not isinstance(estimator, AbstractEstimator):
        raise ValueError(f"`estimator` must be a jaxship estimator (PredictionError, "
                         f"Innovations, ARMAX, DiscreteResponse), got "
                         f"{type(estimator).__name__}.")
    if not isinstance(model, FitResult):
        return estimator.predict(model, dataset)
    if isinstance(estimator, Innovations) and model.noise is not None:
        estimator = dataclasses.replace(estimator, noise=estimator.noise.given(model.noise))
    prediction = estimator.predict(model.model, dataset)
    d = len(model.names)
    return dataclasses.replace(prediction, metrics={
        c: m.counting(d) for c, m in prediction.metrics.items()})
