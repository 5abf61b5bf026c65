"""Measured and simulated trials: `Experiment`, `Dataset`, the trial CSV format and
readers for the measured data sets (Esso Osaka FRT, HSVA and MARIN KVLCC2).

Inside the library every channel is SI with angles in radians and propeller rates in
rev/s, in our sign convention (positive rudder angle turns the ship to starboard,
$r > 0$; x north / forward, y east / starboard, heading from x towards y). Degrees,
rpm and the sign conventions of the sources live only in this module.

**Trial CSV format.** Comma-separated, one header row, one column per channel, each
header `name [unit]`:

| name | meaning | units |
| --- | --- | --- |
| `t` | time | s |
| `delta` | actual rudder angle, positive to starboard | deg, rad |
| `delta_c` | commanded rudder angle | deg, rad |
| `psi` | heading, not wrapped | deg, rad |
| `r` | yaw rate | deg/s, rad/s |
| `u`, `v` | surge and sway velocity through the water (body axes, midship) | m/s |
| `x`, `y` | north and east position | m |
| `n` | propeller rate | rpm, rps |
| `wind_speed` | true wind speed | m/s |
| `wind_dir` | true wind direction the wind comes *from*, from north (x) | deg, rad |

`t`, `delta` and one of `psi`, `r` are required, the rest optional; column order is
free. Rows are numbered from 1 after the header ("row 3" is the third data row) and
every error message names the file, the column, the row and its line. Blank lines and
trailing rows whose cells are all empty (spreadsheet exports) are skipped; an empty or
non-finite cell anywhere else is an error. Unknown column names are an error unless
`allow_unknown=True`, which keeps them, unconverted, in `Experiment.extra`.
"""

import csv
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from ._manoeuvres import Replay
from ._state import ShipState, Trajectory


# channel order of files and of `Experiment`; `t` first
CHANNELS = (
    "t", "delta", "delta_c", "psi", "r", "u", "v", "x", "y", "n", "wind_speed", "wind_dir",
)
_SIGNALS = CHANNELS[1:]

_ANGLE = {"rad": 1.0, "deg": math.pi / 180.0}
_RATE = {"rad/s": 1.0, "deg/s": math.pi / 180.0}
# factors from the file's unit to SI (rad, rad/s, rev/s)
_UNITS = {
    "t": {"s": 1.0},
    "delta": _ANGLE,
    "delta_c": _ANGLE,
    "psi": _ANGLE,
    "r": _RATE,
    "u": {"m/s": 1.0},
    "v": {"m/s": 1.0},
    "x": {"m": 1.0},
    "y": {"m": 1.0},
    "n": {"rps": 1.0, "rpm": 1.0 / 60.0},
    "wind_speed": {"m/s": 1.0},
    "wind_dir": _ANGLE,
}
_DISPLAY_UNITS = {"rad": "deg", "rad/s": "deg/s", "rps": "rpm"}
_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*\[([^\]]*)\]\s*$")

KVLCC2_SCALE = 45.714  # lambda [-], INSEAN model 2487 (SIMMAN 2008)
MARIN_DT = 0.13526  # full-scale sample interval [s] of the MARIN files (50 Hz model scale)


def _to_si(value: np.ndarray, unit: str) -> np.ndarray:
    """Convert from a file unit; degrees via `np.deg2rad` so that writing with
    `np.rad2deg` round-trips to the last bit or two."""
    if unit in ("deg", "deg/s"):
        return np.deg2rad(value)
    if unit == "rpm":
        return value / 60.0
    return value


def _from_si(value: np.ndarray, unit: str) -> np.ndarray:
    if unit in ("deg", "deg/s"):
        return np.rad2deg(value)
    if unit == "rpm":
        return value * 60.0
    return value


def _cumulative_trapezoid(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])


class Experiment(eqx.Module):
    """One trial, measured or simulated: SI channels sampled at the times `t`.

    Every channel of `CHANNELS` is an array of the same length as `t` (float64 NumPy
    arrays, so that they keep their precision whatever JAX's x64 setting).
    `channels` names those that were measured; the others are filled:

    - `r` missing: $r = d\\psi/dt$ by `np.gradient` (second-order central differences);
    - `psi` missing: $\\psi = \\int r\\,dt$ by the cumulative trapezoid rule from
      $\\psi(t_0) = 0$;
    - anything else missing: zeros.

    Filled-in `psi`/`r` are listed in `derived`. `name` and `metadata` (a tuple of
    `(key, value)` pairs with hashable values; see `meta`) are static; `extra` holds
    further measured signals that are not part of the simulation state (relative wind,
    thrust, torque, roll), as SI arrays unless stated otherwise in the reader.

    **Arguments:** `t`, `delta`, optional `psi`, `r`, `u`, `v`, `x`, `y`, `n`,
    `delta_c`, `wind_speed`, `wind_dir` (array-like, SI, our sign convention);
    `name`, `metadata`, `extra`. `t` must be strictly increasing, all values finite.
    """

    t: np.ndarray  # time [s]
    delta: np.ndarray  # actual rudder angle [rad], positive to starboard
    psi: np.ndarray  # heading [rad], not wrapped
    r: np.ndarray  # yaw rate [rad/s]
    u: np.ndarray  # surge velocity [m/s]
    v: np.ndarray  # sway velocity [m/s]
    x: np.ndarray  # north position [m]
    y: np.ndarray  # east position [m]
    n: np.ndarray  # propeller rate [rev/s]
    delta_c: np.ndarray  # commanded rudder angle [rad]
    wind_speed: np.ndarray  # true wind speed [m/s]
    wind_dir: np.ndarray  # true wind direction, coming from, from north [rad]
    extra: dict
    channels: tuple[str, ...] = eqx.field(static=True)
    derived: tuple[str, ...] = eqx.field(static=True)
    name: str = eqx.field(static=True)
    metadata: tuple = eqx.field(static=True)

    def __init__(
        self, t, delta, psi=None, r=None, u=None, v=None, x=None, y=None, n=None,
        delta_c=None, wind_speed=None, wind_dir=None, *, name: str = "experiment",
        metadata=(), extra: dict | None = None,
    ):
        given = dict(
            t=t, delta=delta, psi=psi, r=r, u=u, v=v, x=x, y=y, n=n, delta_c=delta_c,
            wind_speed=wind_speed, wind_dir=wind_dir,
        )
        where = f"Experiment {name!r}"
        arrays = {}
        for key in CHANNELS:
            if given[key] is None:
                continue
            a = np.array(given[key], dtype=np.float64)
            if a.ndim != 1:
                raise ValueError(
                    f"{where}: channel {key!r} must be one-dimensional, got shape {a.shape}."
                )
            arrays[key] = a
        length = arrays["t"].shape[0]
        if length < 2:
            raise ValueError(f"{where}: needs at least two samples, got {length}.")
        for key, a in arrays.items():
            if a.shape[0] != length:
                raise ValueError(
                    f"{where}: channel {key!r} has {a.shape[0]} samples but `t` has {length}."
                )
            bad = np.nonzero(~np.isfinite(a))[0]
            if bad.size:
                raise ValueError(
                    f"{where}: channel {key!r} sample {bad[0]} is {float(a[bad[0]])}; all values "
                    "must be finite."
                )
        steps = np.diff(arrays["t"])
        if np.any(steps <= 0):
            k = int(np.nonzero(steps <= 0)[0][0]) + 1
            raise ValueError(
                f"{where}: `t` must be strictly increasing, but t[{k}] = {float(arrays['t'][k])} "
                f"s follows t[{k - 1}] = {float(arrays['t'][k - 1])} s."
            )
        if "psi" not in arrays and "r" not in arrays:
            raise ValueError(f"{where}: needs a heading `psi` or a yaw rate `r` (or both).")
        channels = tuple(k for k in _SIGNALS if k in arrays)
        derived = []
        if "r" not in arrays:
            arrays["r"] = np.gradient(arrays["psi"], arrays["t"])
            derived.append("r")
        if "psi" not in arrays:
            arrays["psi"] = _cumulative_trapezoid(arrays["r"], arrays["t"])
            derived.append("psi")
        for key in CHANNELS:
            setattr(self, key, arrays.get(key, np.zeros(length)))
        self.channels = channels
        self.derived = tuple(derived)
        self.name = str(name)
        self.metadata = tuple((str(k), v) for k, v in dict(metadata).items())
        self.extra = {} if extra is None else {k: np.asarray(v) for k, v in extra.items()}

    # -- properties ----------------------------------------------------------------

    @property
    def num_samples(self) -> int:
        return int(np.shape(self.t)[0])

    @property
    def dt(self) -> float:
        """Mean sample interval $(t_{N-1} - t_0)/(N-1)$ [s]."""
        return float((self.t[-1] - self.t[0]) / (self.num_samples - 1))

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    @property
    def meta(self) -> dict:
        """`metadata` as a dictionary."""
        return dict(self.metadata)

    def is_uniform(self, rtol: float = 1e-6) -> bool:
        """True when every sample interval equals `dt` to a relative `rtol`."""
        return bool(np.all(np.abs(np.diff(self.t) - self.dt) <= rtol * self.dt))

    def has(self, channel: str) -> bool:
        """True when `channel` was measured (not derived or zero-filled); `t` always."""
        return channel == "t" or channel in self.channels

    # -- construction ----------------------------------------------------------------

    @classmethod
    def from_trajectory(cls, trajectory: Trajectory, *, name: str = "simulation",
                        metadata=()) -> "Experiment":
        """The valid samples of an unbatched `Trajectory` as an experiment with the
        channels t, delta (actual), delta_c (`command.delta`), psi, r, u, v, x, y and n
        (actual)."""
        t = np.asarray(trajectory.t, dtype=np.float64)
        if t.ndim != 1:
            raise ValueError(
                f"`trajectory` is batched (t has shape {t.shape}); pass one trajectory, "
                "e.g. `jax.tree.map(lambda a: a[i], trajectory)`."
            )
        keep = np.asarray(trajectory.valid, dtype=bool)
        s = trajectory.state
        get = lambda a: np.asarray(a, dtype=np.float64)[keep]
        return cls(
            t[keep], get(s.delta), psi=get(s.psi), r=get(s.r), u=get(s.u), v=get(s.v),
            x=get(s.x), y=get(s.y), n=get(s.n), delta_c=get(trajectory.command.delta),
            name=name, metadata=metadata,
        )

    def _measured(self) -> dict:
        return {k: getattr(self, k) for k in self.channels}

    def segment(self, start: float | None = None, stop: float | None = None) -> "Experiment":
        """The samples with `start <= t <= stop` [s] as a new experiment (derived
        channels are recomputed from the kept samples)."""
        keep = np.ones(self.num_samples, dtype=bool)
        if start is not None:
            keep &= self.t >= start
        if stop is not None:
            keep &= self.t <= stop
        measured = {k: a[keep] for k, a in self._measured().items()}
        extra = {
            k: (a[keep] if np.shape(a)[:1] == (self.num_samples,) else a)
            for k, a in self.extra.items()
        }
        return Experiment(self.t[keep], name=self.name, metadata=self.metadata, extra=extra,
                          **measured)

    # -- simulation ------------------------------------------------------------------

    def replay(self, *, rudder: str = "delta", n: float | None = None, rtol: float = 1e-6
               ) -> Replay:
        """The recorded inputs as a `jaxship.Replay` manoeuvre sampled at `dt` from
        `start = t[0]` (so the simulated `t` equals the experiment's).

        `rudder` is the channel replayed as the rudder command (`"delta"`, the measured
        rudder angle, or `"delta_c"`, the commanded angle). The propeller record is the
        measured `n`; without one it is the constant `n` [rev/s] (0 if not given, which
        suits models without a propeller). Requires uniform sampling (to `rtol`).
        """
        if rudder not in ("delta", "delta_c"):
            raise ValueError(f"`rudder` must be 'delta' or 'delta_c', got {rudder!r}.")
        if not self.has(rudder):
            raise ValueError(f"Experiment {self.name!r} has no measured {rudder!r} channel.")
        if not self.is_uniform(rtol):
            raise ValueError(
                f"Experiment {self.name!r} is not uniformly sampled (relative tolerance "
                f"{rtol}); a Replay needs a constant dt."
            )
        if self.has("n"):
            n_record = self.n
        else:
            n_record = np.full(self.num_samples, 0.0 if n is None else float(n))
        return Replay(getattr(self, rudder), n_record, dt=self.dt, start=float(self.t[0]))

    def initial_state(self, *, default_u: float | None = None, default_n: float = 0.0,
                      index: int = 0) -> ShipState:
        """The `ShipState` at sample `index` (the first by default).

        u is measured, else `default_u` [m/s] (an error if neither); r is measured or
        $d\\psi/dt$; psi measured or integrated from r; v, x, y are the measured values
        or 0; n the measured rate or `default_n` [rev/s]; delta the measured rudder.
        """
        if not self.has("u") and default_u is None:
            raise ValueError(
                f"Experiment {self.name!r} has no measured surge velocity 'u'; pass "
                "`default_u=` (e.g. the vessel's nominal speed)."
            )
        pick = lambda key, default: (
            float(getattr(self, key)[index]) if self.has(key) else float(default)
        )
        value = lambda f: jnp.asarray(f)
        return ShipState(
            u=value(pick("u", default_u if default_u is not None else 0.0)),
            v=value(pick("v", 0.0)),
            r=value(float(self.r[index])),
            x=value(pick("x", 0.0)),
            y=value(pick("y", 0.0)),
            psi=value(float(self.psi[index])),
            delta=value(float(self.delta[index])),
            n=value(pick("n", default_n)),
        )


class Dataset(eqx.Module):
    """Several experiments padded to one length, with a mask, for `jax.vmap`.

    Each channel (see `CHANNELS`) is an array of shape `(E, N)` with `E` experiments and
    `N` the longest length; an experiment shorter than `N` is padded by repeating its
    last sample, with the time continuing at its own `dt`, so that padded inputs stay
    finite. `mask[e, k]` is True for real samples. `dt` has shape `(E,)`. Per-experiment
    names, lengths, measured channels and metadata are static.

    Batch simulation: `jax.vmap(lambda m, x0: simulate(vessel, m, x0))(dataset.replays(),
    dataset.initial_states())`; the trajectories' `t` then equals `t` and `valid` equals
    `mask`.
    """

    t: np.ndarray
    delta: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    u: np.ndarray
    v: np.ndarray
    x: np.ndarray
    y: np.ndarray
    n: np.ndarray
    delta_c: np.ndarray
    wind_speed: np.ndarray
    wind_dir: np.ndarray
    mask: np.ndarray  # (E, N) bool
    dt: np.ndarray  # (E,) mean sample interval [s]
    names: tuple[str, ...] = eqx.field(static=True)
    lengths: tuple[int, ...] = eqx.field(static=True)
    experiment_channels: tuple[tuple[str, ...], ...] = eqx.field(static=True)
    experiment_metadata: tuple = eqx.field(static=True)

    @classmethod
    def from_experiments(cls, experiments: Sequence[Experiment], *,
                         num_samples: int | None = None) -> "Dataset":
        """Stack `experiments`, padded to `num_samples` (default: the longest)."""
        experiments = list(experiments)
        if not experiments:
            raise ValueError("`experiments` is empty.")
        for i, e in enumerate(experiments):
            if not isinstance(e, Experiment):
                raise ValueError(f"experiments[{i}] is a {type(e).__name__}, not an Experiment.")
        lengths = tuple(e.num_samples for e in experiments)
        length = max(lengths) if num_samples is None else int(num_samples)
        if length < max(lengths):
            raise ValueError(
                f"`num_samples` ({length}) is shorter than the longest experiment ({max(lengths)})."
            )

        def pad(e, key):
            a = getattr(e, key)
            extra = length - a.shape[0]
            if key == "t":
                return np.concatenate([a, a[-1] + e.dt * np.arange(1, extra + 1)])
            return np.concatenate([a, np.full(extra, a[-1])])

        stacked = {k: np.stack([pad(e, k) for e in experiments]) for k in CHANNELS}
        mask = np.arange(length)[None, :] < np.array(lengths)[:, None]
        return cls(
            **stacked, mask=mask, dt=np.array([e.dt for e in experiments]),
            names=tuple(e.name for e in experiments), lengths=lengths,
            experiment_channels=tuple(e.channels for e in experiments),
            experiment_metadata=tuple(e.metadata for e in experiments),
        )

    @property
    def num_experiments(self) -> int:
        return len(self.lengths)

    @property
    def num_samples(self) -> int:
        """Padded length N."""
        return int(np.shape(self.t)[1])

    @property
    def channels(self) -> tuple[str, ...]:
        """Channels measured in every experiment."""
        return tuple(k for k in _SIGNALS if all(k in c for c in self.experiment_channels))

    def stack(self, names: Sequence[str] = CHANNELS) -> tuple[dict, np.ndarray]:
        """`({name: array (E, N)}, mask (E, N))` for the channels `names`."""
        unknown = [k for k in names if k not in CHANNELS]
        if unknown:
            raise ValueError(f"unknown channel(s) {unknown}; choose from {CHANNELS}.")
        return {k: getattr(self, k) for k in names}, self.mask

    def experiment(self, i: int) -> Experiment:
        """Experiment `i` without its padding (the `extra` signals are not kept)."""
        length = self.lengths[i]
        measured = {
            k: np.asarray(getattr(self, k)[i, :length]) for k in self.experiment_channels[i]
        }
        return Experiment(np.asarray(self.t[i, :length]), name=self.names[i],
                          metadata=self.experiment_metadata[i], **measured)

    def replays(self, *, rudder: str = "delta", n: float | None = None) -> Replay:
        """A batched `Replay` (leading axis E, `num_samples = N`) to `jax.vmap` over;
        each `duration` is that experiment's own, so `valid` matches `mask`."""
        replays = []
        for i in range(self.num_experiments):
            e = self.experiment(i)
            one = e.replay(rudder=rudder, n=n)
            padded = lambda a: np.concatenate([a, np.full(self.num_samples - a.shape[0], a[-1])])
            replays.append(Replay(
                padded(np.asarray(one.delta_record)), padded(np.asarray(one.n_record)),
                dt=np.float64(one.dt), start=np.float64(one.start),
                duration=np.float64(one.duration), num_samples=self.num_samples,
            ))
        return jax.tree.map(lambda *leaves: np.stack(leaves), *replays)

    def initial_states(self, *, default_u: float | None = None, default_n: float = 0.0
                       ) -> ShipState:
        """The experiments' initial states stacked along a leading axis E."""
        states = [
            self.experiment(i).initial_state(default_u=default_u, default_n=default_n)
            for i in range(self.num_experiments)
        ]
        return jax.tree.map(lambda *leaves: jnp.stack(leaves), *states)


# ---------------------------------------------------------------------------------------
# CSV parsing shared by the trial format and the Esso Osaka files


def _read_csv(path: Path, encoding: str = "utf-8-sig"):
    """Header fields, header line number and the data records `(line, fields)`;
    blank lines are skipped and so are trailing records with only empty cells."""
    with open(path, newline="", encoding=encoding) as f:
        reader = csv.reader(f)
        header, header_line, records = None, 0, []
        for fields in reader:
            if not fields or (header is None and all(not s.strip() for s in fields)):
                continue
            if header is None:
                header, header_line = [s.strip() for s in fields], reader.line_num
            else:
                records.append((reader.line_num, fields))
    if header is None:
        raise ValueError(f"{path}: the file is empty; expected a header row.")
    while records and all(not s.strip() for s in records[-1][1]):
        records.pop()
    return header, header_line, records


def _parse_numbers(path, headers, records) -> np.ndarray:
    """Float table of `records`, with an error naming file, column and row on bad cells."""
    ncol = len(headers)
    data = np.empty((len(records), ncol))
    for k, (line, fields) in enumerate(records):
        if len(fields) != ncol:
            raise ValueError(
                f"{path}: row {k + 1} (line {line}) has {len(fields)} fields but the header "
                f"has {ncol} columns."
            )
        for j, text in enumerate(fields):
            where = f"{path}: column '{headers[j]}', row {k + 1} (line {line})"
            if not text.strip():
                raise ValueError(f"{where}: empty value.")
            try:
                value = float(text)
            except ValueError:
                raise ValueError(f"{where}: cannot read {text!r} as a number.") from None
            if not math.isfinite(value):
                raise ValueError(f"{where}: value {text.strip()!r} is not finite (NaN and "
                                 "infinite values are not allowed).")
            data[k, j] = value
    return data


def _check_time(path, header, t, lines, require_uniform, rtol):
    if t.shape[0] < 2:
        raise ValueError(f"{path}: needs at least two data rows, got {t.shape[0]}.")
    steps = np.diff(t)
    bad = np.nonzero(steps <= 0)[0]
    if bad.size:
        k = int(bad[0]) + 1
        raise ValueError(
            f"{path}: column '{header}', row {k + 1} (line {lines[k]}): time {float(t[k])!r} is "
            f"not greater than the previous row's {float(t[k - 1])!r}; time must be strictly "
            "increasing."
        )
    if require_uniform:
        dt = float(np.median(steps))
        bad = np.nonzero(np.abs(steps - dt) > rtol * dt)[0]
        if bad.size:
            k = int(bad[0]) + 1
            raise ValueError(
                f"{path}: column '{header}', row {k + 1} (line {lines[k]}): sampling interval "
                f"{float(steps[k - 1])!r} s differs from the typical (median) interval {dt!r} s; "
                "uniform sampling is required (require_uniform=True)."
            )


def _split_header(path, line, text):
    match = _HEADER.match(text)
    if match is None:
        raise ValueError(
            f"{path}: column '{text}' (header row, line {line}): a header must read "
            "'name [unit]', e.g. 'psi [deg]'."
        )
    return match.group(1), match.group(2).strip()


def read_trial_csv(path, *, require_uniform: bool = False, allow_unknown: bool = False,
                   name: str | None = None, rtol: float = 1e-6) -> Experiment:
    """Read a trial CSV (format in the module docstring) into an `Experiment` (SI).

    **Arguments:**

    - `path`: the file.
    - `require_uniform`: also require a constant sample interval (to `rtol` relative).
    - `allow_unknown`: keep columns with unknown names in `extra` (values as written)
      instead of failing.
    - `name`: experiment name; the file's stem by default.

    **Raises:** `ValueError` naming the file, column and row for a malformed header,
    missing required column, unknown unit or column, empty, unreadable or non-finite
    value, non-increasing time or (with `require_uniform`) non-uniform sampling.
    """
    path = Path(path)
    headers, header_line, records = _read_csv(path)
    columns, extra_columns = {}, {}
    for j, text in enumerate(headers):
        key, unit = _split_header(path, header_line, text)
        where = f"{path}: column '{text}' (header row, line {header_line})"
        if key not in _UNITS:
            if allow_unknown:
                extra_columns[key] = j
                continue
            raise ValueError(
                f"{where}: unknown column name {key!r}; known names are {', '.join(CHANNELS)} "
                "(pass allow_unknown=True to keep unknown columns in `extra`)."
            )
        if key in columns:
            raise ValueError(f"{where}: column {key!r} appears twice.")
        if unit.lower() not in _UNITS[key]:
            raise ValueError(
                f"{where}: unknown unit {unit!r} for {key!r}; use one of "
                f"{', '.join(_UNITS[key])}."
            )
        columns[key] = (j, unit.lower())
    missing = [k for k in ("t", "delta") if k not in columns]
    if missing:
        raise ValueError(
            f"{path}: header row (line {header_line}): missing required column "
            f"{missing[0]!r} (required: t, delta and psi or r)."
        )
    if "psi" not in columns and "r" not in columns:
        raise ValueError(
            f"{path}: header row (line {header_line}): missing required column 'psi' or 'r' "
            "(at least one of heading and yaw rate is needed)."
        )
    data = _parse_numbers(path, headers, records)
    lines = [line for line, _ in records]
    j_t = columns["t"][0]
    _check_time(path, headers[j_t], data[:, j_t], lines, require_uniform, rtol)
    values = {key: _to_si(data[:, j], unit) for key, (j, unit) in columns.items()}
    return Experiment(
        name=path.stem if name is None else name,
        metadata={"file": str(path), "format": "trial csv"},
        extra={k: data[:, j] for k, j in extra_columns.items()},
        **values,
    )


def write_trial_csv(path, data, units: str = "display") -> None:
    """Write an `Experiment` or an unbatched `jaxship.Trajectory` as a trial CSV.

    `units="display"`: degrees, deg/s and rpm; `units="si"`: radians, rad/s and rev/s
    (times in s, lengths in m and speeds in m/s either way). Values are written with
    `repr`, the shortest text that reads back to the same float, so a write-read round
    trip is exact up to the unit conversion (a few ulp for degrees and rpm).

    An experiment's measured `channels` are written (derived and zero-filled ones are
    not, so reading back recomputes them identically); a trajectory's valid samples are
    written with t, delta, delta_c (`command.delta`), psi, r, u, v, x, y and n.
    """
    if units not in ("display", "si"):
        raise ValueError(f"`units` must be 'display' or 'si', got {units!r}.")
    if isinstance(data, Trajectory):
        data = Experiment.from_trajectory(data)
    elif not isinstance(data, Experiment):
        raise ValueError(
            f"`data` must be an Experiment or a Trajectory, got {type(data).__name__}."
        )
    keys = ("t",) + data.channels
    unit_of = {}
    for key in keys:
        si = next(u for u, f in _UNITS[key].items() if f == 1.0)
        unit_of[key] = _DISPLAY_UNITS.get(si, si) if units == "display" else si
    columns = [_from_si(np.asarray(getattr(data, k), dtype=np.float64), unit_of[k]) for k in keys]
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow([f"{k} [{unit_of[k]}]" for k in keys])
        for row in zip(*columns):
            writer.writerow([repr(float(value)) for value in row])


# ---------------------------------------------------------------------------------------
# Readers for the measured data sets in shared/data


def shared_data_dir() -> Path | None:
    """The measured-data folder: `$JAXSHIP_DATA` if that variable is set (None if it
    does not exist), else `../shared/data` next to the repository or the working
    directory; None when absent (tests and notebooks skip on None)."""
    env = os.environ.get("JAXSHIP_DATA")
    if env:
        path = Path(env).expanduser()
        return path if path.is_dir() else None
    for path in (Path(__file__).resolve().parents[2] / "shared" / "data",
                 Path.cwd().resolve().parent / "shared" / "data"):
        if path.is_dir():
            return path
    return None


# Esso Osaka FRT column -> (channel, expected unit); positive delta already gives r > 0
_ESSO_COLUMNS = {
    "t": ("t", "s"),
    "x_position_mid": ("x", "m"),
    "y_position_mid": ("y", "m"),
    "u_velo": ("u", "m/s"),
    "vm_velo": ("v", "m/s"),
    "psi_hat": ("psi", "rad"),
    "r_angvelo": ("r", "rad/s"),
    "n_prop": ("n", "rps"),
    "delta_rudder": ("delta", "rad"),
    "wind_velo_true": ("wind_speed", "m/s"),
    "wind_dir_true": ("wind_dir", "rad"),
    "wind_velo_relative_mid": ("wind_speed_relative", "m/s"),
    "wind_dir_relative_mid": ("wind_dir_relative", "rad"),
}
_ESSO_REQUIRED = ("t", "psi_hat", "r_angvelo", "delta_rudder")


def read_esso_osaka(path) -> Experiment:
    """Read a run of the Esso Osaka 3 m free-running model tests (FRT-DS-ESSO,
    Osaka University 2020; Wakita et al. 2022), model scale, SI.

    The files are already SI, body-fixed u, v at midship and in our sign convention
    (positive delta gives positive r). The heading `psi_hat` is wrapped to
    [-pi, pi] in the files (the README's "not wrapped" is wrong: every turning run
    jumps by 2 pi); it is unwrapped here with `np.unwrap`. x, y are the pond's
    earth-fixed x0, y0 axes (not north/east; psi is measured from x0).
    `wind_speed`/`wind_dir` are the TRUE wind, the direction it comes from, measured
    from x0 (checked: the logged apparent
    wind equals true wind minus ship velocity to 1e-4); the apparent wind is kept in
    `extra` as `wind_speed_relative` [m/s] and `wind_dir_relative` [rad, from the bow,
    coming from]. Trailing empty rows are dropped; files may start at t != 0.
    """
    path = Path(path)
    headers, header_line, records = _read_csv(path)
    columns = {}
    for j, text in enumerate(headers):
        key, unit = _split_header(path, header_line, text)
        if key not in _ESSO_COLUMNS:
            raise ValueError(
                f"{path}: column '{text}' (header row, line {header_line}): unknown Esso Osaka "
                f"column {key!r}; expected {', '.join(_ESSO_COLUMNS)}."
            )
        if unit != _ESSO_COLUMNS[key][1]:
            raise ValueError(
                f"{path}: column '{text}' (header row, line {header_line}): unit {unit!r}, "
                f"expected {_ESSO_COLUMNS[key][1]!r}."
            )
        columns[key] = j
    for key in _ESSO_REQUIRED:
        if key not in columns:
            raise ValueError(
                f"{path}: header row (line {header_line}): missing required column "
                f"'{key} [{_ESSO_COLUMNS[key][1]}]'."
            )
    data = _parse_numbers(path, headers, records)
    lines = [line for line, _ in records]
    _check_time(path, headers[columns["t"]], data[:, columns["t"]], lines, False, 0.0)
    values = {_ESSO_COLUMNS[k][0]: data[:, j] for k, j in columns.items()}
    values["psi"] = np.unwrap(values["psi"])  # wrapped to [-pi, pi] in the files
    extra = {k: values.pop(k) for k in ("wind_speed_relative", "wind_dir_relative") if k in values}
    return Experiment(
        name=path.stem, extra=extra, **values,
        metadata={
            "file": str(path), "format": "esso_osaka", "vessel": "Esso Osaka 3 m model",
            "source": "FRT-DS-ESSO, Osaka University (2020)", "scale": "model",
            "lpp": 3.0, "frame": "pond x0/y0 axes",
        },
    )


def _body_velocity(ue, ve, psi):
    """Body-fixed (u, v) of the earth-fixed velocity (dx/dt, dy/dt) at heading psi [rad]."""
    c, s = np.cos(psi), np.sin(psi)
    return ue * c + ve * s, -ue * s + ve * c


def _numeric_lines(path, lines, first_line, ncol, split):
    """Float table of whitespace- or tab-separated `lines` (line numbers from
    `first_line`), blank lines skipped; errors name the file, column and row."""
    rows, numbers = [], []
    for offset, text in enumerate(lines):
        fields = [s for s in split(text)]
        if all(not s.strip() for s in fields):
            continue
        numbers.append(first_line + offset)
        rows.append(fields)
    headers = [f"column {j + 1}" for j in range(ncol)]
    table = _parse_numbers(path, headers, list(zip(numbers, rows)))
    return table, numbers


def read_hsva_kvlcc2(path) -> Experiment:
    """Read an HSVA CPMC free-running zig-zag of the KVLCC2 (SIMMAN 2008), model
    scale 1:45.714 (Lpp = 7 m), SI.

    Columns: t, x0, y0, psi [deg], dx0/dt, dy0/dt (earth-fixed), r [deg/s], an
    unidentified channel (ignored), delta [deg, positive = rudder to port], n [rps],
    thrust [N], torque [N m]. Converted: angles to radians, the earth-fixed velocities
    to body-fixed u, v with the heading, and delta negated into our convention
    (positive turns to starboard). Thrust and torque go to `extra`.
    """
    path = Path(path)
    text = path.read_text(encoding="cp1252").splitlines()
    if not text or "HSVA" not in text[0]:
        raise ValueError(f"{path}: not an HSVA file (line 1 should name HSVA).")
    table, lines = _numeric_lines(path, text[4:], 5, 12, str.split)
    t, x, y, psi_deg, ue, ve, r_deg, _, delta_deg, n, thrust, torque = table.T
    _check_time(path, "column 1", t, lines, False, 0.0)
    psi = np.deg2rad(psi_deg)
    u, v = _body_velocity(ue, ve, psi)
    return Experiment(
        t, -np.deg2rad(delta_deg),  # HSVA: positive = rudder to port; ours: to starboard
        psi=psi, r=np.deg2rad(r_deg), u=u, v=v, x=x, y=y, n=n,
        name=path.stem, extra={"thrust": thrust, "torque": torque},
        metadata={
            "file": str(path), "format": "hsva_kvlcc2", "vessel": "KVLCC2",
            "source": "HSVA CPMC, SIMMAN 2008", "scale": "model", "lambda": KVLCC2_SCALE,
            "lpp": 7.0,
            "title": " ".join(s.strip() for s in text[1:3]),
        },
    )


def read_marin_kvlcc2(path, *, model_scale: bool = False, dt: float = MARIN_DT
                      ) -> Experiment:
    """Read a MARIN free-running KVLCC2 test (SIMMAN 2008), full scale (Lpp = 320 m).

    Columns: t, x0, y0, phi [deg], psi [deg], dx0/dt, dy0/dt (earth-fixed), p [deg/s],
    r [deg/s], delta [deg, positive = rudder to port], n [rpm], printed with 3
    significant digits. The time column is too coarse to use (1 s steps above 100 s),
    so time is rebuilt as $t_k = k\\,dt$ with `dt` = 0.13526 s (50 Hz at model scale);
    the reader checks that this matches the printed times to within one printed digit.
    Converted: angles to radians, n to rev/s, the earth-fixed velocities to body u, v
    with the (1 deg resolution) heading, delta negated into our convention. Roll `phi`
    [rad] and roll rate `p` [rad/s] go to `extra`. Trailing empty rows are dropped.

    `model_scale=True` Froude-scales to the 1:45.714 model: lengths / lambda,
    velocities and times / sqrt(lambda), yaw/roll rates and n * sqrt(lambda).
    """
    path = Path(path)
    text = path.read_text(encoding="latin-1").splitlines()
    if not text or not text[0].startswith("MARIN"):
        raise ValueError(f"{path}: not a MARIN file (line 1 should start with 'MARIN').")
    table, lines = _numeric_lines(path, text[2:], 3, 11, lambda s: s.split("\t"))
    t_printed, x, y, phi, psi_deg, ue, ve, p, r_deg, delta_deg, rpm = table.T
    t = dt * np.arange(table.shape[0])
    quantum = 10.0 ** (np.floor(np.log10(np.maximum(np.abs(t_printed), 1e-300))) - 2)
    off = np.abs(t - t_printed) > quantum + 1e-9
    if np.any(off[1:]):
        k = int(np.nonzero(off[1:])[0][0]) + 1
        raise ValueError(
            f"{path}: column 1 (time), row {k + 1} (line {lines[k]}): printed time "
            f"{t_printed[k]} s does not match the reconstructed {t[k]:.3f} s = {k} * {dt} s."
        )
    psi = np.deg2rad(psi_deg)
    u, v = _body_velocity(ue, ve, psi)
    r, n = np.deg2rad(r_deg), rpm / 60.0
    p = np.deg2rad(p)
    scale = 1.0
    if model_scale:
        scale = KVLCC2_SCALE
        root = math.sqrt(scale)
        t, x, y, u, v = t / root, x / scale, y / scale, u / root, v / root
        r, p, n = r * root, p * root, n * root
    return Experiment(
        t, -np.deg2rad(delta_deg),  # MARIN: positive = rudder to port; ours: to starboard
        psi=psi, r=r, u=u, v=v, x=x, y=y, n=n,
        name=path.stem, extra={"phi": np.deg2rad(phi), "p": p},
        metadata={
            "file": str(path), "format": "marin_kvlcc2", "vessel": "KVLCC2",
            "source": "MARIN, SIMMAN 2008", "scale": "model" if model_scale else "full",
            "lambda": KVLCC2_SCALE, "lpp": 320.0 / scale,
            "title": text[1].strip() if len(text) > 1 else "",
        },
    )


def read_measured(path, **kwargs) -> Experiment:
    """Read any supported measurement file, recognised by extension and first line:
    MARIN (`.dat`, line 1 starts with 'MARIN') -> `read_marin_kvlcc2`; HSVA (line 1
    names HSVA) -> `read_hsva_kvlcc2`; a CSV with Esso Osaka headers (`psi_hat [rad]`)
    -> `read_esso_osaka`; any other CSV -> `read_trial_csv`. Keyword arguments go to
    the chosen reader."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{path} is a folder; pass one measurement file.")
    if not path.exists():
        raise ValueError(f"{path}: no such file.")
    with open(path, "rb") as f:
        first = f.readline(4096).decode("latin-1").lstrip("\ufeff\xef\xbb\xbf").strip()
    suffix = path.suffix.lower()
    if first.startswith("MARIN"):
        return read_marin_kvlcc2(path, **kwargs)
    if first.startswith("HSVA"):
        return read_hsva_kvlcc2(path, **kwargs)
    if suffix == ".csv" or ("[" in first and "," in first):
        names = [_HEADER.match(s).group(1) if _HEADER.match(s) else s for s in first.split(",")]
        if "psi_hat" in names or "delta_rudder" in names:
            return read_esso_osaka(path, **kwargs)
        if "t" in names:
            return read_trial_csv(path, **kwargs)
    raise ValueError(
        f"{path}: unknown measurement format (first line {first[:60]!r}); supported: trial "
        "CSV ('t [s],delta [deg],...'), Esso Osaka FRT CSV, HSVA and MARIN KVLCC2 .dat files."
    )
