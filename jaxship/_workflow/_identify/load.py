"""`load_model`: one door from a name, a file or a saved identification to the model."""

from __future__ import annotations

import pathlib

import jaxship as js

from .result import Identification, model_from_report, read_result


def load_model(source):
    """The model that `source` names, for `identify`, `simulate`, `design_autopilot`:

    - a vessel preset's name (`jaxship.VESSELS`, case-insensitive, `-` or `_`):
      `get_vessel(name)`;
    - a vessel file (`.toml`, `save_vessel`'s): `load_vessel(path)`;
    - a saved identification: the `result.json` of `jaxship identify` or of
      `Identification.save` (a path, or a folder holding `result.json`), its parsed
      dict, or an `Identification`: its fitted model (every model kind, with its effects
      and wind model; `model_from_report`).

    **Raises** `ValueError` (one line) for a name that is no preset, a missing or bad
    file, or a report that is no identification."""
    if isinstance(source, Identification):
        return source.model
    if isinstance(source, dict):
        return model_from_report(source)
    if not isinstance(source, (str, pathlib.Path)):
        raise ValueError(f"load_model takes a preset name, a vessel file, a result.json or "
                         f"its dict, got {type(source).__name__}.")
    key = str(source).strip().lower().replace("-", "_")
    if isinstance(source, str) and key in js.VESSELS:
        return js.get_vessel(key)
    path = pathlib.Path(source)
    if path.suffix.lower() == ".toml":
        if not path.is_file():
            raise ValueError(f"{source}: no such vessel file.")
        return js.load_vessel(path)
    if path.suffix.lower() == ".json" or path.is_dir():
        return read_result(path)[0]
    raise ValueError(f"unknown model {str(source)!r}; give a preset ({', '.join(js.VESSELS)}), "
                     "a vessel file (.toml) or the result.json of an identification.")
