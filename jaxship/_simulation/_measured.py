"""Readers of the measured data sets (Esso Osaka FRT, HSVA and MARIN KVLCC2 SIMMAN
2008) and `read_measured`, which recognises any supported file; all return
`jaxship.Experiment` in SI units and jaxship's sign convention. The trial CSV format
and the shared parsing helpers are in `_readers.py`."""

import csv
import itertools
import math
import os
import re
from pathlib import Path

import numpy as np

from .._foundation._schema import UTF16_MARKS, check_path, not_text
from ._consistency import unwrap_heading
from ._data import OVER_GROUND, Experiment
from ._readers import (
    _HEADER,
    _check_delimiter,
    _check_rows,
    _check_time,
    _open_text,
    _parse_numbers,
    _read_csv,
    _split_header,
    read_trial_csv,
)


KVLCC2_SCALE = 45.714  # lambda [-], INSEAN model 2487 (SIMMAN 2008)
MARIN_DT = 0.13526  # full-scale sample interval [s] of the MARIN files (50 Hz model scale)

def shared_data_dir() -> Path | None:
    """The measured-data folder: `$JAXSHIP_DATA` if that variable is set (None if it
    does not exist), else the first `shared/data` beside the working directory or one of
    its parents (so `../shared/data` is found from the repository and from
    `notebooks/`, whether jaxship is installed editable or not), else beside the
    source tree; None when absent (tests and notebooks skip on None, except under CI)."""
    env = os.environ.get("JAXSHIP_DATA")
    if env:
        path = Path(env).expanduser()
        return path if path.is_dir() else None
    cwd = Path.cwd().resolve()
    for folder in (cwd, *cwd.parents, Path(__file__).resolve().parents[2]):
        path = folder / "shared" / "data"
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
    (positive delta gives positive r). u, v are over ground (derived from the GNSS
    receiver's track, UPSTREAM_README: the model logs no speed through the water).
    The heading `psi_hat` is wrapped to [-pi, pi] in the files (the README's "not
    wrapped" is wrong: every turning run jumps by 2 pi); it is unwrapped here
    (`unwrap_heading`). x, y are the pond's
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
    data, lines = _parse_numbers(path, headers, records)
    _check_time(path, headers[columns["t"]], data[:, columns["t"]], lines, False, 0.0)
    values = {_ESSO_COLUMNS[k][0]: data[:, j] for k, j in columns.items()}
    values["psi"] = unwrap_heading(values["psi"])[0]  # wrapped to [-pi, pi] in the files
    extra = {k: values.pop(k) for k in ("wind_speed_relative", "wind_dir_relative") if k in values}
    return Experiment(
        name=path.stem, extra=extra, **values,
        metadata={
            "file": str(path), "format": "esso_osaka", "vessel": "Esso Osaka 3 m model",
            "source": "FRT-DS-ESSO, Osaka University (2020)", "scale": "model",
            "lpp": 3.0, "frame": "pond x0/y0 axes", "velocities": OVER_GROUND[1],
        },
    )


def _body_velocity(ue, ve, psi):
    """Body-fixed (u, v) of the earth-fixed velocity (dx/dt, dy/dt) at heading psi [rad]."""
    c, s = np.cos(psi), np.sin(psi)
    return ue * c + ve * s, -ue * s + ve * c


def _text_lines(path: Path, encoding: str):
    """Yield the lines of the text file `path` without their line ends; unreadable
    files and undecodable bytes are one-line `ValueError`s."""
    with _open_text(path, encoding) as f:
        try:
            for line in f:
                yield line.rstrip("\r\n")
        except UnicodeDecodeError:
            raise not_text(path, encoding) from None


def _numeric_lines(path, lines, first_line, ncol, split, layout):
    """Float table of whitespace- or tab-separated `lines` (an iterable, line numbers
    from `first_line`), blank lines skipped, and the line number of each row; errors
    name the file, column and row (`layout`: the expected columns, in words)."""
    def records():
        for offset, text in enumerate(lines):
            fields = split(text)
            if not any(map(str.strip, fields)):
                continue
            yield first_line + offset, fields

    headers = [f"column {j + 1}" for j in range(ncol)]
    return _parse_numbers(path, headers, records(), layout)


def _head(path, lines, count, test, what):
    """The first `count` lines of the iterator `lines`, checked by `test` on line 1."""
    head = list(itertools.islice(lines, count))
    if not head or not "".join(head).strip():
        raise ValueError(f"{path}: the file is empty; expected {what}.")
    if not test(head[0]):
        raise ValueError(f"{path}: not {what} (line 1 is {head[0].strip()[:40]!r}).")
    return head


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
    lines = _text_lines(path, "cp1252")
    text = _head(path, lines, 4, lambda line: "HSVA" in line,
                 "an HSVA file (line 1 names HSVA)")
    table, lines = _numeric_lines(
        path, lines, len(text) + 1, 12, str.split,
        "an HSVA record has 12 numbers separated by spaces (t, x0, y0, psi, dx0/dt, dy0/dt, "
        "r, -, delta, n, thrust, torque)")
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
            "lpp": 7.0, "velocities": OVER_GROUND[1],
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
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"`dt` must be a positive number of seconds, got {dt}.")
    lines = _text_lines(path, "latin-1")
    text = _head(path, lines, 2, lambda line: line.startswith("MARIN"),
                 "a MARIN file (line 1 starts with 'MARIN')")
    table, lines = _numeric_lines(
        path, lines, len(text) + 1, 11, lambda s: s.split("\t"),
        "a MARIN record has 11 numbers separated by tabs (t, x0, y0, phi, psi, dx0/dt, "
        "dy0/dt, p, r, delta, n)")
    _check_rows(path, table.shape[0])
    t_printed, x, y, phi, psi_deg, ue, ve, p, r_deg, delta_deg, rpm = table.T
    t = dt * np.arange(table.shape[0])
    quantum = 10.0 ** (np.floor(np.log10(np.maximum(np.abs(t_printed), 1e-300))) - 2)
    off = np.abs(t - t_printed) > quantum + 1e-9
    if np.any(off[1:]):
        k = int(np.nonzero(off[1:])[0][0]) + 1
        raise ValueError(
            f"{path}: column 1 (time), row {k + 1} (line {lines[k]}): printed time "
            f"{t_printed[k]} s does not match the reconstructed {t[k]:.3f} s = {k} * {dt} s "
            "(a row repeated, missing or out of order, or another sample interval `dt`)."
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
            "lambda": KVLCC2_SCALE, "lpp": 320.0 / scale, "velocities": OVER_GROUND[1],
            "title": text[1].strip() if len(text) > 1 else "",
        },
    )


def header_names(line: str) -> list[str]:
    """The channel names of a CSV header line (`name [unit]` fields, quoted or not)."""
    try:
        fields = next(csv.reader([line]), [])
    except csv.Error:  # not a CSV line (a stray carriage return): no names
        return []
    return [_HEADER.match(f).group(1) if _HEADER.match(f) else f.strip() for f in fields]


# file suffixes of measurement files in a folder (others, e.g. README.md, are not read)
DATA_SUFFIXES = (".csv", ".dat", ".txt")


def measurement_files(folder) -> tuple[list[Path], list[Path]]:
    """`(records, skipped)`: the files of `folder` (not its subfolders), in name order,
    with a `.csv`, `.dat` or `.txt` suffix, split into those whose first line
    `read_measured` recognises and the others (another format, such as a propeller
    open-water table; or not a regular file: a FIFO, a device, a broken link, never
    opened). A header of `name [unit]` fields separated by semicolons or tabs counts
    as a record, so that `read_measured` names its CSV dialect rather than a folder
    skipping it in silence. **Raises** `ValueError` for a file that cannot be read."""
    listed = [item for item in sorted(Path(folder).iterdir())
              if item.suffix.lower() in DATA_SUFFIXES and not item.is_dir()]
    records = [item for item in listed if item.is_file() and _recognised(item)]
    return records, [item for item in listed if item not in records]


def _recognised(path: Path) -> bool:
    """Whether the first line of `path` is one `read_measured` reads (or names the
    reason it cannot: UTF-16, a semicolon or tab dialect)."""
    try:
        with open(path, "rb") as f:
            raw = f.readline(4096)
    except OSError as error:
        raise ValueError(f"{path}: cannot read the file ({error.strerror or error}).") from None
    if raw.startswith(UTF16_MARKS) or b"\x00" in raw:
        return True
    first = raw.decode("latin-1").lstrip("\ufeff\xef\xbb\xbf").strip()
    if first.startswith(("MARIN", "HSVA")):
        return True
    if path.suffix.lower() == ".csv" or ("[" in first and "," in first):
        if set(header_names(first)) & {"t", "psi_hat", "delta_rudder"}:
            return True
    fields = re.split(r"[;\t]", first)
    return len(fields) > 1 and "," not in first and any(_HEADER.match(f) for f in fields)


def read_measured(path, **kwargs) -> Experiment:
    """Read any supported measurement file, recognised by extension and first line:
    MARIN (`.dat`, line 1 starts with 'MARIN') -> `read_marin_kvlcc2`; HSVA (line 1
    names HSVA) -> `read_hsva_kvlcc2`; a CSV with Esso Osaka headers (`psi_hat [rad]`)
    -> `read_esso_osaka`; any other CSV -> `read_trial_csv`. Keyword arguments go to
    the chosen reader."""
    path = check_path(path, "one measurement file")
    try:
        with open(path, "rb") as f:
            first, number = b"", 0
            while not first.strip():  # the first line with something on it
                first, number = f.readline(4096), number + 1
                if not first:
                    raise ValueError(f"{path}: the file is empty; expected a measurement file "
                                     "(trial CSV, Esso Osaka CSV, HSVA or MARIN .dat).")
    except OSError as error:
        raise ValueError(f"{path}: cannot read the file ({error.strerror or error}).") from None
    if first.lstrip(b"\n\r").startswith(UTF16_MARKS) or b"\x00" in first:  # with or without BOM
        raise ValueError(f"{path}: the file is UTF-16 text; save it as UTF-8 (or ASCII) text.")
    first = first.decode("latin-1").lstrip("\ufeff\xef\xbb\xbf").strip()
    suffix = path.suffix.lower()
    if first.startswith("MARIN"):
        return read_marin_kvlcc2(path, **kwargs)
    if first.startswith("HSVA"):
        return read_hsva_kvlcc2(path, **kwargs)
    if suffix == ".csv" or ("[" in first and "," in first):
        names = header_names(first)
        if "psi_hat" in names or "delta_rudder" in names:
            return read_esso_osaka(path, **kwargs)
        if "t" in names:
            return read_trial_csv(path, **kwargs)
    if "[" in first and "," not in first:
        _check_delimiter(path, number, [first])
    raise ValueError(
        f"{path}: unknown measurement format (first line {first[:60]!r}); supported: trial "
        "CSV ('t [s],delta [deg],...'), Esso Osaka FRT CSV, HSVA and MARIN KVLCC2 .dat files."
    )
