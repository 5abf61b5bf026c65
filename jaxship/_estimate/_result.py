"""`FitResult`, the one result type of `jaxship.fit` whatever the estimator, `Prediction`,
that of `jaxship.predict`, and `FitError`, raised by `fit(..., throw=True)` when a fit did
not converge."""

import contextlib
import dataclasses
import statistics

import equinox as eqx
import numpy as np

from .._foundation._contract import get_path, parameter_fields
from .._foundation._frames import fit_to_dataframe
from .._foundation._parameter_report import ParameterReport
from .._foundation._validate import ValidationReport, _to_plain, validate
from ._lm import RESULTS, SolverOutcome


class FitError(RuntimeError):
    """`fit(..., throw=True)`: the fit's result code is not `successful` (the message
    says which and why)."""


class FitResult(SolverOutcome):
    """Result of `fit`.

    - `model`: the model with the estimates (frozen parameters unchanged);
    - `parameters`: `ParameterReport` (values, standard errors, covariance,
      correlation, condition number, identifiability flags) of the free
      parameters, in the model's field order;
    - `metrics`: `{channel: ValidationReport}` on the fitted data, with the
      residuals of the chosen horizon (for `horizon=None` the simulation error);
    - `predictions`: `{channel: (E, N) array}` of model predictions at the dataset's
      samples; `predicted`: (E, N) mask of samples that were predicted (the first
      sample of each experiment is a start value, never predicted);
    - `result`: the `jaxship.RESULTS` code (optimistix's, and `simulation_blew_up`,
      `did_not_move`, `at_bound`, `poorly_determined`, `undetermined`: a fit that blew
      up, never moved, ended on a bound, left a combination undetermined or explains almost
      nothing (no channel's fit reaches 5 %) with a parameter whose 95 % interval includes
      zero is not a success);
      `success` (converged); `message`;
    - `num_steps`: optimiser steps; `cost`: $\\frac12\\sum$ of the squared weighted
      residuals at the optimum;
    - `weights`: `{channel: weight}`; `window_samples`: samples per window for each
      experiment; `horizon`: the estimator's horizon [s] (None: output error);
    - `criterion`: what was minimised (`"prediction error"`, or `"ml"`/`"pem"` of the
      innovations); `noise`, `noise_std`: the noise variances an `Innovations`
      estimator estimates with the model (None otherwise);
    - `names`, `values`, `std`, `covariance`, `correlation`: shortcuts.

    With a prior (`PredictionError(prior=...)`): the estimates are the maximum a
    posteriori ones and the covariance the posterior one; `effective_params` is the
    effective number of estimated values (the trace of the hat matrix) that FPE, AIC and BIC
    charge; `prior` `{name: {"prior_mean", "prior_std", "value", "data_share"}}`, the data's
    share of each coefficient's information (1 - posterior / prior variance); and
    `prior_settings` the prior as set, with the noise variance that weighed it. All None
    without a prior.
    """

    model: eqx.Module  # an AbstractSteeringModel or an AbstractVessel
    parameters: ParameterReport
    metrics: dict
    predictions: dict
    predicted: np.ndarray
    result: RESULTS
    num_steps: int
    cost: float
    weights: dict
    window_samples: tuple[int, ...]
    horizon: float | None
    experiment_names: tuple[str, ...]
    criterion: str = "prediction error"
    noise: dict | None = None  # innovations estimators: {name: variance} at the optimum
    noise_std: dict | None = None  # their standard errors (0 where held, NaN: not computed)
    # `initial=EstimatedStarts()`: the estimated corrections of the window starts' (r, psi),
    # shape (E, W, 2) as the windows of the fit
    start_offsets: np.ndarray | None = None
    effective_params: float | None = None
    prior: dict | None = None
    prior_settings: dict | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return self.parameters.names

    @property
    def values(self) -> np.ndarray:
        return self.parameters.values

    @property
    def std(self) -> np.ndarray:
        return self.parameters.std

    @property
    def covariance(self) -> np.ndarray:
        return self.parameters.covariance

    @property
    def correlation(self) -> np.ndarray:
        return self.parameters.correlation

    @property
    def flags(self) -> tuple[str, ...]:
        return self.parameters.flags

    def to_dataframe(self):
        """One row per free parameter: name, value, std, std_robust, unit and the 95 %
        interval (pandas, an optional dependency)."""
        return fit_to_dataframe(self)

    def interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """Normal confidence intervals `(lower, upper)` of the estimates at `level`
        (two-sided), from the standard errors."""
        z = statistics.NormalDist().inv_cdf(0.5 + level / 2)
        return self.values - z * self.std, self.values + z * self.std

    def summary(self) -> str:
        horizon = "none (output error)" if self.horizon is None else f"{self.horizon} s"
        how = (f"horizon {horizon}" if self.noise is None else
               f"innovations ({self.criterion}, one step of {horizon})")
        lines = [f"{type(self.model).__name__} fitted to {len(self.experiment_names)} "
                 f"experiment(s), {how}: {self.message}, "
                 f"{self.num_steps} steps, cost {self.cost:.6g}",
                 self.parameters.table()]
        if self.prior is not None:
            lines.append(self.prior_table())
        if self.noise is not None:
            lines.append("noise variances: " + ", ".join(
                f"{k} {v:.4g} +- {self.noise_std[k]:.2g}" for k, v in self.noise.items()))
        for c, m in self.metrics.items():
            lines.append(f"{c}: fit {m.fit_percent:.2f} %, loss {m.loss:.4g}, FPE {m.fpe:.4g}, "
                         f"residuals {'white' if m.white else 'not white'}")
        return "\n".join(lines)

    def prior_table(self) -> str:
        """Per coefficient its prior (mean, standard deviation), its estimate and the data's
        share of its information, and the effective number of parameters ("" without a
        prior)."""
        if self.prior is None:
            return ""
        lines = [f"{'prior':>12} {'mean':>14} {'std':>12} {'estimate':>14} {'data share':>10}"]
        for n, row in self.prior.items():
            lines.append(f"{n:>12} {row['prior_mean']:14.6g} {row['prior_std']:12.4g} "
                         f"{row['value']:14.6g} {100 * row['data_share']:9.1f}%")
        lines.append(f"effective number of parameters: {self.effective_params:.4g}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready summary: model name, parameters (value, std, unit; with a prior its
        mean and std and the data's share), frozen values, metrics per channel,
        correlation, condition number, flags, result."""
        fields = {n: get_path(self.model, n) for n in _field_names(self.model)}
        report = self.parameters
        params = {
            n: {"value": float(v), "std": _to_plain(float(s)), "unit": u,
                "relative_std": _to_plain(float(rel))}
            for n, v, s, u, rel in zip(self.names, self.values, self.std, report.units,
                                       report.relative_std)
        }
        prior = {}
        if self.prior is not None:
            for n, row in self.prior.items():
                params[n] |= {k: _to_plain(row[k]) for k in ("prior_mean", "prior_std",
                                                              "data_share")}
            prior = {"prior": _to_plain(self.prior_settings),
                     "effective_params": _to_plain(self.effective_params)}
        return prior | {
            "model": type(self.model).__name__,
            "parameters": params,
            "frozen": {n: _to_plain(float(v)) for n, v in fields.items() if n not in params},
            "train": {c: m.to_dict() for c, m in self.metrics.items()},
            "correlation": _to_plain(self.correlation),
            "condition_number": _to_plain(report.condition_number),
            "flags": list(self.flags),
            "result": self.message,
            "code": self.code_name,
            "success": self.success,
            "num_steps": int(self.num_steps),
            "cost": float(self.cost),
            "horizon": self.horizon,
            "criterion": self.criterion,
            "noise": _to_plain(self.noise),
            "noise_std": _to_plain(self.noise_std),
            "window_samples": list(self.window_samples),
            "weights": {k: float(v) for k, v in self.weights.items()},
            "experiments": list(self.experiment_names),
        }


def _field_names(model):
    return tuple(parameter_fields(model))


@dataclasses.dataclass(frozen=True)
class Validation:
    """How `assemble_result` validates the predictions (`validate`): the rudder channel
    `rudder` (for the residual-input correlation), the number of estimated values
    `num_params` (FPE), `max_lag`; `valid` `{channel: mask}` where only some predicted
    samples count (e.g. the finite ones of a simulation that blew up); `quiet`:
    floating-point warnings silenced (nothing of a blown-up fit means anything)."""

    rudder: str
    num_params: int | float  # float: the effective number of a fit with a prior
    max_lag: int
    valid: dict | None = None
    quiet: bool = False


def assemble_result(model, parameters, ds, predictions: dict, predicted, *,
                    validation: Validation, **stored) -> FitResult:
    """The one place a `FitResult` is built (every estimator's `fit` ends here): each
    channel of `predictions` `{channel: (E, N)}` validated against its measurement in the
    dataset `ds` as `validation` says, and the experiment names from `ds`.

    - `parameters`: the `ParameterReport`, or a callable of the metrics `{channel:
      ValidationReport}` returning it (a report whose robust standard errors depend on
      the residuals' whiteness);
    - `predicted`: the (E, N) mask of predicted samples, the validation mask of every
      channel unless `validation.valid` says otherwise;
    - `stored`: the other fields of `FitResult` (`result`, `num_steps`, `cost`,
      `weights`, `window_samples`, `horizon`, `criterion`, `noise`, `noise_std`), stored
      as given."""
    v = validation
    with np.errstate(all="ignore") if v.quiet else contextlib.nullcontext():
        metrics = _validate_channels(ds, predictions, predicted, v.valid, rudder=v.rudder,
                                     num_params=v.num_params, max_lag=v.max_lag)
    if callable(parameters):
        parameters = parameters(metrics)
    stored |= dict(num_steps=int(stored["num_steps"]), cost=float(stored["cost"]),
                   window_samples=tuple(stored["window_samples"]))
    return FitResult(model=model, parameters=parameters, metrics=metrics,
                     predictions=predictions, predicted=predicted,
                     experiment_names=tuple(ds.names), **stored)


def _validate_channels(ds, predictions: dict, predicted, valid=None, *, rudder: str,
                       num_params: int | float = 0, max_lag: int) -> dict[str, ValidationReport]:
    """`{channel: ValidationReport}` of `predictions` against the measurements in `ds`,
    each on its `valid` mask (default `predicted`)."""
    u = np.asarray(getattr(ds, rudder), dtype=np.float64)
    return {c: validate(np.asarray(getattr(ds, c), dtype=np.float64), line,
                        predicted if valid is None else valid[c], num_params=num_params,
                        u=u, max_lag=max_lag, channel=c)
            for c, line in predictions.items()}


@dataclasses.dataclass(frozen=True)
class Prediction:
    """Result of `predict`: `predictions` `{channel: (E, N)}` at the dataset's samples,
    `predicted` (E, N) mask of predicted samples, `metrics` `{channel:
    ValidationReport}` (fit %, loss, whiteness...), the predictor's `horizon` [s] (None:
    free simulation), `window_samples` per experiment and the `experiment_names`."""

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

    @classmethod
    def validated(cls, ds, predictions: dict, predicted, *, rudder: str, max_lag: int,
                  horizon, window_samples) -> "Prediction":
        """The `Prediction` of `predictions` `{channel: (E, N)}` on the dataset `ds`,
        each channel validated against its measurement (`validate`)."""
        metrics = _validate_channels(ds, predictions, predicted, rudder=rudder,
                                     max_lag=max_lag)
        return cls(predictions, predicted, metrics, horizon, tuple(window_samples),
                   tuple(ds.names))
