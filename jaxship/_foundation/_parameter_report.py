"""Estimates with their uncertainty and an identifiability verdict: the `ParameterReport`
of `parameter_report` (standard errors, robust ones, correlations and the flags of what
the data do not determine), from the covariances of `_covariance.py`. Host-side NumPy
(float64), following Ljung (1999), *System Identification*, 2nd ed., ch. 9 and 16.
"""

import dataclasses
import math

import numpy as np

from ._validate import _to_plain


@dataclasses.dataclass(frozen=True)
class ParameterReport:
    """Estimates with their uncertainty and an identifiability verdict.

    - `names`, `values`, `units`; `std`: standard errors (inf: not determined);
    - `covariance`, `correlation` (d, d);
    - `condition_number`: of the correlation matrix (scale free; 1 for independent
      estimates, large when some combination is poorly determined; inf if singular);
    - `flags`: plain-language findings: parameter pairs with $|\\rho| > 0.95$,
      parameters with relative standard error above 50 %, combinations the data do
      not determine at all, data problems (e.g. no excitation) and residuals that
      are not white (see `uncertainty_flags`). Empty when the estimates are well
      determined and the residuals white.
    - `std_robust`: standard errors that do not assume white residuals (Newey-West
      HAC, see `hac_covariance`); NaN where not computed;
    - `residuals_white`: whether the residuals passed the whiteness test (None: not
      tested);
    - `hac_lags`: the number of lags of `std_robust` (None: not computed);
    - `uncertainty_flags`: the flags (also in `flags`) about the standard errors
      rather than about identifiability; `identifiable` ignores them.
    - `undetermined`: the flags (also in `flags`) of what the data do not determine at
      all (a singular information matrix, no excitation) or, by the robust standard
      error of residuals that are not white, a relative standard error above
      `RELATIVE_STD_FLAG`: a fit with any is `RESULTS.poorly_determined`;
      `bound_flags`: those of estimates that ended on a bound (`RESULTS.at_bound`).

    `std`, `covariance` and `correlation` are the usual white-noise ones; when
    `residuals_white` is False they understate the uncertainty and `std_robust` is
    the one to quote.
    """

    names: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray
    covariance: np.ndarray
    correlation: np.ndarray
    condition_number: float
    flags: tuple[str, ...]
    units: tuple[str, ...] = ()
    std_robust: np.ndarray | None = None
    residuals_white: bool | None = None
    hac_lags: int | None = None
    uncertainty_flags: tuple[str, ...] = ()
    undetermined: tuple[str, ...] = ()
    bound_flags: tuple[str, ...] = ()

    def __post_init__(self):
        if self.std_robust is None:
            object.__setattr__(self, "std_robust", np.full(np.shape(self.values), np.nan))

    @property
    def identifiable(self) -> bool:
        """No identifiability flag (flags about correlated residuals do not count)."""
        return not [f for f in self.flags if f not in self.uncertainty_flags]

    @property
    def has_robust(self) -> bool:
        """Robust (HAC) standard errors were computed."""
        return bool(np.any(~np.isnan(self.std_robust)))

    @property
    def relative_std(self) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.values != 0, self.std / np.abs(self.values), np.inf)

    def table(self) -> str:
        """The estimates as a text table: name, value, std, relative std, unit (and the
        robust std when computed)."""
        robust = self.has_robust
        extra = f" {'std robust':>12}" if robust else ""
        lines = [f"{'parameter':>12} {'value':>14} {'std':>12}{extra} {'rel. std':>9}  unit"]
        units = self.units or ("",) * len(self.names)
        for name, v, s, sr, rel, unit in zip(self.names, self.values, self.std, self.std_robust,
                                             self.relative_std, units):
            extra = f" {sr:12.4g}" if robust else ""
            lines.append(f"{name:>12} {v:14.6g} {s:12.4g}{extra} {100 * rel:8.2f}%  {unit}")
        lines.append(f"condition number of the correlation matrix: {self.condition_number:.4g}")
        lines.extend(f"! {flag}" for flag in self.flags)
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {f.name: _to_plain(getattr(self, f.name)) for f in dataclasses.fields(self)}


def _combination(names, vector):
    order = np.argsort(-np.abs(vector))
    terms = [f"{vector[i]:+.2f} {names[i]}" for i in order if abs(vector[i]) > 1e-3]
    return " ".join(terms).lstrip("+")


# identifiability flags: a correlation above this, a relative standard error above this.
# 50 % puts zero at two standard errors, about the edge of the 95 % interval (value +-
# 1.96 std includes zero from 51 %). Judged on the robust (HAC or cluster) standard error
# where the residuals are not white, the flag leaves the parameter undetermined: the fit
# is `RESULTS.poorly_determined` (issue 72: sea_swift's Norrbin fit, 211 % on K; the
# README's Esso Osaka 3-DOF fit, five coefficients, went through as successful)
CORRELATION_FLAG = 0.95
RELATIVE_STD_FLAG = 0.5


@dataclasses.dataclass(frozen=True)
class RobustErrors:
    """What the residuals say about the standard errors: `white`, whether they passed the
    whiteness test (e.g. `all(m.white for m in metrics)`; None: not tested); `covariance`
    (d, d), a covariance robust to their correlation (e.g. `hac_covariance` with its
    `hac_lags`, or `cluster_from_windows`), or None; `method` names it in the flag."""

    white: bool | None = None
    covariance: np.ndarray | None = None
    hac_lags: int | None = None
    method: str | None = None


def parameter_report(names, values, covariance, *, units=(), null_directions=(),
                     extra_flags=(), undetermined_flags=(),
                     robust: RobustErrors = RobustErrors()) -> ParameterReport:
    """Standard errors, correlation matrix, condition number and identifiability
    flags of estimates `values` with `covariance` (see `ParameterReport`).

    `null_directions` (from `least_squares_covariance`) are reported as combinations
    the data do not determine; `extra_flags` are appended as they are, and those of
    them in `undetermined_flags` (e.g. no excitation) count as undetermined too.

    `robust.covariance` gives `std_robust`. When the residuals are not white
    (`robust.white` False) a flag says that the usual standard errors are too small, by
    how much at most (the largest `std_robust / std`), and the relative-error check
    uses the larger of `std` and `std_robust`. Flags: a correlation above
    `CORRELATION_FLAG`, a relative standard error above `RELATIVE_STD_FLAG`.
    """
    corr_threshold, rel_std_threshold = CORRELATION_FLAG, RELATIVE_STD_FLAG
    robust_covariance, white = robust.covariance, robust.white
    hac_lags, robust_method = robust.hac_lags, robust.method
    names = tuple(names)
    values = np.asarray(values, dtype=np.float64).reshape(-1)
    cov = np.asarray(covariance, dtype=np.float64)
    d = values.shape[0]
    if cov.shape != (d, d):
        raise ValueError(f"`covariance` must be ({d}, {d}), got {cov.shape}.")
    std, corr, condition = _correlation(cov)
    null_flags = _null_flags(names, null_directions)
    flags = list(null_flags)
    for i in range(d):
        for j in range(i + 1, d):
            rho = corr[i, j]
            if np.isfinite(rho) and abs(rho) > corr_threshold:
                flags.append(f"{names[i]} and {names[j]} are strongly correlated "
                             f"(correlation {rho:+.3f}): the data barely separate them.")
    if robust_covariance is None:
        std_robust = np.full(d, np.nan)
    else:
        robust = np.asarray(robust_covariance, dtype=np.float64)
        if robust.shape != (d, d):
            raise ValueError(f"`robust_covariance` must be ({d}, {d}), got {robust.shape}.")
        var_r = np.diag(robust)
        std_robust = np.sqrt(np.where(var_r >= 0, var_r, np.nan))
    use_robust = (white is False) & ~np.isnan(std_robust) & ~(std_robust <= std)
    judged = np.where(use_robust, std_robust, std)
    rel = np.abs(judged) / np.where(values != 0, np.abs(values), np.nan)
    robust_poor = []  # by the robust errors: undetermined (`RELATIVE_STD_FLAG`)
    for i in range(d):
        if np.isfinite(judged[i]) and not (rel[i] <= rel_std_threshold):
            percent = f"{100 * rel[i]:.0f} %" if np.isfinite(rel[i]) else "inf %"
            kind = "robust (HAC) standard error" if use_robust[i] else "standard error"
            flags.append(f"{names[i]} = {values[i]:.4g} is poorly determined: {kind} "
                         f"{judged[i]:.3g} is {percent} of the value (threshold "
                         f"{100 * rel_std_threshold:.0f} %).")
            robust_poor += flags[-1:] if use_robust[i] else []
    undetermined = (null_flags + tuple(f for f in extra_flags if f in undetermined_flags)
                    + tuple(robust_poor))
    flags.extend(extra_flags)
    uncertainty = ()
    if white is False:
        uncertainty = (_not_white_flag(names, std, std_robust, hac_lags, robust_method),)
        flags.extend(uncertainty)
    return ParameterReport(names, values, std, cov, corr, condition, tuple(flags), tuple(units),
                           std_robust=std_robust, residuals_white=None if white is None
                           else bool(white), hac_lags=None if hac_lags is None
                           else int(hac_lags), uncertainty_flags=uncertainty,
                           undetermined=undetermined)


def _correlation(cov) -> tuple[np.ndarray, np.ndarray, float]:
    """`(std, correlation, condition number)` of a covariance (d, d): NaN correlations of
    parameters without a finite positive variance, whose condition number is infinite."""
    d = cov.shape[0]
    var = np.diag(cov).copy()
    std = np.sqrt(np.where(var >= 0, var, np.nan))
    finite = np.isfinite(std) & (std > 0)
    corr = np.full((d, d), np.nan)
    sub = np.ix_(finite, finite)
    corr[sub] = cov[sub] / std[finite][:, None] / std[finite][None, :]
    np.fill_diagonal(corr, np.where(finite, 1.0, np.nan))
    if finite.all() and d:
        eig = np.linalg.eigvalsh(corr)
        return std, corr, float(eig[-1] / eig[0]) if eig[0] > 0 else math.inf
    return std, corr, math.inf


def _null_flags(names, null_directions) -> tuple[str, ...]:
    """A sentence for each direction (d,) of the parameters the data do not determine."""
    flags = []
    for v in null_directions:
        v = np.asarray(v, dtype=float)
        involved = [names[i] for i in np.nonzero(np.abs(v) > 1e-3)[0]]
        if len(involved) == 1:
            flags.append(f"{involved[0]} does not affect the fitted outputs: the data say "
                         "nothing about it (freeze it or use data that excite it).")
        else:
            flags.append(f"the data do not determine the combination {_combination(names, v)} "
                         f"of {', '.join(involved)} (information matrix singular): only other "
                         "combinations of these parameters are identifiable.")
    return tuple(flags)


def _not_white_flag(names, std, std_robust, hac_lags, robust_method=None) -> str:
    head = ("residuals are not white (correlated in time): the usual standard errors "
            "assume white residuals")
    how = robust_method or "Newey-West HAC" + (
        "" if hac_lags is None else f", {int(hac_lags)} lag{'' if int(hac_lags) == 1 else 's'}")
    ok = np.isfinite(std) & np.isfinite(std_robust) & (std > 0)
    if not ok.any():
        if np.all(np.isnan(std_robust)):
            return (f"{head} and understate the uncertainty; no robust standard errors were "
                    "computed (see jaxship._foundation._validate.hac_covariance).")
        return f"{head} and understate the uncertainty; use std_robust ({how})."
    ratio = np.where(ok, std_robust / np.where(ok, std, 1.0), -np.inf)
    i = int(np.argmax(ratio))
    if ratio[i] > 1:
        return (f"{head}, so they are too small by up to {ratio[i]:.3g}x ({names[i]}); use "
                f"std_robust ({how}).")
    return (f"{head}; here the robust standard errors ({how}) are not larger (largest ratio "
            f"{ratio[i]:.3g} for {names[i]}), but quote std_robust.")
