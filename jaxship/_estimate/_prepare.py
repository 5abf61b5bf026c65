"""The checks of a prediction-error fit's model, data and estimator before any work, and
its windows (`_windows.build_windows`), shared by `fit`, `predict`, the bands and the
sensitivity study."""

import numpy as np

from .._foundation._contract import AbstractModel
from .._simulation._integrate import Simulator
from ._initial import EstimatedStarts, MeasuredStates
from ._kalman import SmoothedStates
from ._windows import CHANNEL_NAMES, as_dataset, build_windows, check_data


def prepare_fit(model, dataset, estimator):
    """Check the model, data and estimator and build the windows: `(ds, windows,
    layout)`, shared by `fit` and `predict`."""
    if not isinstance(model, AbstractModel):
        raise ValueError(f"`model` must be a jaxship steering model (AbstractSteeringModel) "
                         f"or vessel (AbstractVessel), got {type(model).__name__}.")
    ds = as_dataset(dataset)
    channels = model.default_channels if estimator.channels is None else tuple(
        estimator.channels)
    for c in channels:
        if c not in CHANNEL_NAMES:
            raise ValueError(f"unknown output channel {c!r}; choose from {CHANNEL_NAMES}.")
        try:
            model.channel_index(c)
        except ValueError:
            raise ValueError(f"unknown output channel {c!r} for {type(model).__name__}, whose "
                             f"outputs are psi, r and its states.") from None
    check_data(ds, estimator.rudder, channels)
    if estimator.wind and not model.wind_loads:
        raise ValueError(f"`wind=True` is for vessels and steering models with a wind "
                         f"effect (jaxship.effects.ApparentWind); {type(model).__name__} "
                         "has no wind loads.")
    servo = estimator.rudder == "delta_c"
    smoothed = isinstance(estimator.initial, (list, tuple))
    starts = smoothed_starts(ds, estimator.initial) if smoothed else None
    needed = [c for c in model.start_channels if starts is None or c not in starts]
    needed += ["delta"] if servo and model.has_servo else []
    needed += ["wind_speed", "wind_dir"] if estimator.wind else []
    for i, name in enumerate(ds.names):
        missing = [c for c in needed if c not in ds.experiment_channels[i]]
        if missing:
            raise ValueError(
                f"experiment {name!r} (dataset entry {i}): no measured {missing[0]!r}; "
                f"{type(model).__name__} restarts every window from the measured "
                f"{', '.join(needed)} (and `wind=True` replays the measured wind), so these "
                "must be measured (or smoothed: `initial=jaxship.smooth_states(...)`; or fit "
                "a steering model instead).")
    if not isinstance(estimator.simulator, Simulator):
        raise ValueError(f"`simulator` must be a jaxship.Simulator, got "
                         f"{type(estimator.simulator).__name__}.")
    if not (smoothed or isinstance(estimator.initial, (MeasuredStates, EstimatedStarts))):
        raise ValueError(f"`initial` must be MeasuredStates(), EstimatedStarts() or a list of "
                         f"SmoothedStates, got {estimator.initial!r}.")
    windows, layout = build_windows(ds, horizon=estimator.horizon, channels=channels,
                                    weights=estimator.weights, rudder=estimator.rudder,
                                    simulator=estimator.simulator, starts=starts,
                                    hold=estimator.hold, wind=bool(estimator.wind))
    return ds, windows, layout


def smoothed_starts(ds, smoothed) -> dict:
    """`{"r": (E, N), "psi": (E, N)}` window starts from `SmoothedStates` (one per
    experiment of `ds`, e.g. from `jaxship.smooth_states`), and `"u"`, `"v"` where
    they are smoothed states (a vessel's)."""
    smoothed = list(smoothed)
    if len(smoothed) != ds.num_experiments or not all(isinstance(s, SmoothedStates)
                                                      for s in smoothed):
        raise ValueError(f"`initial` as smoothed states needs one SmoothedStates per "
                         f"experiment ({ds.num_experiments}), got {len(smoothed)} items.")
    out = {}
    both = lambda name: all(name in s.names for s in smoothed)
    for name in ("r", "psi") + tuple(c for c in ("u", "v") if both(c)):
        a = np.array(getattr(ds, name), dtype=np.float64)
        for i, s in enumerate(smoothed):
            if s.mean.shape[0] != ds.lengths[i]:
                raise ValueError(f"smoothed states {i} have {s.mean.shape[0]} samples, "
                                 f"experiment {ds.names[i]!r} has {ds.lengths[i]}.")
            a[i, :ds.lengths[i]] = s.state(name)
        out[name] = a
    return out


def start_strategy(initial) -> MeasuredStates | EstimatedStarts:
    """The start strategy of `initial`: smoothed states (a list) start as measured ones."""
    return MeasuredStates() if isinstance(initial, (list, tuple)) else initial
