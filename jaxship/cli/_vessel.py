"""What `--vessel` names in every command: a preset, a vessel file (TOML) or the
`result.json` of `jaxship identify` (its fitted vessel or steering model): the model of
`jaxship.load_model`, with a label and the report."""

import dataclasses
import pathlib

from .. import VESSELS, AbstractVessel, load_model
from ..identification import read_report


VESSEL_HELP = ("a preset (see `jaxship vessels`), a vessel file (TOML; `jaxship vessels "
               "--show NAME` writes one to start from) or the result.json of `jaxship "
               "identify` (its fitted model)")


@dataclasses.dataclass(frozen=True)
class ChosenModel:
    """The model `--vessel` names: `model`; `name`, the registry name it is fitted as (a
    preset, `nomoto1`, ...; None for a vessel file's); `label`, for titles; `report`,
    the parsed result.json (None for a preset or a vessel file)."""

    model: object
    name: str | None
    label: str
    report: dict | None = None


def _preset(text: str) -> str | None:
    key = text.strip().lower().replace("-", "_")
    return key if key in VESSELS else None


def read_vessel_option(text: str, *, vessel_only: bool = False,
                       option: str = "--vessel") -> ChosenModel:
    """The model of `--vessel TEXT`; with `vessel_only` a steering model is refused
    (a command that needs a hull: its propeller, track, speed). **Raises** `ValueError`
    (one line) for a name that is none of the three forms or a file that is bad."""
    key = _preset(text)
    if key is not None:
        return ChosenModel(load_model(key), key, key)
    path = pathlib.Path(text)
    if path.suffix.lower() == ".toml":
        if not path.is_file():
            raise ValueError(f"{option} {text}: no such vessel file.")
        return ChosenModel(load_model(path), None, path.stem)
    if path.suffix.lower() == ".json" or path.is_dir():
        model = load_model(path)
        report = read_report(path)
        label = f"{report['model']} fitted ({path})"
        chosen = ChosenModel(model, str(report["model"]), label, report)
        if vessel_only and not isinstance(model, AbstractVessel):
            raise ValueError(f"{option} {text}: the result's model is a steering model "
                             f"({type(model).__name__}); this needs a vessel (a preset, a "
                             "vessel file or the result of identifying a vessel).")
        return chosen
    raise ValueError(f"Unknown vessel {text!r}; give a preset ({', '.join(VESSELS)}), a "
                     "vessel file (.toml) or the result.json of `jaxship identify`.")
