"""`discover`: from disagreement between a fitted model and measured data to a named,
fitted, verified model term (or the answer that nothing is missing).

The base model is fitted; a search (`_search`: forward steps, each followed by a
backward step, over a small beam of candidate sets) names the effects it lacks; every
named effect is reported with its estimate from the final fit and its interval.
"""

import dataclasses
import statistics

import numpy as np

from ..._estimate._excitation import TOO_POOR
from ..._estimate._fit import PredictionError, fit
from ..._estimate._initial import EstimatedStarts, MeasuredStates
from ..._estimate._lm import RESULTS, LevenbergMarquardt
from ..._estimate._result import FitError
from ..._estimate._windows import as_dataset
from ..._foundation._params import default_free
from ..._foundation._progress import Progress
from ..._foundation._validate import NonFiniteError
from ._catalogue import DISCOVERY_CATALOGUE
from ._forces import smoothed_vessel_states
from ._holdout import cost_rise, holdout_check, holdout_indices
from ._locate import locate_disagreement
from ._plumbing import parameters, split
from ._report import DiscoveryReport, Verdict
from ._search import Path, Search


# a held-out rise beyond this many standard errors
HELDOUT_Z = statistics.NormalDist().inv_cdf(0.95)
BLOCK = 60.0  # [s] stretches of the held-out cost's spread when the estimator has no horizon
# every fit of discover stops once an accepted step lowers the cost S by at most 1e-7
# relative (MINPACK's ftol; `fit`'s default 1e-10): with S about N sigma^2 / 2 for N
# residuals, that is 2 dS / sigma^2 <= 1e-7 N likelihood-ratio units, 0.003 on the
# KVLCC2 case (N about 26,000), against thresholds of 10-20. Measured there
# (2026-11-26): the same effects named, estimates and costs equal to 1e-7 relative,
# 18 % fewer steps (base fit 54 -> 40); the README's command 269 -> 246 s (first run).
FIT_SOLVER = LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-7)


@dataclasses.dataclass(frozen=True)
class DiscoveryOptions:
    """How `discover` searches: `max_effects` most effects named; `alpha` family-wise
    false-alarm rate over candidates and iterations; `top` classes refitted per step;
    `equivalence` canonical correlation above which candidates are one class; `beam`
    candidate sets followed at once (`_search`)."""

    max_effects: int = 3
    alpha: float = 0.01
    top: int = 3
    equivalence: float = 0.98
    beam: int = 2


def _has_output(model, channel) -> bool:
    try:
        model.channel_index(channel)
    except ValueError:
        return False
    return True


def _setup(model, train, holdout, estimator, progress) -> dict:
    """What every step of the search shares (see `Search`), before the base fit: the
    datasets, the estimator with its channels and window starts, `loss(m)` and
    `check(m)` (the held-out check)."""
    data = as_dataset(train)
    held = as_dataset(holdout) if holdout else None
    logs = lambda d, *names: all(set(names) <= set(c) for c in d.experiment_channels)
    windy = estimator.wind or logs(data, "wind_speed", "wind_dir")
    held_windy = held is not None and logs(held, "wind_speed", "wind_dir")
    everywhere = lambda c: logs(data, c) and (held is None or logs(held, c))
    vessel = _has_output(model, "x")  # steering models have no track
    if estimator.channels is None and vessel:
        # a vessel fits the channels every record logs, and on records with positions
        # (GNSS) its track too: a current shows
        channels = tuple(c for c in model.default_channels + ("x", "y") if everywhere(c))
        estimator = dataclasses.replace(estimator, channels=channels)
    held_start = MeasuredStates()
    if vessel and not everywhere("v") and not isinstance(estimator.initial, (list, tuple)):
        # a vessel's windows start from its states smoothed from psi, r, u and the track
        smoothed = [smoothed_vessel_states(model, d) for d in (data, held) if d is not None]
        if any(s is None for s in smoothed):
            raise ValueError("records without a measured sway velocity v need psi, r, u and "
                             "the track x, y logged (the drift is smoothed from them).")
        estimator = dataclasses.replace(estimator, initial=smoothed[0])
        held_start = smoothed[-1]
    setup = dict(data=data, train=train, holdout=holdout, estimator=estimator,
                 say=(lambda message: None) if progress is None else (
                     lambda message: progress(Progress("discover", message))))
    # the logged wind replayed where model `m` feels it
    setup["loss"] = lambda m: dataclasses.replace(estimator, wind=bool(windy and m.wind_loads))
    setup["check"] = lambda m: holdout_check(
        m, holdout, setup["channels"], wind=bool(held_windy and m.wind_loads),
        window=estimator.horizon, initial=held_start)
    block = estimator.horizon or BLOCK
    setup["heldout_rise"] = lambda after, current, base: heldout_rise(after, current, base,
                                                                      block)
    return setup


YAW_CHANNELS = ("psi", "r")  # every model predicts them; a missing effect shifts them only


def too_short(data, horizon) -> str:
    """Why records `data` (a `Dataset`) are too short to judge a missing effect, or "":
    the longest lasts less than one prediction window (`horizon` [s]), so no effect
    has a window's time to build up a residual the score could see."""
    lengths = np.asarray(data.lengths) - 1
    longest = float(max(data.t[i, n] - data.t[i, 0] for i, n in enumerate(lengths)))
    if horizon is None or longest >= horizon:
        return ""
    return (f"the training records are too short to judge: the longest lasts {longest:.3g} s, "
            f"less than one {horizon:g} s prediction window; give records of whole manoeuvres "
            "(e.g. zig-zags).")


def not_described(base_fit, names) -> str:
    """Why the base model does not describe the training records, or "": its fit of
    psi or r (in the fit's own prediction windows) is below 0 % on a record, worse than
    the record's own mean. A missing effect of the catalogue leaves the yaw predictable
    over a window (measured: 53-99 % on every record of the hidden-effect cases); a
    record of another ship does not (-253 %)."""
    poor = [f"{name} {c} {fit:.0f} %" for c in YAW_CHANNELS if c in base_fit.metrics
            for name, fit in zip(names, np.asarray(base_fit.metrics[c].fit_per_experiment))
            if fit < 0.0]
    if not poor:
        return ""
    return ("the base model does not describe the training records: its fit is below 0 % "
            f"(worse than the record's mean) on {', '.join(poor)}; records of different ships "
            "or a wrong model? No effect can be judged missing from a model that fits nothing.")


def _base_fit(model, setup, free):
    """The base model's fit, its held-out check and why the records cannot judge a
    missing effect ("" when they can; else the check is None). `FitError` where the
    fitted base model blows up on the held-out records."""
    setup["say"]("fitting the base model")
    base_fit = fit(model, setup["train"], estimator=setup["loss"](model), free=free)
    setup["channels"] = tuple(base_fit.metrics)
    too_poor = [f for f in base_fit.parameters.undetermined if f.startswith(TOO_POOR)]
    why = too_short(setup["data"], setup["estimator"].horizon)
    if not why and (too_poor or base_fit.code == RESULTS.did_not_move):
        why = (f"the base model's fit to the training records is {base_fit.code_name} "
               f"({'; '.join(too_poor) or base_fit.message}): these records cannot tell "
               "whether an effect is missing; give longer records that excite the model "
               "(e.g. zig-zags).")
    why = why or not_described(base_fit, setup["data"].names)
    if why or not setup["holdout"]:
        return base_fit, None, why
    try:
        before = setup["check"](base_fit.model)
    except NonFiniteError as error:  # no bad input: the training records do not hold
        raise FitError(
            f"the base model fitted to the training records (fit: {base_fit.message}) blows "
            f"up on the held-out records ({error}): they do not determine it for those "
            "manoeuvres; train on records that cover them.") from None
    return base_fit, before, ""


def _cannot_judge(base_fit, setup, why, alpha) -> DiscoveryReport:
    """The report of records that cannot judge: the base fit, where it disagrees (for a
    fit that moved on records long enough), no candidate scored."""
    setup["say"](f"cannot judge: {why}")
    disagreement = {}
    if base_fit.code != RESULTS.did_not_move and not too_short(setup["data"],
                                                               setup["estimator"].horizon):
        located = locate_disagreement(base_fit.model, setup["train"], setup["channels"],
                                      wind=setup["loss"](base_fit.model).wind)
        disagreement = {"before": located, "after": located}
    return DiscoveryReport(
        verdict=Verdict.cannot_judge, effects=(), rejected=(), scores={},
        model_before=base_fit.model, model_after=base_fit.model,
        train_cost_before=base_fit.cost, train_cost_after=base_fit.cost,
        holdout_cost_before=None, holdout_cost_after=None, holdout_fit_percent_before=None,
        holdout_fit_percent_after=None, holdout_indices={}, alpha=alpha,
        channels=setup["channels"], disagreement=disagreement, why=why)


def discover(model, train, holdout=None, *, catalogue=DISCOVERY_CATALOGUE,
             estimator: PredictionError = PredictionError(horizon=60.0,
                                                          initial=EstimatedStarts(),
                                                          solver=FIT_SOLVER),
             free=None, options: DiscoveryOptions = DiscoveryOptions(),
             progress=None) -> DiscoveryReport:
    """Find, name and add the effects missing from `model`.

    **Arguments:**

    - `model`: a vessel or steering model (start values of the base fit).
    - `train`: the records the model is fitted and scored on (`Experiment`s or a
      `Dataset`); `holdout`: records of other manoeuvres, used only to check that an
      effect improves predictions (output error) and to report the gap closed.
    - `catalogue`: the candidate effects (`jaxship.DISCOVERY_CATALOGUE`).
    - `estimator`: the prediction-error loss of every fit and score (default: 60 s
      windows, so that the window-clustered score variance holds for coloured
      residuals, each starting from an estimated correction of the measured r and psi,
      and Levenberg-Marquardt stopping at 1e-7 relative cost change, `FIT_SOLVER`; a
      steering model's other states start from their measured values); `free`: the
      base parameters fitted (default the model's). Where every training record logs
      the wind, models that feel it replay it; candidates a model's own equations
      carry (its `built_in_effects`) are not offered; a vessel fits the channels every
      record logs, x and y as well where they are (a current shows there), and where v
      is not logged its windows start from its states smoothed from psi, r, u and the
      track (`smoothed_vessel_states`).
    - `options`: `DiscoveryOptions` (most effects, family-wise false-alarm rate, classes
      refitted per step, equivalence, beam width).
    - `progress`: a callable taking a `Progress` report (stage `"discover"`) at each stage.

    **Returns:** a `DiscoveryReport`; each named effect's parameters are those of the
    final fit, with their robust standard errors and +-3 standard-error intervals.
    `Verdict.cannot_judge` (the reason in `why`, nothing scored) where every record is
    shorter than a prediction window (`too_short`), the base fit is undetermined (no
    rudder moves, too few values) or never moves, or `not_described` holds.

    **Raises:** `jaxship.FitError` where the fitted base model's prediction of the
    held-out records blows up.
    """
    free = tuple(default_free(model) if free is None else free)
    setup = _setup(model, train, holdout, estimator, progress)
    base_fit, before, why = _base_fit(model, setup, free)
    if why:
        return _cannot_judge(base_fit, setup, why, options.alpha)
    # effects join in one order, the start model's first, then the catalogue's: each
    # step's scored model then has the structure of the first (its compilation reused)
    order = {c.id: i for i, c in enumerate(catalogue)} | {e.id: -1 for e in split(model)[1]}
    search = Search(setup | dict(free=free, catalogue=catalogue, options=options, order=order,
                                 entries={c.id: c for c in catalogue}, before=before))
    paths, ended = [Path(base_fit, {}, held=before)], []
    for iteration in range(1, 2 * options.max_effects + 1):  # room for backward steps
        paths, done = search.step(paths, iteration)
        ended += done
        if not paths:
            break
    best = min(ended + paths, key=search.rank)
    current, say = best.fit, setup["say"]
    accepted = tuple(dataclasses.replace(r, parameters=parameters(current, best.names[r.id]),
                                         jointly_with=tuple(j for j in r.jointly_with
                                                            if j in best.names))
                     for r in best.accepted)
    after = setup["check"](current.model) if holdout else None
    say("locating the disagreement before and after")
    channels, loss = setup["channels"], setup["loss"]
    disagreement = {label: locate_disagreement(r.model, train, channels,
                                               wind=loss(r.model).wind)
                    for label, r in (("before", base_fit), ("after", current))}
    return DiscoveryReport(
        verdict=Verdict.missing_effect if accepted else Verdict.nothing_missing, effects=accepted,
        rejected=best.rejected, scores=search.first_scores or {},
        model_before=base_fit.model, model_after=current.model,
        train_cost_before=base_fit.cost, train_cost_after=current.cost,
        holdout_cost_before=before["cost"] if holdout else None,
        holdout_cost_after=after["cost"] if holdout else None,
        holdout_fit_percent_before=before["fit_percent"] if holdout else None,
        holdout_fit_percent_after=after["fit_percent"] if holdout else None,
        holdout_indices=holdout_indices(holdout, before["predictions"],
                                        after["predictions"]) if holdout else {},
        alpha=options.alpha, channels=channels, disagreement=disagreement)


def heldout_rise(after: dict, current: dict, base: dict, block: float) -> str | None:
    """Why the held-out check fails, or None: the held-out cost after a refit (`holdout_check`
    outputs) must not rise beyond `HELDOUT_Z` standard errors over stretches of `block`
    seconds (`cost_rise`; without such spread it must fall), neither against the `current`
    model nor since the `base` model, so that steps each within the spread cannot add up."""
    references = [(current, "")] + ([] if base is current else [(base, " since the base model")])
    for reference, since in references:
        rise, spread = cost_rise(reference, after, block)
        if not rise < HELDOUT_Z * spread:
            change = f"{reference['cost']:.4g} -> {after['cost']:.4g}"
            return (f"the held-out cost rises{since} ({change}; {rise:.3g} against a standard "
                    f"error of {spread:.3g} over the stretches)" if spread else
                    f"the held-out cost does not fall{since} ({change})")
    return None
