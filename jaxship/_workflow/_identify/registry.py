"""The model registry of `identify`: `MODELS` maps a command-line name to a `ModelEntry`
(description, start values, outputs, required channels, simulation and, where it is
not `jaxship.fit`, the estimator). Adding a model is adding one entry."""

import dataclasses
from collections.abc import Callable

import jaxship as js

from . import starts
from .armax import fit_armax_entry, start_armax
from .simulation import simulate_armax_records


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
    - `simulate(model, dataset, rudder, channels, substeps=1, wind=False) ->
      (predictions, mask)`: the output-error simulation of the model on records,
      starting from the measured state (with the logged wind replayed if `wind`):
      `{channel: (E, N) array}` and the (E, N) mask of simulated samples. None:
      `simulate_records`, which serves every steering model and vessel.
    - `fit(start, train, context) -> FitResult`: replaces the prediction-error fit
      (`jaxship.fit` with `context.estimator`) for models it does not serve, e.g.
      the discrete ARMAX model; None: `jaxship.fit`.
    - `free`: the parameters estimated, where not the start model's `param` defaults.
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
    free: tuple[str, ...] | None = None


def _vessel_entry(name: str, vessel=None, description: str = "") -> ModelEntry:
    """The entry of the vessel preset `name`, or of the `vessel` given (`--vessel`)."""
    def start(train, context):
        return js.get_vessel(name) if vessel is None else vessel

    return ModelEntry(
        "vessel preset (3-DOF, default_free estimated): " + js.VESSELS[name].description
        if vessel is None else description,
        start, start,
        start_method=f"the preset's coefficients (get_vessel({name!r}))" if vessel is None
        else "the given vessel's coefficients (--vessel)",
        channels=("psi", "r", "u", "v"), default_channels=("psi", "r", "u", "v"),
        requires=("u", "v"), initial=("measured",),
    )


MODELS: dict[str, ModelEntry] = {
    "nomoto1": ModelEntry(
        "first-order Nomoto model T r' + r = K (delta + delta0): K [1/s], T [s]",
        starts.start_nomoto1, starts.fallback_nomoto1,
    ),
    "nomoto2": ModelEntry(
        "second-order Nomoto model K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)): K [1/s], T1, T2, "
        "T3 [s]",
        starts.start_nomoto2, starts.fallback_nomoto2,
        start_method="a fitted Nomoto1 (linear least-squares start), its T spread over T1, T2, "
        "T3",
    ),
    "nomoto1-nonlinear": ModelEntry(
        "nonlinear first-order Nomoto model T r' + n3 r^3 + n1 r = K delta (Norrbin): K [1/s], "
        "T [s], n3 [s^2/rad^2]",
        starts.start_nonlinear, starts.fallback_nonlinear,
    ),
    "nomoto1-norrbin": ModelEntry(
        "nonlinear first-order Nomoto model T r' + n3 r^3 + n1 r = K delta (Norrbin) of either "
        "course stability: T held at the linear Nomoto1's (the scale), K [1/s], n1 [-] (either "
        "sign: n1 < 0 course unstable, a spiral loop) and n3 [s^2/rad^2] estimated",
        starts.start_norrbin_either, starts.fallback_nonlinear, free=("K", "n1", "n3"),
        start_method="linear least squares with n1 = +1 or -1 (initial_estimate), as "
        "nomoto1-nonlinear",
    ),
    "ross-autopilot": ModelEntry(
        "Ross (2008) autopilot model without roll, driven by the measured u, v (thesis eq. "
        "3.6-3.7): 12 hull terms and the rudder term, scaled coefficients [-]",
        starts.start_ross, starts.fallback_ross, requires=("u", "v"),
        start_method="equation-error linear least squares (ross_initial_estimate)",
    ),
    "linear-sway-yaw": ModelEntry(
        "linear sway-yaw model in prime derivatives driven by the measured u (Astrom & "
        "Kallstrom 1979, eq. 3): Y'v, Y'r, N'v, N'r, Y'delta, N'delta [-]",
        starts.start_linear_sway_yaw, starts.start_linear_sway_yaw, channels=("psi", "r", "v"),
        requires=("u",), start_method="the sea_stratus_linear preset (LinearSwayYaw.from_vessel)",
    ),
    "norrbin-crossflow": ModelEntry(
        "Norrbin's cross-flow model: the linear sway-yaw model plus cross-flow drag C [-] "
        "(Astrom & Kallstrom 1979, sec. 2)",
        starts.start_norrbin, starts.start_norrbin, channels=("psi", "r", "v"), requires=("u",),
        start_method="the sea_stratus_nonlinear preset (NorrbinCrossFlow.from_vessel)",
    ),
    "low-speed-sway-yaw": ModelEntry(
        "sway-yaw model for low speed (LowSpeedSwayYaw): hull terms scaled by the measured "
        "u, the rudder in u^2 + c_R n^2 (propeller race), cross-flow drag and, where wind is "
        "logged, its sway force and yaw moment: 12 coefficients per unit inertia; "
        "model-basin speeds (L = 3 m)",
        starts.start_low_speed, starts.start_low_speed, channels=("psi", "r", "v"),
        requires=("u",), start_method="the class's values (a 3 m model at 0.3 m/s)",
    ),
    "armax": ModelEntry(
        "ARMAX(2,2,2), delay 1 sample, of the yaw rate (Astrom & Kallstrom 1979, eq. 7): "
        "a1, a2 [-], b0, b1 [1/s], c1, c2 [-]; one training record",
        start_armax, start_armax, channels=("psi", "r"), default_channels=("r",),
        initial=("measured",), simulate=simulate_armax_records, fit=fit_armax_entry,
        start_method="pseudo-linear regression (extended least squares) of fit_armax",
    ),
    **{name: _vessel_entry(name) for name in js.VESSELS},
}


def model_key(name: str) -> str:
    """The registry name of `name` (case-insensitive; `-` and `_` interchangeable);
    `ValueError` listing the known names otherwise."""
    key = str(name).strip().lower()
    for candidate in (key, key.replace("-", "_"), key.replace("_", "-")):
        if candidate in MODELS:
            return candidate
    raise ValueError(f"unknown model {name!r}; choose from {', '.join(MODELS)}.")


OWN_VESSEL = "vessel"  # the registry name of a vessel of one's own (a vessel file)


def start_entry(name: str | None, start) -> tuple[str, ModelEntry]:
    """`(name, entry)` of a fit that starts from the model `start` (`--vessel`: a preset,
    a vessel file, an earlier result): a vessel is fitted as the presets are (its
    `default_free` coefficients; named by its preset `name`, else `OWN_VESSEL`), a
    steering model as the registry's `name`; the start values are `start`'s own."""
    if isinstance(start, js.AbstractVessel):
        key = name if name in js.VESSELS else OWN_VESSEL
        base = start.base if isinstance(start, js.effects.AugmentedVessel) else start
        description = f"vessel {type(base).__name__} (3-DOF, default_free estimated)"
        return key, _vessel_entry(key, start, description)
    key = model_key(name)
    given = lambda train, context: start
    return key, dataclasses.replace(MODELS[key], start=given, fallback=given,
                                    start_method="the given model's values (--vessel)")


def get_model_entry(name: str) -> ModelEntry:
    """The registry entry of `name`; `ValueError` listing the known names otherwise."""
    return MODELS[model_key(name)]


# the catalogue name a steering model of each class is fitted as (`start_name`)
_CLASS_NAMES = {js.Nomoto1: "nomoto1", js.Nomoto2: "nomoto2",
                js.NonlinearNomoto: "nomoto1-nonlinear", js.RossAutopilot: "ross-autopilot",
                js.LinearSwayYaw: "linear-sway-yaw", js.NorrbinCrossFlow: "norrbin-crossflow",
                js.LowSpeedSwayYaw: "low-speed-sway-yaw", js.ARMAXModel: "armax"}


def start_name(start, name: str | None) -> str | None:
    """The catalogue name the model `start` is fitted as: `name` if given (a preset's
    for a vessel, e.g. `nomoto1-norrbin` for a `NonlinearNomoto`); else None for a vessel
    (a vessel of one's own) and the entry of its class for a steering model."""
    if name is not None:
        return name if isinstance(start, js.AbstractVessel) else model_key(name)
    if isinstance(start, js.AbstractVessel):
        return None
    base = start.base if isinstance(start, js.effects.AugmentedSteering) else start
    if type(base) not in _CLASS_NAMES:
        raise ValueError(f"no catalogue model fits a {type(base).__name__}; give a vessel, "
                         "a steering model of the catalogue or a catalogue name.")
    return _CLASS_NAMES[type(base)]
