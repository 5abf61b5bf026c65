"""Reading and checking the records of `identify`: measurement files and folders into
`Experiment`s, with errors that name the file and column before any fitting."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

import jaxship as js


def valid_samples(ds: js.Dataset, name: str) -> np.ndarray:
    """The valid samples of channel `name` of every record, concatenated."""
    return np.concatenate([np.asarray(getattr(ds, name))[i, :n] for i, n in enumerate(ds.lengths)])


def rms(a) -> float:
    """Root mean square (0 for an empty array)."""
    a = np.asarray(a, dtype=np.float64)
    return float(np.sqrt(np.mean(a**2))) if a.size else 0.0


def mean_valid(ds: js.Dataset, name: str) -> float:
    """Mean of the valid samples of channel `name` (0 when there are none)."""
    values = valid_samples(ds, name)
    return float(np.mean(values)) if values.size else 0.0


def source(e: js.Experiment) -> str:
    """The file an experiment was read from (its name if none)."""
    return str(e.meta.get("file", e.name))


def _with_velocities(e: js.Experiment, over_ground: bool | None) -> js.Experiment:
    """`e` with the reference of its u, v stated by the user (`--velocities`): a trial
    CSV's as given; a measured data set's reader states its own (over ground), and a
    contradiction is a `ValueError` naming the file."""
    if over_ground is None or e.over_ground == over_ground:
        return e
    if e.meta.get("format") != "trial csv":
        raise ValueError(f"{source(e)}: its reader states that u, v are "
                         f"{'over ground' if e.over_ground else 'through the water'}; "
                         "--velocities applies to trial CSV files only.")
    return e.with_velocities(over_ground=over_ground)


def read_experiments(paths, *, role: str = "training", note=None, taken=(),
                     sample_interval: float | None = None,
                     over_ground: bool | None = None) -> list[js.Experiment]:
    """Read measurement files and folders into experiments.

    A file is read with `read_measured` (trial CSV, Esso Osaka CSV, HSVA and MARIN
    .dat); a folder contributes every file in it (not its subfolders) with a
    `.csv`, `.dat` or `.txt` suffix whose format `read_measured` recognises
    (others, such as a propeller open-water table, are skipped and named in one
    sentence to `note`, a callable, so that a fit never uses fewer records than the
    user meant without saying so), in name order. Experiments with equal names, or with
    a name in `taken` (those of another role's records), get their folder as a prefix.
    With `sample_interval` [s], each record keeps every k-th sample, k the integer
    nearest to `sample_interval / dt` (`Experiment.decimate`; 1 keeps the record), said
    in one sentence to `note`. `over_ground` states the reference of the trial CSVs' u, v
    (None: through the water, as `read_trial_csv` reads them; `_with_velocities`).

    **Raises:** `ValueError` naming the file: missing, unreadable or malformed
    (the readers' messages name the column and row), or a folder with no records.
    """
    if isinstance(paths, (str, Path)):
        paths = [paths]
    experiments = []

    def read(item):  # with the reader's note (a heading unwrapped) said
        e = _with_velocities(js.read_measured(item), over_ground)
        if note is not None and "note" in e.meta:
            note(f"{item}: {e.meta['note']}")
        return e

    for path in paths:
        path = Path(path)
        if path.is_dir():
            found, others = js.measurement_files(path)
            skipped = [item.name for item in others if item.is_file()]
            special = [item.name for item in others if not item.is_file()]  # never opened
            if skipped and note is not None:
                note(f"{path}: skipped {len(skipped)} file(s) whose format is not a "
                     f"measurement record: {', '.join(skipped)}.")
            if special and note is not None:
                note(f"{path}: skipped {len(special)} file(s) that are not regular files (a "
                     f"FIFO, a device, a broken link): {', '.join(special)}.")
            if not found:
                raise ValueError(f"{path}: the {role} folder holds no measurement file "
                                 "(trial CSV, Esso Osaka CSV, HSVA or MARIN .dat).")
            experiments.extend(read(item) for item in found)
        elif not path.exists():
            raise ValueError(f"{path}: no such {role} file or folder.")
        else:
            experiments.append(read(path))
    if not experiments:
        raise ValueError(f"no {role} files given.")
    names = [e.name for e in experiments] + list(taken)
    out = []
    for e in experiments:
        if names.count(e.name) > 1:
            e = e.renamed(f"{Path(source(e)).parent.name}/{e.name}")
        out.append(e)
    names = [e.name for e in out] + list(taken)
    for i, e in enumerate(out):  # still equal (same folder name): number them
        if names.count(e.name) > 1:
            out[i] = e.renamed(f"{e.name}#{i}")
    return out if sample_interval is None else _resampled(out, sample_interval, role, note)


def _resampled(experiments, interval: float, role: str, note) -> list[js.Experiment]:
    """Every k-th sample of each record, k the integer nearest to `interval / dt`."""
    if not (math.isfinite(interval) and interval > 0):
        raise ValueError(f"the sample interval must be a positive number of seconds, got "
                         f"{interval!r}.")
    factors = [max(1, round(interval / e.dt)) for e in experiments]
    for e, k in zip(experiments, factors):
        kept = -(-e.num_samples // k)
        if kept < 3:
            raise ValueError(f"--sample-interval {interval:g}: keeps {kept} sample(s) of the "
                             f"{role} record {source(e)} ({e.duration:.4g} s sampled every "
                             f"{e.dt:.3g} s); a fit needs at least 3: choose an interval of "
                             f"at most {e.duration / 2:.3g} s.")
    if note is not None and any(k > 1 for k in factors):
        changes = sorted({f"{e.dt:.3g} s -> {k * e.dt:.3g} s" for e, k in
                          zip(experiments, factors) if k > 1})
        note(f"{role} records resampled to every k-th sample ({', '.join(changes)}).")
    return [e.decimate(k) if k > 1 else e for e, k in zip(experiments, factors)]


def same_records(train, held_out, *, role: str = "validation",
                 option: str = "--validate") -> list[str]:
    """A sentence for each held-out record (`role`, given by `option`) that is a training
    record (the same samples): its score is no held-out check."""
    return [f"the {role} record {source(e)} holds the samples of the training record "
            f"{source(f)}: its score is no held-out check ({option} records not used in "
            "the fit for one)."
            for e in held_out for f in train
            if e.channels == f.channels and e.num_samples == f.num_samples
            and all(np.array_equal(getattr(e, k), getattr(f, k)) for k in ("t", *e.channels))]


VELOCITIES = {"through-water": False, "over-ground": True}  # `velocities`: over_ground


def over_ground(velocities: str | None) -> bool | None:
    """`read_experiments`' `over_ground` of `velocities` (`VELOCITIES`; None: as read)."""
    if velocities is None:
        return None
    if velocities not in VELOCITIES:
        raise ValueError(f"unknown velocities {velocities!r}; choose "
                         f"{' or '.join(VELOCITIES)} (or None: as the records state).")
    return VELOCITIES[velocities]


def as_experiments(data, role: str, *, note=None, sample_interval: float | None = None,
                   over_ground: bool | None = None) -> list[js.Experiment]:
    """`data` (an `Experiment`, a list of them, a `Dataset` or file paths) as a list
    of experiments, read (files) and resampled as `read_experiments` reads files."""
    reading = dict(note=note, sample_interval=sample_interval, over_ground=over_ground)
    if isinstance(data, (str, Path)):
        return read_experiments([data], role=role, **reading)
    if isinstance(data, Sequence) and data and all(isinstance(e, (str, Path)) for e in data):
        return read_experiments(data, role=role, **reading)
    if isinstance(data, js.Dataset):
        data = [data.experiment(i) for i in range(data.num_experiments)]
    elif isinstance(data, js.Experiment):
        data = [data]
    if not (isinstance(data, Sequence) and data
            and all(isinstance(e, js.Experiment) for e in data)):
        raise ValueError(f"the {role} data must be an Experiment, a list of Experiments, a "
                         f"Dataset or file paths, got {type(data).__name__}.")
    data = [_with_velocities(e, over_ground) for e in data]
    return data if sample_interval is None else _resampled(data, sample_interval, role, note)


# No displacement ship runs beyond a length Froude number U / sqrt(g L) of 1: merchant
# ships run at 0.1-0.3, fast displacement hulls up to about 0.5, and beyond 1 a hull
# planes (Faltinsen 2005, Hydrodynamics of High-Speed Marine Vehicles, ch. 1). A speed
# channel beyond it, for the model's length, is in another unit (knots, km/h) or from
# another ship.
MAX_FROUDE = 1.0
GRAVITY = 9.80665  # standard gravity g [m/s^2] (3rd CGPM, 1901), as the MMG vessels use


def preset_length(model: str) -> float | None:
    """L_pp [m] of the vessel preset `model`; None for other models (no length)."""
    vessel = js.get_vessel(model) if model in js.VESSELS else None
    return float(vessel.length) if isinstance(vessel, js.AbstractVessel) else None


def check_froude(experiments, length: float, role: str, model: str = "") -> None:
    """A `ValueError` naming the file, column and time where a record's u or v beyond
    Froude number `MAX_FROUDE` for a ship of `length` [m] (the model's)."""
    limit = MAX_FROUDE * math.sqrt(GRAVITY * length)
    for e in experiments:
        for channel in ("u", "v"):
            values = np.abs(np.asarray(getattr(e, channel))) if e.has(channel) else None
            if values is None or not (values > limit).any():
                continue
            i = int(np.argmax(values > limit))
            raise ValueError(
                f"{source(e)} ({role} record {e.name!r}): column {channel!r} reaches "
                f"{values[i]:.4g} m/s at t = {e.t[i]:.4g} s, Froude number "
                f"{values[i] / math.sqrt(GRAVITY * length):.3g} for the {length:g} m {model}: "
                f"no displacement ship runs beyond Fn {MAX_FROUDE:g} ({limit:.3g} m/s). Is the "
                "column in knots or km/h rather than m/s, or is the record of another ship?")


def check_experiments(experiments, rudder: str, role: str, model: str = "",
                      requires=()) -> None:
    """Errors naming the file, before any fitting: the replayed rudder and the
    channels the `model` `requires` must be measured, at least 3 uniform samples."""
    for e in experiments:
        where = f"{source(e)} ({role} record {e.name!r})"
        have = ", ".join(c for c in e.channels) or "none"
        if not e.has(rudder):
            raise ValueError(f"{where}: no column {rudder!r} (the replayed rudder); measured "
                             f"channels: {have}. Choose --rudder delta or delta_c.")
        missing = [c for c in requires if not e.has(c)]
        if missing:
            raise ValueError(
                f"{where}: model {model} needs the measured {' and '.join(map(repr, requires))}"
                f" (the surge/sway velocities it is driven by or restarted from), but the record "
                f"has no column {missing[0]!r}; measured channels: {have}. Use records with "
                "them or a Nomoto model.")
        if e.num_samples < 3:
            raise ValueError(f"{where}: needs at least 3 samples, has {e.num_samples}.")
        e.check_uniform("interpolate the record onto a uniform time grid first "
                        "(--sample-interval keeps every k-th sample: it does not make the "
                        "intervals equal).", where=where)
