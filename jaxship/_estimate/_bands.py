"""Prediction bands: what a fitted model predicts for a record, with the spread that its
parameter uncertainty, an unlogged disturbance and the sensors give, by Monte Carlo.

Each of `num_samples` runs draws the free parameters from $N(\\hat\\theta, \\Sigma)$ (the
fit's covariance; by default the robust one, $\\Sigma = D_r C D_r$ with the robust
standard errors $D_r$ and the correlation $C$) and the measured start values it begins
from (r, psi and the position, with the sensor noise), and predicts the record as
`predict` does with the estimator given (a free simulation from the first measured state
for `horizon=None`). Onto each run's outputs it adds the disturbance and the sensor noise
(`measurement_std`); the band of a channel at a sample is the central `level` interval of
the runs there.

The disturbance is what the model does not explain (gusts, current, waves, the model's
own error), as an output disturbance of the yaw rate (the $H(q)e$ of a Box-Jenkins model,
Ljung 1999, *System Identification*, sec. 4.2): a first-order Gauss-Markov process from
zero at the window's measured start, stationary standard deviation $\\sigma$, correlation
time $\\tau$, sampled exactly, $b_{k+1} = a b_k + \\sigma\\sqrt{1 - a^2}\\,e_k$,
$a = e^{-\\Delta t/\\tau}$, $e_k \\sim N(0, 1)$ (Fossen 2011, *Handbook of Marine Craft
Hydrodynamics and Motion Control*, sec. 8.2), added to r and, integrated (trapezoid), to
psi. `calibrate_disturbance` chooses $\\sigma$ and $\\tau$ on training records, so that the
bands cover `level` of their r and of their psi samples; held-out records then test it.
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import scipy  # scipy.signal loads on first use (an import-time saving)

from .._foundation._contract import rebuild
from .._foundation._params import as_arrays
from .._simulation._data import Dataset
from ._fit import PredictionError, _predict, _predict_jit
from ._prepare import prepare_fit
from ._result import FitResult
from ._step import MAX_SUBSTEPS, stable_substeps
from ._windows import to_timeline


START = ("r", "psi", "x", "y")  # the measured start values drawn with their sensor noise


class Disturbance(eqx.Module):
    """The output disturbance of the yaw rate (module docstring): a first-order
    Gauss-Markov process of stationary standard deviation `std` [rad/s] and correlation
    time `tau` [s], integrated into the heading; `std=0` is none."""

    std: float = 0.0
    tau: float = 30.0

    def __check_init__(self):
        if not (math.isfinite(self.std) and self.std >= 0):
            raise ValueError(f"Disturbance: `std` must be a non-negative yaw rate [rad/s], "
                             f"got {self.std!r}.")
        if not (math.isfinite(self.tau) and self.tau > 0):
            raise ValueError(f"Disturbance: `tau` must be a positive number of seconds, got "
                             f"{self.tau!r}.")


@dataclasses.dataclass(frozen=True)
class PredictionBands:
    """The bands of `prediction_bands` on a dataset's records (E) and samples (N):
    `nominal` (the fitted model's prediction), `lower`, `upper` `{channel: (E, N)}`,
    `t` (E, N), `predicted` (E, N) (the samples predicted: not the start values, not
    the padding), `level` (nominal coverage), `disturbance`, `num_samples`,
    `num_dropped` (runs whose simulation was not finite, left out of the bands) and
    `draw_coverage` `{channel: (E, S)}`: the coverage of each record by the band that
    each of the S draws gets. A draw is a record the model and its noise model would
    produce if they were right, so this is the per-record yardstick for `coverage`
    (each draw is one of the S that make the band: a 1/S part of it)."""

    names: tuple[str, ...]
    t: np.ndarray
    predicted: np.ndarray
    nominal: dict
    lower: dict
    upper: dict
    level: float
    disturbance: Disturbance
    num_samples: int
    num_dropped: int
    draw_coverage: dict

    def coverage_range(self, probability: float = 0.9) -> dict[str, np.ndarray]:
        """`{channel: (E, 2)}` the central `probability` range of `draw_coverage`: where a
        correct model's coverage of each record falls with that probability."""
        q = ((1 - probability) / 2, (1 + probability) / 2)
        return {c: np.quantile(v, q, axis=1).T for c, v in self.draw_coverage.items()}

    def coverage(self, dataset) -> dict[str, np.ndarray]:
        """`{channel: (E,)}` the fraction of each record's predicted samples whose
        measured value lies inside the band."""
        ds = dataset if isinstance(dataset, Dataset) else Dataset.from_experiments(
            list(dataset) if isinstance(dataset, (list, tuple)) else [dataset])
        out = {}
        for c in self.lower:
            y = np.asarray(getattr(ds, c))[:, : self.t.shape[1]]
            inside = (y >= self.lower[c]) & (y <= self.upper[c]) & self.predicted
            out[c] = inside.sum(axis=1) / np.maximum(self.predicted.sum(axis=1), 1)
        return out


@eqx.filter_jit
def _runs(model, names, values, windows, key, noise_std, start_std):
    """(S, C, E, W, L) outputs of the runs: parameters `values` (S, d), the start's
    `START` values and the outputs with sensor noise of `start_std` (4,) and `noise_std`
    (C,)."""
    k_start, k_noise = jax.random.split(key)
    shape = (values.shape[0],) + windows.dt.shape
    jitter = jax.random.normal(k_start, (len(START),) + shape) * start_std[:, None, None, None]

    def one(p, jit):
        start = windows.start
        for i, c in enumerate(START):
            if getattr(start, c) is not None:
                start = eqx.tree_at(lambda s, c=c: getattr(s, c), start,
                                    getattr(start, c) + jit[i])
        return _predict(rebuild(model, names, p), dataclasses.replace(windows, start=start))

    out = jax.vmap(one, in_axes=(0, 1))(values, jitter)
    return out + jax.random.normal(k_noise, out.shape) * noise_std[None, :, None, None, None]


def _unit_disturbance(e, dt, tau):
    """(S, E, W, L) Gauss-Markov samples of unit std from zero at the window start, from
    the normal draws `e` (S, E, W, L) and the intervals `dt` (E, W) (module docstring),
    and their trapezoid integral. The recursion is a first-order filter along the samples,
    run by `scipy.signal.lfilter` once per distinct interval."""
    b = np.full_like(e, np.nan)  # NaN where an interval is not finite, as the recursion gives
    for step in np.unique(dt[np.isfinite(dt)]):
        a = math.exp(-step / tau)
        where = dt == step
        b[:, where] = scipy.signal.lfilter([math.sqrt(1.0 - a * a)], [1.0, -a],
                                           e[:, where], axis=-1)
    before = np.concatenate([np.zeros(b.shape[:-1] + (1,)), b[..., :-1]], axis=-1)
    return b, np.cumsum(0.5 * (before + b), axis=-1) * dt[..., None]


def _central_interval(runs, level):
    """The `(1 - level) / 2` and `(1 + level) / 2` quantiles of `runs` along its last
    axis, interpolated linearly between order statistics as `numpy.quantile` does by
    default (Hyndman and Fan 1996, definition 7), from one sort."""
    ordered = np.sort(runs, axis=-1)
    out = []
    for q in ((1 - level) / 2, (1 + level) / 2):
        position = q * (ordered.shape[-1] - 1)
        k = min(int(position), ordered.shape[-1] - 2)
        low, high, t = ordered[..., k], ordered[..., k + 1], position - k
        # numpy's lerp: from the nearer order statistic
        out.append(low + t * (high - low) if t < 0.5 else high - (1 - t) * (high - low))
    return out


class _Runs:
    """The runs of one set of draws, to which disturbances are added (`bands`)."""

    def __init__(self, result, dataset, *, covariance, measurement_std, num_samples,
                 estimator, seed):
        if num_samples < 2:
            raise ValueError(f"`num_samples` must be at least 2, got {num_samples!r}.")
        if not isinstance(estimator, PredictionError):
            raise ValueError(f"`estimator` must be a PredictionError (its replay of the "
                             f"records), got {type(estimator).__name__}.")
        model = as_arrays(result.model if isinstance(result, FitResult) else result)
        ds, windows, self.layout = prepare_fit(model, dataset, estimator)
        needed = min(stable_substeps(model, windows, refuse=False), MAX_SUBSTEPS)
        if needed > windows.substeps:
            windows = dataclasses.replace(windows, substeps=needed)
        rng = np.random.default_rng(seed)
        names, values = _parameter_draws(result, covariance, num_samples, rng)
        noise = dict(measurement_std or {})
        unknown = sorted(set(noise) - set(windows.channels))
        if unknown:
            raise ValueError(f"`measurement_std` names {unknown}, which the estimator does "
                             f"not predict ({windows.channels}).")
        noise_std = jnp.asarray([float(noise.get(c, 0.0)) for c in windows.channels])
        start_std = jnp.asarray([float(noise.get(c, 0.0)) for c in START])
        out = np.asarray(_runs(model, names, jnp.asarray(values), windows,
                               jax.random.key(seed), noise_std, start_std), dtype=np.float64)
        finite = np.all(np.isfinite(out), axis=tuple(range(1, out.ndim)))
        if finite.sum() < 2:
            raise ValueError(f"{num_samples - int(finite.sum())} of {num_samples} runs were "
                             "not finite: the draws leave the region where the model can be "
                             "simulated; check the fit's covariance.")
        runs = out[finite]
        # (C, E, W, L, S): the draws last and contiguous, as the quantiles sort along them
        self.ds, self.channels = ds, windows.channels
        self.runs = np.ascontiguousarray(np.moveaxis(runs, 0, -1))
        self.num_samples, self.num_dropped = num_samples, int(num_samples - finite.sum())
        self.nominal = np.asarray(_predict_jit(model, windows), dtype=np.float64)
        self.dt = np.asarray(windows.dt, dtype=np.float64)
        self.normals = rng.standard_normal(runs.shape[:1] + runs.shape[2:])
        self.unit = {}  # tau -> the unit disturbance and its integral, (E, W, L, S) each

    def bands(self, level, disturbance) -> PredictionBands:
        if not 0 < level < 1:
            raise ValueError(f"`level` must be between 0 and 1, got {level!r}.")
        if not isinstance(disturbance, Disturbance):
            raise ValueError(f"`disturbance` must be a jaxship.Disturbance, got "
                             f"{type(disturbance).__name__}.")
        if disturbance.tau not in self.unit:
            self.unit[disturbance.tau] = tuple(
                np.ascontiguousarray(np.moveaxis(x, 0, -1))
                for x in _unit_disturbance(self.normals, self.dt, disturbance.tau))
        b, integral = self.unit[disturbance.tau]
        added = {"r": disturbance.std * b, "psi": disturbance.std * integral}
        shape = (self.ds.num_experiments, self.ds.num_samples)
        nominal, lower, upper, draws = {}, {}, {}, {}
        for c, name in enumerate(self.channels):
            runs = self.runs[c] + added.get(name, 0.0)
            lo, hi = _central_interval(runs, level)
            nominal[name], hit = to_timeline(self.nominal[c], self.layout, shape)
            lower[name], _ = to_timeline(lo, self.layout, shape)
            upper[name], _ = to_timeline(hi, self.layout, shape)
            inside, _ = to_timeline((runs >= lo[..., None]) & (runs <= hi[..., None]),
                                    self.layout, shape)
            draws[name] = inside.sum(axis=1) / np.maximum(hit.sum(axis=1), 1)[:, None]
        return PredictionBands(
            names=tuple(self.ds.names), t=np.asarray(self.ds.t), predicted=np.asarray(hit),
            nominal=nominal, lower=lower, upper=upper, level=float(level),
            disturbance=disturbance, num_samples=self.num_samples,
            num_dropped=self.num_dropped, draw_coverage=draws)


def _determined_std(report, std) -> np.ndarray:
    """`std` as floats; `ValueError` where the fit does not determine a parameter."""
    std = np.asarray(std, dtype=np.float64)
    bad = [n for n, s in zip(report.names, std) if not np.isfinite(s)]
    if bad:
        raise ValueError(f"the fit does not determine {', '.join(bad)} (infinite standard "
                         "error): no band from its covariance; fix them or pass "
                         "`covariance=None`.")
    return std


class RobustCovariance(eqx.Module):
    """`covariance=RobustCovariance()` (the default): parameters drawn from $N(\\hat\\theta,
    D_r C D_r)$, the robust (HAC) standard errors $D_r$ with the fit's correlation $C$
    (the white-noise ones where no robust ones were computed)."""

    def draws(self, report, num_samples: int, rng) -> np.ndarray:
        std = report.std if report.std_robust is None else report.std_robust
        return normal_draws(report.values, _determined_std(report, std), report.correlation,
                            num_samples, rng)


class WhiteCovariance(eqx.Module):
    """`covariance=WhiteCovariance()`: parameters drawn from the fit's usual (white-noise)
    covariance $D C D$."""

    def draws(self, report, num_samples: int, rng) -> np.ndarray:
        return normal_draws(report.values, _determined_std(report, report.std),
                            report.correlation, num_samples, rng)


class GivenCovariance(eqx.Module):
    """`covariance=GivenCovariance(matrix)`: parameters drawn from $N(\\hat\\theta,$
    `matrix`$)$, a (d, d) covariance of the free parameters."""

    matrix: np.ndarray

    def draws(self, report, num_samples: int, rng) -> np.ndarray:
        values = np.asarray(report.values, dtype=np.float64)
        cov = np.asarray(self.matrix, dtype=np.float64)
        if cov.shape != (values.size, values.size):
            raise ValueError(f"`covariance` must be ({values.size}, {values.size}) for the "
                             f"free parameters {report.names}, got {cov.shape}.")
        return rng.multivariate_normal(values, cov, size=num_samples, method="eigh")


COVARIANCES = (RobustCovariance, WhiteCovariance, GivenCovariance)


def _parameter_draws(result, covariance, num_samples, rng) -> tuple[tuple, np.ndarray]:
    """`(names, (S, d) draws)` of the free parameters of a `FitResult` by the
    `covariance` strategy (None: the estimates only); none of a model taken as known."""
    if covariance is not None and not isinstance(covariance, COVARIANCES):
        raise ValueError(f"`covariance` must be RobustCovariance(), WhiteCovariance(), "
                         f"GivenCovariance(matrix) or None, got {covariance!r}.")
    if not isinstance(result, FitResult):
        if isinstance(covariance, GivenCovariance):
            raise ValueError("a `covariance` array needs the `FitResult` of its parameters.")
        return (), np.zeros((num_samples, 0))
    report = result.parameters
    values = np.asarray(report.values, dtype=np.float64)
    if covariance is None:
        return report.names, np.broadcast_to(values, (num_samples, values.size))
    return report.names, covariance.draws(report, num_samples, rng)


def normal_draws(values, std, correlation, num_samples: int, rng) -> np.ndarray:
    """`(num_samples, d)` draws from $N(\\hat\\theta, D C D)$: the estimates `values`,
    standard errors `std` ($D$) and `correlation` ($C$; None: independent draws)."""
    values, std = np.asarray(values, np.float64), np.asarray(std, np.float64)
    corr = np.eye(values.size) if correlation is None else np.asarray(correlation, np.float64)
    cov = corr * np.outer(std, std)
    return rng.multivariate_normal(values, cov, size=num_samples, method="eigh",
                                   check_valid="ignore")  # rounding: slightly negative


def prediction_bands(result, dataset, *, level: float = 0.9,
                     disturbance: Disturbance = Disturbance(),
                     covariance: RobustCovariance | WhiteCovariance | GivenCovariance | None = (
                         RobustCovariance()),
                     measurement_std: dict | None = None, num_samples: int = 200,
                     estimator: PredictionError = PredictionError(horizon=None),
                     seed: int = 0) -> PredictionBands:
    """The central `level` band of the outputs that `result`'s model predicts for
    `dataset`, from its parameter uncertainty, the `disturbance` and sensor noise (module
    docstring), by `num_samples` runs.

    **Arguments:**

    - `result`: a `FitResult` (its model, free parameters and covariance), or a model
      taken as known (no parameter uncertainty);
    - `dataset`: the records (`Experiment`s or a `Dataset`), replayed as `estimator`
      (a `PredictionError`: its horizon, channels, wind and holds) replays them;
    - `covariance`: how the parameters are drawn: `RobustCovariance()` (default),
      `WhiteCovariance()` (the usual standard errors), `GivenCovariance(matrix)` (a
      (d, d) array for the free parameters), or None (the estimates only);
    - `measurement_std`: `{channel: std}` of the sensors in SI (none by default);
    - `seed`: of the random draws (the same seed, the same bands).

    **Raises:** `ValueError` for a bad level or sample count, a covariance that leaves a
    parameter undetermined, and what `predict` raises for bad data.
    """
    return _Runs(result, dataset, covariance=covariance, measurement_std=measurement_std,
                 num_samples=num_samples, estimator=estimator, seed=seed
                 ).bands(level, disturbance)


def calibrate_disturbance(result, train, *, level: float = 0.9,
                          covariance: RobustCovariance | WhiteCovariance | GivenCovariance
                          | None = RobustCovariance(),
                          measurement_std: dict | None = None, num_samples: int = 200,
                          estimator: PredictionError = PredictionError(horizon=None),
                          seed: int = 0, iterations: int = 14) -> Disturbance:
    """The `Disturbance` whose bands (`prediction_bands` with these arguments) cover
    `level` of the training records' r samples (its `std`) and of their psi samples (its
    `tau`, the heading's spread growing with it): nested bisections on $\\log\\tau$ over
    1 s .. 1e4 s and $\\log\\sigma$ over 1e-7 .. 1 rad/s, on one set of draws. The records
    should be those the model was fitted on; held-out records then test it. A model whose
    bands already cover `level` of both without a disturbance gets none."""
    runs = _Runs(result, train, covariance=covariance, measurement_std=measurement_std,
                 num_samples=num_samples, estimator=estimator, seed=seed)
    hits = lambda bands: bands.predicted.sum(axis=1)

    def covered(std, tau, channel):
        bands = runs.bands(level, Disturbance(std=std, tau=tau))
        return float(np.sum(bands.coverage(runs.ds)[channel] * hits(bands))
                     / np.sum(hits(bands)))

    def bisect(lo, hi, below):  # exp of the log-midpoint where `below` turns False
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if below(math.exp(mid)) else (lo, mid)
        return math.exp(hi)

    def std_for(tau):
        if covered(0.0, tau, "r") >= level:
            return 0.0
        return bisect(math.log(1e-7), 0.0, lambda std: covered(std, tau, "r") < level)

    if "psi" not in runs.channels or "r" not in runs.channels:
        raise ValueError("calibrating the disturbance needs the estimator to predict r and "
                         f"psi, not {runs.channels}.")
    tau = bisect(0.0, math.log(1e4), lambda tau: covered(std_for(tau), tau, "psi") < level)
    return Disturbance(std=std_for(tau), tau=tau)
