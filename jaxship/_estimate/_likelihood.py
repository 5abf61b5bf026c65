"""Innovations-form (PEM) and maximum-likelihood fits of steering models with their
noise (`fit_ml`), by the extended Kalman filter of `jaxship._estimate._kalman` (the
model, the filter and the likelihood are described there).
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from .._foundation._contract import rebuild
from .._foundation._covariance import least_squares_covariance
from .._foundation._parameter_report import parameter_report
from .._foundation._params import Transform, as_arrays, resolve_free
from .._models._holds import FirstOrderHold, ZeroOrderHold
from .._models._steering._base import AbstractSteeringModel
from ._fit import AbstractEstimator, FitResult
from ._kalman import (
    KALMAN_CHANNELS,
    _augmented_names,
    _batch_filter,
    _check_inputs,
    _records,
    _variance,
)
from ._lm import LevenbergMarquardt, solve_least_squares
from ._prior import (
    PRIOR_PASSES,
    PRIOR_RTOL,
    GaussianPrior,
    Prior,
    posterior_fields,
    prior_report,
    with_prior_rows,
)
from ._result import Prediction, Validation, assemble_result
from ._windows import channel_weights


# -- estimation ---------------------------------------------------------------------


class _Noise(eqx.Module):
    """Layout of the noise parameters: the process entries (`"rudder"` or augmented
    state names) and the channels; `estimated` flags, fixed log-variances `fixed`."""

    names: tuple[str, ...] = eqx.field(static=True)  # process names, then channels
    estimated: tuple[bool, ...] = eqx.field(static=True)
    fixed: jax.Array  # log variances of all entries (used where not estimated)
    state_index: tuple[int, ...] = eqx.field(static=True)  # -1: rudder, -2: channel
    num_states: int = eqx.field(static=True)

    def matrices(self, log_var):
        """(Q, q_rudder, R) from the estimated log variances."""
        full, j = [], 0
        for i, est in enumerate(self.estimated):
            if est:
                full.append(log_var[j])
                j += 1
            else:
                full.append(self.fixed[i])
        var = jnp.exp(jnp.stack(full))
        Q = jnp.zeros((self.num_states, self.num_states), var.dtype)
        q_rudder = jnp.zeros((), var.dtype)
        r_diag = []
        for i, k in enumerate(self.state_index):
            if k == -1:
                q_rudder = var[i]
            elif k == -2:
                r_diag.append(var[i])
            else:
                Q = Q.at[k, k].set(var[i])
        return Q, q_rudder, jnp.diag(jnp.stack(r_diag))


def _split(z, d, transform, model):
    p = transform.to_physical(z[:d])
    return rebuild(model, transform.names, p), z[d:]


def _prior_rows(z, transform, prior):
    """The prior's rows $w_i(\\theta_i - \\mu_i)$ of `prior = (mean, w)` at z
    (`GaussianPrior.arrays`)."""
    mean, weight = prior
    return weight * (transform.to_physical(z[: len(transform.names)]) - mean)


def _nll(z, args):
    """$-\\log L$, plus $\\tfrac12\\sum_i((\\theta_i - \\mu_i)/s_i)^2$ with a prior:
    the negative log posterior (`_prior.py`)."""
    model, transform, noise, rec, prior = args
    m, log_var = _split(z, len(transform.names), transform, model)
    Q, q, R = noise.matrices(log_var)
    nll = jnp.sum(_batch_filter(m, rec, Q, q, R).neg_log_likelihood)
    return nll if prior is None else nll + 0.5 * jnp.sum(_prior_rows(z, transform, prior)**2)


def _pem_residuals(z, args):
    model, transform, noise, rec, weights, prior = args
    m, log_var = _split(z, len(transform.names), transform, model)
    Q, q, R = noise.matrices(log_var)
    e = _batch_filter(m, rec, Q, q, R).innovations * weights  # (E, N, C), 0 where masked
    return e if prior is None else with_prior_rows(e, _prior_rows(z, transform, prior))


@eqx.filter_jit
def _ml_solve(z0, model, transform, noise, rec, prior, solver, max_steps):
    # the loss per sample keeps the tolerances independent of the record length
    count = jnp.sum(rec.mask[:, 1:])
    fn = lambda z, args: _nll(z, args) / count
    sol = optx.minimise(fn, solver, z0, args=(model, transform, noise, rec, prior),
                        max_steps=max_steps, throw=False)
    return sol.value, sol.result, sol.stats["num_steps"]


@eqx.filter_jit
def _pem_solve(z0, args, solver, max_steps):
    """LM on the weighted innovations (and a prior's rows) of `_pem_residuals(z, args)`;
    z, result, steps, the innovations and their Jacobian with respect to the physical
    parameters and log variances (the prior's rows left out)."""
    transform, prior = args[1], args[-1]
    z, result, steps, _, res, jac = solve_least_squares(
        _pem_residuals, solver, z0, args, max_steps,
        lambda z: _physical(z, len(transform.names), transform))
    if prior is not None:
        res, jac = res[:-1], jac[:-1]
    return z, result, steps, res, jac


def _physical(z, d, transform):
    """Model parameters in physical units and log variances as one vector."""
    return jnp.concatenate([transform.to_physical(z[:d]), z[d:]])


@eqx.filter_jit
def _ml_hessian(z, model, transform, noise, rec):
    """NLL and its Hessian with respect to (physical parameters, log variances)."""
    d = len(transform.names)
    q = _physical(z, d, transform)

    def f(q):
        m = rebuild(model, transform.names, q[:d])
        Q, qr, R = noise.matrices(q[d:])
        return jnp.sum(_batch_filter(m, rec, Q, qr, R).neg_log_likelihood)

    # forward over forward: half the compile time of `jax.hessian` (forward over
    # reverse through the filter scan) for the few parameters here (test_kalman)
    return f(q), jax.jacfwd(jax.jacfwd(f))(q)


@eqx.filter_jit
def _innovations(z, model, transform, noise, rec):
    """The filter's innovations (E, N, C) and one-step-ahead predictions at z."""
    m, log_var = _split(z, len(transform.names), transform, model)
    Q, q, R = noise.matrices(log_var)
    e = _batch_filter(m, rec, Q, q, R).innovations
    return e, rec.y - e


def _report(model, problem: "_Problem", specs, rudder, estimate, criterion,
            max_lag=25) -> FitResult:
    """The `FitResult` of an innovations fit: the parameter report, the noise, and the
    one-step-ahead predictions of the filter validated per channel. `estimate`: the
    criterion's `(z, result, steps, cov, loss, posterior)` (`posterior_fields`)."""
    z, result, steps, cov, loss, posterior = estimate
    transform, layout, rec, ds, channels = (problem.transform, problem.layout, problem.rec,
                                            problem.ds, problem.channels)
    d = len(specs)
    q = np.asarray(_physical(z, d, transform), dtype=np.float64)
    values = q[:d]
    fitted = rebuild(model, transform.names, [float(v) for v in values])
    report = parameter_report(transform.names, values, cov[:d, :d],
                              units=tuple(s.unit for s in specs))
    log_var = np.asarray(layout.fixed, dtype=np.float64).copy()
    log_std = np.zeros_like(log_var)
    est_index = [i for i, e in enumerate(layout.estimated) if e]
    log_var[est_index] = q[d:]
    with np.errstate(invalid="ignore"):
        log_std[est_index] = np.sqrt(np.diag(cov)[d:])
    var = np.exp(log_var)
    _, pred = _innovations(z, as_arrays(model), transform, layout, rec)
    pred = np.asarray(pred, dtype=np.float64)
    predicted = np.asarray(ds.mask).copy()
    predicted[:, 0] = False  # sample 0 is the prior, never predicted
    predictions = {name: np.where(predicted, pred[..., c], 0.0)
                   for c, name in enumerate(channels)}
    return assemble_result(
        fitted, report, ds, predictions, predicted,
        validation=Validation(rudder, posterior.get("effective_params", int(q.shape[0])),
                              max_lag), result=result,
        num_steps=steps, cost=loss,
        weights=dict(zip(channels, channel_weights(ds, channels, None).tolist())),
        window_samples=(1,) * ds.num_experiments, horizon=float(np.min(ds.dt)),
        criterion=criterion, noise={n: float(v) for n, v in zip(layout.names, var)},
        noise_std={n: float(v * s) for n, v, s in zip(layout.names, var, log_std)},
        **{k: v for k, v in posterior.items() if k != "robust"})


class ProcessNoise(eqx.Module):
    """Where the process noise of an innovations fit enters: `rudder` (default True) a
    rudder-equivalent disturbance held over each interval (entry `"rudder"`), and
    `states`, names of the model's states (or `"psi"`), a diagonal $Q$ entry each
    (entries `"Q_<state>"`)."""

    rudder: bool = True
    states: tuple[str, ...] = ()

    def entries(self, model) -> tuple[tuple[str, ...], tuple[int, ...]]:
        """`(names, state index)` of the noise entries (-1: the rudder)."""
        names = _augmented_names(model)
        if not self.rudder and not self.states:
            raise ValueError("`ProcessNoise` is empty: the rudder or states of the model.")
        for p in self.states:
            if p not in names:
                raise ValueError(f"`ProcessNoise` names {p!r}, which is not a state of "
                                 f"{type(model).__name__} ({', '.join(names)}).")
        rudder = ("rudder",) if self.rudder else ()
        return (rudder + tuple(f"Q_{p}" for p in self.states),
                (-1,) * len(rudder) + tuple(names.index(p) for p in self.states))


class EstimatedNoise(eqx.Module):
    """`Innovations(noise=EstimatedNoise())` (the default): every noise variance is
    estimated with the model."""

    def held(self) -> dict:
        """The variances held fixed: none."""
        return {}

    def given(self, estimated: dict) -> "HeldNoise":
        """The noise a predictor uses after a fit that `estimated` these variances."""
        return HeldNoise(dict(estimated))


class HeldNoise(eqx.Module):
    """`Innovations(noise=HeldNoise({name: variance}))`: these variances held fixed (names
    `"rudder"`, `"Q_<state>"` and the channels), the others estimated; a predictor
    needs every one (`HeldNoise(fit.noise)`)."""

    variances: dict

    def held(self) -> dict:
        return dict(self.variances)

    def given(self, estimated: dict) -> "HeldNoise":
        return self


def _noise_layout(model, ds, channels, process, noise, noise_start, criterion):
    """The `_Noise` layout and the start log variances of the estimated entries.
    Entry names: `"rudder"`, `"Q_<state>"` for process noise on a state, and the
    channels `"psi"`, `"r"` for the measurement noise."""
    names = _augmented_names(model)
    if not isinstance(process, ProcessNoise):
        raise ValueError(f"`process` must be a ProcessNoise, got {process!r}.")
    if not isinstance(noise, (EstimatedNoise, HeldNoise)):
        raise ValueError(f"`noise` must be EstimatedNoise() or HeldNoise(variances), got "
                         f"{noise!r}.")
    process_entries, index = process.entries(model)
    entries = process_entries + channels
    index = index + (-2,) * len(channels)
    # default start values: 10 % of the spread of each channel, 0.5 deg of rudder,
    # 1 % of the spread of the yaw rate (heading for psi) per sample on a state
    mask = np.asarray(ds.mask)
    spread = {}
    for c in ("psi", "r"):
        y = np.asarray(getattr(ds, c), dtype=np.float64)
        mean = np.sum(np.where(mask, y, 0.0), 1, keepdims=True) / mask.sum(1, keepdims=True)
        spread[c] = float(np.sqrt(np.sum(np.where(mask, y - mean, 0.0) ** 2) / mask.sum())) or 1.0
    default = {"rudder": math.radians(0.5) ** 2}
    default.update({c: (0.1 * spread[c]) ** 2 for c in channels})
    default.update({f"Q_{p}": (0.01 * spread["psi" if p == "psi" else "r"]) ** 2
                    for p in process.states})
    fixed_values = noise.held()
    starts = dict(noise_start or {})
    for what, given in (("noise", fixed_values), ("noise_start", starts)):
        for k in given:
            if k not in entries:
                raise ValueError(f"`{what}` names {k!r}, which is not a noise term of this fit "
                                 f"({', '.join(entries)}).")
    values, estimated = [], []
    for e in entries:
        if e in fixed_values:
            v = _variance(e, fixed_values[e], "noise")
        else:
            v = _variance(e, starts.get(e, default[e]), "noise_start")
        if v <= 0:
            raise ValueError(f"noise variance of {e!r} must be positive, got {v}.")
        values.append(math.log(v))
        estimated.append(e not in fixed_values)
    estimated = criterion.held_noise(estimated, first_channel=len(process_entries))
    layout = _Noise(names=entries, estimated=tuple(estimated),
                    fixed=jnp.asarray(values), state_index=index, num_states=len(names))
    z = np.array([v for v, est in zip(values, estimated) if est])
    return layout, z


def fit_ml(model: AbstractSteeringModel, dataset, *, free=None, channels=KALMAN_CHANNELS,
           criterion=None, process=ProcessNoise(), noise=EstimatedNoise(), noise_start=None,
           rudder: str = "delta", substeps: int = 1, max_steps: int = 512,
           solver=None, hold=None, prior: Prior | None = None) -> FitResult:
    """Estimate a steering model with its noise by the Kalman filter's innovations.

    **Arguments:**

    - `model`, `dataset`, `free`: as `jaxship.fit` (start values in the model; `free`
      names or `Free` specs).
    - `channels`: measured outputs, `"psi"` and/or `"r"`.
    - `criterion`: `MaximumLikelihood()` (default): minimise the negative log likelihood
      $\\tfrac12\\sum_k(\\log\\det S_k + \\varepsilon_k^TS_k^{-1}\\varepsilon_k)$ over the
      model parameters and the log noise variances with `optimistix.BFGS`; standard
      errors from the inverse Hessian (`jax.hessian`) of $-\\log L$ (Ljung 1999,
      sec. 7.4 and eq. 9.29). `InnovationsLeastSquares()`: prediction-error method with
      the innovations predictor (Ljung 1999, sec. 4.3 and 7.2): minimise
      $\\tfrac12\\sum_k\\|W\\varepsilon_k\\|^2$ ($W$ = 1/std of each channel) with
      Levenberg-Marquardt and forward-mode Jacobians; the noise variances set the
      filter gain and are estimated as well, except the first channel's, which fixes
      the scale (the innovations are invariant to it); standard errors as `fit`.
    - `process`: where the process noise enters: a `ProcessNoise` (default: the rudder;
      a rudder-equivalent disturbance held over each interval; `states=`: names of the
      model's states or `"psi"`, a diagonal $Q$ entry each, named `"Q_<state>"`).
    - `noise`: `EstimatedNoise()` (default) or `HeldNoise({name: variance})`, values to
      hold fixed (names `"rudder"`, `"Q_<state>"` and the channels; the others are
      estimated).
    - `noise_start`: dict of start variances (default: 10 % of each channel's spread
      for R, (0.5 deg)^2 for the rudder, 1 % of the spread on states).
    - `rudder`, `substeps`: as `PredictionError`.
    - `max_steps`, `solver`: optimiser step limit and an optimistix solver (default
      `BFGS(rtol=1e-8, atol=1e-8)` for ML, jaxship's `LevenbergMarquardt(rtol=1e-9,
      atol=1e-9)` with MINPACK's cost test for PEM).
    - `prior`: a Gaussian prior on the free model coefficients (`jaxship.strategies.Prior`,
      none on the noise variances): the fit is the maximum a posteriori estimate, its
      covariance the posterior one, and the result reports the effective number of
      parameters and per coefficient the prior and the data's share of its information
      (`FitResult.prior`; `_prior.py`). None (default): no prior.

    **Returns:** a `FitResult` with the noise variances (`noise`, `noise_std`), the
    criterion, and the filter's one-step-ahead predictions and their metrics.
    """
    criterion = MaximumLikelihood() if criterion is None else criterion
    if not isinstance(criterion, (MaximumLikelihood, InnovationsLeastSquares)):
        raise ValueError(f"`criterion` must be MaximumLikelihood() or "
                         f"InnovationsLeastSquares(), got {criterion!r}.")
    ds, channels = _check_inputs(model, dataset, channels, rudder, substeps, vessels=False)
    specs = resolve_free(model, free)
    transform = Transform.from_specs(specs)
    layout, z_noise = _noise_layout(model, ds, channels, process, noise, noise_start, criterion)
    rec = _records(ds, channels, rudder, substeps, hold)
    z0 = jnp.asarray(np.concatenate([transform.to_unconstrained([s.start for s in specs]),
                                     z_noise]), dtype=float)
    problem = _Problem(as_arrays(model), transform, layout, rec, ds, channels,
                       GaussianPrior.build(prior, specs, model))
    estimate = criterion.estimate(problem, z0, solver, int(max_steps))
    return _report(model, problem, specs, rudder, estimate, criterion.name)


class _Problem(eqx.Module):
    """What an innovations criterion minimises over: the model as arrays, the parameter
    transform, the noise layout, the filter's records, the dataset and its channels."""

    model: eqx.Module
    transform: Transform
    layout: _Noise
    rec: eqx.Module
    ds: eqx.Module
    channels: tuple[str, ...] = eqx.field(static=True)
    prior: GaussianPrior | None = None  # in the log likelihood's scale (variance 1)


class MaximumLikelihood(eqx.Module):
    """`Innovations(criterion=MaximumLikelihood())` (the default): minimise the negative
    log likelihood of the innovations over the model parameters and the log noise
    variances (BFGS; standard errors from the inverse Hessian; Ljung 1999, sec. 7.4)."""

    name = "ml"  # the `FitResult.criterion` label

    def held_noise(self, estimated: list, first_channel: int) -> list:
        """The likelihood fixes every noise variance: none is held."""
        return estimated

    def estimate(self, problem: _Problem, z0, solver, max_steps: int):
        """`(z, result, steps, cov, loss, posterior)`: BFGS (default `rtol = atol = 1e-8`)
        on $-\\log L$ (with a prior, the negative log posterior), the covariance the
        inverse of its Hessian $H + P$, $P = \\mathrm{diag}(1/s_i^2)$ (infinite variances
        where it is not positive definite); with a prior, `posterior` has the effective
        number of parameters $\\mathrm{tr}\\,H(H + P)^{-1}$ and the data's share of each
        coefficient's information $1 - [(H + P)^{-1}]_{ii}/s_i^2$ (`_prior.py`)."""
        p = problem
        solver = optx.BFGS(rtol=1e-8, atol=1e-8) if solver is None else solver
        z, result, steps = _ml_solve(z0, p.model, p.transform, p.layout, p.rec,
                                     None if p.prior is None else p.prior.arrays(), solver,
                                     max_steps)
        loss, hess = _ml_hessian(z, p.model, p.transform, p.layout, p.rec)
        hess = np.asarray(hess, dtype=np.float64)
        precision = np.zeros(hess.shape[0]) if p.prior is None else \
            p.prior.precision(hess.shape[0])
        try:
            cov = np.linalg.inv(hess + np.diag(precision))
        except np.linalg.LinAlgError:
            cov = np.full_like(hess, np.inf)
        if not np.all(np.isfinite(cov)) or np.any(np.diag(cov) <= 0):
            cov = np.where(np.eye(hess.shape[0], dtype=bool), np.inf, 0.0)
        posterior = {}
        if p.prior is not None:
            d = p.prior.columns
            determined = bool(np.all(np.isfinite(cov)))
            share = 1.0 - np.diag(cov)[:d] * precision[:d] if determined else np.full(d, np.nan)
            values = np.asarray(_physical(z, d, p.transform), dtype=np.float64)[:d]
            posterior = {
                "effective_params": float(np.trace(hess @ cov)) if determined else math.nan,
                "prior": prior_report(p.prior.names, p.prior.mean, p.prior.sd, values, share),
                "prior_settings": p.prior.prior.to_dict()}
        return z, result, steps, cov, float(loss), posterior


class InnovationsLeastSquares(eqx.Module):
    """`Innovations(criterion=InnovationsLeastSquares())`: the prediction-error method with
    the innovations predictor, the weighted innovations minimised as least squares
    (Levenberg-Marquardt; Ljung 1999, secs. 4.3, 7.2); the first channel's noise variance
    is held, as the innovations do not fix the overall noise scale."""

    name = "pem"  # the `FitResult.criterion` label

    def held_noise(self, estimated: list, first_channel: int) -> list:
        """The innovations do not fix the overall noise scale (scaling Q, R and P0 by one
        number leaves the gains unchanged): the first channel's variance is held."""
        estimated = list(estimated)
        estimated[first_channel] = False
        return estimated

    def estimate(self, problem: _Problem, z0, solver, max_steps: int):
        """`(z, result, steps, cov, loss, posterior)`: Levenberg-Marquardt (default `rtol =
        atol = 1e-9`) on the weighted innovations $W\\varepsilon_k$, the covariance of
        `least_squares_covariance` over the predicted samples; with a prior, its rows
        $\\hat\\sigma(\\theta_i - \\mu_i)/s_i$ join them, refitted until the noise variance
        $\\hat\\sigma^2$ settles, and the covariance is the posterior one (`_prior.py`, as
        `PredictionError`)."""
        p = problem
        solver = LevenbergMarquardt(rtol=1e-9, atol=1e-9) if solver is None else solver
        weights = jnp.asarray(channel_weights(p.ds, p.channels, None), dtype=float)
        mask = np.asarray(p.ds.mask).copy()
        mask[:, 0] = False  # sample 0 is the prior, never predicted
        count = len(p.channels)

        def rows_of(res, jac):
            res, jac = np.asarray(res), np.asarray(jac)
            return (np.concatenate([res[..., c][mask] for c in range(count)]),
                    np.concatenate([jac[..., c, :][mask] for c in range(count)]))

        prior, total = p.prior, 0
        if prior is not None:  # weighed by the start's residual variance, then refitted
            e, _ = _innovations(z0, p.model, p.transform, p.layout, p.rec)
            start = np.asarray(e * weights)[mask]
            prior = dataclasses.replace(prior, variance=float(np.mean(start**2)) or 1.0)
        for _ in range(1 if prior is None else PRIOR_PASSES):
            args = (p.model, p.transform, p.layout, p.rec, weights,
                    None if prior is None else prior.arrays())
            z, result, steps, res, jac = _pem_solve(z0, args, solver, max_steps)
            total += int(steps)
            rows, jrows = rows_of(res, jac)
            if prior is None:
                break
            variance = prior.noise_variance(rows, jrows)
            if not abs(variance - prior.variance) > PRIOR_RTOL * prior.variance:
                break
            prior, z0 = dataclasses.replace(prior, variance=variance), z
        groups = np.repeat(np.arange(count), int(mask.sum()))
        precision = None if prior is None else prior.precision(jrows.shape[1])
        cov, _ = least_squares_covariance(jrows, rows, groups, prior_precision=precision)
        values = np.asarray(_physical(z, len(p.transform.names), p.transform))
        posterior = posterior_fields(prior, precision, jrows,
                                     values[: len(p.transform.names)], blown=False)
        return z, result, total, cov, 0.5 * float(np.sum(rows**2)), posterior


class Innovations(AbstractEstimator):
    """The innovations estimator of `jaxship.fit`: the extended Kalman filter's
    one-step-ahead prediction errors, minimised by maximum likelihood with the noise
    variances (`criterion=MaximumLikelihood()`) or as least squares
    (`InnovationsLeastSquares()`); the other arguments are those of `fit_ml`. The
    `FitResult` carries the noise (`noise`, `noise_std`) and the filter's predictions."""

    criterion: MaximumLikelihood | InnovationsLeastSquares = MaximumLikelihood()
    channels: tuple[str, ...] = KALMAN_CHANNELS
    process: ProcessNoise = ProcessNoise()
    noise: EstimatedNoise | HeldNoise = EstimatedNoise()
    noise_start: dict | None = None
    rudder: str = "delta"
    substeps: int = 1
    max_steps: int = 512
    solver: object = None
    hold: ZeroOrderHold | FirstOrderHold | dict | None = None
    prior: Prior | None = None

    def fit(self, model, dataset, free=None, progress=None) -> FitResult:
        return fit_ml(model, dataset, free=free, channels=self.channels,
                      criterion=self.criterion, process=self.process, noise=self.noise,
                      noise_start=self.noise_start, rudder=self.rudder,
                      substeps=self.substeps, max_steps=self.max_steps, solver=self.solver,
                      hold=self.hold, prior=self.prior)

    def predict(self, model, dataset) -> Prediction:
        """The filter's one-step-ahead predictions with the noise variances `noise`
        (every entry given, e.g. `Innovations(noise=HeldNoise(fit.noise))`; `jaxship.predict`
        of a
        `FitResult` takes them from it)."""
        ds, channels = _check_inputs(model, dataset, self.channels, self.rudder,
                                     self.substeps, vessels=False)
        layout, z = _noise_layout(model, ds, channels, self.process, self.noise, None,
                                  MaximumLikelihood())
        missing = [n for n, estimated in zip(layout.names, layout.estimated) if estimated]
        if missing:
            raise ValueError(f"the innovations predictor needs every noise variance; "
                             f"missing {', '.join(missing)} (pass `Innovations(noise="
                             "HeldNoise(fit.noise))` or predict from the FitResult).")
        rec = _records(ds, channels, self.rudder, self.substeps, self.hold)
        _, pred = _innovations(jnp.zeros(0), as_arrays(model), Transform.from_specs(()),
                               layout, rec)
        predicted = np.asarray(ds.mask).copy()
        predicted[:, 0] = False  # sample 0 is the prior, never predicted
        pred = np.asarray(pred, dtype=np.float64)
        predictions = {c: np.where(predicted, pred[..., i], 0.0) for i, c in enumerate(channels)}
        return Prediction.validated(ds, predictions, predicted, rudder=self.rudder,
                                    max_lag=25, horizon=float(np.min(ds.dt)),
                                    window_samples=(1,) * ds.num_experiments)
