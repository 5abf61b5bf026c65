"""Validation figures of an identified model: loss, FPE, AIC/BIC, fit %, residual
whiteness and residual-input independence (parameter uncertainty:
`jaxship._foundation._covariance`; identifiability: `_parameter_report`).

Definitions follow the thesis (seed 000, eq. 3.18-3.23) and Ljung (1999), *System
Identification*, 2nd ed., ch. 16. Everything here is host-side NumPy (float64): these
are reports, not part of a differentiable computation.

Signals are arrays of shape `(N,)` or `(E, N)` (E experiments padded to N samples)
with an optional boolean `mask` of the same shape; masked samples are excluded and
`N` in every formula counts the valid samples only. Correlations are computed within
each experiment (lagged pairs never straddle two experiments or a masked sample) and
pooled.
"""

import collections
import contextlib
import dataclasses
import functools
import hashlib
import math

import numpy as np


try:  # optional (scikit-learn's dependency): NumPy's BLAS on one thread, see `_one_thread`
    from threadpoolctl import ThreadpoolController
except ImportError:  # pragma: no cover - without it the BLAS keeps its threads
    ThreadpoolController = None


Z99 = 2.5758293035489004  # two-sided 99 % quantile of the standard normal (MATLAB `resid`)
_Z99_ONE_SIDED = 2.3263478740408408  # one-sided 99 % quantile, for chi-square bounds


def chi2_quantile_99(dof: int) -> float:
    """99 % quantile of the chi-square distribution with `dof` degrees of freedom
    (Wilson & Hilferty 1931 cube-root approximation, within 0.5 % for dof >= 3)."""
    k = float(dof)
    if k <= 0:
        return 0.0
    a = 2.0 / (9.0 * k)
    return k * (1.0 - a + _Z99_ONE_SIDED * math.sqrt(a)) ** 3


def _to_plain(value):
    if isinstance(value, np.ndarray):
        return [_to_plain(v) for v in value.tolist()] if value.ndim else _to_plain(value.item())
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else (None if math.isnan(value) else
                                                   ("inf" if value > 0 else "-inf"))
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.bool_,)):
        return bool(value)
    if isinstance(value, (list, tuple)):
        return [_to_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _to_plain(v) for k, v in value.items()}
    if dataclasses.is_dataclass(value):
        return value.to_dict()
    return value


def _prepare(y, mask=None):
    y = np.asarray(y, dtype=np.float64)
    if y.ndim == 1:
        y = y[None, :]
    if y.ndim != 2:
        raise ValueError(f"signals must have shape (N,) or (E, N), got {y.shape}.")
    if mask is None:
        mask = np.ones(y.shape, dtype=bool)
    else:
        mask = np.broadcast_to(np.asarray(mask, dtype=bool).reshape(
            (1,) * (2 - np.ndim(mask)) + np.shape(mask)), y.shape)
    return y, mask


class NonFiniteError(ValueError):
    """Measured or predicted values that are not finite (a prediction that blew up)."""


@dataclasses.dataclass(frozen=True)
class Correlation:
    """A correlation function with its 99 % test.

    - `lags`: the lags [samples];
    - `values`: normalised correlation at each lag;
    - `band`: half-width of the 99 % confidence band of one value, $2.58/\\sqrt N$;
    - `statistic`, `threshold`: the portmanteau test statistic and its 99 % bound
      (see `residual_autocorrelation`, `residual_input_correlation`);
    - `passed`: `statistic <= threshold` (white / independent at the 1 % level);
    - `num_outside`: lags whose value is outside the band (lag 0 of an
      autocorrelation excluded).
    """

    lags: np.ndarray
    values: np.ndarray
    band: float
    statistic: float
    threshold: float
    passed: bool
    num_outside: int

    def to_dict(self) -> dict:
        return {f.name: _to_plain(getattr(self, f.name)) for f in dataclasses.fields(self)}


def _lagged_sum(a, b, mask, lag):
    """$\\sum_k a_k b_{k-lag}$ over pairs where both samples are valid (per row)."""
    n = a.shape[1]
    if abs(lag) >= n:
        return 0.0
    if lag >= 0:
        x, y, m = a[:, lag:], b[:, : n - lag], mask[:, lag:] & mask[:, : n - lag]
    else:
        x, y, m = a[:, : n + lag], b[:, -lag:], mask[:, : n + lag] & mask[:, -lag:]
    return float(np.sum(np.where(m, x * y, 0.0)))


def residual_autocorrelation(e, mask=None, *, max_lag: int = 25) -> Correlation:
    """Normalised autocorrelation $r_e(\\tau) = R_e(\\tau)/R_e(0)$, $\\tau = 0..M$,
    of the residuals, and the whiteness test of Ljung (1999, eq. 16.61): under white
    residuals $\\zeta = N\\sum_{\\tau=1}^{M} r_e(\\tau)^2$ is $\\chi^2(M)$; the residuals
    are called white when $\\zeta$ is below its 99 % quantile. The band is
    $\\pm 2.58/\\sqrt N$ (MATLAB `resid`)."""
    e, mask = _prepare(e, mask)
    num = int(mask.sum())
    if num < 2:
        raise ValueError(f"need at least 2 valid residuals, got {num}.")
    max_lag = int(min(max_lag, num - 1))
    r0 = _lagged_sum(e, e, mask, 0)
    lags = np.arange(max_lag + 1)
    if r0 == 0.0:  # perfect residuals: white by convention
        values = np.where(lags == 0, 1.0, 0.0)
    else:
        values = np.array([_lagged_sum(e, e, mask, k) / r0 for k in lags])
    band = Z99 / math.sqrt(num)
    statistic = float(num * np.sum(values[1:] ** 2))
    threshold = chi2_quantile_99(max_lag)
    return Correlation(lags, values, band, statistic, threshold, bool(statistic <= threshold),
                       int(np.sum(np.abs(values[1:]) > band)))


def residual_input_correlation(e, u, mask=None, *, max_lag: int = 25) -> Correlation:
    """Normalised cross-correlation
    $r_{eu}(\\tau) = \\sum_k e_k u_{k-\\tau} / \\sqrt{\\sum e_k^2 \\sum u_k^2}$,
    $\\tau = -M..M$ (positive lags: past inputs against the present residual), and
    the independence test of Ljung (1999, eq. 16.65-16.66): with $r$ the vector of
    the $2M+1$ values and $R_u$ the matrix of the input's normalised
    autocorrelations $r_u(\\tau_i - \\tau_j)$,
    $\\zeta = N r^T R_u^{+} r$ is $\\chi^2(\\mathrm{rank}\\,R_u)$ when the
    residuals are white and independent of the input (the test accounts for a
    correlated input such as a held rudder). A constant input makes $R_u$ rank one.
    The band of a single value is $\\pm 2.58/\\sqrt N$ (MATLAB `resid`). Neither
    signal has its mean removed: a residual bias that tracks the input level is a
    model error to report."""
    e, mask = _prepare(e, mask)
    u = np.broadcast_to(np.asarray(u, dtype=np.float64).reshape(e.shape), e.shape)
    num = int(mask.sum())
    if num < 2:
        raise ValueError(f"need at least 2 valid residuals, got {num}.")
    max_lag = int(min(max_lag, num - 1))
    lags = np.arange(-max_lag, max_lag + 1)
    ee, uu = _lagged_sum(e, e, mask, 0), _lagged_sum(u, u, mask, 0)
    band = Z99 / math.sqrt(num)
    if ee == 0.0 or uu == 0.0:
        values = np.zeros(lags.shape)
        return Correlation(lags, values, band, 0.0, chi2_quantile_99(1), True, 0)
    values = np.array([_lagged_sum(e, u, mask, k) for k in lags]) / math.sqrt(ee * uu)
    ru = {k: _lagged_sum(u, u, mask, k) / uu for k in range(0, 2 * max_lag + 1)}
    matrix = np.array([[ru[abs(int(i - j))] for j in lags] for i in lags])
    with _one_thread():
        w, v = np.linalg.eigh(matrix)
    keep = w > 1e-10 * max(w.max(), 1e-300)
    proj = v[:, keep].T @ values
    statistic = float(num * np.sum(proj**2 / w[keep]))
    threshold = chi2_quantile_99(int(keep.sum()))
    return Correlation(lags, values, band, statistic, threshold, bool(statistic <= threshold),
                       int(np.sum(np.abs(values) > band)))


@functools.cache
def _blas_pools():
    """threadpoolctl's controller of the loaded thread pools (made once, on first use:
    it scans the loaded libraries), or None without threadpoolctl."""
    return None if ThreadpoolController is None else ThreadpoolController()


def _one_thread():
    """NumPy's BLAS held to one thread: a 51 x 51 eigenvalue problem (the independence
    test's) took about 90 ms a call with OpenBLAS's threads competing with XLA's or
    another process' for two cores, 0.3 ms on one thread (issue 70)."""
    pools = _blas_pools()
    return contextlib.nullcontext() if pools is None else pools.limit(limits=1,
                                                                       user_api="blas")


@dataclasses.dataclass(frozen=True)
class ValidationReport:
    """The validation figures of one output channel.

    - `channel`: its name; `num_samples` N (valid samples); `num_params` d;
    - `loss`: $V_N = \\frac1N\\sum\\varepsilon^2$ (thesis eq. 3.18);
    - `abs_sum`: $\\sum|\\varepsilon|$ (eq. 3.19);
    - `rms`: $\\sqrt{V_N}$ (eq. 3.20, the thesis' "standard deviation");
    - `mean`, `std`: mean and standard deviation (mean removed) of the residuals;
    - `fpe`: Akaike's final prediction error $V_N(1 + d/N)/(1 - d/N)$
      (eq. 3.21-3.22; infinite for $d \\ge N$);
    - `aic`, `bic`: $N\\ln V_N + 2d + N(\\ln 2\\pi + 1)$ and
      $N\\ln V_N + d\\ln N + N(\\ln 2\\pi + 1)$ (Gaussian log-likelihood form, as
      MATLAB's `aic`);
    - `fit_percent`: $100(1 - \\|y - \\hat y\\| / \\|y - \\bar y\\|)$ (eq. 3.23), with
      $\\bar y$ each experiment's own mean and the norms pooled over experiments;
      `fit_per_experiment` the same per experiment (100 is perfect, 0 no better
      than the mean, negative worse);
    - `autocorrelation`, `cross_correlation`: `Correlation`s of the residuals and of
      residuals with the input (None without an input).
    """

    channel: str
    num_samples: int
    num_params: int | float
    loss: float
    abs_sum: float
    rms: float
    mean: float
    std: float
    fpe: float
    aic: float
    bic: float
    fit_percent: float
    fit_per_experiment: np.ndarray
    autocorrelation: Correlation
    cross_correlation: Correlation | None

    @property
    def white(self) -> bool:
        """The residuals pass the 99 % whiteness test."""
        return self.autocorrelation.passed

    def counting(self, num_params: int) -> "ValidationReport":
        """This report with `num_params` d estimated parameters: FPE, AIC and BIC
        charged for them (the formulas above), the other figures unchanged."""
        return dataclasses.replace(self, num_params=int(num_params),
                                   **_criteria(self.loss, int(num_params), self.num_samples))

    def to_dict(self) -> dict:
        return {f.name: _to_plain(getattr(self, f.name)) for f in dataclasses.fields(self)}


def fit_percent(y, yhat, mask=None) -> float:
    """$100(1 - \\|y - \\hat y\\| / \\|y - \\bar y\\|)$ (thesis eq. 3.23), pooled over
    experiments with each experiment's own mean (see `ValidationReport`)."""
    y, mask = _prepare(y, mask)
    yhat, _ = _prepare(yhat, mask)
    with np.errstate(over="ignore"):  # a prediction that blew up: inf, fit -inf
        err = np.sum(np.where(mask, (y - yhat) ** 2, 0.0))
    count = np.maximum(mask.sum(axis=1, keepdims=True), 1)
    mean = np.sum(np.where(mask, y, 0.0), axis=1, keepdims=True) / count
    spread = np.sum(np.where(mask, (y - mean) ** 2, 0.0))
    if spread == 0.0:
        return 100.0 if err == 0.0 else -math.inf
    return float(100.0 * (1.0 - math.sqrt(err / spread)))


def final_prediction_error(loss: float, num_params: int, num_samples: int) -> float:
    """Akaike's FPE $V_N(1 + d/N)/(1 - d/N)$ (thesis eq. 3.21); inf for $d \\ge N$."""
    ratio = num_params / num_samples
    return math.inf if ratio >= 1 else float(loss * (1 + ratio) / (1 - ratio))


def _criteria(loss: float, d: float, num: int) -> dict:
    """`fpe`, `aic`, `bic` of a loss on `num` samples with `d` estimated parameters (see
    `ValidationReport`)."""
    log_loss = math.log(loss) if loss > 0 else -math.inf
    const = num * (math.log(2 * math.pi) + 1)
    return {"fpe": final_prediction_error(loss, d, num),
            "aic": num * log_loss + 2 * d + const,
            "bic": num * log_loss + d * math.log(num) + const}


def validate(y, yhat, mask=None, *, num_params: int = 0, u=None, max_lag: int = 25,
             channel: str = "y") -> ValidationReport:
    """Validation figures of a model output `yhat` against the measured `y` (see
    `ValidationReport`), with the input `u` (same shape) for the cross-correlation.

    **Arguments:**

    - `y`, `yhat`: arrays `(N,)` or `(E, N)`.
    - `mask`: valid samples (default all).
    - `num_params`: the number d of estimated parameters (a float: an effective
      number, e.g. of a fit with a prior).
    - `u`: the input (e.g. rudder angle) at the same samples, or None.
    - `max_lag`: largest lag M of the correlation tests [samples].
    - `channel`: a name for the report.
    """
    y, mask = _prepare(y, mask)
    yhat, _ = _prepare(yhat, mask)
    if yhat.shape != y.shape:
        raise ValueError(f"`yhat` has shape {yhat.shape} but `y` has {y.shape}.")
    num = int(mask.sum())
    if num < 2:
        raise ValueError(f"channel {channel!r}: need at least 2 valid samples, got {num}.")
    bad = mask & ~(np.isfinite(y) & np.isfinite(yhat))
    if bad.any():
        raise NonFiniteError(f"channel {channel!r}: non-finite values at {int(bad.sum())} "
                             "valid samples.")
    e = np.where(mask, y - yhat, 0.0)
    loss = float(np.sum(e**2) / num)
    # the effective number of parameters of a fit with a prior is not a whole number
    d = num_params if isinstance(num_params, float) else int(num_params)
    mean = float(np.sum(e) / num)
    # (a prediction that blew up but stayed finite squares to inf: no OverflowError)
    std = float(np.sqrt(max(loss - np.square(mean), 0.0)))
    per_experiment = np.array([
        fit_percent(y[i], yhat[i], mask[i]) if mask[i].sum() >= 2 else np.nan
        for i in range(y.shape[0])
    ])
    return ValidationReport(
        channel=channel,
        num_samples=num,
        num_params=d,
        loss=loss,
        abs_sum=float(np.sum(np.abs(e))),
        rms=math.sqrt(loss),
        mean=mean,
        std=std,
        **_criteria(loss, d, num),
        fit_percent=fit_percent(y, yhat, mask),
        fit_per_experiment=per_experiment,
        autocorrelation=_once(residual_autocorrelation, (e, mask), max_lag),
        cross_correlation=None if u is None else _once(residual_input_correlation,
                                                       (e, u, mask), max_lag),
    )


_TESTS: collections.OrderedDict = collections.OrderedDict()  # the last `_KEPT` tests
_KEPT = 32


def _once(test, arrays, max_lag):
    """`test(*arrays, max_lag=)`, computed once for the same residuals (and input and
    mask): `identify` validates each residual series twice, the fit's own report and the
    assessment's with the parameters counted (issue 70: 12 tests, 6 of them repeats).
    The last `_KEPT` results are kept, keyed on the arrays' bytes."""
    digest = hashlib.blake2b(digest_size=16)
    for a in arrays:
        a = np.ascontiguousarray(a)
        digest.update(f"{a.dtype}{a.shape}".encode())
        digest.update(a.tobytes())
    key = (test.__name__, int(max_lag), digest.digest())
    if key not in _TESTS:
        _TESTS[key] = test(*arrays, max_lag=max_lag)
        if len(_TESTS) > _KEPT:
            _TESTS.popitem(last=False)
    _TESTS.move_to_end(key)
    return _TESTS[key]
