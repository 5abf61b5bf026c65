"""Measured and simulated trials: `Experiment` and `Dataset` (file formats and
readers in `jaxship._simulation._readers`).

Inside the library every channel is SI with angles in radians and propeller rates in
rev/s, in our sign convention (positive rudder angle turns the ship to starboard,
$r > 0$; x north / forward, y east / starboard, heading from x towards y). Degrees,
rpm and the sign conventions of the sources live only in the readers
(`jaxship._simulation._readers` and `_measured`).
"""

from collections.abc import Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._foundation._state import ShipState, Trajectory
from .._models._manoeuvres import Replay


# channel order of files and of `Experiment`; `t` first
CHANNELS = (
    "t", "delta", "delta_c", "psi", "r", "u", "v", "x", "y", "n", "wind_speed", "wind_dir",
)
_SIGNALS = CHANNELS[1:]


def _cumulative_trapezoid(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])


def _spacing(t) -> tuple[float, np.dtype]:
    """The spacing of JAX's float type (float32 unless x64 is enabled) at the largest
    |t|, and that type."""
    dtype = jax.dtypes.canonicalize_dtype(jnp.float64)
    return float(np.spacing(np.asarray(np.max(np.abs(t)), dtype))), dtype


def sampling_tolerance(t, rtol: float = 1e-6) -> float:
    """The largest $|t_{k+1} - t_k - \\Delta t|$ [s] of uniform sampling:
    $\\mathrm{rtol}\\,\\Delta t + 8\\,\\epsilon$, $\\epsilon$ the spacing of JAX's float
    type at the largest |t|, whose rounding of the time stamps (a simulation in float32,
    epoch time stamps) is no irregularity."""
    t = np.asarray(t, dtype=np.float64)
    return rtol * (t[-1] - t[0]) / (t.shape[0] - 1) + 8 * _spacing(t)[0]


def check_uniform(t, where: str, advice: str, rtol: float = 1e-6) -> None:
    """A one-line `ValueError` naming `where` and giving `advice` when the time stamps
    `t` are not uniform (`sampling_tolerance`), or when JAX's float type cannot resolve
    the sample interval at their size (then saying how to enable float64)."""
    t = np.asarray(t, dtype=np.float64)
    steps = np.diff(t)
    dt = float((t[-1] - t[0]) / steps.shape[0])
    spacing, dtype = _spacing(t)
    if spacing > 0.1 * dt:
        x64 = ("enable float64 (`jax.config.update('jax_enable_x64', True)` before any "
               "computation) or " if dtype != np.float64 else "")
        raise ValueError(f"{where}: column 't': {dtype.name} resolves time stamps of "
                         f"{np.max(np.abs(t)):.4g} s only to {spacing:.3g} s, too coarse for "
                         f"the {dt:.4g} s sample interval: {x64}subtract the first time stamp.")
    off = np.nonzero(np.abs(steps - dt) > sampling_tolerance(t, rtol))[0]
    if off.size:
        k = int(off[0]) + 1
        raise ValueError(f"{where}: column 't': sampling is not uniform (t[{k}] - t[{k - 1}] "
                         f"= {steps[k - 1]:.6g} s, mean interval {dt:.6g} s); {advice}")


OVER_GROUND = ("velocities", "over ground")  # metadata of records whose u, v are over ground


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
    `(key, value)` pairs with hashable values; see `meta`) are static; the metadata
    `("velocities", "over ground")` says that `u`, `v` are the track's velocity over
    ground in body axes (GNSS, a basin's carriage: every reader of measured data sets
    it), not through the water (`over_ground`); `extra` holds
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
    def over_ground(self) -> bool:
        """Whether `u`, `v` are over ground (metadata `("velocities", "over ground")`);
        else through the water, as a simulation's. They differ by the current, which
        `fit` adds to a vessel's predicted u, v of such a record
        (`jaxship.effects.UniformCurrent`)."""
        return dict(self.metadata).get("velocities") == OVER_GROUND[1]

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
        """True when every sample interval equals `dt` to a relative `rtol` and the
        rounding of the float type (`sampling_tolerance`)."""
        return bool(np.all(np.abs(np.diff(self.t) - self.dt)
                           <= sampling_tolerance(self.t, rtol)))

    def has(self, channel: str) -> bool:
        """True when `channel` was measured (not derived or zero-filled); `t` always."""
        return channel == "t" or channel in self.channels

    def check_uniform(self, advice: str | None = None, *, where: str | None = None) -> None:
        """A one-line `ValueError` naming the record (or `where`), the first sample
        interval off `dt` and `advice`, when the record is not uniformly sampled
        (`is_uniform`), or when JAX's float type cannot resolve its time stamps."""
        check_uniform(self.t, where or f"Experiment {self.name!r}", advice or "")

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
        return self._kept(keep)

    def decimate(self, factor: int) -> "Experiment":
        """Every `factor`-th sample, from the first, as a new experiment (derived channels
        recomputed). No anti-aliasing filter: the motions should lie well below the new
        Nyquist frequency $1/(2\\,\\text{factor}\\,dt)$, as a ship's do at a few samples
        per second."""
        if isinstance(factor, bool) or not isinstance(factor, (int, np.integer)) or factor < 1:
            raise ValueError(f"`factor` must be a positive integer, got {factor!r}.")
        return self._kept(slice(None, None, int(factor)))

    def renamed(self, name: str) -> "Experiment":
        """The same record under another `name`."""
        return self._relabelled(name, self.metadata)

    def with_velocities(self, *, over_ground: bool) -> "Experiment":
        """The same record with its `u`, `v` stated over ground (`over_ground=True`:
        GNSS, a basin's carriage) or through the water (the metadata `"velocities"`)."""
        metadata = {k: v for k, v in self.metadata if k != OVER_GROUND[0]}
        return self._relabelled(self.name, metadata | (dict([OVER_GROUND]) if over_ground
                                                       else {}))

    def _relabelled(self, name: str, metadata) -> "Experiment":
        return Experiment(self.t, name=name, metadata=metadata, extra=self.extra,
                          **self._measured())

    def _kept(self, keep) -> "Experiment":
        """The samples `keep` (a mask or slice) of the measured channels and of the
        `extra` signals logged at the samples."""
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

    def bucketed(self) -> "Dataset":
        """The dataset padded (masked) to the next of the lengths $\\{4, 5, 6, 7\\}\\cdot 2^k$
        at or above its own (at most 25 % more samples), so that records of nearby
        lengths share one compiled program (a filter that skips masked samples gives the
        same result)."""
        n = self.num_samples
        k = max(n.bit_length() - 3, 0)
        length = min(m << k for m in (4, 5, 6, 7, 8) if m << k >= n) if n > 4 else n
        if length == n:
            return self
        return Dataset.from_experiments([self.experiment(i) for i in
                                         range(self.num_experiments)], num_samples=length)

    @property
    def num_experiments(self) -> int:
        return len(self.lengths)

    @property
    def over_ground(self) -> np.ndarray:
        """(E,) bool: whether each experiment's u, v are over ground
        (`Experiment.over_ground`)."""
        return np.array([dict(m).get("velocities") == OVER_GROUND[1]
                         for m in self.experiment_metadata], dtype=bool)

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
