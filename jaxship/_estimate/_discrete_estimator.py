"""`DiscreteResponse`: Lu & Zhao's discrete response models as an estimator of
`jaxship.fit`, returning a `FitResult` like every other estimator.

The model says which structure is fitted: `Nomoto1` the linear first-order model
(Lu & Zhao 2008, eq. 7), `NonlinearNomoto` the nonlinear one (eq. 8), `Nomoto2` the
linear second-order (eq. 9) and `nonlinear_nomoto2` the nonlinear second-order
(eq. 10). The estimate is the equation-error fit of `DiscreteResponse.regress` (least
squares or epsilon-SVR), converted to the continuous model's parameters; their
covariance is the least-squares covariance of the discrete coefficients,
$\\hat\\sigma^2(X^TX)^{-1}$ with $\\hat\\sigma^2 = \\mathrm{RSS}/(N - p)$, carried to the
continuous parameters by the delta method (a central-difference Jacobian of the
conversion). The predictions are the one-step predictions of r (horizon one sample).
"""

import equinox as eqx
import numpy as np
import optimistix as optx

from .._foundation._contract import parameter_fields
from .._foundation._parameter_report import parameter_report
from .._models._effects import AugmentedSteering, YawCubicDamping
from .._models._holds import ZeroOrderHold
from .._models._steering.nomoto import Nomoto1, Nomoto2, NonlinearNomoto
from .._simulation._data import Experiment
from ._discrete import (
    COEFFICIENTS,
    DiscreteResponseFit,
    EulerDiscretisation,
    ExactDiscretisation,
    LeastSquaresRegression,
    SupportVectorRegression,
    continuous_parameters,
    regress,
    regressors,
)
from ._fit import AbstractEstimator, PredictionError
from ._result import FitResult, Prediction, Validation, assemble_result
from ._windows import as_dataset, check_data


# the continuous model's parameters from Lu & Zhao's (continuous_parameters)
_PARAMETERS = {
    "linear1": lambda p: {"K": p["K"], "T": p["T"], "delta0": p["delta_r"]},
    "nonlinear1": lambda p: {"K": p["K"], "T": p["T"], "n3": p["beta1"] / abs(p["alpha1"]),
                             "n0": -p["K"] * p["delta_r"]},
    "linear2": lambda p: {"K": p["K"], "T1": p["T1"], "T2": p["T2"], "T3": p["T3"],
                          "delta0": p["delta_r"]},
    "nonlinear2": lambda p: {"K": p["K"], "T1": p["T1"], "T2": p["T2"], "T3": p["T3"],
                             "delta0": p["delta_r"], "yaw_cubic_damping.beta": p["beta1"]},
}


def structure_of(model) -> str:
    """Lu & Zhao's structure of a steering model; `ValueError` for other models."""
    if isinstance(model, Nomoto1):
        return "linear1"
    if isinstance(model, NonlinearNomoto):
        return "nonlinear1"
    if isinstance(model, Nomoto2):
        return "linear2"
    if (isinstance(model, AugmentedSteering) and isinstance(model.base, Nomoto2)
            and len(model.effects) == 1 and isinstance(model.effects[0], YawCubicDamping)):
        return "nonlinear2"
    raise ValueError("the DiscreteResponse estimator fits Nomoto1, NonlinearNomoto, Nomoto2 "
                     f"or nonlinear_nomoto2 (Lu & Zhao 2008, eqs. 7-10), got "
                     f"{type(model).__name__}.")


class DiscreteResponse(AbstractEstimator):
    """Equation-error fit of Lu & Zhao's discrete response models for `jaxship.fit`:
    `method` `LeastSquaresRegression()` (default) or `SupportVectorRegression(C,
    epsilon)`; `discretisation` `ExactDiscretisation()` (linear models' default) or
    `EulerDiscretisation()`; `rudder` `"delta"` or `"delta_c"`. Equation-error
    estimates are biased by noise on r (errors in variables): use them as start values
    or quick looks, `PredictionError` for final estimates. `free` must be None: the
    structure fixes the parameters (with $n_1 = 1$ and $\\alpha_1 = 1$ frozen)."""

    method: LeastSquaresRegression | SupportVectorRegression = LeastSquaresRegression()
    discretisation: ExactDiscretisation | EulerDiscretisation | None = eqx.field(
        static=True, default=None)
    rudder: str = eqx.field(static=True, default="delta")
    max_lag: int = 25

    def fit(self, model, dataset, free=None, progress=None) -> FitResult:
        structure = structure_of(model)
        if free is not None:
            raise ValueError("the DiscreteResponse estimator fits every parameter of its "
                             "structure; `free` must be None.")
        ds = as_dataset(dataset)
        check_data(ds, self.rudder, ("r",))
        records = [_experiment(ds, i, self.rudder) for i in range(ds.num_experiments)]
        res = regress(structure, records, method=self.method,
                      discretisation=self.discretisation, rudder="delta")
        fitted = res.to_steering()
        values = _PARAMETERS[structure](res.parameters)
        names = tuple(values)
        fields = parameter_fields(fitted)
        covariance = _covariance(res, records)
        report = parameter_report(names, np.array([values[k] for k in names]), covariance,
                                  units=tuple(fields[k].unit for k in names))
        line, mask = np.zeros(ds.r.shape), np.zeros(ds.r.shape, bool)
        order = 1 if structure.endswith("1") else 2
        for i, e in enumerate(records):
            line[i, order:e.t.size] = res.one_step(e.r, e.delta)
            mask[i, order:e.t.size] = True
        r = np.asarray(ds.r, dtype=np.float64)
        return assemble_result(
            fitted, report, ds, {"r": line}, mask,
            validation=Validation(self.rudder, len(names), self.max_lag),
            result=optx.RESULTS.successful if res.converged
            else optx.RESULTS.nonlinear_max_steps_reached, num_steps=1,
            cost=0.5 * float(np.sum(((r - line) * mask) ** 2)), weights={"r": 1.0},
            window_samples=(1,), horizon=res.dt,
            criterion=f"equation error ({self.method.name}, Lu & Zhao {structure})")

    def regress(self, structure, data, *, alpha1: float = 1.0) -> DiscreteResponseFit:
        """Lu & Zhao's discrete model itself, the step `fit` converts to a model: the
        equation-error regression (eqs. 7-10) of `structure` (`"linear1"`,
        `"nonlinear1"`, `"linear2"`, `"nonlinear2"`, or a steering model of one of them,
        as `fit` takes) on `data` (an `Experiment` or a list of them, one sample
        interval; regressions never reach across records), with this estimator's
        `method`, `discretisation` and `rudder`, `alpha1` the fixed linear coefficient
        of `nonlinear2` (1 as in Lu & Zhao). Returns the discrete coefficients with their
        continuous indices, Lu & Zhao's own quantities (`alpha1`, `alpha2`, `beta1`,
        `delta_r`, `S_over_P`, ...), the equation-error RMS and whether the solver
        converged; its `simulate` runs the difference equation and `to_steering` gives the
        model `fit` returns. Use it for the discrete model (which exists also where the
        second-order time constants are complex and `fit` has no model to return); fit
        models with `jaxship.fit(model, data, estimator=DiscreteResponse(...))`.
        **Raises** `ValueError` for bad arguments or data that do not excite the
        coefficients (singular regression)."""
        if not isinstance(structure, str):
            structure = structure_of(structure)
        return regress(structure, data, method=self.method, discretisation=self.discretisation,
                       rudder=self.rudder, alpha1=alpha1)

    def predict(self, model, dataset) -> Prediction:
        """One-step-ahead predictions of r by the continuous `model` over each sample
        interval from the measured state, the rudder held (`PredictionError(horizon=0,
        hold=ZeroOrderHold())`): for the linear first-order structure the discrete model's
        own
        zero-order-hold prediction; for the others the continuous model the estimate
        was converted to, integrated rather than differenced."""
        structure_of(model)  # one of Lu & Zhao's structures
        one_step = PredictionError(horizon=0.0, channels=("r",), rudder=self.rudder,
                                   hold=ZeroOrderHold(), max_lag=self.max_lag)
        return one_step.predict(model, dataset)


def _experiment(ds, i, rudder) -> Experiment:
    n = int(ds.lengths[i])
    return Experiment(np.asarray(ds.t[i, :n]), np.asarray(getattr(ds, rudder)[i, :n]),
                      r=np.asarray(ds.r[i, :n]), name=ds.names[i])


def _covariance(res: DiscreteResponseFit, records) -> np.ndarray:
    """The covariance of the discrete coefficients (the method's own: least squares',
    NaN for SVR) carried to the continuous parameters by the delta method."""
    parts = [regressors(res.structure, e.r, e.delta) for e in records]
    x = np.concatenate([p[0] for p in parts])
    keys = COEFFICIENTS[res.structure]
    cov_c = res.method.covariance(x, res.rms)
    coef = np.array([res.coefficients[k] for k in keys])

    def convert(c):
        p = continuous_parameters(res.structure, dict(zip(keys, c)), res.dt,
                                  discretisation=res.discretisation)
        return np.array(list(_PARAMETERS[res.structure](p).values()))

    jac = np.empty((convert(coef).size, coef.size))
    for j in range(coef.size):
        step = 1e-6 * max(abs(coef[j]), 1e-12)
        up, down = coef.copy(), coef.copy()
        up[j] += step
        down[j] -= step
        jac[:, j] = (convert(up) - convert(down)) / (2 * step)
    return jac @ cov_c @ jac.T
