"""The settings of a fit: a preset's own (`VESSELS[name].fit_settings`: the horizon, the
records' sample interval, the free coefficients and the wind loads a protocol chose on
training runs only) where the fit starts from the preset itself and the option is not
given; the leading `+` of `free`, which adds names to the default set."""

from __future__ import annotations

from typing import NamedTuple

import equinox as eqx

import jaxship as js

from .registry import model_key, start_name
from .result import Identification
from .selection import AUTO, is_auto


class Settings(NamedTuple):
    """The settings `identify` fits with: `name`, the catalogue name (`"auto"`: the
    choice; None: a vessel of one's own), `horizon` [s] (None: output error),
    `sample_interval` [s] (None: as recorded), `free` (None: the model's default set;
    a text `"+NAME,..."`: names added to it, `added_free`),
    `start` (the model to start from; None: the catalogue's start values), `note`
    (the preset's settings used, in one sentence; None when none was) and `prior` (the
    prior's relative scale, `identify`'s `prior`; None: no prior)."""

    name: str | None
    horizon: float | None
    sample_interval: float | None
    free: tuple[str, ...] | None
    start: object
    note: str | None
    prior: float | None = None


def _is_preset(name, start) -> bool:
    """Whether the fit starts from the preset `name` itself: named (`start` None) or its
    unchanged instance (`--vessel NAME`), not a vessel file or an earlier result."""
    if name not in js.VESSELS:
        return False
    if start is None:
        return True
    preset = js.get_vessel(name)
    same = eqx.tree_equal(start, preset)
    return type(start) is type(preset) and bool(same)


def free_names(free, default) -> tuple[str, ...] | str | None:
    """`free`: None (`default`), names (a sequence, or a text of comma-separated names),
    or a text starting with `+`: its names added to `default`; where `default` is None
    (a model whose set is known once its start is: its `default_free`), the text
    `"+NAME,..."`, which `added_free` resolves then."""
    if free is None:
        return default
    text = free if isinstance(free, str) else ",".join(free)
    add = text.strip().startswith("+")
    names = tuple(n.strip() for n in text.strip().lstrip("+").split(",") if n.strip())
    if not names:
        raise ValueError(f"--free {free!r}: give coefficient names, comma separated.")
    if not add:
        return names
    return "+" + ",".join(names) if default is None else tuple(dict.fromkeys(default + names))


def added_free(free, default, start) -> tuple[str, ...] | None:
    """The free set of a fit from the model `start`: `free` itself, or for a text
    `"+NAME,..."` (`free_names`) its names added to `default` (None: `start`'s
    `default_free`). An unknown name is left to `jaxship.fit`, which refuses it naming
    the model's parameters."""
    if not isinstance(free, str):
        return free
    base = js.default_free(start) if default is None else tuple(default)
    return tuple(dict.fromkeys(base + free_names(free, ())))


def fit_settings(model, *, name: str | None = None, horizon=..., sample_interval=None,
                 free=None, prior=...) -> Settings:
    """The `Settings` `identify(model, ..., name=name, horizon=horizon, ...)` fits with:
    the options given, else the preset's `fit_settings` where the fit starts from a
    preset that has them, the preset itself (its name, or its unchanged instance with its
    `name`); then the preset starts with the settings' wind loads. `horizon=...`: not
    given (None is output error), and so for `prior` (None is no prior). A `free` text
    starting with `+` adds to the preset's set (its `default_free` where it has no
    settings). **Raises** `ValueError` for an unknown model name."""
    name, start = _start(model, name)
    given_prior = prior is not ...
    if name == AUTO:
        return Settings(AUTO, None if horizon is ... else horizon, sample_interval, free,
                        None, None, prior if given_prior else None)
    settings = js.VESSELS[name].fit_settings if _is_preset(name, start) else None
    given_horizon = horizon is not ...
    if settings is None:  # a "+" set is resolved once the start is known (`added_free`)
        return Settings(name, horizon if given_horizon else None, sample_interval,
                        free_names(free, None), start, None, prior if given_prior else None)
    used = [text for given, text in (
        (given_horizon, f"--horizon {settings.horizon:g}"),
        (sample_interval is not None, f"--sample-interval {settings.sample_interval:g}"),
        (free is not None, "--free " + ",".join(settings.free)),
        (given_prior or settings.prior is None, f"--prior {settings.prior}"))
        if not given]
    if settings.wind_model is not None:  # the chosen wind loads
        start = eqx.tree_at(lambda v: v.wind_model, js.get_vessel(name), settings.wind_model)
        used.append(f"wind loads {type(settings.wind_model).__name__}")
    note = None if not used else (f"the {name} preset's settings: {'; '.join(used)} "
                                  f"({settings.source}).")
    return Settings(name, horizon if given_horizon else settings.horizon,
                    settings.sample_interval if sample_interval is None else sample_interval,
                    free_names(free, settings.free), start, note,
                    prior if given_prior else settings.prior)


def _start(model, name) -> tuple[str | None, object]:
    """`(name, start)` of `identify`'s `model`: a catalogue name (`AUTO` for the choice)
    and no start, or the catalogue name a model object is fitted as (`start_name`) and
    the model."""
    if isinstance(model, Identification):
        return start_name(model.model, name or model.model_name), model.model
    if isinstance(model, str):
        return (AUTO if is_auto(model) else model_key(model)), None
    if not isinstance(model, (js.AbstractModel, js.ARMAXModel)):
        raise ValueError(f"`model` must be a catalogue name, 'auto', a model or an "
                         f"Identification, got {type(model).__name__}.")
    return start_name(model, name), model
