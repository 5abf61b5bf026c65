"""Plausible size of effects whose parameters have family units (no one range holds
for a yaw moment in N m on a vessel and in rad/s on a Nomoto model): the effect's
loads expressed as the rudder angle that gives the same loads, a ship-independent
measure (a constant yaw moment on a Nomoto model is exactly a rudder offset $N_0/K$).
"""

import jax
import jax.numpy as jnp
import numpy as np

from ..._estimate._windows import apparent_wind
from ..._foundation._contract import parameter_fields, rebuild
from ..._models._steering._base import AbstractSteeringModel, AuxInputs


# SOLAS II-1/29.3.2: a main steering gear puts the rudder from 35 deg one side to 30 deg
# the other; 35 deg is hard over, the largest moment a rudder is built to give
HARD_OVER = float(np.radians(35.0))


def _zeroed(model, effect_id):
    """`model` with every parameter of the effect `effect_id` at zero (the base)."""
    effect = model.lookup(effect_id)
    names = tuple(f"{effect_id}.{k}" for k in parameter_fields(effect))
    return rebuild(model, names, jnp.zeros(len(names)))


def _samples(ds, wind: bool) -> dict:
    """The measured signals at every valid sample of dataset `ds`, flattened."""
    mask = np.asarray(ds.mask, dtype=bool)
    names = ("r", "delta", "u", "v", "n")
    out = {k: np.asarray(getattr(ds, k), dtype=float)[mask] for k in names}
    if wind:
        out |= {k: np.asarray(a, dtype=float)[mask] for k, a in apparent_wind(ds).items()}
    return out


def rudder_equivalent(model, effect_id: str, ds, wind: bool = False) -> float:
    """The rudder angle [rad] whose loads match those of the effect `effect_id` of
    `model` over the valid samples of dataset `ds` (measured states, the logged wind
    where `wind`): for every load the rudder acts on (a steering model's state
    equations, a vessel's sway force and yaw moment),
    $\\delta_{eq} = \\lVert f_e\\rVert / \\lVert\\partial f/\\partial\\delta\\rVert$,
    norms over the samples, $f_e$ the effect's share and $\\partial f/\\partial\\delta$
    the rudder's per radian with the effect (a propeller race that gives the rudder
    its force is then at most the rudder angle itself); the largest over the loads."""
    s = _samples(ds, wind)
    base = _zeroed(model, effect_id)
    if isinstance(model, AbstractSteeringModel):

        def loads(m, r, delta, u, v, n, wind_u=None, wind_v=None):
            return m.rhs(m.initial_state(r), delta, AuxInputs(u, v, n, wind_u, wind_v))
    else:

        def loads(m, r, delta, u, v, n, **_):
            return m.forces(u, v, r, delta, n)[1:]  # sway force and yaw moment

    def per_sample(x):
        share = loads(model, **x) - loads(base, **x)
        gain = jax.jvp(lambda d: loads(model, **(x | {"delta": d})), (x["delta"],),
                       (jnp.ones_like(x["delta"]),))[1]
        return share, gain

    share, gain = jax.vmap(per_sample)({k: jnp.asarray(v) for k, v in s.items()})
    share, gain = np.linalg.norm(share, axis=0), np.linalg.norm(gain, axis=0)
    acts = gain > 1e-9 * max(gain.max(), 1e-300)
    return float(np.max(share[acts] / gain[acts])) if acts.any() else float("inf")
