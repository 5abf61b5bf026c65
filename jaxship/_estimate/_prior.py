"""`Prior`: a Gaussian prior on the free coefficients of a prediction-error fit, which
makes Levenberg-Marquardt return the maximum a posteriori (MAP) estimate.

With the prior $\\theta_i \\sim N(\\mu_i, s_i^2)$, independent, and white output errors of
variance $\\sigma^2$ (in the fit's weighted residual scale), the negative log posterior is,
up to a constant, $\\frac{1}{2\\sigma^2}\\big(\\sum \\varepsilon^2 + \\sigma^2\\sum_i
((\\theta_i - \\mu_i)/s_i)^2\\big)$: the residual vector gains the rows
$\\sigma(\\theta_i - \\mu_i)/s_i$ (Tikhonov regularisation in its Bayesian reading:
Tarantola 2005, *Inverse Problem Theory*, sec. 3.2.2; Aster, Borchers & Thurber 2013,
*Parameter Estimation and Inverse Problems*, ch. 11). The rows are built from the physical
values $\\theta = p(z)$, so the bounds' transform of the optimiser leaves the prior on the
physical coefficients. $\\sigma^2$ is not known before the fit: it is estimated with the
coefficients, $\\hat\\sigma^2 = \\sum\\varepsilon^2 / (N - d_\\text{eff})$ at the MAP
(the joint posterior mode with a flat prior on $\\log\\sigma$ up to the degrees of freedom),
by refitting from the last estimate until $\\hat\\sigma^2$ settles (`fixed_point`).

The posterior covariance is $\\hat\\sigma^2 (J^TJ + P)^{-1}$ with the prior precision
$P = \\hat\\sigma^2\\,\\mathrm{diag}(1/s_i^2)$ in the same scale (`least_squares_covariance`
with `prior_precision`), and the effective number of parameters, which FPE, AIC and BIC
charge, is the trace of the hat matrix, $d_\\text{eff} = \\mathrm{tr}\\,J(J^TJ + P)^{-1}J^T$
(Hastie, Tibshirani & Friedman 2009, *Elements of Statistical Learning*, eq. 3.50;
Ljung 1999, sec. 16.4 on regularisation). The data's share of a coefficient's
information is $1 - [(J^TJ + P)^{-1}]_{ii} P_{ii}$, one minus the posterior variance over
the prior variance (0: the prior alone, 1: the data alone).
"""

import dataclasses
import math

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from .._foundation._contract import get_path
from .._foundation._covariance import effective_parameters, information_share


# the noise variance's fixed point: refits until it changes by less than this, at most
# `PRIOR_PASSES` of them (each a warm start from the last estimate)
PRIOR_RTOL = 1e-3
PRIOR_PASSES = 8


class Prior(eqx.Module):
    """A Gaussian prior on the free coefficients of `PredictionError(prior=...)` (and of
    `Innovations` and `ARMAX`, whose docstrings say how): the fit returns the maximum a
    posteriori estimate, its posterior covariance, the effective
    number of parameters (`FitResult.effective_params`) and per coefficient the prior, the
    estimate and the data's share of its information (`FitResult.prior`).

    **Arguments:**

    - `mean`: a model of the same class whose values of the free coefficients are the
      prior means (e.g. the captive-test preset); None (default): the fit's start values.
    - `scale`: the prior standard deviation, one number for every free coefficient or a
      dict `{name: number}` (coefficients it does not name get no prior); `math.inf`: no
      prior on that coefficient. Positive.
    - `relative`: `scale` is a fraction of the mean's magnitude (default True: 0.3 is a
      standard deviation of 30 % of each mean; a coefficient whose mean is zero then gets no
      prior), or False: in the coefficient's own SI units.

    See `jaxship/_estimate/_prior.py` for the equations and their sources.
    """

    mean: object = None
    scale: float | dict = 0.3
    relative: bool = True

    def __check_init__(self):
        values = self.scale.values() if isinstance(self.scale, dict) else [self.scale]
        for v in values:
            if not (isinstance(v, (int, float)) and v > 0):
                raise ValueError(f"a prior's scale must be a positive number (math.inf: no "
                                 f"prior), got {v!r}.")

    def resolve(self, names, starts, model) -> tuple[np.ndarray, np.ndarray]:
        """`(mean, sd)` (d,) of the free coefficients `names` (start values `starts`) of
        `model`; sd is inf where the coefficient has no prior."""
        source = model if self.mean is None else self.mean
        if self.mean is not None and type(self.mean) is not type(model):
            raise ValueError(f"the prior's mean is a {type(self.mean).__name__}, the fitted "
                             f"model a {type(model).__name__}: they must be the same class.")
        mean = np.array([float(s) if self.mean is None else float(get_path(source, n))
                         for n, s in zip(names, starts)])
        if isinstance(self.scale, dict):
            unknown = [n for n in self.scale if n not in names]
            if unknown:
                raise ValueError(f"the prior's scale names {unknown[0]!r}, which is not a "
                                 f"free coefficient; they are {', '.join(names)}.")
            scale = np.array([float(self.scale.get(n, math.inf)) for n in names])
        else:
            scale = np.full(len(names), float(self.scale))
        sd = scale * np.abs(mean) if self.relative else scale
        return mean, np.where(sd > 0, sd, math.inf)  # relative to a zero mean: no prior

    def to_dict(self) -> dict:
        """The prior's settings for a result file (its mean as "start" or the model's
        class)."""
        return {"mean": "start" if self.mean is None else type(self.mean).__name__,
                "scale": self.scale if isinstance(self.scale, dict) else float(self.scale),
                "relative": bool(self.relative)}


def prior_report(names, mean, sd, values, share) -> dict:
    """`{name: {"prior_mean", "prior_std", "value", "data_share"}}` with the data's share
    of each coefficient's information `share` (`information_share`) clipped to [0, 1]
    against rounding."""
    return {n: {"prior_mean": float(m), "prior_std": float(s), "value": float(v),
                "data_share": float(np.clip(c, 0.0, 1.0))}
            for n, m, s, v, c in zip(names, mean, sd, values, share)}


@dataclasses.dataclass(frozen=True)
class GaussianPrior:
    """A `Prior` resolved for a fit: the means and standard deviations (d,) of the free
    parameters (sd inf: none), the number of columns of the Jacobian (with estimated
    window starts, which have no prior) and the noise variance of the weighted residuals
    that weighs it (`_prior.py`)."""

    prior: Prior
    names: tuple[str, ...]
    mean: np.ndarray
    sd: np.ndarray
    columns: int
    variance: float

    @classmethod
    def build(cls, prior, specs, model, start_residuals=None) -> "GaussianPrior | None":
        """None without a prior (or with no finite scale), else the start's: the variance
        of the start's weighted residuals `start_residuals()` (1, the measured spread,
        where not finite), or 1 without them (a log likelihood, which has its own noise
        scale: the prior's rows are then $(\\theta_i - \\mu_i)/s_i$)."""
        if prior is None:
            return None
        if not isinstance(prior, Prior):
            raise ValueError(f"`prior` must be a jaxship.strategies.Prior, got "
                             f"{type(prior).__name__}.")
        names = tuple(s.name for s in specs)
        mean, sd = prior.resolve(names, [s.start for s in specs], model)
        if not np.isfinite(sd).any():
            return None
        if start_residuals is None:
            return cls(prior, names, mean, sd, len(specs), 1.0)
        resid = start_residuals()
        if resid.size < len(specs):
            raise ValueError(f"a prior on {len(specs)} coefficients needs at least as many "
                             "predicted samples.")
        variance = float(np.mean(resid**2))
        return cls(prior, names, mean, sd, len(specs),
                   variance if np.isfinite(variance) else 1.0)

    def precision(self, columns: int) -> np.ndarray:
        """The prior's precision in the residuals' scale, sigma^2 / sd^2, for `columns`
        columns (0 for those beyond the free parameters)."""
        out = np.zeros(columns)
        out[: self.columns] = self.variance / self.sd**2
        return out

    def arrays(self):
        return (jnp.asarray(self.mean, dtype=float),
                jnp.asarray(np.sqrt(self.precision(self.columns)), dtype=float))

    def noise_variance(self, rows, jrows) -> float:
        """$\\hat\\sigma^2 = \\sum\\varepsilon^2 / (N - d_\\text{eff})$ at this MAP."""
        d_eff = effective_parameters(jrows, self.precision(jrows.shape[1]))
        return float(np.sum(rows**2)) / max(rows.size - d_eff, 1.0)


def with_prior_rows(out, rows):
    """The residuals `out` (K, ...) with the prior's rows (d,) laid in one more leading
    slice of zeros (K + 1, ...): the residuals' layout stays, and the solver sees them all
    (needs d <= the size of one slice)."""
    slab = jnp.zeros(math.prod(out.shape[1:]), out.dtype).at[: rows.shape[0]].set(rows)
    return jnp.concatenate([out, slab.reshape((1,) + out.shape[1:])])


def posterior_fields(prior, precision, jrows, values, blown) -> dict:
    """With a prior: the `FitResult` fields `effective_params` (the trace of the hat
    matrix, window starts counted in full), `prior` (per coefficient its prior, estimate
    and the data's share of its information) and `prior_settings`, and `robust`, the
    prior's `(precision, variance)` for the robust covariances. Without one: {}."""
    if prior is None:
        return {}
    d = prior.columns
    nan = np.full(d, np.nan)
    share = nan if blown else information_share(jrows, precision)[:d]
    d_eff = math.nan if blown else effective_parameters(jrows, precision)
    return {"effective_params": d_eff, "robust": (precision, prior.variance),
            "prior": prior_report(prior.names, prior.mean, prior.sd, values, share),
            "prior_settings": prior.prior.to_dict() | {"noise_variance": prior.variance}}
