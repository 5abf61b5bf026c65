"""`fit`, the one verb of estimation, and its prediction-error strategy.

The estimator restarts the model from the measured state every `horizon` seconds
and sums the squared, weighted output errors of all windows of all experiments
(vmapped; padding masked): Astrom & Kallstrom (1979) found a finite horizon of
6-60 s essential on full-scale data; `horizon=None` is output error and a horizon
of one sample equation error. The optimiser is `optimistix.LevenbergMarquardt` in
the scaled, unconstrained parameter space of `_params.Transform` (with MINPACK's
cost-based stopping rule added, `_lm.py`), the Jacobian by forward-mode autodiff
through the simulator's time loop (`_integrate.integrate`), computed once per evaluation
(`_lm.stored_jacobian`). Steering models and vessels alike (the shared model contract).
"""

import abc
import contextlib
import dataclasses
import math
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from .._foundation._contract import rebuild
from .._foundation._covariance import (
    cluster_from_windows,
    hac_from_windows,
    least_squares_covariance,
)
from .._foundation._exported import persistent
from .._foundation._parameter_report import RobustErrors, parameter_report
from .._foundation._params import Transform, as_arrays, resolve_free
from .._foundation._progress import ProgressCallback, reporting_steps
from .._foundation._sharding import sharded_vmap
from .._models._holds import FirstOrderHold, ZeroOrderHold
from .._simulation._data import Dataset
from .._simulation._integrate import Simulator, integrate, replay_policy
from ._excitation import excitation_flags
from ._initial import EstimatedStarts, MeasuredStates
from ._linear import LinearStart
from ._lm import (
    RESULTS,
    BlockDampedNewtonDescent,
    Chunk,
    LevenbergMarquardt,
    as_code,
    blockwise_jacfwd,
    solve_least_squares,
    value_and_jacfwd,
)
from ._prepare import prepare_fit, start_strategy
from ._prior import (
    PRIOR_PASSES,
    PRIOR_RTOL,
    GaussianPrior,
    Prior,
    posterior_fields,
    with_prior_rows,
)
from ._result import FitError, FitResult, Prediction, Validation, assemble_result
from ._step import MAX_SUBSTEPS, stable_substeps
from ._verdict import final_verdict, optimiser_verdict
from ._windows import Windows, to_timeline


# windows needed for window-clustered standard errors (Cameron & Miller 2015 advise
# against few clusters); with fewer, the Newey-West HAC covariance is used
MIN_CLUSTERS = 20
# optimiser steps between two progress reports of a fit (`_solve_reporting`): the README's
# identify example converges in 5, the 20-coefficient vessel fit of benchmarks/fit.py in 34
PROGRESS_STEPS = 8


class AbstractEstimator(eqx.Module):
    """A strategy of `fit`: how the model is compared with the data and the comparison
    minimised. Subclasses implement `fit(model, dataset, free, progress) -> FitResult`:
    `PredictionError` (output error, equation error and every horizon between),
    `Innovations` (the Kalman filter's one-step-ahead errors, by prediction error or
    maximum likelihood with estimated noise) and `ARMAX` (for `ARMAXModel`)."""

    @abc.abstractmethod
    def fit(self, model, dataset, free, progress) -> "FitResult":
        """Estimate the free parameters of `model` from `dataset` (see `jaxship.fit`)."""

    @abc.abstractmethod
    def predict(self, model, dataset) -> "Prediction":
        """The estimator's predictions of `dataset`'s outputs by `model`, validated
        (see `jaxship.predict`)."""


class PredictionError(AbstractEstimator):
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
      are outputs of vessels and of steering models with a state of that name;
      `"x"` and `"y"` (earth-fixed position, m; measured, e.g. GNSS) of vessels,
      whose windows then start from the measured position. `None` (default):
      `("psi", "r")` for steering models, `("psi", "r", "u", "v")` for vessels.
    - `weights`: per-channel residual weights (dict or sequence); default
      1 / (standard deviation of the measured channel), which makes the residuals
      dimensionless.
    - `rudder`: the replayed rudder channel, `"delta"` (measured angle) or
      `"delta_c"` (command).
    - `simulator`: the numerics of the predictions (`jaxship.Simulator`): its solver
      (classical RK4 by default, or any diffrax solver, adaptive with a step-size
      controller) and its steps per sample interval (`substeps`, or `max_step` [s];
      default one step per sample), at least: a start model whose fastest mode (the
      largest eigenvalue modulus $\\rho$ of its field's Jacobian at the first window
      start) makes one RK4 step unstable gets more, so that
      $\\rho\\,dt/\\text{steps} \\le 2.5$ (RK4 is stable to 2.785 on the real axis).
    - `solver`: an `optimistix` least-squares solver; by default jaxship's
      `LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-10)`: optimistix's solver with
      Nielsen's damping update (and optional geodesic acceleration) that also stops,
      like MINPACK, once an accepted step lowers the cost by at most `ftol` relative
      (`jaxship/_estimate/_lm.py`).
    - `max_steps`: optimiser step limit (0: the start values are the estimates).
    - `start`: a start-value strategy run before the optimiser, `LinearStart()` (the
      equation-error least-squares estimates of the free parameters of `Nomoto1`,
      `NonlinearNomoto` and `RossAutopilot`); None (default): the model's values.
    - `max_lag`: largest lag of the residual correlation tests [samples].
    - `initial`: where each window starts: `MeasuredStates()` (default), the measured r
      and psi as they are; `EstimatedStarts()`, with corrections of the start r and psi
      of every window estimated too (for output error on noisy data). A list of
      `SmoothedStates` (one per experiment, from `jaxship.smooth_states`) starts
      the windows from the EKF + RTS smoothed r and psi instead (and a vessel's u and
      v: so a vessel can be fitted to records without a logged v); the targets stay
      the measurements.
    - `wind`: vessels only: replay the measured true wind (`wind_speed`,
      `wind_dir`) as loads of `jaxship.Wind` on the vessel's wind areas. Default
      False: calm water.
    - `hold`: how the replayed signals are interpolated between samples (MATLAB's
      `InterSample`): `None` (default) linearly for measured, continuous signals
      (the rudder angle `delta`, `n`, `u`, `v`, the wind speed: first-order hold) and
      held for commands (`delta_c`) and the wind direction (zero-order hold);
      `ZeroOrderHold()` or `FirstOrderHold()` for all; or a dict by channel name
      overriding some.
    - `prior`: a Gaussian prior on the free coefficients (`jaxship.strategies.Prior`):
      the fit returns the maximum a posteriori estimate with its posterior covariance,
      charges FPE, AIC and BIC for the effective number of parameters and reports each
      coefficient's prior and the data's share of its information (`FitResult.prior`).
      None (default): no prior, least squares.
    """

    horizon: float | None = None
    channels: tuple[str, ...] | None = None
    weights: dict | tuple | None = None
    rudder: str = "delta"
    simulator: Simulator = Simulator(max_step=math.inf)
    solver: optx.AbstractLeastSquaresSolver = LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-10)
    max_steps: int = 256
    start: LinearStart | None = None
    max_lag: int = 25
    initial: MeasuredStates | EstimatedStarts | list = MeasuredStates()
    wind: bool = False
    hold: ZeroOrderHold | FirstOrderHold | dict | None = None
    prior: Prior | None = None

    def fit(self, model, dataset, free=None, progress=None) -> "FitResult":
        return _fit_prediction_error(self, model, dataset, free, progress)

    def predict(self, model, dataset) -> "Prediction":
        """The windows of `fit` (a free simulation of each record for `horizon=None`),
        integrated with the step that follows the model's fastest mode, as in `fit`."""
        ds, windows, layout = prepare_fit(model, dataset, self)
        model = as_arrays(model)
        needed = min(stable_substeps(model, windows, refuse=False), MAX_SUBSTEPS)
        if needed > windows.substeps:
            windows = dataclasses.replace(windows, substeps=needed)
        pred = np.asarray(_predict_jit(model, windows), dtype=np.float64)
        shape = (ds.num_experiments, ds.num_samples)
        predictions = {}
        for c, name in enumerate(windows.channels):
            predictions[name], hit = to_timeline(pred[c], layout, shape)
        return Prediction.validated(ds, predictions, hit, rudder=self.rudder,
                                    max_lag=self.max_lag, horizon=self.horizon,
                                    window_samples=layout["lengths"])


def _predict(model, w: Windows, offsets=None):
    """Model outputs at the window samples, shape (C, E, W, L). `offsets` (E, W, 2):
    estimated corrections of the measured r and psi at the window starts, or None.
    Any model of the shared contract (`replay_state`, `replay_field`, `channel_index`)."""
    field = model.replay_field(w.servo)  # built once per evaluation (e.g. M^-1)
    index = [model.channel_index(c) for c in w.channels]
    corrected = jnp.array([model.channel_index("r"), model.channel_index("psi")])
    holds = dict(w.holds)

    def one(start, records, dt, offset):
        y0 = model.replay_state(start, w.servo)
        if offset is not None:
            y0 = y0.at[corrected].add(offset)
        ground = start.ground_scale
        y0 = model.with_current(y0, -ground)  # over-ground u, v: through the water
        num = records["delta"].shape[0] - 1

        def observe(y, _):  # and u, v over ground again where the record's are
            y = model.with_current(y, ground)
            return jnp.stack([model.measure(c, y[i]) for c, i in zip(w.channels, index)])

        out, _ = integrate(lambda t, y, a: field(t, y, a[0].at(t - a[1])), y0,
                           (replay_policy(records, dt, holds), None), (0.0, dt, num),
                           w.simulator, w.substeps, observe, emit="end")
        return out  # (L, C)

    out = sharded_vmap(one, w.start, w.records, w.dt, offsets, batch_dims=2)
    return jnp.moveaxis(out, -1, 0)


@persistent  # traced and lowered once per installation
@eqx.filter_jit
def _predict_jit(model, w: Windows):
    """`_predict` compiled."""
    return _predict(model, w)


def _start_residuals(model, w: Windows) -> np.ndarray:
    """The weighted residuals of `model` at the windows' valid samples (NumPy)."""
    pred = np.asarray(_predict_jit(as_arrays(model), w), dtype=np.float64)
    resid = np.asarray(w.weights)[:, None, None, None] * (w.targets - pred)
    return resid[np.broadcast_to(np.asarray(w.mask), resid.shape)]


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


class _Args(NamedTuple):
    """The residual function's arguments: the model as arrays, the transform of its free
    parameters, the windows, the start offsets' scale (None: measured starts) and the
    prior's arrays `(mean, sigma / sd)` of its residual rows (None: no prior)."""

    model: object
    transform: Transform
    windows: Windows
    offset_scale: object = None
    prior: object = None


def _residual_fn(z, args):
    model, transform, w, offset_scale, prior = args
    p, offsets = _split(z, transform, w, offset_scale)
    physical = transform.to_physical(p)
    out = _residuals(rebuild(model, transform.names, physical), w, offsets)
    if prior is None:
        return out
    mean, weight = prior  # the prior's rows sigma (p - mu) / s (`_prior.py`) as one
    return with_prior_rows(out, weight * (physical - mean))  # more channel


@persistent  # traced and lowered once per installation
@eqx.filter_jit
def _solve(z0, args: _Args, solver, max_steps, chunk=None):
    """LM from z0; the estimate z, result, steps, the physical parameters and start
    offsets q, the predictions (C, E, W, L) and the Jacobian with respect to q (and
    with a `Chunk`, `resume` and `stopped`: `solve_least_squares`)."""
    _, transform, windows, offset_scale, prior = args

    def physical(z):
        p, offsets = _split(z, transform, windows, offset_scale)
        p = transform.to_physical(p)
        return p if offsets is None else jnp.concatenate([p, jnp.reshape(offsets, (-1,))])

    jacobian = value_and_jacfwd
    if offset_scale is not None:  # each window's start corrections: block-sparse columns
        shared_and_blocks = (len(transform.names), windows.start.r.shape)
        jacobian = blockwise_jacfwd(*shared_and_blocks)
        if isinstance(solver, LevenbergMarquardt) and solver.blockwise:  # block by block
            solver = eqx.tree_at(lambda s: s.descent, solver,
                                 BlockDampedNewtonDescent(*shared_and_blocks))
    z, result, steps, q, residual, jac, *part = solve_least_squares(
        _residual_fn, solver, z0, args, max_steps, physical, jacobian, chunk)
    if prior is not None:  # the windows' channels, without the prior's
        residual, jac = residual[:-1], jac[:-1]
    pred = windows.targets - residual / windows.weights[:, None, None, None]
    return (z, result, steps, q[: len(transform.names)], pred, jac, *part)


def _solve_reporting(z0, args: _Args, solver, max_steps, report):
    """`_solve` in parts of at most `PROGRESS_STEPS` steps (`Chunk`), `report(steps,
    cost)` after each: the same steps, iterates and outcome, and no host callback in
    the compiled programs (one for the first part, one for the others)."""
    if max_steps == 0 or not isinstance(solver, LevenbergMarquardt):
        return _solve(z0, args, solver, max_steps)
    windows = args.windows
    z, resume, total = z0, None, 0
    while True:
        chunk = Chunk(resume, jnp.asarray(min(PROGRESS_STEPS, max_steps - total)))
        z, result, steps, q, pred, jac, resume, stopped = _solve(z, args, solver, max_steps,
                                                                 chunk)
        total += int(steps)
        residual = np.asarray(windows.weights)[:, None, None, None] * (
            np.asarray(windows.targets) - np.asarray(pred))  # NumPy: no XLA program
        report(total, 0.5 * float(np.sum(np.where(np.asarray(windows.mask)[None], residual,
                                                  0.0) ** 2)))
        if bool(stopped) or total >= max_steps:
            break
    if not bool(stopped):  # as optimistix says when its loop ends on `max_steps`
        result = optx.RESULTS.nonlinear_max_steps_reached
    return z, result, jnp.asarray(total), q, pred, jac


def fit(model, dataset, *, estimator: AbstractEstimator = PredictionError(), free=None,
        progress: ProgressCallback | None = None, throw: bool = False) -> FitResult:
    """Estimate the free parameters of a steering model or a vessel from measured data.

    **Arguments:**

    - `model`: any model of the shared contract, a steering model
      (`AbstractSteeringModel`) or a 3-DOF vessel (`AbstractVessel`), whose field
      values are the start values and the values of frozen parameters.
    - `dataset`: a `Dataset`, an `Experiment` or a list of experiments (merged:
      different lengths, sample intervals and propeller rates are fine). Each needs
      a measured rudder and uniform sampling; r and psi are measured or derived; a
      vessel's windows start from the measured u and v too.
    - `estimator`: the strategy (`AbstractEstimator`): `PredictionError` (horizon,
      channels, weights, holds, solver, start values `LinearStart`; the default),
      `Innovations` (the Kalman filter's innovations, maximum likelihood with the
      noise), `ARMAX` or `DiscreteResponse`.
    - `free`: which parameters to estimate: `None` (the model's defaults: its `param`
      fields declared free), a sequence of field
      names, or `{name: Free(value, lower=, upper=, scale=) or None}`.
    - `progress`: a callable receiving `Progress` reports of the optimiser's steps, at
      most `PROGRESS_STEPS` (8) steps apart (the library never prints). The fit is the
      same with or without one, bit for bit.
    - `throw`: raise `FitError` (the code's sentence) unless the fit converged. Default
      False: the outcome is `FitResult.result`, for batches of fits.

    **Returns:** a `FitResult` whose `result` code (`jaxship.RESULTS`) says what the fit
    knows: `successful` only when the optimiser converged, the simulation stayed finite,
    the estimates moved from a start where the cost was not stationary, no estimate sits
    on a bound (`at_bound`), the fit explains more than noise would or determines every
    parameter's sign (`undetermined`: no channel's fit reaches 5 % and a parameter's 95 %
    interval includes zero) and the data determine every combination of the parameters
    (`poorly_determined`); the flags of `parameters` say which. The covariance is
    $\\hat\\sigma^2(J^TJ)^{-1}$ in the physical parameters (per-channel noise variances:
    see `jaxship._foundation._covariance.least_squares_covariance`), which is right for
    white residuals: output error with measurement noise only, or a horizon that makes
    the residuals white. Check `metrics[c].white`.

    **Raises:** `ValueError` for bad data (non-finite values, naming the experiment,
    channel and sample; no rudder record; non-uniform sampling; a channel the model
    needs but the record lacks), unknown parameter names or start values outside the
    bounds; `FitError` with `throw=True` when the fit did not converge.
    """
    if not isinstance(estimator, AbstractEstimator):
        raise ValueError(f"`estimator` must be a jaxship estimator (PredictionError, "
                         f"Innovations, ARMAX, DiscreteResponse), got "
                         f"{type(estimator).__name__}.")
    out = final_verdict(estimator.fit(model, dataset, free, progress), model, free)
    if throw and not out.success:
        raise FitError(f"fit of {type(model).__name__}: {out.message}"
                       + "".join(f" {f}" for f in out.parameters.undetermined
                                 + out.parameters.bound_flags))
    return out


def _fit_prediction_error(estimator, model, dataset, free, progress) -> FitResult:
    """`PredictionError.fit`: windows, Levenberg-Marquardt, the report."""
    if estimator.start is not None:
        model = estimator.start(model, dataset, free, estimator.rudder)
    ds, windows, layout = prepare_fit(model, dataset, estimator)
    specs = resolve_free(model, free)
    starts = start_strategy(estimator.initial)
    starts.check(layout["lengths"])
    base = as_arrays(model)
    needed = stable_substeps(base, windows)
    if needed > windows.substeps:  # the step follows the start model's fastest mode
        windows = dataclasses.replace(windows, substeps=needed)
    specs = _jacobian_scales(specs, base, windows)
    transform = Transform.from_specs(specs)
    z0 = transform.to_unconstrained(np.array([s.start for s in specs]))
    offset_scale, offsets0 = starts.start_parameters(ds, windows.start.r.size)
    if offset_scale is not None:
        offset_scale = jnp.asarray(offset_scale, dtype=float)
    z0 = jnp.asarray(np.concatenate([z0, offsets0]), dtype=float)
    solver = estimator.solver
    prior = GaussianPrior.build(estimator.prior, specs, model,
                                lambda: _start_residuals(model, windows))
    with reporting_steps(progress, f"fitting {type(model).__name__}",
                         int(estimator.max_steps)) as (step, finish):
        z, windows, optimum, prior = _optimise(
            z0, _Problem(base, ds, estimator, specs, transform, windows, layout, starts,
                         prior), offset_scale, solver, None if progress is None else step)
        out = _report(_Problem(model, ds, estimator, specs, transform, windows, layout,
                               starts, prior), optimum)
        finish(out.num_steps, out.cost)
    if offset_scale is not None:
        offsets = _split(z, transform, windows, offset_scale)[1]
        out = dataclasses.replace(out, start_offsets=np.asarray(offsets, dtype=np.float64))
    return out


def _optimise(z0, problem, offset_scale, solver, report=None):
    """Levenberg-Marquardt from z0 on `problem` (its model the start as arrays), refitted
    from the estimate with the integration steps its fastest mode needs and, with a prior,
    until the noise variance that weighs the prior settles (`_prior.py`); `report(steps,
    cost)` between parts of each run (`_solve_reporting`) where given. Returns `(z,
    windows, _Optimum, prior)`, the prior with the variance of the last solve."""
    base, transform, windows, prior = (problem.model, problem.transform, problem.windows,
                                       problem.prior)
    max_steps, total = int(problem.estimator.max_steps), 0
    for _ in range(1 if prior is None else PRIOR_PASSES):
        for _ in range(3):  # and the estimate's: refitted with the steps it needs
            args = _Args(base, transform, windows, offset_scale,
                         None if prior is None else prior.arrays())
            if report is None:
                solved = _solve(z0, args, solver, max_steps)
            else:  # steps counted on from the runs before
                solved = _solve_reporting(z0, args, solver, max_steps,
                                          lambda k, cost, t=total: report(t + k, cost))
            z, result, num_steps, p, pred, jac = solved
            total += int(num_steps)
            needed = stable_substeps(rebuild(base, transform.names, p), windows, refuse=False)
            if needed <= windows.substeps or needed > MAX_SUBSTEPS:
                break
            windows, z0 = dataclasses.replace(windows, substeps=needed), z
        if prior is None:
            break
        rows, jrows, _, _ = _rows(problem._replace(windows=windows), pred, jac)
        variance = prior.noise_variance(rows, jrows)
        if not abs(variance - prior.variance) > PRIOR_RTOL * prior.variance:
            break  # settled (or not finite: the report says the simulation blew up)
        prior, z0 = dataclasses.replace(prior, variance=variance), z
    return z, windows, _Optimum(p, pred, jac, result, total), prior


def _rows(problem, pred, jac):
    """`(rows, jrows, groups, columns)`: the weighted residuals (N,) of the windows'
    samples, channel by channel, their Jacobian (N, d + estimated window starts), the
    channel of each row and the Jacobian's columns used (the free parameters, then the
    start offsets of windows that exist, where they are estimated)."""
    channels, mask = problem.windows.channels, problem.layout["mask"]
    pred = np.asarray(pred, dtype=np.float64)
    jac = np.asarray(jac, dtype=np.float64)
    targets = np.asarray(problem.windows.targets, dtype=np.float64)
    d = len(problem.specs)
    columns = np.concatenate([np.arange(d), d + problem.starts.start_columns(mask)])
    resid = problem.layout["weights"][:, None, None, None] * (targets - pred)
    rows = np.concatenate([resid[c][mask] for c in range(len(channels))])
    jrows = np.concatenate([jac[c][mask][:, columns] for c in range(len(channels))])
    groups = np.concatenate([np.full(int(mask.sum()), c) for c in range(len(channels))])
    return rows, jrows, groups, columns


def _jacobian_scales(specs, model, windows):
    """Specs whose scale is 0 (unbounded parameters starting at zero) get the scale
    that gives their Jacobian column the median norm of the others (scaled)."""
    zero = np.array([s.scale == 0.0 for s in specs])
    if not zero.any():
        return specs
    provisional = [dataclasses.replace(s, scale=s.scale or 1.0) for s in specs]
    transform = Transform.from_specs(provisional)
    start = jnp.asarray([s.start for s in specs], dtype=float)
    jac = _jacobian(start, model, transform, windows)
    norms = np.sqrt(np.sum(np.asarray(jac, dtype=np.float64).reshape(-1, len(specs)) ** 2,
                           axis=0))
    scaled = norms * np.array([s.scale for s in provisional])
    reference = np.median(scaled[~zero]) if (~zero).any() else 1.0
    return tuple(
        dataclasses.replace(s, scale=float(reference / norms[i]) if norms[i] > 0 else 1.0)
        if zero[i] else s for i, s in enumerate(specs))


@persistent  # traced once per installation
@eqx.filter_jit
def _jacobian(p, model, transform, windows):
    """Forward-mode Jacobian (C, E, W, L, d) of the weighted residuals with respect to
    the physical parameters p."""
    return jax.jacfwd(lambda q: _residuals(rebuild(model, transform.names, q), windows))(p)


class _Problem(NamedTuple):
    """A prediction-error fit as posed: the start model, its data and estimator, the free
    parameters and their transform, the windows (as last solved) and their layout, the
    start strategy."""

    model: object
    ds: Dataset
    estimator: object
    specs: list
    transform: Transform
    windows: object
    layout: dict
    starts: object
    prior: GaussianPrior | None = None


class _Optimum(NamedTuple):
    """What `_solve` found: parameters, window predictions, Jacobian, the optimiser's
    result and its number of steps."""

    p: object
    pred: object
    jac: object
    result: object
    num_steps: object


def _report(problem: _Problem, optimum: _Optimum) -> FitResult:
    """The `FitResult` from the optimum: residuals, covariance, identifiability and
    validation metrics on the host (shared by steering-model and vessel fits)."""
    model, ds, estimator, specs, transform, windows, layout, starts, prior = problem
    p, pred, jac, result, num_steps = optimum
    channels = windows.channels
    d = len(specs)
    values = np.asarray(p, dtype=np.float64)
    fitted = rebuild(model, transform.names, [float(v) for v in values])

    # residuals, Jacobian and covariance on the host
    rows, jrows, groups, columns = _rows(problem, pred, jac)
    pred = np.asarray(pred, dtype=np.float64)
    jac = np.asarray(jac, dtype=np.float64)
    targets = np.asarray(windows.targets, dtype=np.float64)
    mask = layout["mask"]
    weights = layout["weights"]
    resid = weights[:, None, None, None] * (targets - pred)
    code = as_code(result)
    result = optimiser_verdict(code, specs, p, rows, jrows[:, :d], pred, targets, mask)
    if prior is not None and result == RESULTS.did_not_move:
        result = code  # a narrow prior centred on the start holds the estimate there
    blown = result == RESULTS.simulation_blew_up  # nothing below means anything: NaN
    with np.errstate(all="ignore") if blown else contextlib.nullcontext():
        cost = 0.5 * float(np.sum(rows**2))
    nan = np.full((columns.shape[0],) * 2, np.nan)
    precision = None if prior is None else prior.precision(columns.shape[0])
    full, null = (nan, []) if blown else least_squares_covariance(
        jrows, rows, groups, prior_precision=precision)
    covariance = full[:d, :d]
    posterior = posterior_fields(prior, precision, jrows, values, blown)
    null = [v[:d] / np.linalg.norm(v[:d]) for v in null if np.linalg.norm(v[:d]) > 1e-3]
    flags, no_excitation = excitation_flags(ds, estimator.rudder, rows.size, columns.shape[0])

    shape = (ds.num_experiments, ds.num_samples)
    predictions = {}
    for c, name in enumerate(channels):
        predictions[name], hit = to_timeline(pred[c], layout, shape)

    def report(metrics):
        # standard errors that do not assume white residuals, reported and flagged when
        # the residuals fail the whiteness test: clustered by prediction window when there
        # are enough windows (they restart from measurements), else Newey-West HAC in time
        white = all(m.white for m in metrics.values())
        windows_used = int(mask.any(axis=-1).sum())
        if blown:
            robust, lags, method = nan, None, "none (the simulation blew up)"
        elif windows_used >= MIN_CLUSTERS:
            robust, _ = cluster_from_windows(jac[..., columns], resid, mask,
                                             prior=posterior.get("robust"))
            lags, method = None, f"clustered by prediction window, {windows_used} windows"
        else:
            robust, lags = hac_from_windows(jac[..., columns], resid, layout,
                                            num_samples=shape[1], focus=np.arange(d),
                                            prior=posterior.get("robust"))
            method = f"Newey-West HAC, {lags} lags"
        return parameter_report(transform.names, values, covariance,
                                units=tuple(s.unit for s in specs), null_directions=null,
                                extra_flags=flags,
                                undetermined_flags=flags if no_excitation else (),
                                robust=RobustErrors(white, robust[:d, :d], lags, method))

    return assemble_result(
        fitted, report, ds, predictions, hit, validation=Validation(
            estimator.rudder, posterior.get("effective_params", columns.shape[0]),
            estimator.max_lag, quiet=blown,
            # blown up: the finite samples only
            valid={c: hit & np.isfinite(line) for c, line in predictions.items()}),
        result=result, num_steps=num_steps, cost=cost,
        weights={c: float(w) for c, w in zip(channels, weights)},
        window_samples=layout["lengths"], horizon=estimator.horizon,
        **{k: v for k, v in posterior.items() if k != "robust"})
