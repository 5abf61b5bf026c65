"""The `armax` entry of the registry: start values and the fit of `ARMAXModel` by
`fit_armax` (one-step prediction error on one training record), reported as a
`FitResult` so that the rest of `identify` treats it as any other model."""

from __future__ import annotations

import warnings

import numpy as np
import optimistix as optx

import jaxship as js

from .._armax_model import ARMAX_NAMES, ARMAX_ORDERS, ARMAXModel
from .._params import parameter_fields
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


def _fit_raw(train: js.Dataset, rudder: str, **kwargs):
    y, u, dt, source = _record(train, rudder)
    try:
        return js.fit_armax(y, u, dt=dt, **ARMAX_ORDERS, **kwargs), y, u, dt
    except ValueError as error:
        raise ValueError(f"{source}: armax: {error}") from None


def _excitation_flags(train: js.Dataset, rudder: str) -> list[str]:
    """A flag when the rudder of the training record never moves."""
    d = np.asarray(getattr(train, rudder))[0, : train.lengths[0]]
    if np.ptp(d) > 0.0:
        return []
    return [f"the rudder input is constant in every experiment ({train.names[0]}): the data "
            "contain no excitation, so the steering parameters cannot be identified; use a "
            "zig-zag, PRBS or turning record."]


def start_armax(train: js.Dataset, context: StartContext) -> ARMAXModel:
    """The pseudo-linear regression (extended least squares) start of `fit_armax`."""
    res, _, _, dt = _fit_raw(train, context.rudder, max_iter=0)
    return ARMAXModel.from_result(res, dt)


def fit_armax_entry(start: ARMAXModel, train: js.Dataset, context: StartContext) -> js.FitResult:
    """`fit_armax` on the training record as a `FitResult`: the one-step prediction
    of r is the criterion (horizon one sample)."""
    if context.estimator.horizon is not None:
        context.note(f"armax is fitted by its one-step prediction error (maximum likelihood); "
                     f"--horizon {context.estimator.horizon:g} is not used.")
    if tuple(context.channels) != ("r",):
        raise ValueError("armax models the yaw rate: fit it with channels 'r'.")
    res, y, u, dt = _fit_raw(train, context.rudder)
    model = ARMAXModel.from_result(res, dt)
    values = np.array([float(getattr(model, n)) for n in ARMAX_NAMES])
    units = tuple(parameter_fields(model)[n].unit for n in ARMAX_NAMES)
    report = js.parameter_report(ARMAX_NAMES, values, np.asarray(res.covariance), units=units,
                                 extra_flags=_excitation_flags(train, context.rudder))
    first = max(ARMAX_ORDERS["na"], ARMAX_ORDERS["nk"] + ARMAX_ORDERS["nb"] - 1,
                ARMAX_ORDERS["nc"], 1)  # the first sample of fit_armax's loss
    eps = res.residuals(y, u)
    shape = (1, train.num_samples)
    line, mask = np.zeros(shape), np.zeros(shape, dtype=bool)
    line[0, :y.size] = y - eps
    mask[0, first:y.size] = True
    rudder = np.asarray(getattr(train, context.rudder), dtype=np.float64)
    metrics = {"r": js.validate(np.asarray(train.r, dtype=np.float64), line, mask,
                                num_params=len(ARMAX_NAMES), u=rudder,
                                max_lag=context.estimator.max_lag, channel="r")}
    result = js.FitResult(
        model=model, parameters=report, metrics=metrics, predictions={"r": line},
        predicted=mask,
        result=optx.RESULTS.successful if res.converged
        else optx.RESULTS.nonlinear_max_steps_reached,
        num_steps=int(res.iterations), cost=0.5 * float(np.sum(eps[first:] ** 2)),
        weights={"r": 1.0}, window_samples=(1,), horizon=dt,
        experiment_names=tuple(train.names))
    if report.flags:
        warnings.warn("fit of ARMAX: " + " ".join(report.flags), js.IdentifiabilityWarning,
                      stacklevel=2)
    return result
