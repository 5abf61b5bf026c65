"""`identify`: estimate a named steering model from measured trials and validate it.

One call runs the whole identification workflow of the thesis (seed 000, ch. 3) and
of MATLAB's System Identification Toolbox: read the records, compute start values by
linear least squares (`initial_estimate`), fit by prediction error (`fit`), simulate
the fitted model on the training and on held-out records (output error, starting
from the measured state), and collect loss, FPE, AIC/BIC, fit %, residual tests,
standard errors, the correlation matrix and plain-language identifiability flags
in an `IdentificationResult`.

The library stays quiet: progress goes to the `progress` callable (see `Progress`),
which the `jaxship identify` command turns into a tqdm bar; the fit's result code says
whether it converged, and its problems are plain sentences in the result's `warnings`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

import jaxship as js

from ... import Progress
from ..._foundation._params import parameter_fields
from .assessment import assess
from .data import (
    as_experiments,
    check_experiments,
    check_froude,
    preset_length,
    same_records,
    valid_samples,
)
from .registry import MODELS, model_key, start_entry
from .result import IdentificationResult
from .simulation import simulate_records
from .starts import StartContext


class FitDivergedError(ValueError):
    """`identify`'s fit diverged: the model's outputs became non-finite from every start
    tried (the `jaxship identify` command exits with status 3)."""


def _values_text(model) -> str:
    names = tuple(parameter_fields(model))
    if not names:  # a vessel: its default free coefficients
        names = js.default_free(model)
    return ", ".join(f"{n} = {float(getattr(model, n)):.4g}" for n in names)


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
             progress: Callable[[Progress], None] | None = None,
             start=None, free=None) -> IdentificationResult:
    """Estimate a registered steering model from training records and validate it.

    **Arguments:**

    - `train`: the training records: an `Experiment`, a list of them, a `Dataset`,
      or file/folder paths (see `read_experiments`).
    - `model`: a name in `MODELS`: `nomoto1`, `nomoto2`, `nomoto1-nonlinear`,
      `ross-autopilot`, `linear-sway-yaw`, `norrbin-crossflow`, `low-speed-sway-yaw`,
      `armax` or a vessel preset of `jaxship.VESSELS` (its `default_free`
      coefficients are estimated from the preset's values; records need u and v).
      Models that feel the wind (vessels, `low-speed-sway-yaw`) get the logged wind
      replayed when every training record logs it (each validation set likewise).
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
    - `start`: a model to start from (`--vessel`: a vessel of a preset or a vessel
      file, the model of an earlier result), fitted as `model` is (`start_entry`); a
      vessel's `model` is its preset name, or None for a vessel of one's own.
    - `free`: the names of the estimated parameters; None: the model's `default_free`.

    Start values: the entry's `start` (linear least squares by `initial_estimate`,
    or a nested fit); if it fails (e.g. no excitation) the entry's neutral
    `fallback`, with a note. Then `fit` with `PredictionError(horizon, channels,
    rudder)`.

    **Returns:** an `IdentificationResult`; `to_json()` gives `model`,
    `parameters` (`{name: {value, std, unit, relative_std, start}}`, SI), `frozen`,
    `constants` (fixed non-parameter fields: `model_from_report` rebuilds the model),
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
    `FitDivergedError` (a `ValueError`) when the fit diverged from every start tried.

    Nothing is warned or printed: the fit's result code (`result.fit.code`) says whether
    it converged, and the result's `warnings` hold a plain sentence for a fit that did not
    (the step limit, divergence, a blow-up) and every flag of the estimates (an estimate
    on a bound, no excitation: the fit still returns, with infinite standard errors).

    Records without a measured psi (or r) are filled by `Experiment` (psi integrated
    from r, r differenced from psi); a note says so, and with the default `channels`
    such a channel is not fitted when every training record lacks it.
    """
    name, entry = start_entry(model, start) if start is not None else \
        (model_key(model), MODELS[model_key(model)])
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
    train_ds = js.Dataset.from_experiments(train_exps)
    valid_ds = None if held_out is None else js.Dataset.from_experiments(held_out)
    notes, caught = same_records(train_exps, held_out or []), []
    longest = max(e.duration for e in train_exps)
    if horizon is not None and horizon >= longest:
        notes.append(f"the horizon (--horizon {horizon:g} s) is not shorter than any training "
                     f"record (the longest: {longest:.4g} s): each record is one window, so the "
                     "fit is output error (--horizon none).")
    if default_channels:  # a default u or v that never varies (e.g. no surge dynamics)
        constant = [c for c in channels
                    if c in ("u", "v") and np.ptp(valid_samples(train_ds, c)) == 0]
        if constant and len(constant) < len(channels):
            channels = tuple(c for c in channels if c not in constant)
            notes.append(f"the measured {', '.join(constant)} is constant in the training "
                         f"records: not fitted (channels {', '.join(channels)}).")
    channels = _derived_notes(train_exps, held_out, channels, default_channels, notes)

    report = progress if progress is not None else (lambda event: None)
    solver = js.LevenbergMarquardt(rtol=1e-9, atol=1e-9)
    estimator = js.PredictionError(horizon=horizon, channels=channels, rudder=rudder,
                                simulator=js.Simulator(max_step=math.inf, substeps=int(substeps)),
                                solver=solver,
                                max_steps=int(max_steps),
                                initial={"estimate": js.EstimatedStarts(),
                                         "measured": js.MeasuredStates()}[initial])

    def run_fit(start_model, *, free=None, stage="fitting", custom=None):
        relay = lambda event: report(dataclasses.replace(event, message=stage))
        if custom is not None and free is not None:
            raise ValueError(f"model {name} is fitted by its own estimator: it takes no "
                             "choice of free parameters.")
        if custom is None:
            return js.fit(start_model, train_ds, estimator=estimator, free=free,
                          progress=relay)
        total = int(max_steps)  # an entry's own estimator (e.g. ARMAX): no steps to show
        relay(Progress("fit", stage, step=0, total=total))
        result = custom(start_model, train_ds, context)
        relay(Progress("fit", stage, step=int(result.num_steps), total=total,
                       cost=float(result.cost), done=True))
        return result

    context = StartContext(rudder=rudder, channels=channels, estimator=estimator,
                           fit=run_fit, note=notes.append)
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
    wind = getattr(start, "wind_loads", False) and logs_wind(train_ds)
    if wind:  # replayed where the model feels it, as `jaxship.discover` does
        estimator = dataclasses.replace(estimator, wind=True)
        notes.append(f"every training record logs the wind (wind_speed, wind_dir): replayed "
                     f"as loads on {type(start).__name__}.")

    def attempt(start_model):
        try:
            outcome = run_fit(start_model, free=entry.free if free is None else free,
                              stage=f"fitting {name}",
                              custom=entry.fit)
        except np.linalg.LinAlgError as error:  # NaN residuals: the simulation blew up
            return None, str(error)
        if not math.isfinite(outcome.cost):
            return None, f"cost {outcome.cost}"
        return outcome, ""

    outcome, why = attempt(start)
    if outcome is None and not neutral:
        notes.append(f"the fit from the {method} start diverged (non-finite model outputs: "
                     f"{why}); restarted from the neutral fallback start.")
        start = entry.fallback(train_ds, context)
        method = "neutral fallback (the fit from the regression start diverged)"
        outcome, why = attempt(start)
    if outcome is None:
        raise FitDivergedError(
            f"the fit of {name} diverged: the model's outputs became non-finite ({why}) from "
            f"the start {_values_text(start)}; try a finite --horizon, --initial measured or "
            "another model."
        )
    result = outcome
    problems = _convergence_problems(result, int(max_steps))
    caught.extend(problems)
    caught.extend(result.flags)

    d = len(result.names)
    simulate = entry.simulate or simulate_records
    max_lag = int(estimator.max_lag)
    # the criterion's horizon: the estimator's, or the entry's own (ARMAX: one sample)
    criterion = result.horizon
    train_block = assess("prediction" if criterion is not None else "simulation", criterion,
                          train_ds, rudder, result.predictions, result.predicted,
                          int(result.metrics[channels[0]].num_params), max_lag,
                          start="estimated" if initial == "estimate" else "measured")
    report(Progress("validate", "simulating the training records"))
    def measured(ds):  # psi and r always exist (derived if need be); other outputs if measured
        return tuple(c for c in entry.channels if c in ("psi", "r") or c in ds.channels)

    predictions, mask = simulate(result.model, train_ds, rudder, measured(train_ds),
                                 substeps=int(substeps), wind=wind)
    train_sim = assess("simulation", None, train_ds, rudder, predictions, mask, d, max_lag,
                        notes)
    valid_block = None
    if valid_ds is not None:
        report(Progress("validate", "simulating the validation records"))
        held_wind = wind and logs_wind(valid_ds)
        if wind and not held_wind:
            notes.append("the validation records do not all log the wind: simulated in calm "
                         "air.")
        predictions, mask = simulate(result.model, valid_ds, rudder, measured(valid_ds),
                                     substeps=int(substeps), wind=held_wind)
        valid_block = assess("simulation", None, valid_ds, rudder, predictions, mask, d,
                              max_lag, notes)
    report(Progress("validate", "validation", done=True))

    frozen = list(result.to_dict()["frozen"])
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
                 "initial": initial, "max_steps": int(max_steps), "substeps": int(substeps),
                 "free": None if free is None else list(free)},
        notes=tuple(notes), warnings=tuple(caught),
    )
    return out


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
