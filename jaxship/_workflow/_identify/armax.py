"""The `armax` entry of the registry: start values and the fit of `ARMAXModel` by
`fit_armax` (one-step prediction error on one training record), reported as a
`FitResult` so that the rest of `identify` treats it as any other model."""

from __future__ import annotations

import numpy as np

import jaxship as js

from ... import ARMAXModel
from .starts import StartContext


def _record(train: js.Dataset, rudder: str):
    """`(r, rudder, dt, source)` of the one training record `fit_armax` takes."""
    if train.num_experiments != 1:
        raise ValueError(f"armax is fitted to one record (fit_armax), got "
                         f"{train.num_experiments} training records ({', '.join(train.names)}); "
                         "give one and validate on the others with --validate.")
    n = int(train.lengths[0])
    y = np.asarray(train.r, dtype=np.float64)[0, :n]
    u = np.asarray(getattr(train, rudder), dtype=np.float64)[0, :n]
    return y, u, float(np.asarray(train.dt)[0]), str(dict(train.experiment_metadata[0]).get(
        "file", train.names[0]))


def start_armax(train: js.Dataset, context: StartContext) -> ARMAXModel:
    """The pseudo-linear regression (extended least squares) start of `fit_armax`:
    `jaxship.fit` with the `ARMAX` estimator and no Gauss-Newton iteration."""
    _, _, dt, source = _record(train, context.rudder)
    estimator = js.ARMAX(rudder=context.rudder, max_iter=0)
    try:
        return js.fit(ARMAXModel(dt=dt), train, estimator=estimator).model
    except ValueError as error:
        raise ValueError(f"{source}: armax: {error}") from None


def fit_armax_entry(start: ARMAXModel, train: js.Dataset, context: StartContext) -> js.FitResult:
    """`jaxship.fit` with the `ARMAX` estimator on the training record: the one-step
    prediction of r is the criterion (horizon one sample), with `identify`'s prior
    (`--prior`) where one is given."""
    if context.estimator.horizon is not None:
        context.note(f"armax is fitted by its one-step prediction error (maximum likelihood); "
                     f"--horizon {context.estimator.horizon:g} is not used.")
    if tuple(context.channels) != ("r",):
        raise ValueError("armax models the yaw rate: fit it with channels 'r'.")
    _record(train, context.rudder)  # one record, named in the error otherwise
    estimator = js.ARMAX(rudder=context.rudder, max_lag=context.estimator.max_lag,
                         prior=context.estimator.prior)  # `--prior`, centred on the start
    try:
        result = js.fit(start, train, estimator=estimator)
    except ValueError as error:
        raise ValueError(f"{_record(train, context.rudder)[3]}: armax: {error}") from None
    return result
