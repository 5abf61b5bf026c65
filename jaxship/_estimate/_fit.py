"""`fit`: prediction-error identification of response models with Levenberg-Marquardt.

The estimator restarts the model from the measured state every `horizon` seconds
and sums the squared, weighted output errors of all windows of all experiments
(vmapped; padding masked): Astrom & Kallstrom (1979) found a finite horizon of
6-60 s essential on full-scale data; `horizon=None` is output error and a horizon
of one sample equation error. The optimiser is `optimistix.LevenbergMarquardt` in
the scaled, unconstrained parameter space of `_params.Transform` (with MINPACK's
cost-based stopping rule added, `_lm.py`), the Jacobian by forward-mode autodiff
through the RK4 scan, computed once per evaluation (`_lm.stored_jacobian`).
"""

import math
import warnings

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from .._sharding import sharded_vmap
from .._steering._base import AbstractSteeringModel, propagate
from .._validate import (
    ParameterReport,
    least_squares_covariance,
    parameter_report,
    validate,
)
from ._lm import LevenbergMarquardt, SolverOutcome, solve_least_squares
from ._params import Transform, as_arrays, rebuild, resolve_free
from ._windows import Windows, as_dataset, build_windows, check_data, to_timeline


class IdentifiabilityWarning(UserWarning):
    """The data do not determine some estimated parameters well (see the flags of
    `FitResult.parameters`)."""


class ConvergenceWarning(UserWarning):
    """The optimiser stopped without meeting its tolerances."""


class PredictionError(eqx.Module):
    """Prediction-error estimator: the loss and the optimiser of `fit`.

    **Arguments:**

    - `horizon`: prediction horizon $T_p$ [s]. Each experiment is cut into windows
      of `round(horizon / dt)` samples (at least one, at most the record); every
      window starts from the measured state (r and psi at its first sample; hidden
      states as the model's `window_state` reconstructs them from the record, e.g.
      `Nomoto2` from the heading and the rudder integral). `None` (default): one window per
      experiment, output error (simulation error); `0` or any value below 1.5 dt:
      equation error (one-step-ahead prediction from measured states).
    - `channels`: fitted outputs, `"psi"` (heading, rad) and/or `"r"` (yaw rate,
      rad/s). Both are unwrapped records, so the heading error is a plain
      difference (no angle wrapping, which would make output error periodic).
      `"u"` and `"v"` (surge and sway velocity, m/s; measured in every experiment)
      are outputs of vessels and of steering models with a state of that name.
      `None` (default): `("psi", "r")` for steering models, `("psi", "r", "u", "v")`
      for vessels.
    - `weights`: per-channel residual weights (dict or sequence); default
      1 / (standard deviation of the measured channel), which makes the residuals
      dimensionless.
    - `rudder`: the replayed rudder channel, `"delta"` (measured angle) or
      `"delta_c"` (command).
    - `substeps`: RK4 steps per sample interval.
    - `solver`: an `optimistix` least-squares solver; by default jaxship's
      `LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-10)`: optimistix's solver that
      also stops, like MINPACK, once an accepted step lowers the cost by at most
      `ftol` relative (`jaxship/_estimate/_lm.py`).
    - `max_steps`: optimiser step limit.
    - `max_lag`: largest lag of the residual correlation tests [samples].
    - `initial`: `"measured"` (default) starts each window from the measured r and
      psi as they are; `"estimate"` adds corrections of the start r and psi of every
      window to the estimated parameters (nuisance parameters, reported in no table
      but counted in the FPE), which removes the errors-in-variables bias of a noisy
      start sample: use it for output error on noisy data (MATLAB's
      `InitialState='estimate'`). Costs two parameters per window. A list of
      `SmoothedStates` (one per experiment, from `jaxship.smooth_states`) starts
      the windows from the EKF + RTS smoothed r and psi instead (the targets stay
      the measurements).
    - `wind`: vessels only: replay the measured true wind (`wind_speed`,
      `wind_dir`, held over each interval) as loads of `jaxship.Wind` on the
      vessel's wind areas. Default False: calm water.
    """

    horizon: float | None = None
    channels: tuple[str, ...] | None = None
    weights: dict | tuple | None = None
    rudder: str = "delta"
    substeps: int = 1
    solver: optx.AbstractLeastSquaresSolver = LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-10)
    max_steps: int = 256
    max_lag: int = 25
    initial: str | list = "measured"
    wind: bool = False


def _predict(model, w: Windows, offsets=None):
    """Model outputs at the window samples, shape (C, E, W, L). `offsets` (E, W, 2):
    estimated corrections of the measured r and psi at the window starts, or None."""

    def one(start, delta, aux, dt, offset):
        x0 = model.window_state(start)
        psi0 = start.psi
        if offset is not None:
            x0 = x0.at[0].add(offset[0])
            psi0 = psi0 + offset[1]
        psi, r, states = propagate(model, x0, psi0, delta, aux, dt, w.substeps)
        out = {"psi": psi, "r": r}
        for c in w.channels:  # "u", "v": the model state of that name
            if c not in out:
                out[c] = states[:, model.state_names.index(c)]
        return out

    out = sharded_vmap(one, w.start, w.delta, w.aux, w.dt, offsets, batch_dims=2)
    return jnp.stack([out[c] for c in w.channels])


def _residuals(model, w: Windows, offsets=None):
    pred = _predict(model, w, offsets)
    diff = w.weights[:, None, None, None] * (w.targets - pred)
    return jnp.where(w.mask[None], diff, 0.0)


def _split(q, transform, w, offset_scale):
    """Physical model parameters and start offsets (or None) from the vector q."""
    d = len(transform.names)
    if offset_scale is None:
        return q[:d], None
    shape = w.start.r.shape + (2,)
    return q[:d], jnp.reshape(q[d:], shape) * offset_scale


def _residual_fn(z, args):
    model, transform, w, offset_scale = args
    p, offsets = _split(z, transform, w, offset_scale)
    return _residuals(rebuild(model, transform.names, transform.to_physical(p)), w, offsets)


@eqx.filter_jit
def _solve(z0, model, transform, windows, offset_scale, solver, max_steps):
    """LM from z0; the estimate z, result, steps, the physical parameters and start
    offsets q, the predictions (C, E, W, L) and the Jacobian with respect to q."""

    def physical(z):
        p, offsets = _split(z, transform, windows, offset_scale)
        p = transform.to_physical(p)
        return p if offsets is None else jnp.concatenate([p, jnp.reshape(offsets, (-1,))])

    z, result, steps, q, residual, jac = solve_least_squares(
        _residual_fn, solver, z0, (model, transform, windows, offset_scale), max_steps,
        physical)
    pred = windows.targets - residual / windows.weights[:, None, None, None]
    return z, result, steps, q[: len(transform.names)], pred, jac


@eqx.filter_jit
def _evaluate(z, model, transform, windows, offset_scale):
    """Physical parameters, predictions (C, E, W, L) and the Jacobian of the
    weighted residuals with respect to the physical parameters and the physical
    start offsets (C, E, W, L, d + 2 E W), by forward mode."""
    p, offsets = _split(z, transform, windows, offset_scale)
    p = transform.to_physical(p)
    q = p if offsets is None else jnp.concatenate([p, jnp.reshape(offsets, (-1,))])

    def f(q):
        pp, oo = q[: p.shape[0]], None
        if offsets is not None:
            oo = jnp.reshape(q[p.shape[0]:], offsets.shape)
        return _residuals(rebuild(model, transform.names, pp), windows, oo)

    pred = _predict(rebuild(model, transform.names, p), windows, offsets)
    return p, pred, jax.jacfwd(f)(q)


def _progress(**kwargs):
    jax.debug.print("step {}: trial cost {}, accepted cost {}", kwargs["num_steps"][1],
                    kwargs["loss_this_step"][1], kwargs["loss_last_accepted_step"][1])


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
    - `result`: the optimistix `RESULTS` code; `success`; `message`;
    - `num_steps`: optimiser steps; `cost`: $\\frac12\\sum$ of the squared weighted
      residuals at the optimum;
    - `weights`: `{channel: weight}`; `window_samples`: samples per window for each
      experiment; `horizon`: the estimator's horizon [s] (None: output error);
    - `names`, `values`, `std`, `covariance`, `correlation`: shortcuts.
    """

    model: eqx.Module  # an AbstractSteeringModel or an AbstractVessel
    parameters: ParameterReport
    metrics: dict
    predictions: dict
    predicted: np.ndarray
    result: optx.RESULTS
    num_steps: int
    cost: float
    weights: dict
    window_samples: tuple[int, ...]
    horizon: float | None
    experiment_names: tuple[str, ...]

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

    def interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """Normal confidence intervals `(lower, upper)` of the estimates at `level`
        (two-sided), from the standard errors."""
        z = _normal_quantile(0.5 + level / 2)
        return self.values - z * self.std, self.values + z * self.std

    def summary(self) -> str:
        horizon = "none (output error)" if self.horizon is None else f"{self.horizon} s"
        lines = [f"{type(self.model).__name__} fitted to {len(self.experiment_names)} "
                 f"experiment(s), horizon {horizon}: {self.message}, "
                 f"{self.num_steps} steps, cost {self.cost:.6g}",
                 self.parameters.table()]
        for c, m in self.metrics.items():
            lines.append(f"{c}: fit {m.fit_percent:.2f} %, loss {m.loss:.4g}, FPE {m.fpe:.4g}, "
                         f"residuals {'white' if m.white else 'not white'}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready summary: model name, parameters (value, std, unit), frozen
        values, metrics per channel, correlation, condition number, flags, result."""
        from .._validate import _to_plain

        fields = {n: getattr(self.model, n) for n in _field_names(self.model)}
        params = {
            n: {"value": float(v), "std": _to_plain(float(s)), "unit": u}
            for n, v, s, u in zip(self.names, self.values, self.std, self.parameters.units)
        }
        return {
            "model": type(self.model).__name__,
            "parameters": params,
            "frozen": {n: _to_plain(float(v)) for n, v in fields.items() if n not in params},
            "train": {c: m.to_dict() for c, m in self.metrics.items()},
            "correlation": _to_plain(self.correlation),
            "condition_number": _to_plain(self.parameters.condition_number),
            "flags": list(self.flags),
            "result": self.message,
            "success": self.success,
            "num_steps": int(self.num_steps),
            "cost": float(self.cost),
            "horizon": self.horizon,
            "window_samples": list(self.window_samples),
            "weights": {k: float(v) for k, v in self.weights.items()},
            "experiments": list(self.experiment_names),
        }


def _field_names(model):
    from .._vessel._base import AbstractVessel
    from ._params import parameter_fields

    if isinstance(model, AbstractVessel):
        from ._vessel_fit import vessel_coefficients

        return tuple(vessel_coefficients(model))
    return tuple(parameter_fields(model))


def _normal_quantile(p: float) -> float:
    """Standard normal quantile (Acklam's rational approximation, |error| < 1.2e-9)."""
    a = [-3.969683028665376e01, 2.209460984245205e02, -2.759285104469687e02,
         1.383577518672690e02, -3.066479806614716e01, 2.506628277459239e00]
    b = [-5.447609879822406e01, 1.615858368580409e02, -1.556989798598866e02,
         6.680131188771972e01, -1.328068155288572e01]
    c = [-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e00,
         -2.549732539343734e00, 4.374664141464968e00, 2.938163982698783e00]
    d = [7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e00,
         3.754408661907416e00]
    if not 0 < p < 1:
        raise ValueError(f"probability must be in (0, 1), got {p}.")
    low = 0.02425
    if p < low or p > 1 - low:
        q = math.sqrt(-2 * math.log(p if p < low else 1 - p))
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / (
            (((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1)
        return x if p < low else -x
    q = p - 0.5
    r = q * q
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q / (
        ((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1)


def _offset_scales(ds) -> np.ndarray:
    """Scales of the start corrections (r, psi): 1 % of each channel's spread."""
    mask = np.asarray(ds.mask)
    out = []
    for name in ("r", "psi"):
        y = np.asarray(getattr(ds, name), dtype=np.float64)
        mean = np.sum(np.where(mask, y, 0.0), axis=1, keepdims=True) / mask.sum(axis=1,
                                                                            keepdims=True)
        spread = math.sqrt(np.sum(np.where(mask, (y - mean) ** 2, 0.0)) / mask.sum())
        out.append(0.01 * spread if spread > 0 else 1e-3)
    return np.array(out)


def _excitation_flags(ds, rudder) -> list[str]:
    flags, constant = [], []
    for i, name in enumerate(ds.names):
        d = np.asarray(getattr(ds, rudder))[i, : ds.lengths[i]]
        if np.ptp(d) == 0.0:
            constant.append(name)
    if constant and len(constant) == ds.num_experiments:
        flags.append(
            f"the rudder input is constant in every experiment ({', '.join(constant)}): the "
            "data contain no excitation, so the steering parameters cannot be identified; "
            "use a zig-zag, PRBS or turning record."
        )
    elif constant:
        flags.append(f"the rudder input is constant in experiment(s) {', '.join(constant)}: "
                     "they add no excitation.")
    return flags


def fit(model: AbstractSteeringModel, dataset, *, estimator: PredictionError = PredictionError(),
        free=None, verbose=False) -> FitResult:
    """Estimate the free parameters of a response model from measured data.

    **Arguments:**

    - `model`: an `AbstractSteeringModel` whose field values are the start values
      (e.g. from `initial_estimate`) and the values of frozen parameters.
    - `dataset`: a `Dataset`, an `Experiment` or a list of experiments (merged:
      different lengths, sample intervals and propeller rates are fine). Each needs
      a measured rudder and uniform sampling; r and psi are measured or derived.
    - `estimator`: a `PredictionError` (horizon, channels, weights, solver).
    - `free`: which parameters to estimate: `None` (the model's defaults, see its
      `param` fields), a sequence of field names, or `{name: Free(value, lower=,
      upper=, scale=) or None}`.
    - `verbose`: print the optimiser's progress (True, or a callable taking the
      optimistix verbose keyword arguments).

    **Returns:** a `FitResult`. The covariance is $\\hat\\sigma^2(J^TJ)^{-1}$ in the
    physical parameters (per-channel noise variances: see
    `jaxship._validate.least_squares_covariance`), which is right for white
    residuals: output error with measurement noise only, or a horizon that makes the
    residuals white. Check `metrics[c].white`.

    **Raises:** `ValueError` for bad data (non-finite values, naming the experiment,
    channel and sample; no rudder record; non-uniform sampling), unknown parameter
    names or start values outside the bounds.

    **Warns:** `IdentifiabilityWarning` when the parameter report has flags (strong
    correlations, large relative errors, undetermined combinations, no excitation);
    `ConvergenceWarning` when the optimiser did not converge.
    """
    from .._vessel._base import AbstractVessel

    if not isinstance(estimator, PredictionError):
        raise ValueError(f"`estimator` must be a PredictionError, got {type(estimator).__name__}.")
    if isinstance(model, AbstractVessel):
        from ._vessel_fit import fit_vessel

        return fit_vessel(model, dataset, estimator=estimator, free=free, verbose=verbose)
    if not isinstance(model, AbstractSteeringModel):
        raise ValueError(f"`model` must be a jaxship steering model (AbstractSteeringModel) "
                         f"or vessel (AbstractVessel), got {type(model).__name__}.")
    if estimator.wind:
        raise ValueError("`wind=True` is for vessels; steering models have no wind loads.")
    ds = as_dataset(dataset)
    channels = ("psi", "r") if estimator.channels is None else tuple(estimator.channels)
    for c in channels:
        if c in ("u", "v") and c not in model.state_names:
            raise ValueError(f"unknown output channel {c!r} for {type(model).__name__}, whose "
                             f"outputs are psi, r and its states {model.state_names}.")
    check_data(ds, estimator.rudder, channels)
    if int(estimator.substeps) < 1:
        raise ValueError(f"`substeps` must be a positive integer, got {estimator.substeps}.")
    specs = resolve_free(model, free)
    transform = Transform.from_specs(specs)
    smoothed = not isinstance(estimator.initial, str)
    starts = _smoothed_starts(ds, estimator.initial) if smoothed else None
    if not smoothed and estimator.initial not in ("measured", "estimate"):
        raise ValueError(f"`initial` must be 'measured', 'estimate' or a list of smoothed "
                         f"states, got {estimator.initial!r}.")
    windows, layout = build_windows(ds, horizon=estimator.horizon, channels=channels,
                                    weights=estimator.weights, rudder=estimator.rudder,
                                    substeps=int(estimator.substeps), starts=starts)
    estimate_starts = estimator.initial == "estimate"
    if estimate_starts and min(layout["lengths"]) < 2:
        raise ValueError("`initial='estimate'` needs windows of at least 2 samples (with one "
                         "sample the estimated start explains every residual); use a longer "
                         "`horizon` or initial='measured'.")
    start = np.array([s.start for s in specs])
    z0 = transform.to_unconstrained(start)
    offset_scale = None
    if estimate_starts:
        offset_scale = jnp.asarray(_offset_scales(ds), dtype=float)
        z0 = np.concatenate([z0, np.zeros(windows.start.r.size * 2)])
    z0 = jnp.asarray(z0, dtype=float)
    solver = estimator.solver
    if verbose and hasattr(solver, "verbose"):
        solver = eqx.tree_at(lambda s: s.verbose, solver, verbose if callable(verbose)
                             else _progress)
    base = as_arrays(model)
    _, result, num_steps, p, pred, jac = _solve(z0, base, transform, windows, offset_scale,
                                                solver, int(estimator.max_steps))
    return _report(model, ds, estimator, specs, transform, windows, layout, p, pred, jac,
                   result, num_steps, estimate_starts=estimate_starts, verbose=verbose,
                   stacklevel=3)


def _smoothed_starts(ds, smoothed) -> dict:
    """`{"r": (E, N), "psi": (E, N)}` window starts from `SmoothedStates` (one per
    experiment of `ds`, e.g. from `jaxship.smooth_states`)."""
    smoothed = list(smoothed)
    if len(smoothed) != ds.num_experiments or not all(hasattr(s, "state") for s in smoothed):
        raise ValueError(f"`initial` as smoothed states needs one SmoothedStates per "
                         f"experiment ({ds.num_experiments}), got {len(smoothed)} items.")
    out = {}
    for name in ("r", "psi"):
        a = np.array(getattr(ds, name), dtype=np.float64)
        for i, s in enumerate(smoothed):
            if s.mean.shape[0] != ds.lengths[i]:
                raise ValueError(f"smoothed states {i} have {s.mean.shape[0]} samples, "
                                 f"experiment {ds.names[i]!r} has {ds.lengths[i]}.")
            a[i, :ds.lengths[i]] = s.state(name)
        out[name] = a
    return out


def _report(model, ds, estimator, specs, transform, windows, layout, p, pred, jac, result,
            num_steps, *, estimate_starts=False, verbose=False, stacklevel=2) -> FitResult:
    """The `FitResult` from the optimum: residuals, covariance, identifiability and
    validation metrics on the host (shared by steering-model and vessel fits)."""
    channels = windows.channels
    d = len(specs)
    values = np.asarray(p, dtype=np.float64)
    fitted = rebuild(model, transform.names, [float(v) for v in values])

    # residuals, Jacobian and covariance on the host
    pred = np.asarray(pred, dtype=np.float64)
    jac = np.asarray(jac, dtype=np.float64)
    targets = np.asarray(windows.targets, dtype=np.float64)
    mask = layout["mask"]
    weights = layout["weights"]
    columns = np.arange(d)
    if estimate_starts:  # the start offsets of windows that exist
        used = np.repeat(mask.any(axis=-1).reshape(-1), 2)
        columns = np.concatenate([columns, d + np.nonzero(used)[0]])
    resid = weights[:, None, None, None] * (targets - pred)
    rows = np.concatenate([resid[c][mask] for c in range(len(channels))])
    jrows = np.concatenate([jac[c][mask][:, columns] for c in range(len(channels))])
    groups = np.concatenate([np.full(int(mask.sum()), c) for c in range(len(channels))])
    cost = 0.5 * float(np.sum(rows**2))
    full, null = least_squares_covariance(jrows, rows, groups)
    covariance = full[:d, :d]
    null = [v[:d] / np.linalg.norm(v[:d]) for v in null if np.linalg.norm(v[:d]) > 1e-3]
    flags = _excitation_flags(ds, estimator.rudder)
    report = parameter_report(transform.names, values, covariance,
                              units=tuple(s.unit for s in specs), null_directions=null,
                              extra_flags=flags)
    num_params = columns.shape[0]

    shape = (ds.num_experiments, ds.num_samples)
    predictions, metrics = {}, {}
    u = np.asarray(getattr(ds, estimator.rudder), dtype=np.float64)
    for c, name in enumerate(channels):
        timeline, hit = to_timeline(pred[c], layout, shape)
        predictions[name] = timeline
        measured = np.asarray(getattr(ds, name), dtype=np.float64)
        metrics[name] = validate(measured, timeline, hit, num_params=num_params, u=u,
                                 max_lag=estimator.max_lag, channel=name)
    out = FitResult(
        model=fitted, parameters=report, metrics=metrics, predictions=predictions,
        predicted=hit, result=result, num_steps=int(num_steps), cost=cost,
        weights={c: float(w) for c, w in zip(channels, weights)},
        window_samples=tuple(layout["lengths"]), horizon=estimator.horizon,
        experiment_names=tuple(ds.names),
    )
    if verbose:
        print(out.summary())
    if not out.success:
        warnings.warn(f"fit of {type(model).__name__}: the optimiser stopped without "
                      f"converging ({out.message}).", ConvergenceWarning, stacklevel=stacklevel)
    if report.flags:
        warnings.warn(f"fit of {type(model).__name__}: " + " ".join(report.flags),
                      IdentifiabilityWarning, stacklevel=stacklevel)
    return out
