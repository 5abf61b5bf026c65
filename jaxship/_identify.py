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
`ModelEntry`. Entries whose outputs or simulation differ from the yaw-rate response
models (3-DOF vessel presets, ARMAX) override `channels` and `simulate`.

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
from ._estimate._fit import (
    ConvergenceWarning,
    FitResult,
    IdentifiabilityWarning,
    PredictionError,
    fit,
)
from ._estimate._linear import initial_estimate
from ._estimate._params import as_arrays, parameter_fields
from ._estimate._windows import build_windows
from ._steering._base import AbstractSteeringModel, propagate
from ._steering.nomoto import Nomoto1, Nomoto2, NonlinearNomoto
from ._validate import ValidationReport, _to_plain, validate


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
    - `simulate(model, dataset, rudder, channels) -> (predictions, mask)`: the
      output-error simulation of the model on records, starting from the measured
      state: `{channel: (E, N) array}` and the (E, N) mask of simulated samples.
      The default serves every `AbstractSteeringModel`.
    """

    description: str
    start: Callable
    fallback: Callable
    start_method: str = "linear least squares (initial_estimate)"
    channels: tuple[str, ...] = ("psi", "r")
    simulate: Callable | None = None


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
}


def get_model_entry(name: str) -> ModelEntry:
    """The registry entry of `name`; `ValueError` listing the known names otherwise."""
    key = str(name).strip().lower()
    if key not in MODELS:
        raise ValueError(f"unknown model {name!r}; choose from {', '.join(MODELS)}.")
    return MODELS[key]


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


def _check_experiments(experiments, rudder: str, role: str) -> None:
    """Errors naming the file, before any fitting."""
    for e in experiments:
        where = f"{_source(e)} ({role} record {e.name!r})"
        if not e.has(rudder):
            have = ", ".join(c for c in e.channels) or "none"
            raise ValueError(f"{where}: no column {rudder!r} (the replayed rudder); measured "
                             f"channels: {have}. Choose --rudder delta or delta_c.")
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
    return ", ".join(f"{n} = {float(getattr(model, n)):.4g}" for n in parameter_fields(model))


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
             rudder: str = "delta", channels=("psi", "r"), initial: str = "auto",
             max_steps: int = 256, substeps: int = 1,
             progress: Callable[[Progress], None] | None = None) -> IdentificationResult:
    """Estimate a registered steering model from training records and validate it.

    **Arguments:**

    - `train`: the training records: an `Experiment`, a list of them, a `Dataset`,
      or file/folder paths (see `read_experiments`).
    - `model`: a name in `MODELS` (`nomoto1`, `nomoto2`, `nomoto1-nonlinear`).
    - `horizon`: prediction horizon of the fit [s] (`PredictionError.horizon`):
      None (default) output error, 0 equation error, else windows of `horizon`
      seconds from the measured state.
    - `validate`: held-out records (same forms as `train`) or None. The fitted
      model is simulated on them from each record's measured first state (output
      error) and assessed with the same figures.
    - `rudder`: the replayed rudder channel, `"delta"` or `"delta_c"`.
    - `channels`: fitted outputs, a subset of `("psi", "r")` (or `"psi,r"`).
    - `initial`: start of each fitted window (`PredictionError.initial`):
      `"measured"` (the measured r and psi), `"estimate"` (corrections of them are
      estimated with the parameters, which removes the bias a noisy start sample
      gives output error) or `"auto"` (default): `"estimate"` for output error
      (`horizon=None`), `"measured"` otherwise. Validation simulations always start
      from the measured state.
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
    `channels: {psi|r: {loss, fpe, aic, bic, fit_percent,
    fit_percent_per_experiment, whiteness, input_independence, ...}}`,
    `correlation` (`names`, `matrix`), `identifiability` (`identifiable`,
    `condition_number`, plain-language `flags`), `data`, `start`, `options`,
    `notes`, `warnings`.

    **Raises:** `ValueError` naming the file/record and column for unknown models
    or channels, missing files, a missing rudder column, non-finite values or
    non-uniform sampling.

    **Warns:** `IdentifiabilityWarning` when the estimates are flagged (e.g. no
    excitation: the fit still returns, with infinite standard errors), and
    `ConvergenceWarning` when the optimiser did not converge.
    """
    entry = get_model_entry(model)
    name = str(model).strip().lower()
    if rudder not in ("delta", "delta_c"):
        raise ValueError(f"unknown rudder channel {rudder!r}; choose 'delta' (measured angle) "
                         "or 'delta_c' (command).")
    channels = _parse_channels(channels, entry.channels)
    if horizon is not None:
        horizon = float(horizon)
        if not (math.isfinite(horizon) and horizon >= 0):
            raise ValueError(f"the horizon must be a non-negative number of seconds or None "
                             f"(output error), got {horizon}.")
    if initial not in ("auto", "measured", "estimate"):
        raise ValueError(f"unknown initial state {initial!r}; choose 'auto', 'measured' or "
                         "'estimate'.")
    if initial == "auto":
        initial = "estimate" if horizon is None else "measured"
    if int(max_steps) < 1:
        raise ValueError(f"`max_steps` must be a positive integer, got {max_steps}.")
    train_exps = _as_experiments(train, "training")
    _check_experiments(train_exps, rudder, "training")
    held_out = None
    if validate is not None:
        held_out = _as_experiments(validate, "validation")
        _check_experiments(held_out, rudder, "validation")
    train_ds = Dataset.from_experiments(train_exps)
    valid_ds = None if held_out is None else Dataset.from_experiments(held_out)

    report = progress if progress is not None else (lambda event: None)
    solver = optx.LevenbergMarquardt(rtol=1e-9, atol=1e-9, verbose=_verbose_hook)
    estimator = PredictionError(horizon=horizon, channels=channels, rudder=rudder,
                                substeps=int(substeps), solver=solver,
                                max_steps=int(max_steps), initial=initial)
    notes, caught = [], []

    def run_fit(start_model, *, free=None, stage="fitting"):
        total = int(max_steps)
        report(Progress("fit", stage, step=0, total=total))
        _RECEIVERS.append(lambda step, cost: report(Progress("fit", stage, step=step,
                                                             total=total, cost=cost)))
        try:
            with warnings.catch_warnings(record=True) as got:
                warnings.simplefilter("always")
                result = fit(start_model, train_ds, estimator=estimator, free=free)
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
            outcome = run_fit(start_model, stage=f"fitting {name}")
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
    simulate = entry.simulate or (lambda m, ds, rud, chans: simulate_steering_records(
        m, ds, rud, chans, substeps=int(substeps)))
    max_lag = int(estimator.max_lag)
    train_block = _assess("prediction" if horizon is not None else "simulation", horizon,
                          train_ds, rudder, result.predictions, result.predicted,
                          int(result.metrics[channels[0]].num_params), max_lag,
                          start="estimated" if initial == "estimate" else "measured")
    report(Progress("validate", "simulating the training records"))
    def measured(ds):  # psi and r always exist (derived if need be); other outputs if measured
        return tuple(c for c in entry.channels if c in ("psi", "r") or c in ds.channels)

    predictions, mask = simulate(result.model, train_ds, rudder, measured(train_ds))
    train_sim = _assess("simulation", None, train_ds, rudder, predictions, mask, d, max_lag,
                        notes)
    valid_block = None
    if valid_ds is not None:
        report(Progress("validate", "simulating the validation records"))
        predictions, mask = simulate(result.model, valid_ds, rudder, measured(valid_ds))
        valid_block = _assess("simulation", None, valid_ds, rudder, predictions, mask, d,
                              max_lag, notes)
    report(Progress("validate", "validation", done=True))

    frozen = [n for n in parameter_fields(result.model) if n not in result.names]
    if frozen:
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
