"""`identify`: estimate a named steering model from measured trials and validate it.

One call runs the whole identification workflow of the thesis (seed 000, ch. 3) and
of MATLAB's System Identification Toolbox: read the records, compute start values by
linear least squares (`initial_estimate`), fit by prediction error (`fit`), simulate
the fitted model on the training and on held-out records (output error, starting
from the measured state), and collect loss, FPE, AIC/BIC, fit %, residual tests,
standard errors, the correlation matrix and plain-language identifiability flags
in an `IdentificationResult` (JSON via `to_json`; figures via
`jaxship.plotting.save_identification_figures`).

**The model registry.** `MODELS` maps a command-line name to a `ModelEntry`: a
description and a function `start(train, context)` that builds the start model from
the training data (a `Dataset`). Adding a model is adding one entry; see
`ModelEntry`. Entries whose outputs, data or simulation differ from the yaw-rate
response models override `channels`, `requires`, `initial` and `simulate` (the
3-DOF vessel presets, one entry per `jaxship.VESSELS` name), and `fit` (the
discrete ARMAX model, estimated by `fit_armax` instead of `jaxship.fit`).

The library stays quiet: progress goes to the `progress` callable (see `Progress`),
which the `jaxship identify` command turns into a tqdm bar; identifiability and
convergence problems are `IdentifiabilityWarning`/`ConvergenceWarning` and flags in
the result.
"""

import dataclasses
import json
import math
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import equinox as eqx
import jax
import numpy as np
import optimistix as optx

from ._data import Dataset, Experiment, read_measured
from ._estimate._armax import fit_armax
from ._estimate._fit import (
    ConvergenceWarning,
    FitResult,
    IdentifiabilityWarning,
    PredictionError,
    _excitation_flags,
    _field_names,
    fit,
)
from ._estimate._linear import initial_estimate
from ._estimate._lm import LevenbergMarquardt
from ._estimate._params import as_arrays, param, parameter_fields
from ._estimate._predict import predict
from ._estimate._windows import build_windows
from ._steering._base import AbstractSteeringModel, propagate
from ._steering.nomoto import Nomoto1, Nomoto2, NonlinearNomoto
from ._steering.ross import RossAutopilot, ross_initial_estimate
from ._steering.sway_yaw import LinearSwayYaw, NorrbinCrossFlow
from ._validate import ValidationReport, _to_plain, parameter_report, validate
from ._vessel.catalogue import VESSELS, get_vessel


CHANNEL_UNITS = {"psi": "rad", "r": "rad/s", "u": "m/s", "v": "m/s"}
# file suffixes read from a folder (others, e.g. README.md, are skipped)
_DATA_SUFFIXES = (".csv", ".dat", ".txt")


# ---------------------------------------------------------------------------------------
# progress


@dataclasses.dataclass(frozen=True)
class Progress:
    """A progress report of `identify`, passed to its `progress` callable.

    - `stage`: `"start"` (start values), `"fit"` (an optimisation), `"validate"`
      (simulation on the data);
    - `message`: what is being done, in words;
    - `step`: the optimiser's step count during a fit (None for stage messages);
    - `total`: the step limit of the fit;
    - `cost`: the cost $\\frac12\\sum\\varepsilon^2$ of the last accepted step;
    - `done`: True for the last report of a stage.
    """

    stage: str
    message: str
    step: int | None = None
    total: int | None = None
    cost: float | None = None
    done: bool = False


# The host-side receivers of the optimiser's step reports. The solver's verbose hook
# is one module-level function (so that a new `progress` never recompiles the fit);
# it sends each step through `jax.debug.callback` to the receiver of the `identify`
# call that is running, pushed here for the duration of its fits.
_RECEIVERS: list = []


def _receive_step(step, cost):
    if _RECEIVERS:
        step = int(step)  # before the first step the accepted cost is not yet known
        _RECEIVERS[-1](step, float(cost) if step > 0 else None)


def _verbose_hook(**kwargs):
    jax.debug.callback(_receive_step, kwargs["num_steps"][1],
                       kwargs["loss_last_accepted_step"][1])


# ---------------------------------------------------------------------------------------
# the registry


@dataclasses.dataclass(frozen=True)
class StartContext:
    """What a `ModelEntry.start` function gets besides the training data:

    - `rudder`: the replayed rudder channel (`"delta"` or `"delta_c"`);
    - `channels`: the fitted output channels;
    - `estimator`: the `PredictionError` of the main fit (for nested fits);
    - `fit`: `fit(model, *, free=None, stage=...)` runs a quiet, progress-reporting
      fit on the training data with `estimator` and returns its `FitResult`
      (e.g. `nomoto2` starts from a fitted `Nomoto1`);
    - `note`: `note(text)` adds a line to the result's `notes`.
    """

    rudder: str
    channels: tuple[str, ...]
    estimator: PredictionError
    fit: Callable
    note: Callable


@dataclasses.dataclass(frozen=True)
class ModelEntry:
    """One identifiable model of `jaxship identify --model NAME`.

    - `description`: one line for listings and the result.
    - `start(train, context) -> model`: the start model from the training data
      (`Dataset`) and a `StartContext`; its free parameters (its `param` defaults)
      are estimated by `fit`, its frozen ones are kept. Raise `ValueError` when
      the data cannot give start values; `fallback` is then used (and noted).
    - `fallback(train, context) -> model`: a neutral start model when `start`
      fails, e.g. on records without excitation (the fit then reports the problem
      in its flags).
    - `start_method`: how `start` gets its values, in words (for the report).
    - `channels`: the output channels the model predicts (and can be fitted to).
    - `default_channels`: the channels fitted when none are given.
    - `requires`: channels every record must have measured (e.g. the surge and
      sway velocities that drive `RossAutopilot`); a record without one is a
      `ValueError` naming its file.
    - `initial`: the window-start modes the fit supports (`PredictionError.initial`);
      `"auto"` picks `"estimate"` for output error where it is supported.
    - `simulate(model, dataset, rudder, channels, substeps=1) -> (predictions,
      mask)`: the output-error simulation of the model on records, starting from
      the measured state: `{channel: (E, N) array}` and the (E, N) mask of
      simulated samples. The default (`simulate_steering_records`) serves every
      `AbstractSteeringModel`.
    - `fit(start, train, context) -> FitResult`: replaces the prediction-error fit
      (`jaxship.fit` with `context.estimator`) for models it does not serve, e.g.
      the discrete ARMAX model; None: `jaxship.fit`.
    """

    description: str
    start: Callable
    fallback: Callable
    start_method: str = "linear least squares (initial_estimate)"
    channels: tuple[str, ...] = ("psi", "r")
    simulate: Callable | None = None
    default_channels: tuple[str, ...] = ("psi", "r")
    requires: tuple[str, ...] = ()
    initial: tuple[str, ...] = ("measured", "estimate")
    fit: Callable | None = None


def _rms(a):
    a = np.asarray(a, dtype=np.float64)
    return float(np.sqrt(np.mean(a**2))) if a.size else 0.0


def _valid(ds: Dataset, name: str) -> np.ndarray:
    return np.concatenate([np.asarray(getattr(ds, name))[i, :n] for i, n in enumerate(ds.lengths)])


def _neutral_nomoto1(train: Dataset, rudder: str = "delta") -> Nomoto1:
    """K from the ratio of the yaw-rate and rudder spreads (0.1 1/s without rudder
    motion), T ten sample intervals: a start, not an estimate."""
    spread = _rms(_valid(train, rudder) - np.mean(_valid(train, rudder)))
    k = _rms(_valid(train, "r")) / spread if spread > 0 else 0.1
    k = k if math.isfinite(k) and k > 0 else 0.1
    return Nomoto1(K=k, T=10.0 * float(np.max(train.dt)))


def _start_nomoto1(train: Dataset, context: StartContext) -> Nomoto1:
    return initial_estimate(Nomoto1(K=1.0, T=1.0), train, rudder=context.rudder)


def _fallback_nomoto1(train: Dataset, context: StartContext) -> Nomoto1:
    return _neutral_nomoto1(train, context.rudder)


def _start_nomoto2(train: Dataset, context: StartContext) -> Nomoto2:
    """A fitted `Nomoto1` (K, T) spread over the three time constants with the
    same effective $T = T_1 + T_2 - T_3$: $T_2 = 0.2\\,T$, $T_3 = 0.3\\,T$, $T_1 =
    1.1\\,T$ (a small lead-lag pair; $T_2 \\ne T_3$ so that neither cancels)."""
    try:
        first = _start_nomoto1(train, context)
    except ValueError as error:
        context.note(f"Nomoto1 linear least-squares start failed ({error}); neutral start used.")
        first = _neutral_nomoto1(train, context.rudder)
    first = context.fit(first, stage="fitting Nomoto1 for the Nomoto2 start").model
    k, t = float(first.K), float(first.T)
    context.note(f"Nomoto2 start from the fitted Nomoto1: K = {k:.6g} 1/s, T = {t:.6g} s.")
    return Nomoto2(K=k, T1=1.1 * t, T2=0.2 * t, T3=0.3 * t)


def _fallback_nomoto2(train: Dataset, context: StartContext) -> Nomoto2:
    first = _neutral_nomoto1(train, context.rudder)
    return Nomoto2(K=first.K, T1=1.1 * first.T, T2=0.2 * first.T, T3=0.3 * first.T)


def _linear_nonlinear(train: Dataset, context: StartContext, why: str) -> NonlinearNomoto:
    context.note(f"nonlinear Nomoto start: {why}; started from the linear Nomoto1 "
                 "least-squares K, T with n3 = 0 instead.")
    first = initial_estimate(Nomoto1(K=1.0, T=1.0), train, rudder=context.rudder)
    return NonlinearNomoto(K=first.K, T=first.T, n3=0.0)


def _start_nonlinear(train: Dataset, context: StartContext) -> NonlinearNomoto:
    """Midpoint least squares with $n_1 = 1$ (course stable); if that gives $T \\le 0$,
    again with $n_1 = -1$ (course unstable). The cubic term must stabilise
    ($n_3 \\ge 0$, Norrbin); a regression that says otherwise (noise in the yaw
    acceleration biases it) is replaced by the linear Nomoto1 start with $n_3 = 0$."""
    try:
        start = initial_estimate(NonlinearNomoto(K=1.0, T=1.0, n1=1.0), train,
                                 rudder=context.rudder)
    except ValueError as error:
        if "T =" not in str(error):
            raise
        try:
            start = initial_estimate(NonlinearNomoto(K=1.0, T=1.0, n1=-1.0), train,
                                     rudder=context.rudder)
        except ValueError as again:
            if "T =" not in str(again):
                raise
            return _linear_nonlinear(train, context, "the regression gives T <= 0 for both "
                                     "n1 = +1 and n1 = -1")
        if not start.n3 > 0:
            return _linear_nonlinear(train, context, f"with n1 = -1 the regression gives "
                                     f"n3 = {start.n3:.4g} <= 0 (unbounded turning)")
        context.note("nonlinear Nomoto start: n1 = +1 gave T <= 0, so the course-unstable "
                     "characteristic n1 = -1 is used.")
        return start
    if start.n3 < 0:
        return _linear_nonlinear(train, context, f"the regression gives n3 = {start.n3:.4g} "
                                 "< 0 (a destabilising cubic term)")
    return start


def _fallback_nonlinear(train: Dataset, context: StartContext) -> NonlinearNomoto:
    first = _neutral_nomoto1(train, context.rudder)
    return NonlinearNomoto(K=first.K, T=first.T)


# -- Ross autopilot -----------------------------------------------------------------------


def _mean_valid(train: Dataset, name: str) -> float:
    values = _valid(train, name)
    return float(np.mean(values)) if values.size else 0.0


def _ross_scales(train: Dataset) -> dict:
    """Reference scales of `RossAutopilot` from the training records: $U_0$ the mean
    measured surge speed, $n_0$ the mean propeller rate (1 rev/s when not measured)
    and $L = 0.3\\,U_0/\\mathrm{rms}(r)$, which makes the scaled yaw rate $r' = rL/U_0$
    of order 0.3 (the coefficients' conditioning; any $L$ gives the same model,
    see `RossAutopilot.dimensional`)."""
    speed = abs(_mean_valid(train, "u"))
    speed = speed if math.isfinite(speed) and speed > 0 else 1.0
    rate = abs(_mean_valid(train, "n")) if "n" in train.channels else 0.0
    rate = rate if math.isfinite(rate) and rate > 0 else 1.0
    spread = _rms(_valid(train, "r"))
    length = 0.3 * speed / spread if spread > 0 else 1.0
    return dict(length=float(length), speed=float(speed), rate=float(rate))


def _start_ross(train: Dataset, context: StartContext) -> RossAutopilot:
    scales = _ross_scales(train)
    context.note("RossAutopilot reference scales (frozen): L = {length:.6g} m, U0 = {speed:.6g} "
                 "m/s, n0 = {rate:.6g} rev/s; the estimates are the scaled coefficients a of "
                 "these (RossAutopilot.dimensional() converts them).".format(**scales))
    return ross_initial_estimate(RossAutopilot(**scales), train, rudder=context.rudder)


def _fallback_ross(train: Dataset, context: StartContext) -> RossAutopilot:
    """The neutral Nomoto1 in Ross form: $a_{ur}u'r'$ damping with time constant T and
    the rudder term $a_\\delta u'^2\\delta$ with gain K at the reference speed."""
    scales = _ross_scales(train)
    first = _neutral_nomoto1(train, context.rudder)
    length, speed = scales["length"], scales["speed"]
    return RossAutopilot(**scales, n_ur=-length / (speed * float(first.T)),
                         n_delta=float(first.K) * length**2 / (float(first.T) * speed**2))


# -- sway-yaw models ------------------------------------------------------------------


def _sway_yaw_start(model, train: Dataset, context: StartContext, preset: str):
    speed = abs(_mean_valid(train, "u"))
    if math.isfinite(speed) and speed > 0:
        model = eqx.tree_at(lambda m: m.speed, model, speed)
    context.note(f"{type(model).__name__} start: the {preset} derivatives (Astrom & Kallstrom "
                 f"1979), with its length L = {float(model.length):.6g} m (the unit of the prime "
                 "system) and its mass terms (frozen); speed = the mean measured u "
                 f"{float(model.speed):.6g} m/s.")
    return model


def _start_linear_sway_yaw(train: Dataset, context: StartContext) -> LinearSwayYaw:
    return _sway_yaw_start(LinearSwayYaw.from_vessel(get_vessel("sea_stratus_linear")), train,
                           context, "sea_stratus_linear")


def _start_norrbin(train: Dataset, context: StartContext) -> NorrbinCrossFlow:
    return _sway_yaw_start(NorrbinCrossFlow.from_vessel(get_vessel("sea_stratus_nonlinear")),
                           train, context, "sea_stratus_nonlinear")


# -- ARMAX --------------------------------------------------------------------------------

ARMAX_ORDERS = dict(na=2, nb=2, nc=2, nk=1)


class ARMAXModel(eqx.Module):
    """The ARMAX model of `jaxship identify --model armax` (Astrom & Kallstrom 1979,
    eq. 7) with the fixed orders `ARMAX_ORDERS` ($n_a = n_b = n_c = 2$, delay
    $n_k = 1$ sample) and $y = r$ [rad/s], $u = \\delta$ [rad]:

    $$r(t) + a_1r(t-1) + a_2r(t-2) = b_0\\delta(t-1) + b_1\\delta(t-2)
    + e(t) + c_1e(t-1) + c_2e(t-2).$$

    A discrete model of the sample interval `dt` (frozen), estimated by
    `fit_armax` (one-step prediction error)."""

    a1: float = param(0.0, unit="-")  # a_1 [-] of A(q^-1)
    a2: float = param(0.0, unit="-")  # a_2 [-]
    b0: float = param(0.0, unit="1/s")  # b_0 [(rad/s)/rad] of B(q^-1), delta(t - 1)
    b1: float = param(0.0, unit="1/s")  # b_1 [(rad/s)/rad], delta(t - 2)
    c1: float = param(0.0, unit="-")  # c_1 [-] of C(q^-1)
    c2: float = param(0.0, unit="-")  # c_2 [-]
    nk: float = param(1.0, free=False, unit="samples")  # delay n_k (frozen)
    dt: float = param(1.0, free=False, unit="s")  # sample interval [s] (frozen)

    def polynomials(self):
        """`(A, B, C)` coefficient arrays (leading 1 for A and C)."""
        f = lambda *xs: np.array([float(x) for x in xs])
        return f(1.0, self.a1, self.a2), f(self.b0, self.b1), f(1.0, self.c1, self.c2)


_ARMAX_NAMES = ("a1", "a2", "b0", "b1", "c1", "c2")


def _armax_record(train: Dataset, rudder: str):
    """`(r, rudder, dt, source)` of the one training record `fit_armax` takes."""
    if train.num_experiments != 1:
        raise ValueError(f"armax is fitted to one record (fit_armax), got "
                         f"{train.num_experiments} training records ({', '.join(train.names)}); "
                         "give one and validate on the others with --validate.")
    n = int(train.lengths[0])
    y = np.asarray(train.r, dtype=np.float64)[0, :n]
    u = np.asarray(getattr(train, rudder), dtype=np.float64)[0, :n]
    return y, u, float(np.asarray(train.dt)[0]), str(dict(train.experiment_metadata[0]).get(
        "file", train.names[0]))


def _armax_fit_raw(train: Dataset, rudder: str, **kwargs):
    y, u, dt, source = _armax_record(train, rudder)
    try:
        return fit_armax(y, u, dt=dt, **ARMAX_ORDERS, **kwargs), y, u, dt
    except ValueError as error:
        raise ValueError(f"{source}: armax: {error}") from None


def _armax_model(res, dt) -> ARMAXModel:
    values = np.concatenate([res.A[1:], res.B, res.C[1:]])
    return ARMAXModel(**dict(zip(_ARMAX_NAMES, map(float, values))), nk=float(res.nk),
                      dt=float(dt))


def _start_armax(train: Dataset, context: StartContext) -> ARMAXModel:
    """The pseudo-linear regression (extended least squares) start of `fit_armax`."""
    res, _, _, dt = _armax_fit_raw(train, context.rudder, max_iter=0)
    return _armax_model(res, dt)


def _fit_armax_entry(start: ARMAXModel, train: Dataset, context: StartContext) -> FitResult:
    """`fit_armax` on the training record as a `FitResult`: the one-step prediction
    of r is the criterion (horizon one sample)."""

    if context.estimator.horizon is not None:
        context.note(f"armax is fitted by its one-step prediction error (maximum likelihood); "
                     f"--horizon {context.estimator.horizon:g} is not used.")
    if tuple(context.channels) != ("r",):
        raise ValueError("armax models the yaw rate: fit it with channels 'r'.")
    res, y, u, dt = _armax_fit_raw(train, context.rudder)
    model = _armax_model(res, dt)
    values = np.array([float(getattr(model, n)) for n in _ARMAX_NAMES])
    units = tuple(parameter_fields(model)[n].unit for n in _ARMAX_NAMES)
    report = parameter_report(_ARMAX_NAMES, values, np.asarray(res.covariance), units=units,
                              extra_flags=_excitation_flags(train, context.rudder))
    first = max(ARMAX_ORDERS["na"], ARMAX_ORDERS["nk"] + ARMAX_ORDERS["nb"] - 1,
                ARMAX_ORDERS["nc"], 1)  # the first sample of fit_armax's loss
    eps = res.residuals(y, u)
    shape = (1, train.num_samples)
    line, mask = np.zeros(shape), np.zeros(shape, dtype=bool)
    line[0, :y.size] = y - eps
    mask[0, first:y.size] = True
    rudder = np.asarray(getattr(train, context.rudder), dtype=np.float64)
    metrics = {"r": validate(np.asarray(train.r, dtype=np.float64), line, mask,
                             num_params=len(_ARMAX_NAMES), u=rudder,
                             max_lag=context.estimator.max_lag, channel="r")}
    result = FitResult(
        model=model, parameters=report, metrics=metrics, predictions={"r": line},
        predicted=mask,
        result=optx.RESULTS.successful if res.converged
        else optx.RESULTS.nonlinear_max_steps_reached,
        num_steps=int(res.iterations), cost=0.5 * float(np.sum(eps[first:] ** 2)),
        weights={"r": 1.0}, window_samples=(1,), horizon=dt,
        experiment_names=tuple(train.names))
    if report.flags:
        warnings.warn("fit of ARMAX: " + " ".join(report.flags), IdentifiabilityWarning,
                      stacklevel=2)
    return result


def simulate_armax_records(model: ARMAXModel, dataset: Dataset, rudder: str,
                           channels=("psi", "r"), substeps: int = 1):
    """Output-error simulation of an `ARMAXModel` on every record (the noise-free
    part $A r = B\\delta(t - n_k)$): the recursion starts at the measured r of the
    first sample, with r and the rudder before it held at their first values; psi
    integrates the simulated r (trapezoid rule) from the measured first heading.
    `substeps` is unused (a discrete model). Returns `(predictions, mask)` as
    `simulate_steering_records`."""
    A, B, _ = model.polynomials()
    nk = int(round(float(model.nk)))
    shape = (dataset.num_experiments, dataset.num_samples)
    out = {"psi": np.zeros(shape), "r": np.zeros(shape)}
    mask = np.zeros(shape, dtype=bool)
    for i, n in enumerate(dataset.lengths):
        r = np.asarray(dataset.r, dtype=np.float64)[i, :n]
        d = np.asarray(getattr(dataset, rudder), dtype=np.float64)[i, :n]
        pad = max(A.size - 1, nk + B.size - 1)
        y = np.concatenate([np.full(pad, r[0]), np.zeros(n)])
        x = np.concatenate([np.full(pad, d[0]), d])
        y[pad] = r[0]
        for k in range(pad + 1, pad + n):
            y[k] = (B @ x[k - nk - np.arange(B.size)]
                    - A[1:] @ y[k - 1 - np.arange(A.size - 1)])
        sim = y[pad:]
        dt = float(np.asarray(dataset.dt)[i])
        psi0 = float(np.asarray(dataset.psi)[i, 0])
        out["r"][i, :n] = sim
        out["psi"][i, :n] = psi0 + np.concatenate([[0.0], np.cumsum(0.5 * dt * (sim[1:]
                                                                               + sim[:-1]))])
        mask[i, 1:n] = True
    return {c: out[c] for c in channels}, mask


# -- vessel presets -----------------------------------------------------------------------


def simulate_vessel_records(vessel, dataset: Dataset, rudder: str,
                            channels=("psi", "r", "u", "v"), substeps: int = 1):
    """Output-error simulation of a 3-DOF vessel on every record from its measured
    first state (`jaxship.predict` with horizon None), replaying the recorded
    rudder and propeller rate. Returns `(predictions, mask)` as
    `simulate_steering_records`."""
    out = predict(vessel, dataset, estimator=PredictionError(
        horizon=None, channels=tuple(channels), rudder=rudder, substeps=int(substeps)))
    return out.predictions, np.asarray(out.predicted, dtype=bool)


def _vessel_entry(name: str) -> ModelEntry:
    def start(train, context):
        return get_vessel(name)

    return ModelEntry(
        "vessel preset (3-DOF, default_free estimated): " + VESSELS[name].description,
        start, start,
        start_method=f"the preset's coefficients (get_vessel({name!r}))",
        channels=("psi", "r", "u", "v"), default_channels=("psi", "r", "u", "v"),
        requires=("u", "v"), initial=("measured",), simulate=simulate_vessel_records,
    )


MODELS: dict[str, ModelEntry] = {
    "nomoto1": ModelEntry(
        "first-order Nomoto model T r' + r = K (delta + delta0): K [1/s], T [s]",
        _start_nomoto1, _fallback_nomoto1,
    ),
    "nomoto2": ModelEntry(
        "second-order Nomoto model K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)): K [1/s], T1, T2, "
        "T3 [s]",
        _start_nomoto2, _fallback_nomoto2,
        start_method="a fitted Nomoto1 (linear least-squares start), its T spread over T1, T2, "
        "T3",
    ),
    "nomoto1-nonlinear": ModelEntry(
        "nonlinear first-order Nomoto model T r' + n3 r^3 + n1 r = K delta (Norrbin): K [1/s], "
        "T [s], n3 [s^2/rad^2]",
        _start_nonlinear, _fallback_nonlinear,
    ),
    "ross-autopilot": ModelEntry(
        "Ross (2008) autopilot model without roll, driven by the measured u, v (thesis eq. "
        "3.6-3.7): 12 hull terms and the rudder term, scaled coefficients [-]",
        _start_ross, _fallback_ross, requires=("u", "v"),
        start_method="equation-error linear least squares (ross_initial_estimate)",
    ),
    "linear-sway-yaw": ModelEntry(
        "linear sway-yaw model in prime derivatives driven by the measured u (Astrom & "
        "Kallstrom 1979, eq. 3): Y'v, Y'r, N'v, N'r, Y'delta, N'delta [-]",
        _start_linear_sway_yaw, _start_linear_sway_yaw, channels=("psi", "r", "v"),
        requires=("u",), start_method="the sea_stratus_linear preset (LinearSwayYaw.from_vessel)",
    ),
    "norrbin-crossflow": ModelEntry(
        "Norrbin's cross-flow model: the linear sway-yaw model plus cross-flow drag C [-] "
        "(Astrom & Kallstrom 1979, sec. 2)",
        _start_norrbin, _start_norrbin, channels=("psi", "r", "v"), requires=("u",),
        start_method="the sea_stratus_nonlinear preset (NorrbinCrossFlow.from_vessel)",
    ),
    "armax": ModelEntry(
        "ARMAX(2,2,2), delay 1 sample, of the yaw rate (Astrom & Kallstrom 1979, eq. 7): "
        "a1, a2 [-], b0, b1 [1/s], c1, c2 [-]; one training record",
        _start_armax, _start_armax, channels=("psi", "r"), default_channels=("r",),
        initial=("measured",), simulate=simulate_armax_records, fit=_fit_armax_entry,
        start_method="pseudo-linear regression (extended least squares) of fit_armax",
    ),
    **{name: _vessel_entry(name) for name in VESSELS},
}


def get_model_entry(name: str) -> ModelEntry:
    """The registry entry of `name`; `ValueError` listing the known names otherwise."""
    return MODELS[model_key(name)]


def model_key(name: str) -> str:
    """The registry name of `name` (case-insensitive; `-` and `_` interchangeable)."""
    key = str(name).strip().lower()
    for candidate in (key, key.replace("-", "_"), key.replace("_", "-")):
        if candidate in MODELS:
            return candidate
    raise ValueError(f"unknown model {name!r}; choose from {', '.join(MODELS)}.")


# ---------------------------------------------------------------------------------------
# data


def _renamed(e: Experiment, name: str) -> Experiment:
    measured = {k: getattr(e, k) for k in e.channels}
    return Experiment(e.t, name=name, metadata=e.metadata, extra=e.extra, **measured)


def _source(e: Experiment) -> str:
    return str(e.meta.get("file", e.name))


def read_experiments(paths, *, role: str = "training") -> list[Experiment]:
    """Read measurement files and folders into experiments.

    A file is read with `read_measured` (trial CSV, Esso Osaka CSV, HSVA and MARIN
    .dat); a folder contributes every file in it (not its subfolders) with a
    `.csv`, `.dat` or `.txt` suffix whose format `read_measured` recognises
    (others, such as a propeller open-water table, are skipped), in name order.
    Experiments with equal names get their folder as a prefix.

    **Raises:** `ValueError` naming the file: missing, unreadable or malformed
    (the readers' messages name the column and row), or a folder with no records.
    """
    if isinstance(paths, (str, Path)):
        paths = [paths]
    experiments = []
    for path in paths:
        path = Path(path)
        if path.is_dir():
            found = 0
            for item in sorted(path.iterdir()):
                if not item.is_file() or item.suffix.lower() not in _DATA_SUFFIXES:
                    continue
                try:
                    experiments.append(read_measured(item))
                except ValueError as error:
                    if "unknown measurement format" in str(error):
                        continue
                    raise
                found += 1
            if not found:
                raise ValueError(f"{path}: the {role} folder holds no measurement file "
                                 "(trial CSV, Esso Osaka CSV, HSVA or MARIN .dat).")
        elif not path.exists():
            raise ValueError(f"{path}: no such {role} file or folder.")
        else:
            experiments.append(read_measured(path))
    if not experiments:
        raise ValueError(f"no {role} files given.")
    names = [e.name for e in experiments]
    out = []
    for e in experiments:
        if names.count(e.name) > 1:
            e = _renamed(e, f"{Path(_source(e)).parent.name}/{e.name}")
        out.append(e)
    names = [e.name for e in out]
    for i, e in enumerate(out):  # still equal (same folder name): number them
        if names.count(e.name) > 1:
            out[i] = _renamed(e, f"{e.name}#{i}")
    return out


def _as_experiments(data, role: str) -> list[Experiment]:
    if isinstance(data, Dataset):
        return [data.experiment(i) for i in range(data.num_experiments)]
    if isinstance(data, Experiment):
        return [data]
    if isinstance(data, (str, Path)):
        return read_experiments([data], role=role)
    if isinstance(data, Sequence) and data:
        if all(isinstance(e, Experiment) for e in data):
            return list(data)
        if all(isinstance(e, (str, Path)) for e in data):
            return read_experiments(data, role=role)
    raise ValueError(f"the {role} data must be an Experiment, a list of Experiments, a "
                     f"Dataset or file paths, got {type(data).__name__}.")


def _check_experiments(experiments, rudder: str, role: str, model: str = "",
                       requires=()) -> None:
    """Errors naming the file, before any fitting: the replayed rudder and the
    channels the `model` `requires` must be measured."""
    for e in experiments:
        where = f"{_source(e)} ({role} record {e.name!r})"
        have = ", ".join(c for c in e.channels) or "none"
        if not e.has(rudder):
            raise ValueError(f"{where}: no column {rudder!r} (the replayed rudder); measured "
                             f"channels: {have}. Choose --rudder delta or delta_c.")
        missing = [c for c in requires if not e.has(c)]
        if missing:
            raise ValueError(
                f"{where}: model {model} needs the measured {' and '.join(map(repr, requires))}"
                f" (the surge/sway velocities it is driven by or restarted from), but the record "
                f"has no column {missing[0]!r}; measured channels: {have}. Use records with "
                "them or a Nomoto model.")
        if e.num_samples < 3:
            raise ValueError(f"{where}: needs at least 3 samples, has {e.num_samples}.")
        if not e.is_uniform():
            steps = np.diff(e.t)
            k = int(np.argmax(np.abs(steps - e.dt))) + 1
            raise ValueError(
                f"{where}: column 't': sampling is not uniform (t[{k}] - t[{k - 1}] = "
                f"{steps[k - 1]!r} s, mean interval {e.dt!r} s); resample the record first."
            )


# ---------------------------------------------------------------------------------------
# simulation and assessment


@eqx.filter_jit
def _simulate_windows(model, windows):
    """Heading, yaw rate (E, W, L) and model states (E, W, L, S) of each window from
    its measured start."""

    def one(start, delta, aux, dt):
        return propagate(model, model.window_state(start), start.psi, delta, aux, dt,
                         windows.substeps)

    return jax.vmap(jax.vmap(one))(windows.start, windows.delta, windows.aux, windows.dt)


def simulate_steering_records(model: AbstractSteeringModel, dataset: Dataset, rudder: str,
                              channels=("psi", "r"), substeps: int = 1):
    """Output-error simulation of a steering model on every record of `dataset`,
    each starting from its measured state at the first sample (hidden states by the
    model's `window_state`), driven by the recorded `rudder` and auxiliary inputs.

    `channels`: `"psi"`, `"r"` and names of model states (e.g. a sway velocity `"v"`).

    **Returns:** `({channel: (E, N) array}, mask (E, N))`; the first sample of each
    record (the start value) and the padding are not in the mask."""
    unknown = [c for c in channels if c not in ("psi", "r") + tuple(model.state_names)]
    if unknown:
        raise ValueError(f"{type(model).__name__} has no output {unknown[0]!r}; its outputs are "
                         f"psi, r and its states {', '.join(model.state_names)}.")
    windows, layout = build_windows(dataset, horizon=None, channels=("psi", "r"), weights=None,
                                    rudder=rudder, substeps=int(substeps))
    psi, r, states = _simulate_windows(as_arrays(model), windows)
    shape = (dataset.num_experiments, dataset.num_samples)
    mask = layout["mask"]
    e_idx = np.broadcast_to(np.arange(shape[0])[:, None, None], mask.shape)
    hit = np.zeros(shape, dtype=bool)
    hit[e_idx[mask], layout["target"][mask]] = True
    predictions = {}
    for name in channels:
        if name == "psi":
            values = psi
        elif name == "r":
            values = r
        else:
            values = states[..., model.state_names.index(name)]
        line = np.zeros(shape)
        line[e_idx[mask], layout["target"][mask]] = np.asarray(values, dtype=np.float64)[mask]
        predictions[name] = line
    return predictions, hit


@dataclasses.dataclass(frozen=True)
class Assessment:
    """A model's outputs on a set of records and their validation figures.

    - `kind`: `"prediction"` (the fit criterion: windows of `horizon` seconds from
      the measured state) or `"simulation"` (output error from the first sample);
    - `horizon`: the prediction horizon [s] (None for output error);
    - `data`: the `Dataset`; `rudder`: its replayed rudder channel;
    - `start`: `"measured"` (each window starts from the measured r, psi) or
      `"estimated"` (the fit estimated corrections of them);
    - `predictions`: `{channel: (E, N) array}` [rad, rad/s]; `mask`: (E, N) samples
      that were predicted;
    - `metrics`: `{channel: ValidationReport}` (loss, FPE, AIC, BIC, fit %,
      whiteness and residual-input tests).
    """

    kind: str
    horizon: float | None
    data: Dataset
    rudder: str
    predictions: dict
    mask: np.ndarray
    metrics: dict
    start: str = "measured"

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.data.names)

    def residuals(self, channel: str) -> np.ndarray:
        """Measured minus predicted `channel`, (E, N), 0 where not predicted."""
        measured = np.asarray(getattr(self.data, channel), dtype=np.float64)
        return np.where(self.mask, measured - self.predictions[channel], 0.0)

    def to_dict(self) -> dict:
        """JSON-ready: kind, horizon, experiments and per-channel figures."""
        return {
            "kind": self.kind,
            "horizon_s": self.horizon,
            "start": self.start,
            "rudder": self.rudder,
            "experiments": list(self.names),
            "channels": {c: _metrics_dict(m, self.names) for c, m in self.metrics.items()},
        }


def _test_dict(corr) -> dict | None:
    if corr is None:
        return None
    return {
        "passed": bool(corr.passed),
        "statistic": _to_plain(corr.statistic),
        "threshold_99": _to_plain(corr.threshold),
        "band_99": _to_plain(corr.band),
        "max_lag": int(np.max(np.abs(corr.lags))),
        "lags_outside_band": int(corr.num_outside),
    }


def _metrics_dict(m: ValidationReport, names) -> dict:
    unit = CHANNEL_UNITS.get(m.channel, "")
    return {
        "unit": unit,
        "loss": _to_plain(m.loss),
        "loss_unit": f"({unit})^2" if unit else "",
        "fpe": _to_plain(m.fpe),
        "aic": _to_plain(m.aic),
        "bic": _to_plain(m.bic),
        "fit_percent": _to_plain(m.fit_percent),
        "fit_percent_per_experiment": {n: _to_plain(v) for n, v in
                                       zip(names, m.fit_per_experiment)},
        "rms": _to_plain(m.rms),
        "mean": _to_plain(m.mean),
        "num_samples": int(m.num_samples),
        "num_params": int(m.num_params),
        "whiteness": _test_dict(m.autocorrelation),
        "input_independence": _test_dict(m.cross_correlation),
    }


def _values_text(model) -> str:
    names = tuple(parameter_fields(model))
    if not names:  # a vessel: its default free coefficients
        from ._estimate._vessel_fit import default_free

        names = default_free(model)
    return ", ".join(f"{n} = {float(getattr(model, n)):.4g}" for n in names)


def _assess(kind, horizon, ds, rudder, predictions, mask, num_params, max_lag, notes=None,
            start="measured"):
    u = np.asarray(getattr(ds, rudder), dtype=np.float64)
    mask = np.array(mask, dtype=bool)
    bad = np.zeros(mask.shape, dtype=bool)
    for yhat in predictions.values():
        bad |= mask & ~np.isfinite(yhat)
    for i in np.nonzero(bad.any(axis=1))[0]:  # keep the samples before the blow-up
        k = int(np.argmax(bad[i]))
        mask[i, k:] = False
        if notes is not None:
            notes.append(f"the {kind} of record {ds.names[i]!r} diverged at t = "
                         f"{float(ds.t[i, k]):.6g} s (non-finite outputs); its metrics use the "
                         "samples before.")
    metrics = {}
    for c, yhat in predictions.items():
        measured = np.asarray(getattr(ds, c), dtype=np.float64)
        metrics[c] = validate(measured, yhat, mask, num_params=num_params, u=u,
                              max_lag=max_lag, channel=c)
    return Assessment(kind, horizon, ds, rudder, dict(predictions), mask, metrics, start)


# ---------------------------------------------------------------------------------------
# the result


@dataclasses.dataclass(frozen=True)
class IdentificationResult:
    """Result of `identify`.

    - `model_name`: the registry name; `description`: its line;
    - `fit`: the `FitResult` (fitted `model`, `parameters` report with standard
      errors, correlation and flags, optimiser result);
    - `start`: the start model; `start_method`: how its values were obtained;
    - `train`: `Assessment` of the fit criterion on the training records;
    - `train_simulation`: output-error `Assessment` on the training records;
    - `validation`: output-error `Assessment` on the held-out records, or None;
    - `options`: horizon [s], rudder, channels; `notes`, `warnings`: texts.
    """

    model_name: str
    description: str
    fit: FitResult
    start: AbstractSteeringModel
    start_method: str
    train: Assessment
    train_simulation: Assessment
    validation: Assessment | None
    options: dict
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def model(self) -> AbstractSteeringModel:
        """The fitted model."""
        return self.fit.model

    @property
    def flags(self) -> tuple[str, ...]:
        """Plain-language identifiability findings (empty: well determined)."""
        return tuple(self.fit.flags)

    @property
    def identifiable(self) -> bool:
        return not self.flags

    def summary(self) -> str:
        """A text report: parameters with standard errors, fit % per block, flags."""
        lines = [f"{self.model_name}: {type(self.model).__name__}, "
                 f"{'converged' if self.fit.success else 'NOT converged: ' + self.fit.message}"
                 f" in {self.fit.num_steps} steps",
                 self.fit.parameters.table()]
        for label, block in (("train (criterion)", self.train),
                             ("train (simulation)", self.train_simulation),
                             ("validation (simulation)", self.validation)):
            if block is None:
                continue
            parts = [f"{c} fit {m.fit_percent:.2f} %, FPE {m.fpe:.4g}"
                     for c, m in block.metrics.items()]
            lines.append(f"{label}: " + "; ".join(parts))
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready report (schema in the `identify` docstring)."""
        fitted = self.fit.to_dict()
        report = self.fit.parameters
        start = {n: _to_plain(float(getattr(self.start, n))) for n in report.names}
        parameters = {}
        for name, entry in fitted["parameters"].items():
            rel = report.relative_std[report.names.index(name)]
            parameters[name] = {**entry, "relative_std": _to_plain(float(rel)),
                                "start": start[name]}

        def records(block):
            if block is None:
                return []
            ds = block.data
            return [{"name": ds.names[i],
                     "file": dict(ds.experiment_metadata[i]).get("file"),
                     "samples": int(ds.lengths[i]),
                     "dt_s": float(ds.dt[i]),
                     "duration_s": float(ds.dt[i] * (ds.lengths[i] - 1)),
                     "channels": list(ds.experiment_channels[i])}
                    for i in range(ds.num_experiments)]

        return {
            "model": self.model_name,
            "model_class": type(self.model).__name__,
            "description": self.description,
            "options": _to_plain(self.options),
            "data": {"train": records(self.train), "validation": records(self.validation)},
            "start": {"method": self.start_method, "parameters": start},
            "parameters": parameters,
            "frozen": fitted["frozen"],
            "fit": {k: fitted[k] for k in ("success", "result", "num_steps", "cost",
                                          "window_samples", "weights")},
            "train": self.train.to_dict(),
            "train_simulation": self.train_simulation.to_dict(),
            "validation": None if self.validation is None else self.validation.to_dict(),
            "correlation": {"names": list(report.names),
                            "matrix": _to_plain(np.asarray(report.correlation))},
            "identifiability": {
                "identifiable": self.identifiable,
                "condition_number": _to_plain(report.condition_number),
                "flags": list(self.flags),
            },
            "notes": list(self.notes),
            "warnings": list(self.warnings),
        }

    def to_json(self, indent: int | None = 2) -> str:
        """`to_dict` as JSON text (non-finite numbers as "inf"/"-inf"/null)."""
        return json.dumps(self.to_dict(), indent=indent)


# ---------------------------------------------------------------------------------------
# identify


def _parse_channels(channels, allowed) -> tuple[str, ...]:
    if isinstance(channels, str):
        channels = [c for c in channels.replace(" ", "").split(",") if c]
    channels = tuple(channels)
    if not channels:
        raise ValueError(f"no output channel given; choose from {', '.join(allowed)}.")
    for c in channels:
        if c not in allowed:
            raise ValueError(f"unknown output channel {c!r}; choose from {', '.join(allowed)}.")
    if len(set(channels)) != len(channels):
        raise ValueError(f"output channels repeat: {', '.join(channels)}.")
    return channels


def identify(train, *, model: str, horizon: float | None = None, validate=None,
             rudder: str = "delta", channels=None, initial: str = "auto",
             max_steps: int = 256, substeps: int = 1,
             progress: Callable[[Progress], None] | None = None) -> IdentificationResult:
    """Estimate a registered steering model from training records and validate it.

    **Arguments:**

    - `train`: the training records: an `Experiment`, a list of them, a `Dataset`,
      or file/folder paths (see `read_experiments`).
    - `model`: a name in `MODELS`: `nomoto1`, `nomoto2`, `nomoto1-nonlinear`,
      `ross-autopilot`, `linear-sway-yaw`, `norrbin-crossflow`, `armax` or a vessel
      preset of `jaxship.VESSELS` (its `default_free` coefficients are estimated
      from the preset's values; records need u and v).
    - `horizon`: prediction horizon of the fit [s] (`PredictionError.horizon`):
      None (default) output error, 0 equation error, else windows of `horizon`
      seconds from the measured state.
    - `validate`: held-out records (same forms as `train`) or None. The fitted
      model is simulated on them from each record's measured first state (output
      error) and assessed with the same figures.
    - `rudder`: the replayed rudder channel, `"delta"` or `"delta_c"`.
    - `channels`: fitted outputs, a subset of the entry's `channels` (or a text
      such as `"psi,r"`); None: the entry's `default_channels` (`psi, r`; `psi, r,
      u, v` for vessel presets; `r` for armax).
    - `initial`: start of each fitted window (`PredictionError.initial`):
      `"measured"` (the measured r and psi), `"estimate"` (corrections of them are
      estimated with the parameters, which removes the bias a noisy start sample
      gives output error) or `"auto"` (default): `"estimate"` for output error
      (`horizon=None`) where the entry supports it, `"measured"` otherwise. Validation
      simulations always start from the measured state.
    - `max_steps`: optimiser step limit; `substeps`: RK4 steps per sample interval.
    - `progress`: a callable receiving `Progress` reports, or None (quiet).

    Start values: the entry's `start` (linear least squares by `initial_estimate`,
    or a nested fit); if it fails (e.g. no excitation) the entry's neutral
    `fallback`, with a note. Then `fit` with `PredictionError(horizon, channels,
    rudder)`.

    **Returns:** an `IdentificationResult`; `to_json()` gives `model`,
    `parameters` (`{name: {value, std, unit, relative_std, start}}`, SI), `frozen`,
    `fit` (optimiser result), `train` (the fit criterion), `train_simulation` and
    `validation` (output error; None without held-out data), each with
    `channels: {psi|r|u|v: {loss, fpe, aic, bic, fit_percent,
    fit_percent_per_experiment, whiteness, input_independence, ...}}`,
    `correlation` (`names`, `matrix`), `identifiability` (`identifiable`,
    `condition_number`, plain-language `flags`), `data`, `start`, `options`,
    `notes`, `warnings`.

    **Raises:** `ValueError` naming the file/record and column for unknown models
    or channels, missing files, a missing rudder column, a missing u or v the model
    needs (`ross-autopilot`, vessel presets; u for the sway-yaw models), non-finite
    values or non-uniform sampling; for `armax`, more than one training record.

    **Warns:** `IdentifiabilityWarning` when the estimates are flagged (e.g. no
    excitation: the fit still returns, with infinite standard errors), and
    `ConvergenceWarning` when the optimiser did not converge.
    """
    name = model_key(model)
    entry = MODELS[name]
    if rudder not in ("delta", "delta_c"):
        raise ValueError(f"unknown rudder channel {rudder!r}; choose 'delta' (measured angle) "
                         "or 'delta_c' (command).")
    default_channels = channels is None
    channels = _parse_channels(entry.default_channels if default_channels else channels,
                               entry.channels)
    if horizon is not None:
        horizon = float(horizon)
        if not (math.isfinite(horizon) and horizon >= 0):
            raise ValueError(f"the horizon must be a non-negative number of seconds or None "
                             f"(output error), got {horizon}.")
    if initial not in ("auto", "measured", "estimate"):
        raise ValueError(f"unknown initial state {initial!r}; choose 'auto', 'measured' or "
                         "'estimate'.")
    if initial == "auto":
        initial = "estimate" if horizon is None and "estimate" in entry.initial else "measured"
    if initial not in entry.initial:
        raise ValueError(f"model {name} supports initial {' or '.join(entry.initial)}, not "
                         f"{initial!r}.")
    if int(max_steps) < 1:
        raise ValueError(f"`max_steps` must be a positive integer, got {max_steps}.")
    train_exps = _as_experiments(train, "training")
    _check_experiments(train_exps, rudder, "training", name, entry.requires)
    held_out = None
    if validate is not None:
        held_out = _as_experiments(validate, "validation")
        _check_experiments(held_out, rudder, "validation", name, entry.requires)
    train_ds = Dataset.from_experiments(train_exps)
    valid_ds = None if held_out is None else Dataset.from_experiments(held_out)
    notes, caught = [], []
    if default_channels:  # a default u or v that never varies (e.g. no surge dynamics)
        constant = [c for c in channels if c in ("u", "v") and np.ptp(_valid(train_ds, c)) == 0]
        if constant and len(constant) < len(channels):
            channels = tuple(c for c in channels if c not in constant)
            notes.append(f"the measured {', '.join(constant)} is constant in the training "
                         f"records: not fitted (channels {', '.join(channels)}).")

    report = progress if progress is not None else (lambda event: None)
    solver = LevenbergMarquardt(rtol=1e-9, atol=1e-9, verbose=_verbose_hook)
    estimator = PredictionError(horizon=horizon, channels=channels, rudder=rudder,
                                substeps=int(substeps), solver=solver,
                                max_steps=int(max_steps), initial=initial)

    def run_fit(start_model, *, free=None, stage="fitting", custom=None):
        total = int(max_steps)
        report(Progress("fit", stage, step=0, total=total))
        _RECEIVERS.append(lambda step, cost: report(Progress("fit", stage, step=step,
                                                             total=total, cost=cost)))
        try:
            with warnings.catch_warnings(record=True) as got:
                warnings.simplefilter("always")
                if custom is None:
                    result = fit(start_model, train_ds, estimator=estimator, free=free)
                else:  # an entry's own estimator (e.g. ARMAX)
                    result = custom(start_model, train_ds, context)
        finally:
            _RECEIVERS.pop()
        report(Progress("fit", stage, step=int(result.num_steps), total=total,
                        cost=float(result.cost), done=True))
        return result, got

    def nested_fit(start_model, *, free=None, stage="fitting"):
        result, got = run_fit(start_model, free=free, stage=stage)
        for w in got:  # the nested fit's problems are reported by the main fit, if at all
            if not issubclass(w.category, (IdentifiabilityWarning, ConvergenceWarning)):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return result

    context = StartContext(rudder=rudder, channels=channels, estimator=estimator,
                           fit=nested_fit, note=notes.append)
    report(Progress("start", "start values"))
    try:
        start = entry.start(train_ds, context)
        method = entry.start_method
    except ValueError as error:
        start = entry.fallback(train_ds, context)
        method = "neutral fallback (the start-value regression failed)"
        notes.append(f"start values: {error} A neutral start was used instead; the fit "
                     "below says whether the data determine the parameters.")
    report(Progress("start", "start values", done=True))

    def attempt(start_model):
        try:
            outcome = run_fit(start_model, stage=f"fitting {name}", custom=entry.fit)
        except np.linalg.LinAlgError as error:  # NaN residuals: the simulation blew up
            return None, str(error)
        if not math.isfinite(outcome[0].cost):
            return None, f"cost {outcome[0].cost}"
        return outcome, ""

    outcome, why = attempt(start)
    if outcome is None and not method.startswith("neutral"):
        notes.append(f"the fit from the {method} start diverged (non-finite model outputs: "
                     f"{why}); restarted from the neutral fallback start.")
        start = entry.fallback(train_ds, context)
        method = "neutral fallback (the fit from the regression start diverged)"
        outcome, why = attempt(start)
    if outcome is None:
        raise ValueError(
            f"the fit of {name} diverged: the model's outputs became non-finite ({why}) from "
            f"the start {_values_text(start)}; try a finite --horizon, --initial measured or "
            "another model."
        )
    result, got = outcome
    for w in got:
        if issubclass(w.category, (IdentifiabilityWarning, ConvergenceWarning)):
            caught.append(str(w.message))
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)

    d = len(result.names)
    simulate = entry.simulate or simulate_steering_records
    max_lag = int(estimator.max_lag)
    # the criterion's horizon: the estimator's, or the entry's own (ARMAX: one sample)
    criterion = result.horizon
    train_block = _assess("prediction" if criterion is not None else "simulation", criterion,
                          train_ds, rudder, result.predictions, result.predicted,
                          int(result.metrics[channels[0]].num_params), max_lag,
                          start="estimated" if initial == "estimate" else "measured")
    report(Progress("validate", "simulating the training records"))
    def measured(ds):  # psi and r always exist (derived if need be); other outputs if measured
        return tuple(c for c in entry.channels if c in ("psi", "r") or c in ds.channels)

    predictions, mask = simulate(result.model, train_ds, rudder, measured(train_ds),
                                 substeps=int(substeps))
    train_sim = _assess("simulation", None, train_ds, rudder, predictions, mask, d, max_lag,
                        notes)
    valid_block = None
    if valid_ds is not None:
        report(Progress("validate", "simulating the validation records"))
        predictions, mask = simulate(result.model, valid_ds, rudder, measured(valid_ds),
                                     substeps=int(substeps))
        valid_block = _assess("simulation", None, valid_ds, rudder, predictions, mask, d,
                              max_lag, notes)
    report(Progress("validate", "validation", done=True))

    frozen = [n for n in _field_names(result.model) if n not in result.names]
    if len(frozen) > 12:  # a vessel preset: listed in the report's "frozen"
        notes.append(f"{len(frozen)} coefficients of the preset are frozen (not estimated); "
                     "see `frozen`.")
    elif frozen:
        notes.append("frozen parameters (not estimated): "
                     + ", ".join(f"{n} = {float(getattr(result.model, n)):.6g}" for n in frozen)
                     + ".")
    out = IdentificationResult(
        model_name=name, description=entry.description, fit=result, start=start,
        start_method=method, train=train_block, train_simulation=train_sim,
        validation=valid_block,
        options={"horizon_s": horizon, "rudder": rudder, "channels": list(channels),
                 "initial": initial, "max_steps": int(max_steps), "substeps": int(substeps)},
        notes=tuple(notes), warnings=tuple(caught),
    )
    if not result.success:
        warnings.warn(f"identify {name}: the optimiser stopped without converging "
                      f"({result.message}).", ConvergenceWarning, stacklevel=2)
    if result.flags:
        warnings.warn(f"identify {name}: " + " ".join(result.flags), IdentifiabilityWarning,
                      stacklevel=2)
    return out
