"""ARMAX models of ship steering (Astrom & Kallstrom 1979, eq. 7; seed 001)

$$A(q^{-1})\\,y(t) = B(q^{-1})\\,u(t - n_k) + C(q^{-1})\\,e(t),$$

$A = 1 + a_1q^{-1} + \\dots + a_{n_a}q^{-n_a}$, $B = b_0 + b_1q^{-1} + \\dots +
b_{n_b-1}q^{-(n_b-1)}$, $C = 1 + c_1q^{-1} + \\dots + c_{n_c}q^{-n_c}$, $\\{e(t)\\}$
white with variance $\\lambda^2$ (their $\\lambda C e$ with unit-variance $e$). Usually
$y = r$ [rad/s] and $u = \\delta$ [rad] with $n_k = 1$ (eq. 7 writes $u(t-1)$).

Identified by the prediction-error method (Ljung 1999, secs. 7.2, 10.2): the
one-step predictor $\\hat y(t|\\theta) = y(t) - \\varepsilon(t, \\theta)$ with
$C\\varepsilon = Ay - Bu$, minimising $\\sum\\varepsilon^2$ (the maximum-likelihood
estimate for Gaussian $e$, as Astrom & Kallstrom use). Start values from the
pseudo-linear regression (extended least squares): a long ARX model gives estimates
of $e$, then one linear regression on $(-y, u, \\hat e)$ lags; then Gauss-Newton
with Levenberg-Marquardt damping on the gradient
$\\partial\\varepsilon/\\partial\\theta = -\\varphi(t, \\theta)/C(q)$. numpy/scipy, no JAX:
the filters are recursions of a few coefficients.
"""

import dataclasses
import math
from typing import NamedTuple

import numpy as np
import optimistix as optx
import scipy  # scipy.signal loads on first use (an import-time saving)

from .._foundation._contract import parameter_fields
from .._foundation._covariance import effective_parameters
from .._foundation._parameter_report import parameter_report
from .._models._armax_model import ARMAX_NAMES, ARMAX_ORDERS, ARMAXModel
from ._discrete import continuous_parameters
from ._excitation import excitation_flags
from ._fit import AbstractEstimator
from ._prior import PRIOR_PASSES, PRIOR_RTOL, GaussianPrior, Prior, posterior_fields
from ._result import FitResult, Prediction, Validation, assemble_result
from ._windows import as_dataset, check_data


def _lags(x, lags, start):
    """Columns x(t - l) for l in lags, rows t = start..N-1."""
    return np.stack([x[start - l: x.size - l] for l in lags], axis=1) if lags else \
        np.zeros((x.size - start, 0))


@dataclasses.dataclass(frozen=True)
class ARMAXResult:
    """Result of `fit_armax`: polynomials `A` (leading 1), `B` (coefficient of
    $u(t-n_k)$ first), `C` (leading 1) as arrays, the delay `nk`, the sample
    interval `dt` [s] (or None), the innovation variance `noise_variance`
    $\\hat\\lambda^2$, the covariance `covariance` of $\\theta = (a, b, c)$ (Gauss-Newton,
    $\\hat\\lambda^2(J^TJ)^{-1}$), the loss `loss` (mean squared one-step error), the
    number of iterations, whether the iteration `converged` and the one-step errors'
    Jacobian (n, d) at the estimate."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    nk: int
    dt: float | None
    noise_variance: float
    covariance: np.ndarray
    loss: float
    iterations: int
    converged: bool
    jacobian: np.ndarray | None = None

    @property
    def std(self) -> np.ndarray:
        """Standard errors of (a_1.., b_0.., c_1..)."""
        return np.sqrt(np.diag(self.covariance))

    def residuals(self, y, u) -> np.ndarray:
        """One-step prediction errors $\\varepsilon(t)$ (zero initial conditions)."""
        return _residuals(np.asarray(y, float), np.asarray(u, float), self.A, self.B, self.C,
                          self.nk)

    def one_step(self, y, u) -> np.ndarray:
        """One-step-ahead predictions $\\hat y(t|t-1) = y(t) - \\varepsilon(t)$."""
        y = np.asarray(y, float)
        return y - self.residuals(y, u)

    def simulate(self, u) -> np.ndarray:
        """The noise-free output $y = (B/A)\\,u(t - n_k)$ from rest."""
        return scipy.signal.lfilter(self.B, self.A, _delay(np.asarray(u, float), self.nk))

    def nomoto(self) -> dict | None:
        """The continuous model whose zero-order-hold sampling this is, where the orders
        allow it (y = r, u = delta, nk = 1, needs `dt`): $n_a = n_b = 1$ gives Nomoto's
        first-order `K` [1/s], `T` [s]; $n_a = n_b = 2$ the second-order `K`, `T1`,
        `T2`, `T3` (and `T` = T1 + T2 - T3), as `DiscreteResponse.regress`'s
        `continuous_parameters`. None for other orders or without `dt`; NaN entries
        where the poles have no real continuous counterpart."""
        if self.dt is None or self.nk != 1:
            return None
        na, nb = self.A.size - 1, self.B.size
        if na == 1 and nb == 1:
            c = {"a1": -self.A[1], "a2": self.B[0], "b0": 0.0}
            p = continuous_parameters("linear1", c, self.dt)
            return {"K": p["K"], "T": p["T"]}
        if na == 2 and nb == 2:
            c = {"a1": -self.A[1], "a2": -self.A[2], "b1": self.B[0], "b2": self.B[1],
                 "c0": 0.0}
            p = continuous_parameters("linear2", c, self.dt)
            return {k: p[k] for k in ("K", "T1", "T2", "T3", "T")}
        return None


class _Coefficient(NamedTuple):
    """An ARMAX coefficient as `GaussianPrior.build` reads a free parameter."""

    name: str
    start: float


def _delay(u, nk):
    return np.concatenate([np.zeros(nk), u[:u.size - nk]]) if nk else u


def _residuals(y, u, A, B, C, nk):
    w = scipy.signal.lfilter(A, [1.0], y) - scipy.signal.lfilter(B, [1.0], _delay(u, nk))
    return scipy.signal.lfilter([1.0], C, w)


def _check(y, u, na, nb, nc, nk):
    y = np.asarray(y, dtype=np.float64)
    u = np.asarray(u, dtype=np.float64)
    if y.ndim != 1 or u.shape != y.shape:
        raise ValueError(f"`y` and `u` must be 1-D arrays of one length, got shapes {y.shape} "
                         f"and {u.shape}.")
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(u))):
        raise ValueError("`y` and `u` must be finite.")
    for name, v, low in (("na", na, 0), ("nb", nb, 1), ("nc", nc, 0), ("nk", nk, 0)):
        if int(v) != v or v < low:
            raise ValueError(f"`{name}` must be an integer >= {low}, got {v}.")
    n0 = max(na, nk + nb - 1, nc)
    if y.size < 5 * (na + nb + nc) + n0 + 10:
        raise ValueError(f"{y.size} samples are too few for {na + nb + nc} parameters.")
    if np.ptp(u) == 0:
        raise ValueError(f"the rudder input is constant ({u[0]:.4g} rad throughout): it does "
                         "not excite B; use a record whose rudder moves (a zig-zag or PRBS).")
    return y, u, n0


def _pseudo_linear_start(y, ud, start: int, orders, arx_order) -> np.ndarray:
    """The start of `fit_armax`: the innovations of a long ARX model (order `arx_order`,
    default `max(20, 4 (na + nb + nc))`, capped by the data) as the lagged noise
    regressors of a linear least-squares fit of (A, B, C) from sample `start` on (the
    pseudo-linear regression of the module docstring); `ud` is the delayed input."""
    na, nb, nc = orders
    e = np.zeros_like(y)
    if nc:
        m = int(arx_order or max(20, 4 * (na + nb + nc)))
        m = min(m, (y.size - 10) // 3)
        xa = np.hstack([-_lags(y, range(1, m + 1), m), _lags(ud, range(0, m), m)])
        th = np.linalg.lstsq(xa, y[m:], rcond=None)[0]
        e[m:] = y[m:] - xa @ th
    phi = np.hstack([-_lags(y, range(1, na + 1), start), _lags(ud, range(0, nb), start),
                     _lags(e, range(1, nc + 1), start)])
    return np.linalg.lstsq(phi, y[start:], rcond=None)[0]


def fit_armax(y, u, *, na: int = 2, nb: int = 2, nc: int = 2, nk: int = 1,
              dt: float | None = None, max_iter: int = 100, tol: float = 1e-10,
              arx_order: int | None = None, prior=None) -> ARMAXResult:
    """Fit an ARMAX model (Astrom & Kallstrom 1979, eq. 7) by prediction-error
    minimisation.

    **Arguments:** `y` output (e.g. yaw rate r [rad/s]) and `u` input (rudder
    [rad]), 1-D arrays of one length (one uniformly sampled record); the orders `na`,
    `nb`, `nc` and the delay `nk` (samples); `dt` [s], only for `nomoto()`;
    `max_iter`, `tol` (relative decrease of the loss, and of the step) of the
    Gauss-Newton/Levenberg-Marquardt iteration; `arx_order` of the long ARX model of
    the start (default `max(20, 4 (na + nb + nc))`, capped by the data).

    The loss uses the samples t >= max(na, nk + nb - 1, nc); errors before are
    computed with zero initial conditions of $1/C$ and left out.

    `prior`: `(mean, sd)` (d,) of a Gaussian prior on $\\theta = (a, b, c)$ (sd inf: none):
    the estimate is the maximum a posteriori one, minimising $\\sum\\varepsilon^2 +
    \\hat\\lambda^2\\sum_i((\\theta_i - \\mu_i)/s_i)^2$ with $\\hat\\lambda^2 =
    \\sum\\varepsilon^2/(n - d_\\text{eff})$ refitted until it settles, and the covariance
    the posterior $\\hat\\lambda^2(J^TJ + P)^{-1}$, $P = \\hat\\lambda^2\\mathrm{diag}(1/s_i^2)$
    (`jaxship/_estimate/_prior.py`); `ARMAXResult.jacobian` keeps $J$ for its report.

    **Raises:** `ValueError` for bad orders or data.
    """
    y, u, n0 = _check(y, u, na, nb, nc, nk)
    ud = _delay(u, nk)
    a_lags, b_lags, c_lags, start = range(1, na + 1), range(0, nb), range(1, nc + 1), max(n0, 1)
    theta = _pseudo_linear_start(y, ud, start, (na, nb, nc), arx_order)

    def polys(th):
        A = np.concatenate([[1.0], th[:na]])
        B = th[na:na + nb]
        C = np.concatenate([[1.0], th[na + nb:]])
        return A, B, C

    def evaluate(th):
        A, B, C = polys(th)
        if nc and np.any(np.abs(np.roots(C)) >= 1.0):
            return np.inf, None
        eps = _residuals(y, u, A, B, C, nk)
        return float(np.mean(eps[start:] ** 2)), eps

    def jacobian(th, eps):
        A, B, C = polys(th)
        # d eps / d theta = -phi / C with phi = (-y lags, u lags, eps lags)
        cols = [scipy.signal.lfilter([1.0], C, _delay(y, i)) for i in a_lags]
        cols += [-scipy.signal.lfilter([1.0], C, _delay(ud, j)) for j in b_lags]
        cols += [-scipy.signal.lfilter([1.0], C, _delay(eps, i)) for i in c_lags]
        return np.stack(cols, axis=1)[start:]

    if nc and np.any(np.abs(np.roots(polys(theta)[2])) >= 1.0):
        theta[na + nb:] *= 0.0  # an unstable C from the start: begin from C = 1
    n = y.size - start
    mean, sd = (np.zeros(theta.size), np.full(theta.size, np.inf)) if prior is None else \
        (np.asarray(prior[0], dtype=np.float64), np.asarray(prior[1], dtype=np.float64))
    weight = np.zeros(theta.size)  # the prior's rows weight (theta - mean), sigma / sd
    if prior is not None:
        weight = math.sqrt(evaluate(theta)[0]) / sd  # weighed by the start's variance
    iterations = 0
    for _ in range(1 if prior is None else PRIOR_PASSES):
        theta, eps, it, converged = _levenberg_marquardt(
            theta, lambda th: evaluate(th) + (weight * (th - mean) / math.sqrt(n),),
            jacobian, weight / math.sqrt(n), start, max_iter, tol)
        iterations += it
        J = jacobian(theta, eps)
        precision = weight**2
        d_eff = effective_parameters(J, precision)
        sigma2 = float(np.sum(eps[start:] ** 2) / max(n - d_eff, 1))
        new = np.sqrt(sigma2) / sd
        if prior is None or np.allclose(new**2, precision, rtol=PRIOR_RTOL, atol=0):
            break
        weight = new
    A, B, C = polys(theta)
    try:
        cov = sigma2 * np.linalg.inv(J.T @ J + np.diag(precision))
    except np.linalg.LinAlgError:
        cov = np.full((theta.size, theta.size), np.nan)
    return ARMAXResult(A, B, C, int(nk), None if dt is None else float(dt), sigma2, cov,
                       float(np.mean(eps[start:] ** 2)), iterations, converged, J)


def _levenberg_marquardt(theta, evaluate, jacobian, prior_weight, start, max_iter, tol):
    """Gauss-Newton with Levenberg-Marquardt damping from `theta` on the mean squared
    one-step error plus the prior's rows' mean square: `evaluate(theta)` returns `(loss,
    eps, prior_rows / sqrt(n))` (loss inf where C is unstable), `jacobian(theta, eps)` the
    errors' (n, d); the prior's Jacobian is `diag(prior_weight)`. Returns `(theta, eps,
    iterations, converged)`."""
    def total(out):
        loss, eps, rows = out
        return loss + float(np.sum(rows**2)), eps, rows

    loss, eps, rows = total(evaluate(theta))
    lam, converged, it = 1e-3, False, 0
    n = eps.size - start
    for it in range(1, max_iter + 1):
        J = np.vstack([jacobian(theta, eps) / math.sqrt(n), np.diag(prior_weight)])
        g = J.T @ np.concatenate([eps[start:] / math.sqrt(n), rows])
        H = J.T @ J
        improved = False
        for _ in range(30):
            step = np.linalg.solve(H + lam * np.diag(np.diag(H) + 1e-300), -g)
            new_loss, new_eps, new_rows = total(evaluate(theta + step))
            if new_loss <= loss:
                improved = True
                break
            lam *= 10.0
        if not improved:
            converged = True  # no descent direction left at machine precision
            break
        small = (loss - new_loss <= tol * loss
                 and np.linalg.norm(step) <= math.sqrt(tol) * (1 + np.linalg.norm(theta)))
        theta, loss, eps, rows = theta + step, new_loss, new_eps, new_rows
        lam = max(lam / 10.0, 1e-12)
        if small or loss == 0.0:
            converged = True
            break
    return theta, eps, it, converged


class ARMAX(AbstractEstimator):
    """The ARMAX estimator of `jaxship.fit` for `ARMAXModel`: `fit_armax` (one-step
    prediction error, Gauss-Newton; Astrom & Kallstrom 1979, eq. 7) on one record's
    yaw rate and replayed rudder `rudder`, reported as a `FitResult` with the one-step
    predictions (horizon one sample). `free` must be None: all six coefficients are
    estimated. `prior`: a Gaussian prior on them (`jaxship.strategies.Prior`, its mean
    by default the model given, e.g. a sampled Nomoto model's polynomials), which makes
    the estimate the maximum a posteriori one (`fit_armax`)."""

    rudder: str = "delta"
    max_iter: int = 100
    max_lag: int = 25
    prior: Prior | None = None

    def fit(self, model, dataset, free=None, progress=None) -> FitResult:
        if not isinstance(model, ARMAXModel):
            raise ValueError(f"the ARMAX estimator fits an ARMAXModel, got "
                             f"{type(model).__name__}.")
        if free is not None:
            raise ValueError("the ARMAX estimator estimates all six coefficients; `free` "
                             "must be None.")
        ds = as_dataset(dataset)
        check_data(ds, self.rudder, ("r",))
        if ds.num_experiments != 1:
            raise ValueError(f"ARMAX is fitted to one record, got {ds.num_experiments} "
                             f"({', '.join(ds.names)}).")
        n = int(ds.lengths[0])
        y = np.asarray(ds.r, dtype=np.float64)[0, :n]
        u = np.asarray(getattr(ds, self.rudder), dtype=np.float64)[0, :n]
        dt = float(np.asarray(ds.dt)[0])
        specs = [_Coefficient(k, float(getattr(model, k))) for k in ARMAX_NAMES]
        prior = GaussianPrior.build(self.prior, specs, model)
        res = fit_armax(y, u, dt=dt, max_iter=self.max_iter, **ARMAX_ORDERS,
                        prior=None if prior is None else (prior.mean, prior.sd))
        fitted = ARMAXModel.from_result(res, dt)
        fields = parameter_fields(fitted)
        values = np.array([float(getattr(fitted, k)) for k in ARMAX_NAMES])
        if prior is not None:  # weighed by the estimate's innovation variance
            prior = dataclasses.replace(prior, variance=res.noise_variance)
        precision = None if prior is None else prior.precision(len(ARMAX_NAMES))
        posterior = posterior_fields(prior, precision, res.jacobian, values, blown=False)
        flags, no_excitation = excitation_flags(ds, self.rudder)
        report = parameter_report(ARMAX_NAMES, values, np.asarray(res.covariance),
                                  units=tuple(fields[k].unit for k in ARMAX_NAMES),
                                  extra_flags=flags,
                                  undetermined_flags=flags if no_excitation else ())
        first = max(ARMAX_ORDERS["na"], ARMAX_ORDERS["nk"] + ARMAX_ORDERS["nb"] - 1,
                    ARMAX_ORDERS["nc"], 1)  # the first sample of fit_armax's loss
        eps = res.residuals(y, u)
        line, mask = np.zeros((1, ds.num_samples)), np.zeros((1, ds.num_samples), bool)
        line[0, :n], mask[0, first:n] = y - eps, True
        return assemble_result(
            fitted, report, ds, {"r": line}, mask,
            validation=Validation(self.rudder, posterior.get("effective_params",
                                                             len(ARMAX_NAMES)), self.max_lag),
            result=optx.RESULTS.successful if res.converged
            else optx.RESULTS.nonlinear_max_steps_reached, num_steps=res.iterations,
            cost=0.5 * float(np.sum(eps[first:] ** 2)), weights={"r": 1.0},
            window_samples=(1,), horizon=dt, criterion="one-step prediction error (ARMAX)",
            noise={"innovations": float(res.noise_variance)}, noise_std={"innovations": math.nan},
            **{k: v for k, v in posterior.items() if k != "robust"})

    def predict(self, model, dataset) -> Prediction:
        """One-step-ahead predictions of r by `model`'s polynomials,
        $\\hat y(t|t-1) = y(t) - \\varepsilon(t)$ (eq. 7, zero initial conditions), on
        each record (its sample interval must be the model's `dt`)."""
        if not isinstance(model, ARMAXModel):
            raise ValueError(f"the ARMAX estimator predicts with an ARMAXModel, got "
                             f"{type(model).__name__}.")
        ds = as_dataset(dataset)
        check_data(ds, self.rudder, ("r",))
        A, B, C = model.polynomials()
        first = max(A.size - 1, int(model.nk) + B.size - 1, C.size - 1, 1)
        line, mask = np.zeros(ds.r.shape), np.zeros(ds.r.shape, bool)
        for i, n in enumerate(int(k) for k in ds.lengths):
            dt = float(np.asarray(ds.dt)[i])
            if not math.isclose(dt, float(model.dt), rel_tol=1e-6):
                raise ValueError(f"record {ds.names[i]!r} is sampled every {dt:g} s, the "
                                 f"ARMAX model every {float(model.dt):g} s.")
            y = np.asarray(ds.r, dtype=np.float64)[i, :n]
            u = np.asarray(getattr(ds, self.rudder), dtype=np.float64)[i, :n]
            line[i, :n] = y - _residuals(y, u, A, B, C, int(model.nk))
            mask[i, first:n] = True
        return Prediction.validated(ds, {"r": line}, mask, rudder=self.rudder,
                                    max_lag=self.max_lag, horizon=float(model.dt),
                                    window_samples=(1,) * ds.num_experiments)
