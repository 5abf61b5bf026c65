"""Host-side preparation of a fit: data checks and the prediction windows.

A record of N samples is cut into windows of L samples (L = round(T_p / dt), at
least 1, at most N - 1). Window w starts at sample s = wL from the measured state
and predicts samples s + 1 .. s + L with the recorded inputs replayed between samples
as `resolve_holds` says (linear for measured signals, held for commands), so every
sample but the first of each experiment is predicted exactly once.
L = N - 1 (one window) is output error (simulation error); L = 1 is equation error
(one-step-ahead prediction). Experiments of different lengths and sample intervals
are padded to common (windows, steps) shapes with a mask.
"""

import math
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._models._holds import HOLDS, FirstOrderHold, ZeroOrderHold, check_hold
from .._models._steering._base import AuxInputs, WindowStart
from .._simulation._data import Dataset, Experiment, check_uniform
from .._simulation._integrate import Simulator


# fittable outputs: heading and yaw rate for every model; surge and sway velocity for
# vessels and for steering models with a state of that name (see `_fit._predict`);
# the earth-fixed position for vessels (where a current or leeway shows)
CHANNEL_NAMES = ("psi", "r", "u", "v", "x", "y")
MEASURED_ONLY = ("u", "v", "x", "y")  # fitted only where measured (never derived)


def as_dataset(data) -> Dataset:
    """An `Experiment`, a sequence of them or a `Dataset` as a `Dataset`."""
    if isinstance(data, Dataset):
        return data
    if isinstance(data, Experiment):
        return Dataset.from_experiments([data])
    if isinstance(data, (list, tuple)):
        for i, e in enumerate(data):
            if not isinstance(e, Experiment):
                raise ValueError(f"`dataset[{i}]` is a {type(e).__name__}, not a "
                                 "jaxship.Experiment.")
        return Dataset.from_experiments(list(data))
    raise ValueError(
        f"`dataset` must be a jaxship Dataset, an Experiment or a list of Experiments, got "
        f"{type(data).__name__}."
    )


def check_data(ds: Dataset, rudder: str, channels, *, rtol: float = 1e-6) -> None:
    """Raise `ValueError` naming the experiment for non-finite values, a missing
    rudder record, non-uniform sampling or too few samples."""
    if rudder not in ("delta", "delta_c"):
        raise ValueError(f"`rudder` must be 'delta' or 'delta_c', got {rudder!r}.")
    for c in channels:
        if c not in CHANNEL_NAMES:
            raise ValueError(f"unknown output channel {c!r}; choose from {CHANNEL_NAMES}.")
    if not channels:
        raise ValueError(f"`channels` is empty; choose from {CHANNEL_NAMES}.")
    for i, name in enumerate(ds.names):
        n = ds.lengths[i]
        where = f"experiment {name!r} (dataset entry {i})"
        if n < 2:
            raise ValueError(f"{where}: needs at least 2 samples, has {n}.")
        if rudder not in ds.experiment_channels[i]:
            raise ValueError(f"{where}: no measured rudder channel {rudder!r}; estimation "
                             "replays the recorded rudder.")
        for c in channels:
            if c in MEASURED_ONLY and c not in ds.experiment_channels[i]:
                raise ValueError(f"{where}: output channel {c!r} is fitted but was not "
                                 "measured; drop it from `channels` or use data with it.")
        t = np.asarray(ds.t)[i, :n]
        for key in dict.fromkeys(("t", rudder, "psi", "r", "u", "v", "n", *channels)):
            a = np.asarray(getattr(ds, key))[i, :n]
            bad = np.nonzero(~np.isfinite(a))[0]
            if bad.size:
                k = int(bad[0])
                raise ValueError(
                    f"{where}: channel {key!r} is {a[k]} at sample {k} (t = {t[k]!r} s) and at "
                    f"{bad.size - 1} more samples; all values must be finite (cut the record "
                    "with Experiment.segment or repair the file)."
                )
        check_uniform(t, where, "the inputs are replayed at a constant interval: "
                      "interpolate the record onto a uniform time grid first.", rtol)


# how each replayed signal is interpolated between samples (MATLAB's `InterSample`):
# measured continuous signals linearly (first-order hold), commands held (zero-order)
_FOH, _ZOH = FirstOrderHold(), ZeroOrderHold()
DEFAULT_HOLDS = {"delta": _FOH, "delta_c": _ZOH, "u": _FOH, "v": _FOH, "n": _FOH,
                 "wind_speed": _FOH, "wind_dir": _ZOH, "wind_u": _FOH, "wind_v": _FOH}


def apparent_wind(ds: Dataset) -> dict:
    """The ship's velocity through the air in body axes, `{"wind_u", "wind_v"}` (E, N)
    [m/s], from the logged true wind (speed, direction it comes from), the measured
    heading and u, v: $(u, v) - R(\\psi)^T v_w$, $v_w = -V_w(\\cos\\beta_w,
    \\sin\\beta_w)$ the air's earth-fixed velocity (Fossen 2021, eq. 10.6)."""
    north = -np.asarray(ds.wind_speed) * np.cos(ds.wind_dir)
    east = -np.asarray(ds.wind_speed) * np.sin(ds.wind_dir)
    cos, sin = np.cos(ds.psi), np.sin(ds.psi)
    return {"wind_u": np.asarray(ds.u) - (north * cos + east * sin),
            "wind_v": np.asarray(ds.v) - (-north * sin + east * cos)}


def resolve_holds(rudder: str, hold, names) -> tuple[tuple[str, str], ...]:
    """`(replayed name, hold)` pairs: `hold` None (the defaults by channel, the rudder
    by the channel it is read from), one `ZeroOrderHold()` or `FirstOrderHold()` for every
    signal, or a dict overriding some channels (keys are channel names, e.g. "delta_c",
    "n")."""
    source = {name: (rudder if name == "delta" else name) for name in names}
    chosen = {src: DEFAULT_HOLDS[src] for src in source.values()}
    if isinstance(hold, HOLDS):
        chosen = dict.fromkeys(chosen, hold)
    elif isinstance(hold, dict):
        unknown = [k for k in hold if k not in chosen]
        if unknown:
            raise ValueError(f"`hold` names {unknown[0]!r}, which is not replayed here; the "
                             f"replayed channels are {sorted(chosen)}.")
        chosen.update(hold)
    elif hold is not None:
        raise ValueError(f"`hold` must be None, ZeroOrderHold(), FirstOrderHold() or a dict "
                         f"of them, got {hold!r}.")
    for k, v in chosen.items():
        check_hold(v, f"hold of {k!r}")
    return tuple((name, chosen[src]) for name, src in source.items())


class Windows(eqx.Module):
    """The prediction windows of a dataset, as arrays for the jitted fit.

    `records`: `{name: (E, W, L + 1)}` the replayed signals (`"delta"`: the rudder
    channel replayed, `"u"`, `"v"`, `"n"`, and the wind when asked for) at the window
    start and the L samples after it, interpolated between samples as `holds` says;
    `mask`: (E, W, L); `start` (a `WindowStart` with leaves (E, W)) and `dt`: (E, W);
    `targets`: (C, E, W, L) measured outputs at the ends of the intervals; `weights`:
    (C,); `servo`: the replayed rudder is the command, which the vessel's servo turns
    into the angle.
    """

    records: dict
    dt: jax.Array
    start: WindowStart
    targets: jax.Array
    mask: jax.Array
    weights: jax.Array
    channels: tuple[str, ...] = eqx.field(static=True)
    substeps: int = eqx.field(static=True)  # solver steps per sample interval
    simulator: Simulator = Simulator(max_step=math.inf)  # its solver (no arrays: static)
    holds: tuple = eqx.field(static=True, default=())
    servo: bool = eqx.field(static=True, default=False)


def window_lengths(ds: Dataset, horizon) -> tuple[int, ...]:
    """Samples per window for each experiment: round(horizon / dt) clipped to
    [1, N - 1]; N - 1 (output error) for `horizon=None`."""
    out = []
    for i, n in enumerate(ds.lengths):
        if horizon is None:
            out.append(n - 1)
            continue
        horizon = float(horizon)
        if not (horizon >= 0 and math.isfinite(horizon)):
            raise ValueError(f"`horizon` must be None or a non-negative number of seconds, "
                             f"got {horizon}.")
        steps = int(round(horizon / float(np.asarray(ds.dt)[i])))
        out.append(min(max(steps, 1), n - 1))
    return tuple(out)


def channel_weights(ds: Dataset, channels, weights) -> np.ndarray:
    """Residual weights: given, or 1/std of each measured channel (the within-experiment
    standard deviation over valid samples, pooled), 1 for a constant channel."""
    if weights is not None:
        if isinstance(weights, dict):
            missing = [c for c in channels if c not in weights]
            if missing:
                raise ValueError(f"`weights` has no entry for channel {missing[0]!r}.")
            w = np.array([float(weights[c]) for c in channels])
        else:
            w = np.asarray(weights, dtype=float).reshape(-1)
            if w.shape[0] != len(channels):
                raise ValueError(f"`weights` has {w.shape[0]} entries for {len(channels)} "
                                 "channels.")
        if not np.all(np.isfinite(w) & (w > 0)):
            raise ValueError(f"`weights` must be positive and finite, got {w}.")
        return w
    mask = np.asarray(ds.mask)
    out = []
    for c in channels:
        y = np.asarray(getattr(ds, c))
        count = mask.sum(axis=1)
        mean = np.sum(np.where(mask, y, 0.0), axis=1) / count
        var = np.sum(np.where(mask, (y - mean[:, None]) ** 2, 0.0)) / mask.sum()
        out.append(1.0 / math.sqrt(var) if var > 0 else 1.0)
    return np.array(out)


def build_windows(ds: Dataset, *, horizon, channels, weights, rudder: str = "delta",
                  simulator: Simulator = Simulator(max_step=math.inf),
                  starts: dict | None = None, hold=None,
                  wind: bool = False):
    """`(Windows, layout)`; `layout` holds the NumPy index arrays to map window
    predictions back onto the samples: `target` (E, W, L) sample index, `mask`.
    `starts`: optional `{"r": (E, N), "psi": (E, N)}` (and `"u"`, `"v"`) start values of
    the windows in place of the measured ones (e.g. smoothed states); targets stay
    measured. `hold`: see `resolve_holds`; `wind`: also replay the measured wind, and
    the apparent wind it makes (`apparent_wind`) for steering models."""
    lengths = window_lengths(ds, horizon)
    index = _window_index(ds, lengths)
    num_exp, num_w = ds.num_experiments, index.start.shape[1]
    derived = apparent_wind(ds) if wind else {}
    samples = _Samples(ds, derived, starts)
    weights = channel_weights(ds, channels, weights)
    dt_e = np.asarray(ds.dt, dtype=np.float64)
    dt = np.broadcast_to(dt_e[:, None], (num_exp, num_w))
    rud = np.asarray(getattr(ds, rudder), dtype=np.float64)
    names = ("delta", "u", "v", "n") + (("wind_speed", "wind_dir", *derived) if wind else ())
    holds = resolve_holds(rudder, hold, names)
    f = lambda a: jnp.asarray(a, dtype=float)
    rows = np.arange(num_exp)[:, None, None]
    records = {name: f(rud[rows, index.record] if name == "delta" else
                       samples.at(name, index.record, rows)) for name in names}
    windows = Windows(
        records=records,
        dt=f(dt),
        start=_window_start(samples, rud, dict(holds)["delta"], index.start, names),
        targets=f(np.stack([samples.at(c, index.target, rows) for c in channels])),
        mask=jnp.asarray(index.mask),
        weights=f(weights),
        channels=tuple(channels),
        substeps=simulator.steps_per_sample(np.asarray(dt)),
        simulator=simulator,
        holds=holds,
        servo=rudder == "delta_c",
    )
    layout = {"target": index.target, "mask": index.mask, "lengths": lengths,
              "weights": weights}
    return windows, layout


class _WindowIndex(NamedTuple):
    """NumPy index arrays of the windows: `start` (E, W) first sample, `target` (E, W, L)
    predicted samples (clipped to the dataset), `mask` (E, W, L) the real ones, `record`
    (E, W, L + 1) the samples replayed (beyond a record's end its last sample holds)."""

    start: np.ndarray
    target: np.ndarray
    mask: np.ndarray
    record: np.ndarray


def _window_index(ds: Dataset, lengths) -> _WindowIndex:
    """Cut each record into windows of `lengths[e]` samples after a start sample."""
    num = ds.num_samples
    counts = [len(range(0, n - 1, L)) for n, L in zip(ds.lengths, lengths)]
    num_w, num_l = max(counts), max(lengths)
    w_idx = np.arange(num_w)[None, :, None]
    l_idx = np.arange(num_l)[None, None, :]
    size = np.array(lengths)[:, None, None]
    start = w_idx * size  # (E, W, 1)
    target = start + l_idx + 1
    valid_len = np.array(ds.lengths)[:, None, None]
    mask = (l_idx < size) & (target <= valid_len - 1) & (w_idx < np.array(counts)[:, None, None])
    # the samples replayed in each window: its start and the L after it (clipped to the
    # experiment: beyond its end the last sample holds)
    record_index = np.minimum(start + np.arange(num_l + 1)[None, None, :], valid_len - 1)
    return _WindowIndex(start=np.clip(start[..., 0], 0, num - 1),
                        target=np.clip(target, 0, num - 1), mask=mask, record=record_index)


class _Samples(NamedTuple):
    """The dataset's channels (with the derived apparent wind) and the start values that
    replace the measured ones (`starts`, or None)."""

    ds: Dataset
    derived: dict
    starts: dict | None

    def at(self, name, index, r):
        """Samples of channel `name` at rows `r`, columns `index`."""
        return np.asarray(self.derived[name] if name in self.derived
                          else getattr(self.ds, name), dtype=np.float64)[r, index]

    def start_at(self, name, index, r):
        """As `at`, from the given start values where there are any."""
        if self.starts is not None and name in self.starts:
            return np.asarray(self.starts[name], dtype=np.float64)[r, index]
        return self.at(name, index, r)


def _window_start(samples: _Samples, rud, rudder_hold, start_index, names) -> WindowStart:
    """Each window's start: states, rudder, the replayed rudder's integral up to it
    (trapezoidal for a first-order hold, rectangles for a zero-order hold: exact for
    either), the first sample's states, elapsed time and track position."""
    ds = samples.ds
    num_exp, num_w = start_index.shape
    dt_e = np.asarray(ds.dt, dtype=np.float64)
    rows2 = np.arange(num_exp)[:, None]
    pieces = rudder_hold.interval_mean(rud[:, :-1], rud[:, 1:])
    integral = np.concatenate([np.zeros((num_exp, 1)), np.cumsum(pieces, axis=1)], axis=1)
    integral = integral * dt_e[:, None]
    first = lambda name: np.broadcast_to(
        samples.start_at(name, np.zeros((1, 1), dtype=int), np.arange(num_exp)[:, None]),
        (num_exp, num_w))
    f = lambda a: jnp.asarray(a, dtype=float)
    at = lambda name: f(samples.at(name, start_index, rows2))
    start_at = lambda name: f(samples.start_at(name, start_index, rows2))
    return WindowStart(
        r=start_at("r"),
        psi=start_at("psi"),
        delta=f(rud[rows2, start_index]),
        r_first=f(first("r")),
        psi_first=f(first("psi")),
        delta_integral=f(integral[rows2, start_index]),
        elapsed=f(start_index * dt_e[:, None]),
        aux=AuxInputs(*(start_at(c) if c in names else None
                        for c in ("u", "v", "n", "wind_u", "wind_v"))),
        rudder_angle=at("delta"),
        x=at("x"), y=at("y"),
        ground=f(np.broadcast_to(ds.over_ground[:, None], (num_exp, num_w))),
    )


def to_timeline(values, layout, shape) -> tuple[np.ndarray, np.ndarray]:
    """Scatter window values (E, W, L, ...) onto the samples (E, N, ...); returns
    `(timeline, predicted_mask)` (samples never predicted, e.g. sample 0, are False)."""
    values = np.asarray(values)
    out = np.zeros(tuple(shape) + values.shape[3:])
    hit = np.zeros(shape, dtype=bool)
    mask = layout["mask"]
    e_idx = np.broadcast_to(np.arange(shape[0])[:, None, None], mask.shape)
    out[e_idx[mask], layout["target"][mask]] = values[mask]
    hit[e_idx[mask], layout["target"][mask]] = True
    return out, hit
