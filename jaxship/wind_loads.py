"""Wind-load models, the `wind_model` of a vessel (its wind areas scale them):

    import equinox as eqx
    import jaxship as js
    lab = eqx.tree_at(lambda v: v.wind_model, js.get_vessel("esso_osaka"),
                      js.wind_loads.FujiwaraWindLoads.esso_osaka())

`FossenWindLoads` (Fossen 2021, eq. 10.7-10.10, the default of every preset) and
`FujiwaraWindLoads` (Fujiwara, Ueno & Nimura 1998); `AbstractWindLoads` for one's own.
"""

from ._models._environment import (
    AbstractWindLoads as AbstractWindLoads,
    FossenWindLoads as FossenWindLoads,
)
from ._models._fujiwara_wind import FujiwaraWindLoads as FujiwaraWindLoads


__all__ = [
    # vessels: Wind loads
    "FossenWindLoads",
    "FujiwaraWindLoads",
    "AbstractWindLoads",
]
