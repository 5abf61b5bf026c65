"""The trial CSV format (`read_trial_csv`, `write_trial_csv`) and the parsing helpers
the readers of the measured data sets (`_measured.py`) share; all return
`jaxship.Experiment` in SI units and our sign convention.

**Trial CSV format.** Comma-separated, one header row, one column per channel, each
header `name [unit]`:

| name | meaning | units |
| --- | --- | --- |
| `t` | time | s |
| `delta` | actual rudder angle, positive to starboard | deg, rad |
| `delta_c` | commanded rudder angle | deg, rad |
| `psi` | heading, not wrapped | deg, rad |
| `r` | yaw rate | deg/s, rad/s |
| `u`, `v` | surge and sway velocity, body axes, midship (through the water) | m/s |
| `x`, `y` | north and east position | m |
| `n` | propeller rate | rpm, rps |
| `wind_speed` | true wind speed | m/s |
| `wind_dir` | true wind direction the wind comes *from*, from north (x) | deg, rad |

`t`, `delta` and one of `psi`, `r` are required, the rest optional; column order is
free. A wrapped heading (jumps of about 360 deg, at +-180 or in 0-360) is unwrapped, with
a note in the metadata (`"note"`); columns that disagree by a unit (psi against the
integrated r, the positions against u, v: `_consistency.check_consistency`) are refused;
where a pair of columns cannot be checked so (a heading that turns less than 5 deg, fewer
than 3 samples), the metadata's `"unchecked"` says which and why.
Rows are numbered from 1 after the header ("row 3" is the third data row) and
every error message names the file, the column, the row and its line. Blank lines and
trailing rows whose cells are all empty (spreadsheet exports) are skipped; an empty or
non-finite cell anywhere else is an error. Unknown column names are an error unless
`allow_unknown=True`, which keeps them, unconverted, in `Experiment.extra`. `u`, `v` are
through the water unless read with `over_ground=True` (a GNSS track, a basin's carriage).
"""

import csv
import math
import re
from pathlib import Path

import equinox as eqx
import numpy as np

from .._foundation._schema import not_text, open_text
from .._foundation._state import Trajectory
from ._consistency import check_consistency, unwrap_heading
from ._data import CHANNELS, OVER_GROUND, Experiment, sampling_tolerance


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
# what no ship logs, in SI, and the unit a column beyond it likely holds: a rudder beyond
# 90 deg, a yaw rate beyond 60 deg/s (a 3 m model turns at about 10 deg/s), a speed beyond
# 50 m/s (Fn 0.9 for a 320 m hull), a propeller beyond 3600 rpm, a wind from beyond a turn
_PLAUSIBLE = {
    "delta": (math.pi / 2, "the rudder angle", {"rad": "deg"}),
    "delta_c": (math.pi / 2, "the rudder angle", {"rad": "deg"}),
    "r": (math.radians(60.0), "the yaw rate", {"rad/s": "deg/s"}),
    "u": (50.0, "the speed", {}),
    "v": (50.0, "the speed", {}),
    "n": (60.0, "the propeller rate", {"rps": "rpm"}),
    "wind_dir": (2 * math.pi + 1e-9, "the direction", {"rad": "deg"}),
}
_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*\[([^\]]*)\]\s*$")



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


# ---------------------------------------------------------------------------------------
# CSV parsing shared by the trial format and the Esso Osaka files

_CHUNK = 1024  # rows converted at a time: small, so that the rows die young (cheap GC)
_DELIMITERS = {";": "semicolons", "\t": "tabs", "|": "vertical bars"}


def _open_text(path: Path, encoding: str):
    """`path` opened for reading CSV text (`open_text`'s refusals)."""
    return open_text(path, "one measurement file", encoding=encoding, newline="")


def _csv_records(path: Path, encoding: str):
    """Yield `(line, fields)` for every CSV record of `path` (blank lines give no
    fields); decoding and CSV errors become one-line `ValueError`s naming the line."""
    with _open_text(path, encoding) as f:
        reader = csv.reader(f)
        try:
            for fields in reader:
                yield reader.line_num, fields
        except UnicodeDecodeError:
            raise not_text(path, encoding) from None
        except csv.Error as error:
            raise ValueError(f"{path}: line {reader.line_num + 1}: not a readable CSV record "
                             f"({error}).") from None


def _data_records(records):
    """The data records after the header: blank lines skipped, and records with only
    empty cells kept only when a record with a value follows (so trailing empty rows of
    spreadsheet exports are dropped, and an empty row inside the data is an error)."""
    pending = []
    for record in records:
        fields = record[1]
        if not fields:
            continue
        if not any(map(str.strip, fields)):
            pending.append(record)
            continue
        if pending:
            yield from pending
            pending.clear()
        yield record


def _check_delimiter(path, line, header):
    """A header of one field holding semicolons or tabs: the file is not comma-separated."""
    if len(header) == 1:
        for delimiter, name in _DELIMITERS.items():
            if delimiter in header[0]:
                raise ValueError(
                    f"{path}: header row (line {line}): the columns are separated by {name}, "
                    "not commas; save the file as comma-separated CSV (decimal points, not "
                    "commas)."
                )


def _read_csv(path: Path, encoding: str = "utf-8-sig"):
    """Header fields, header line number and an iterator of the data records
    `(line, fields)` (see `_data_records`); records before the header with only empty
    cells are skipped."""
    records = _csv_records(path, encoding)
    for line, fields in records:
        if any(map(str.strip, fields)):
            header = [s.strip() for s in fields]
            _check_delimiter(path, line, header)
            return header, line, _data_records(records)
    raise ValueError(f"{path}: the file is empty; expected a header row such as "
                     "'t [s],delta [deg],psi [deg]'.")


def _parse_numbers(path, headers, records, layout=None) -> tuple[np.ndarray, list[int]]:
    """Float table of the `(line, fields)` `records` (any iterable; converted in chunks)
    and the line number of each row; an error names the file, column and row of the
    first bad cell. `layout`: the expected layout, for a row with the wrong number of
    fields (default: the header's column count)."""
    ncol = len(headers)
    layout = layout or f"the header has {ncol} columns"
    blocks, lines, chunk = [], [], []

    def convert():
        try:
            block = np.array([fields for _, fields in chunk], dtype=np.float64)
            good = bool(np.isfinite(block).all())
        except ValueError:
            good = False
        if not good:  # find the bad cell (or parse what numpy would not, as float() does)
            block = _checked_block(path, headers, chunk, len(lines) - len(chunk))
        blocks.append(block)
        chunk.clear()

    for line, fields in records:
        if len(fields) != ncol:
            raise ValueError(
                f"{path}: row {len(lines) + 1} (line {line}) has {len(fields)} fields but "
                f"{layout}."
            )
        lines.append(line)
        chunk.append((line, fields))
        if len(chunk) == _CHUNK:
            convert()
    if chunk:
        convert()
    data = np.concatenate(blocks) if blocks else np.empty((0, ncol))
    return data, lines


def _checked_block(path, headers, chunk, offset) -> np.ndarray:
    """The float table of `chunk` (whose first row is row `offset + 1`) read cell by
    cell, with the error for its first empty, unreadable or non-finite cell."""
    block = np.empty((len(chunk), len(headers)))
    for k, (line, fields) in enumerate(chunk):
        for j, text in enumerate(fields):
            try:
                value = float(text)
            except ValueError:
                value = None
            if value is not None and math.isfinite(value):
                block[k, j] = value
                continue
            where = f"{path}: column '{headers[j]}', row {offset + k + 1} (line {line})"
            if not text.strip():
                raise ValueError(f"{where}: empty value.")
            if value is None:
                raise ValueError(f"{where}: cannot read {text!r} as a number.")
            raise ValueError(f"{where}: value {text.strip()!r} is not finite (NaN and "
                             "infinite values are not allowed).")
    return block


def _check_rows(path, count):
    if count < 2:
        raise ValueError(f"{path}: needs at least two data rows, got {count}.")


def _check_time(path, header, t, lines, require_uniform, rtol):
    _check_rows(path, t.shape[0])
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
        bad = np.nonzero(np.abs(steps - dt) > sampling_tolerance(t, rtol))[0]
        if bad.size:
            k = int(bad[0]) + 1
            raise ValueError(
                f"{path}: column '{header}', row {k + 1} (line {lines[k]}): sampling interval "
                f"{steps[k - 1]:.6g} s differs from the typical (median) interval {dt:.6g} s; "
                "uniform sampling is required (require_uniform=True)."
            )


def _split_header(path, line, text):
    if "\n" in text or "\r" in text:  # a quote never closed: the header ran on
        lines = text.splitlines()
        raise ValueError(
            f"{path}: header row (line {line - len(lines) + 1}): the quote opened in column "
            f"'{lines[0][:40]}' is never closed, so the header runs on over {len(lines)} lines."
        )
    match = _HEADER.match(text)
    if match is None:
        raise ValueError(
            f"{path}: column '{text}' (header row, line {line}): a header must read "
            "'name [unit]', e.g. 'psi [deg]'."
        )
    return match.group(1), match.group(2).strip()


def read_trial_csv(path, *, require_uniform: bool = False, allow_unknown: bool = False,
                   name: str | None = None, rtol: float = 1e-6,
                   over_ground: bool = False) -> Experiment:
    """Read a trial CSV (format in the module docstring) into an `Experiment` (SI).

    **Arguments:**

    - `path`: the file.
    - `require_uniform`: also require a constant sample interval (to `rtol` relative).
    - `allow_unknown`: keep columns with unknown names in `extra` (values as written)
      instead of failing.
    - `name`: experiment name; the file's stem by default.
    - `over_ground`: the file's `u`, `v` are over ground (a GNSS track, a basin's
      carriage: `Experiment.over_ground`), not through the water (the default).

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
    data, lines = _parse_numbers(path, headers, records)
    j_t = columns["t"][0]
    _check_time(path, headers[j_t], data[:, j_t], lines, require_uniform, rtol)
    values = {key: _to_si(data[:, j], unit) for key, (j, unit) in columns.items()}
    for key, (j, unit) in columns.items():
        if key in _PLAUSIBLE:
            _check_plausible(path, headers[j], key, unit, values[key], lines)
    notes = {}
    if "psi" in values:
        values["psi"], wraps = unwrap_heading(values["psi"])
        if wraps:
            notes["note"] = (f"column '{headers[columns['psi'][0]]}' wraps around "
                             f"{wraps} time(s) (jumps of about 360 deg): unwrapped.")
    unchecked = check_consistency(str(path), values["t"], values,
                                  {k: headers[j] for k, (j, _) in columns.items()},
                                  {k: unit for k, (_, unit) in columns.items()})
    if unchecked:
        notes["unchecked"] = " ".join(unchecked)
    return Experiment(
        name=path.stem if name is None else name,
        metadata={"file": str(path), "format": "trial csv", **notes,
                  **dict([OVER_GROUND] if over_ground else [])},
        extra={k: data[:, j] for k, j in extra_columns.items()},
        **values,
    )


def _beyond(key, si) -> tuple[int, str, str] | None:
    """The first sample of the SI channel `si` beyond what any ship logs (`_PLAUSIBLE`),
    its value and the range it leaves, in display units ("114.6 deg", "the rudder angle
    of any ship (at most 90 deg)"); None where every sample is within."""
    limit, what, _ = _PLAUSIBLE[key]
    beyond = np.nonzero(np.abs(np.asarray(si)) > limit)[0]
    if not beyond.size:
        return None
    i = int(beyond[0])
    si_unit = next(u for u, f in _UNITS[key].items() if f == 1.0)
    shown = _DISPLAY_UNITS.get(si_unit, si_unit)
    scale = lambda x: float(_from_si(np.array(x), shown))
    return i, f"{scale(abs(si[i])):.4g} {shown}", f"{what} of any ship (at most " \
        f"{scale(limit):.4g} {shown})"


def _check_plausible(path, header, key, unit, si, lines):
    """A `ValueError` naming the file, column, row and likely unit where a channel is
    beyond what any ship logs (`_beyond`): e.g. degrees in a column labelled rad."""
    found = _beyond(key, si)
    if found is None:
        return
    (i, value, range_), likely = found, _PLAUSIBLE[key][2]
    hint = (f"; is the column in {likely[unit]} rather than {unit}?" if unit in likely else
            "; check the column's unit.")
    raise ValueError(f"{path}: column '{header}', row {i + 1} (line {lines[i]}): {value} is "
                     f"beyond {range_}{hint}")


class DisplayUnits(eqx.Module):
    """`write_trial_csv(units=DisplayUnits())` and the manoeuvre indices' `to_dict` (the
    default of both): angles in degrees, rates in deg/s, shaft speed in rpm (times in s,
    lengths in m, speeds in m/s; the indices' speed loss in percent)."""

    def unit(self, si: str) -> str:
        """The unit a quantity measured in the SI unit `si` is written in."""
        return _DISPLAY_UNITS.get(si, si)


class SIUnits(eqx.Module):
    """`write_trial_csv(units=SIUnits())`, `to_dict(units=SIUnits())` of the manoeuvre
    indices: every quantity in its SI unit (rad, rad/s, rev/s, s, m, m/s)."""

    def unit(self, si: str) -> str:
        """The unit a quantity measured in the SI unit `si` is written in: `si`."""
        return si


def write_trial_csv(path, data, units: DisplayUnits | SIUnits = DisplayUnits()) -> None:
    """Write an `Experiment` or an unbatched `jaxship.Trajectory` as a trial CSV.

    `units`: `DisplayUnits()` (degrees, deg/s and rpm) or `SIUnits()` (radians, rad/s and
    rev/s; times in s, lengths in m and speeds in m/s either way). Values are written with
    `repr`, the shortest text that reads back to the same float, so a write-read round
    trip is exact up to the unit conversion (a few ulp for degrees and rpm). A value
    too large to write in display units (above about 3e306 rad) is a `ValueError`, and so
    is one that `read_trial_csv` would refuse as beyond what any ship logs (`_PLAUSIBLE`):
    nothing is written then.

    An experiment's measured `channels` are written (derived and zero-filled ones are
    not, so reading back recomputes them identically); a trajectory's valid samples are
    written with t, delta, delta_c (`command.delta`), psi, r, u, v, x, y and n.
    """
    if not isinstance(units, (DisplayUnits, SIUnits)):
        raise ValueError(f"`units` must be DisplayUnits() or SIUnits(), got {units!r}.")
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
        unit_of[key] = units.unit(si)
    with np.errstate(over="ignore"):  # an overflow is the error below, not a warning
        columns = [_from_si(np.asarray(getattr(data, k), dtype=np.float64), unit_of[k])
                   for k in keys]
    for key, column in zip(keys, columns):
        bad = np.nonzero(~np.isfinite(column))[0]
        if bad.size:  # finite in SI (an Experiment is) but too large in display units
            raise ValueError(
                f"channel {key!r} sample {bad[0]} is {float(getattr(data, key)[bad[0]])!r} in SI, "
                f"which is not finite in {unit_of[key]}; write it with units=SIUnits()."
            )
        found = _beyond(key, getattr(data, key)) if key in _PLAUSIBLE else None
        if found is not None:  # saving refuses what reading would (issue 72)
            i, value, range_ = found
            raise ValueError(f"channel {key!r} sample {i} is {value}, beyond {range_}: "
                             "read_trial_csv would refuse the file, so it is not written.")
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow([f"{k} [{unit_of[k]}]" for k in keys])
        for row in zip(*columns):
            writer.writerow([repr(float(value)) for value in row])


# ---------------------------------------------------------------------------------------
# Readers for the measured data sets in shared/data
