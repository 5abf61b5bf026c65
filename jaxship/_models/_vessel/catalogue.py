"""The vessel catalogue: preset names, factories and their sources."""

import dataclasses
from collections.abc import Callable

from . import esso_osaka, mariner, mmg, nomoto, ross, sway_yaw


@dataclasses.dataclass(frozen=True)
class Preset:
    """A named preset: the factory that builds it."""

    factory: Callable

    @property
    def description(self) -> str:
        """First line of the factory's docstring (names the model and its source)."""
        return (self.factory.__doc__ or "").strip().splitlines()[0]


VESSELS = {
    "thesis": Preset(ross.thesis_vessel),
    "mariner": Preset(mariner.mariner),
    "kvlcc2": Preset(mmg.kvlcc2),
    "esso_osaka": Preset(esso_osaka.esso_osaka),
    "sea_stratus_linear": Preset(sway_yaw.sea_stratus_linear),
    "sea_stratus_nonlinear": Preset(sway_yaw.sea_stratus_nonlinear),
    "compass_island_linear": Preset(sway_yaw.compass_island_linear),
    "compass_island_nonlinear": Preset(sway_yaw.compass_island_nonlinear),
    "sea_swift": Preset(sway_yaw.sea_swift),
    "sea_scout": Preset(nomoto.sea_scout),
}


def get_vessel(name: str):
    """A fresh instance of the preset `name` (see `VESSELS`)."""
    key = name.strip().lower().replace("-", "_")
    if key not in VESSELS:
        raise ValueError(f"Unknown vessel {name!r}; choose one of: {', '.join(VESSELS)}.")
    return VESSELS[key].factory()
