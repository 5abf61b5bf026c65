"""`identify`: estimate a named steering model from measured trials and validate it.

One call runs the whole identification workflow of the thesis (seed 000, ch. 3) and
of MATLAB's System Identification Toolbox: read the records, compute start values by
linear least squares (`initial_estimate`), fit by prediction error (`fit`), simulate
the fitted model on the training and on held-out records (output error, starting
from the measured state), and collect loss, FPE, AIC/BIC, fit %, residual tests,
standard errors, the correlation matrix and plain-language identifiability flags
in an `Identification`.

The library stays quiet: progress goes to the `progress` callable (see `Progress`),
which the `jaxship identify` command turns into a tqdm bar; the fit's result code says
whether it converged, and its problems are plain sentences in the result's `warnings`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

import jaxship as js

from ... import Progress
from .assessment import assess
from .data import (
    as_experiments,
    check_experiments,
    check_froude,
    over_ground,
    preset_length,
    same_records,
    valid_samples,
)
from .plausibility import implausible, propeller_rate_slip, rudder_in_rad, wind_too_strong
from .registry import MODELS, model_key, start_entry
from .result import Identification
from .selection import AUTO, CANDIDATES, choose, with_selection
from .settings import added_free, fit_settings
from .simulation import simulate_records
from .starts import StartContext


class FitDivergedError(ValueError):
    """`identify`'s fit diverged: the model's outputs became non-finite from every start
    tried (the `jaxship identify` command exits with status 3)."""


def _values_text(model) -> str:
    """The start's values: a vessel's default free coefficients, a steering model's all."""
    names = (js.default_free(model) if isinstance(model, js.AbstractVessel)
             else model.parameter_names())
    return ", ".join(f"{n} = {float(model.get_parameter(n)):.4g}" for n in names)


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


def identify(model, train, *, validate=None, horizon=..., free=None,
             sample_interval: float | None = None, velocities: str | None = None,
             rudder: str = "delta", channels=None, initial=None,
             max_steps: int = 256, progress: Callable[[Progress], None] | None = None,
             name: str | None = None, substeps: int = 1,
             prior=...) -> Identification:
    """Estimate a steering model or a vessel from training records and validate it, as
    `jaxship identify` does (the command calls this).

    **Arguments:**

    - `model`: the start: a catalogue name of `jaxship.identification.MODELS`
      (`nomoto1`, `nomoto2`, `nomoto1-nonlinear`, `nomoto1-norrbin`, `ross-autopilot`,
      `linear-sway-yaw`, `norrbin-crossflow`, `low-speed-sway-yaw`, `armax` or a vessel
      preset of `jaxship.VESSELS`: its `default_free` coefficients are estimated from the
      preset's values; records need u and v), `"auto"` (each model of
      `jaxship.identification.CANDIDATES` fitted, the one with the least BIC of its fit
      criterion on the training records returned, with its `selection`), a model (a
      vessel or a steering model, e.g. from `load_model`: fitted from its own values) or
      an earlier `Identification` (its fitted model, fitted as it was).
    - `train`, `validate`: records: file or folder paths, an `Experiment`, a list of
      them or a `Dataset` (`jaxship.identification.read_experiments`); `validate` None:
      no held-out records. Models that feel the wind (vessels, `low-speed-sway-yaw`)
      get the logged wind replayed when every training record logs it.
    - `horizon`: prediction horizon of the fit [s] (`PredictionError.horizon`): None
      output error, 0 equation error, else windows of `horizon` seconds from the
      measured state; `...` (default): the preset's own where the fit starts from a
      preset that has `fit_settings`, else None.
    - `free`: the estimated parameters (names, or a comma-separated text; a leading `+`
      adds them to the default set); None: the preset's own set where it has one, else
      the model's `default_free`.
    - `sample_interval`: each record keeps every k-th sample, k the integer nearest to
      `sample_interval / dt` [s]; None: the preset's own where it has one, else as
      recorded. `velocities`: the trial CSVs' u, v, `"through-water"` or `"over-ground"`
      (None: as the records state).
    - `rudder`: the replayed rudder channel, `"delta"` or `"delta_c"`.
    - `channels`: fitted outputs, a subset of the entry's `channels` (or a text such as
      `"psi,r"`); None: the entry's `default_channels` (`psi, r`; `psi, r, u, v` for
      vessels; `r` for armax).
    - `initial`: start of each fitted window (`PredictionError.initial`):
      `MeasuredStates()` (the measured r and psi), `EstimatedStarts()` (corrections of
      them estimated with the parameters, which removes the bias a noisy start sample
      gives output error) or None (default): `EstimatedStarts` for output error where the
      entry supports it, `MeasuredStates` otherwise (the command's `--initial measured`,
      `estimate`, `auto` are the same). Validation always starts from the measured state.
    - `max_steps`: optimiser step limit; `substeps`: RK4 steps per sample interval.
    - `prior`: a Gaussian prior on the estimated coefficients centred on the start (the
      preset's, the vessel file's, the earlier result's values; a steering model's start
      values), with a standard deviation of `prior` times each start value's magnitude
      (`jaxship.strategies.Prior(scale=prior)`): the fit returns the maximum a posteriori
      estimate, charged for its effective number of parameters; result.json records the
      prior and per coefficient its data share. None or `math.inf`: no prior; `...`
      (default): the preset's own where the fit starts from a preset that has
      `fit_settings`, else no prior.
    - `progress`: a callable receiving `Progress` reports, or None (quiet).
    - `name`: the catalogue name a `model` object is fitted as (a preset's name for its
      vessel, `nomoto1-norrbin` for a `NonlinearNomoto`); None: a vessel of one's own,
      a steering model's class's entry.

    The preset's `fit_settings` (horizon, sample interval, free set, wind loads, prior) apply
    where the fit starts from the preset itself (its name, or its unchanged instance with
    `name`) and the option is not given; a note says which were used. Start values: the
    entry's `start` (linear least squares by `initial_estimate`, or a nested fit); if it
    fails (e.g. no excitation) the entry's neutral `fallback`, with a note; a fit that
    diverges from a regression start is restarted once from the fallback. Then `fit` with
    `PredictionError(horizon, channels, rudder)` and Levenberg-Marquardt (rtol = atol =
    1e-9); the assessment counts the d estimated parameters in FPE and AIC/BIC
    (FPE = V (1 + d/N) / (1 - d/N), thesis eq. 3.21).

    **Returns:** an `Identification` (`summary()`, `to_dict()`, `save(path)`).

    **Raises:** `ValueError` (one line) naming the file/record and column for unknown
    models or channels, missing files, a missing rudder column, a missing u or v the
    model needs, non-finite values or non-uniform sampling; for `armax`, more than one
    training record. `FitDivergedError` (a `ValueError`) when the fit diverged from every
    start tried.

    Nothing is warned or printed: the fit's result code (`result.fit.code`) says whether
    it converged, and the result's `warnings` hold a plain sentence for a fit that did not
    and every flag of the estimates; `notes` say what was done to the records and the
    options.
    """
    settings = fit_settings(model, name=name, horizon=horizon,
                            sample_interval=sample_interval, free=free, prior=prior)
    notes = [] if settings.note is None else [settings.note]
    reading = dict(note=notes.append, sample_interval=settings.sample_interval,
                   over_ground=over_ground(velocities))
    train = as_experiments(train, "training", **reading)
    validate = None if validate is None else as_experiments(validate, "validation", **reading)
    options = _Options(settings.horizon, rudder, channels, _initial(initial), max_steps, substeps,
                       settings.free, default_channels=channels is None,
                       prior=prior_scale(settings.prior))
    if settings.name == AUTO:  # each candidate fitted, one chosen (`selection`)
        result = _chosen((train, validate), options, progress)
    else:
        result = _identify((train, validate), settings.name, settings.start, options,
                           progress)
    return dataclasses.replace(result, notes=tuple(notes) + result.notes)


def _identify(records, model: str | None, start, asked: _Options,
              progress: Callable[[Progress], None] | None) -> Identification:
    """`identify` of the catalogue model `model` (None: a vessel of one's own, `start`)
    from `start` (None: the entry's start values) on the read `records = (train,
    validate)`, with the options `asked`."""
    name, entry = start_entry(model, start) if start is not None else \
        (model_key(model), MODELS[model_key(model)])
    options = _checked_options(name, entry, asked)
    records = _read_records(*records, options.rudder, name, entry, start)
    notes, caught = same_records(records.train, records.held_out or []), []
    options = options._replace(channels=_fitted_channels(records, options, notes))
    report = progress if progress is not None else (lambda event: None)
    fitting = _Fitting(name, records.train_ds, _estimator(options), report, options.max_steps)
    context = StartContext(rudder=options.rudder, channels=options.channels,
                           estimator=fitting.estimator, fit=fitting.run, note=notes.append)
    fitting.context = context
    start, method, neutral = _start_values(entry, records.train_ds, context, report, notes)
    if entry.fit is None:  # `--free +NAME`: added to the start's default set
        options = options._replace(free=added_free(options.free, entry.free, start))
    wind = getattr(start, "wind_loads", False) and logs_wind(records.train_ds)
    if wind:  # replayed where the model feels it, as `jaxship.discover` does
        fitting.estimator = dataclasses.replace(fitting.estimator, wind=True)
        notes.append(f"every training record logs the wind (wind_speed, wind_dir): replayed "
                     f"as loads on {type(start).__name__}.")
    result, start, method = _fit_or_restart(fitting, entry, options, context,
                                            (start, method, neutral), notes)
    caught.extend(_convergence_problems(result, options.max_steps))
    caught.extend(result.flags)
    caught.extend(_implausible(result.model, records, start, name))
    blocks = _assessments(result, entry, records, options, fitting, wind, notes)
    _frozen_notes(result, notes)
    return Identification(
        model_name=name, description=entry.description, fit=result, start=start,
        start_method=method, train=blocks[0], train_simulation=blocks[1],
        validation=blocks[2], options=options.to_json(), notes=tuple(notes),
        warnings=tuple(caught),
    )


def _implausible(model, records, start, name) -> list[str]:
    """`plausibility`'s warnings: a training record's rudder that looks like rad labelled
    deg, wind beyond any trial's or (for a vessel) a propeller rate too low to be in rpm,
    and the model's Nomoto indices against those of ships (made nondimensional by the
    ship's length, where the preset or vessel gives one, and the mean measured u)."""
    vessel = start if isinstance(start, js.AbstractVessel) else None
    out = [w for e in records.train for w in (
        rudder_in_rad(e), wind_too_strong(e),
        None if vessel is None else propeller_rate_slip(e, vessel)) if w is not None]
    length = float(vessel.length) if vessel is not None else preset_length(name)
    speeds = [np.asarray(e.u) for e in records.train if e.has("u")]
    speed = float(np.mean(np.concatenate(speeds))) if speeds else None
    return out + list(implausible(model, length=length, speed=speed))


def _chosen(records, options: _Options, progress) -> Identification:
    """`_identify` of each model of `CANDIDATES` on `records = (train, validate)` with the
    same `options`, the one chosen by `selection.choose` (the training records' fit
    criterion only) returned with its `selection`."""
    if options.free is not None:
        raise ValueError("--free does not go with --model auto: the candidates estimate "
                         "different parameters; choose a model to set them.")
    results, failed = {}, {}
    for name in CANDIDATES:
        try:
            results[name] = _identify(records, name, None, options, progress)
        except FitDivergedError as error:
            failed[name] = str(error)
    name, selection = choose(results, failed)
    return with_selection(results[name], selection)


def prior_scale(scale) -> float | None:
    """`identify`'s relative prior scale checked: a positive number, None for no prior (also
    for infinity, or the texts "inf" and "none")."""
    if scale is None or (isinstance(scale, str) and scale.strip().lower() in ("none", "inf")):
        return None
    try:
        value = float(scale)
    except (TypeError, ValueError):
        value = math.nan
    if not value > 0:
        raise ValueError(f"the prior's scale (--prior) {scale!r} must be a positive number "
                         "(a standard deviation relative to each start value, e.g. 0.3) or "
                         "inf/none (no prior).")
    return None if math.isinf(value) else value


def _initial(initial) -> str:
    """The name of `identify`'s `initial` (a strategy, None, or the command's text)."""
    if initial is None:
        return "auto"
    names = {js.MeasuredStates: "measured", js.EstimatedStarts: "estimate"}
    return names.get(type(initial), initial)


class _Options(NamedTuple):
    """`identify`'s options (as asked, then as `_checked_options` returns them)."""

    horizon: float | None
    rudder: str
    channels: tuple[str, ...]
    initial: str
    max_steps: int
    substeps: int
    free: tuple[str, ...] | None
    default_channels: bool  # no channels given: the entry's defaults, which data may thin
    prior: float | None = None  # the prior's scale relative to the start values

    def to_json(self) -> dict:
        return {"horizon_s": self.horizon, "rudder": self.rudder,
                "channels": list(self.channels), "initial": self.initial,
                "max_steps": self.max_steps, "substeps": self.substeps,
                "free": None if self.free is None else list(self.free)} | (
                    {} if self.prior is None else {"prior_scale": self.prior})


def _checked_options(name, entry, asked: _Options) -> _Options:
    """`identify`'s options as asked, checked against the model's entry: channels parsed
    (the entry's defaults when none is given), `initial="auto"` resolved (`"estimate"` for
    output error where the entry supports it, else `"measured"`)."""
    if asked.rudder not in ("delta", "delta_c"):
        raise ValueError(f"unknown rudder channel {asked.rudder!r}; choose 'delta' (measured "
                         "angle) or 'delta_c' (command).")
    channels = _parse_channels(entry.default_channels if asked.default_channels
                               else asked.channels, entry.channels)
    horizon, initial = asked.horizon, asked.initial
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
    if int(asked.max_steps) < 1:
        raise ValueError(f"`max_steps` must be a positive integer, got {asked.max_steps}.")
    return asked._replace(horizon=horizon, channels=channels, initial=initial,
                          max_steps=int(asked.max_steps), substeps=int(asked.substeps))


class _Records(NamedTuple):
    """The training and held-out records, as experiments and as datasets."""

    train: list
    held_out: list | None
    train_ds: js.Dataset
    valid_ds: js.Dataset | None


def _read_records(train, validate, rudder, name, entry, start) -> _Records:
    """Read and check the training and held-out records (columns the model needs, Froude
    number against the vessel's length where one is known)."""
    train_exps = as_experiments(train, "training")
    check_experiments(train_exps, rudder, "training", name, entry.requires)
    held_out = None
    if validate is not None:
        held_out = as_experiments(validate, "validation")
        check_experiments(held_out, rudder, "validation", name, entry.requires)
    length = float(start.length) if isinstance(start, js.AbstractVessel) else \
        preset_length(name)
    if length is not None:
        check_froude(train_exps, length, "training", name)
        check_froude(held_out or [], length, "validation", name)
    valid_ds = None if held_out is None else js.Dataset.from_experiments(held_out)
    return _Records(train_exps, held_out, js.Dataset.from_experiments(train_exps), valid_ds)


def _fitted_channels(records, options, notes) -> tuple[str, ...]:
    """The fitted output channels: those asked for (or the entry's default, less a default
    u or v that never varies and a default psi or r every training record derives), with
    a note on each dropped channel and on a horizon no shorter than the records."""
    channels, default_channels = options.channels, options.default_channels
    longest = max(e.duration for e in records.train)
    if options.horizon is not None and options.horizon >= longest:
        start = ("from each record's measured first state (--horizon none estimates that "
                 "state too: --initial estimate)" if options.initial == "measured" else
                 "from an estimated first state, as --horizon none")
        notes.append(f"the horizon (--horizon {options.horizon:g} s) is not shorter than any "
                     f"training record (the longest: {longest:.4g} s): each record is one "
                     f"window, so the fit is output error {start}.")
    if default_channels:  # a default u or v that never varies (e.g. no surge dynamics)
        constant = [c for c in channels
                    if c in ("u", "v") and np.ptp(valid_samples(records.train_ds, c)) == 0]
        if constant and len(constant) < len(channels):
            channels = tuple(c for c in channels if c not in constant)
            notes.append(f"the measured {', '.join(constant)} is constant in the training "
                         f"records: not fitted (channels {', '.join(channels)}).")
    return _derived_notes(records.train, records.held_out, channels, default_channels, notes)


def _estimator(options: _Options) -> js.PredictionError:
    """The prediction-error estimator of `identify`'s fit."""
    return js.PredictionError(
        horizon=options.horizon, channels=options.channels, rudder=options.rudder,
        simulator=js.Simulator(max_step=math.inf, substeps=options.substeps),
        solver=js.LevenbergMarquardt(rtol=1e-9, atol=1e-9), max_steps=options.max_steps,
        initial={"estimate": js.EstimatedStarts(),
                 "measured": js.MeasuredStates()}[options.initial],
        prior=None if options.prior is None else js.strategies.Prior(scale=options.prior))


@dataclasses.dataclass
class _Fitting:
    """A quiet, progress-reporting fit on the training data (`StartContext.fit`): with
    `estimator` (replaced by its wind-replaying copy once the start is known) or an
    entry's own estimator (`custom`, called with `context`)."""

    name: str
    train_ds: js.Dataset
    estimator: js.PredictionError
    report: Callable
    max_steps: int
    context: StartContext | None = None

    def run(self, start_model, *, free=None, stage="fitting", custom=None):
        relay = lambda event: self.report(dataclasses.replace(event, message=stage))
        if custom is not None and free is not None:
            raise ValueError(f"model {self.name} is fitted by its own estimator: it takes no "
                             "choice of free parameters.")
        if custom is None:
            return js.fit(start_model, self.train_ds, estimator=self.estimator, free=free,
                          progress=relay)
        total = self.max_steps  # an entry's own estimator (e.g. ARMAX): no steps to show
        relay(Progress("fit", stage, step=0, total=total))
        result = custom(start_model, self.train_ds, self.context)
        relay(Progress("fit", stage, step=int(result.num_steps), total=total,
                       cost=float(result.cost), done=True))
        return result

    def attempt(self, start_model, entry, free):
        """The fit from `start_model`, or `(None, why)` when its outputs became non-finite."""
        try:
            outcome = self.run(start_model, free=entry.free if free is None else free,
                               stage=f"fitting {self.name}", custom=entry.fit)
        except np.linalg.LinAlgError as error:  # NaN residuals: the simulation blew up
            return None, str(error)
        if not math.isfinite(outcome.cost):
            return None, f"cost {outcome.cost}"
        return outcome, ""


def _start_values(entry, train_ds, context, report, notes):
    """The entry's start values, or its neutral fallback (with a note) when the start
    regression fails. Returns `(start, method, neutral)`."""
    report(Progress("start", "start values"))
    try:
        start = entry.start(train_ds, context)
        method, neutral = entry.start_method, False
    except ValueError as error:
        start = entry.fallback(train_ds, context)
        method, neutral = "neutral fallback (the start-value regression failed)", True
        notes.append(f"start values: {error} A neutral start was used instead; the fit "
                     "below says whether the data determine the parameters.")
    report(Progress("start", "start values", done=True))
    return start, method, neutral


def _fit_or_restart(fitting, entry, options, context, begun, notes):
    """The fit from the start values; if it diverges from a regression start, once more
    from the neutral fallback. Returns `(result, start, method)`; raises
    `FitDivergedError` when no start gives finite outputs."""
    start, method, neutral = begun
    outcome, why = fitting.attempt(start, entry, options.free)
    if outcome is None and not neutral:
        notes.append(f"the fit from the {method} start diverged (non-finite model outputs: "
                     f"{why}); restarted from the neutral fallback start.")
        start = entry.fallback(fitting.train_ds, context)
        method = "neutral fallback (the fit from the regression start diverged)"
        outcome, why = fitting.attempt(start, entry, options.free)
    if outcome is None:
        raise FitDivergedError(
            f"the fit of {fitting.name} diverged: the model's outputs became non-finite "
            f"({why}) from the start {_values_text(start)}; try a finite --horizon, "
            "--initial measured or another model."
        )
    return outcome, start, method


def _assessments(result, entry, records, options, fitting, wind, notes):
    """The fit criterion on the training records, and the output-error simulations of the
    fitted model on the training and held-out records (None without held-out records)."""
    # the estimated parameters, or with a prior their effective number
    d = len(result.names) if result.effective_params is None else result.effective_params
    simulate = entry.simulate or simulate_records
    max_lag = int(fitting.estimator.max_lag)
    report, rudder, channels = fitting.report, options.rudder, options.channels
    # the criterion's horizon: the estimator's, or the entry's own (ARMAX: one sample)
    criterion = result.horizon
    train_block = assess("prediction" if criterion is not None else "simulation", criterion,
                          records.train_ds, rudder, (result.predictions, result.predicted),
                          (result.metrics[channels[0]].num_params, max_lag),
                          start="estimated" if options.initial == "estimate" else "measured")
    report(Progress("validate", "simulating the training records"
                    + (" and the validation records" if records.valid_ds is not None else "")))

    def measured(ds):  # psi and r always exist (derived if need be); other outputs if measured
        return tuple(c for c in entry.channels if c in ("psi", "r") or c in ds.channels)

    valid_ds = records.valid_ds
    held_wind = wind and valid_ds is not None and logs_wind(valid_ds)
    runs = [(records.train_ds, records.train, wind)] + (
        [] if valid_ds is None else [(valid_ds, records.held_out, held_wind)])
    simulated = _simulated(result.model, runs, simulate, rudder, measured, options.substeps)
    train_sim = assess("simulation", None, records.train_ds, rudder, simulated[0],
                       (d, max_lag), notes)
    if wind and valid_ds is not None and not held_wind:
        notes.append("the validation records do not all log the wind: simulated in calm air.")
    valid_block = None if valid_ds is None else assess(
        "simulation", None, valid_ds, rudder, simulated[1], (d, max_lag), notes)
    report(Progress("validate", "validation", done=True))
    return train_block, train_sim, valid_block


def _simulated(model, runs, simulate, rudder, measured, substeps):
    """The output-error simulation `(predictions, mask)` of each `(dataset, experiments,
    wind)` of `runs`: in one call where they simulate the same channels in the same air
    (one compiled program for records of every length), else one call each."""
    same = len({(measured(ds), wind) for ds, _, wind in runs}) == 1
    if len(runs) > 1 and same:
        both = js.Dataset.from_experiments([e for _, experiments, _ in runs
                                            for e in experiments])
        predictions, mask = simulate(model, both, rudder, measured(runs[0][0]),
                                     substeps=substeps, wind=runs[0][2])
        parts, first = [], 0
        for ds, _, _ in runs:
            rows = slice(first, first + ds.num_experiments)
            cut = lambda a: np.asarray(a)[rows, : ds.num_samples]
            parts.append(({c: cut(a) for c, a in predictions.items()}, cut(mask)))
            first += ds.num_experiments
        return parts
    return [simulate(model, ds, rudder, measured(ds), substeps=substeps, wind=wind)
            for ds, _, wind in runs]


def _frozen_notes(result, notes) -> None:
    """A note on the parameters the fit froze (a preset's many: only their number)."""
    frozen = list(result.to_dict()["frozen"])
    if len(frozen) > 12:  # a vessel preset: listed in the report's "frozen"
        notes.append(f"{len(frozen)} coefficients of the preset are frozen (not estimated); "
                     "see `frozen`.")
    elif frozen:
        notes.append("frozen parameters (not estimated): "
                     + ", ".join(f"{n} = {float(getattr(result.model, n)):.6g}" for n in frozen)
                     + ".")


def logs_wind(ds: js.Dataset) -> bool:
    """Whether every record of `ds` logs the true wind (`wind_speed`, `wind_dir`)."""
    return all({"wind_speed", "wind_dir"} <= set(c) for c in ds.experiment_channels)


def _derived_notes(train, held_out, channels, default_channels, notes) -> tuple[str, ...]:
    """Notes on the psi or r that records lack and `Experiment` derived (psi integrated
    from r, r differenced from psi); a default fitted channel derived in every training
    record is dropped from the fit (it repeats the other channel, with the integration
    or differencing error). Returns the fitted channels."""
    how = {"psi": "integrated from the measured r (psi = 0 at the start)",
           "r": "differenced from the measured psi"}
    for c in ("psi", "r"):
        for role, records in (("training", train), ("validation", held_out or [])):
            derived = [e.name for e in records if c in e.derived]
            if not derived:
                continue
            names = ", ".join(derived[:5]) + (f" and {len(derived) - 5} more"
                                              if len(derived) > 5 else "")
            plural = "s" if len(derived) > 1 else ""
            text = (f"{c} is not measured in the {role} record{plural} {names}: it is "
                    f"{how[c]}, so their {c} fit % compares the model with that derived "
                    f"{c}, not with a measurement")
            if (role == "training" and default_channels and c in channels
                    and len(channels) > 1 and len(derived) == len(records)):
                channels = tuple(k for k in channels if k != c)
                text += f"; {c} is not fitted (channels {', '.join(channels)})"
            notes.append(text + ".")
    return channels


def _convergence_problems(result, max_steps: int) -> list[str]:
    """A plain sentence for a fit that stopped without converging (none when it did, or
    when its parameter flags already say why: an estimate on a bound, a combination the
    data do not determine)."""
    code = result.code
    if result.success or code in (js.RESULTS.at_bound, js.RESULTS.poorly_determined,
                                     js.RESULTS.undetermined):
        return []
    if code in (js.RESULTS.simulation_blew_up, js.RESULTS.did_not_move):
        return [f"{result.message}."]
    if code in (js.RESULTS.nonlinear_max_steps_reached, js.RESULTS.max_steps_reached) \
            or int(result.num_steps) >= max_steps:
        return [f"the fit stopped at the step limit ({max_steps}) before converging; the "
                "estimates are those of the last step, not an optimum: raise --max-steps or "
                "check the data and the model."]
    if code == js.RESULTS.nonlinear_divergence:
        return [f"the fit diverged after {int(result.num_steps)} steps (the optimiser's steps "
                "grew without bound); the estimates mean nothing: try a finite --horizon, "
                "--initial measured or another model."]
    if code == js.RESULTS.singular:
        return [f"the fit stopped after {int(result.num_steps)} steps: the optimiser's linear "
                "solve failed (a singular Jacobian: some parameters do not change the "
                "outputs); see the identifiability flags."]
    return [f"the fit stopped after {int(result.num_steps)} steps without converging "
            f"({result.message.splitlines()[0]})."]
