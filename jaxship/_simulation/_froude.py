"""Froude scaling: a vessel, a trajectory or a record at another size, the Froude
number $U/\\sqrt{gL}$ kept (ITTC 7.5-02-06-01 sec. 2; Lewis 1989, PNA vol. III ch. 9).

With the length ratio $\\lambda = L_{new}/L_{old}$ and the same water density, a
quantity of dimension $\\mathrm{kg}^a\\,\\mathrm{m}^b\\,\\mathrm{s}^c$ scales by
$\\lambda^{3a + b + c/2}$: lengths by $\\lambda$, times by $\\sqrt\\lambda$, speeds by
$\\sqrt\\lambda$, rates (yaw rate, propeller rate) by $1/\\sqrt\\lambda$, masses and
forces by $\\lambda^3$, moments by $\\lambda^4$; angles and non-dimensional coefficients
stay. A vessel's factors come from the units of its `param` fields and of its wind
model's (`FujiwaraWindLoads`' geometry); its rudder servo and shaft scale as the rates
and time constants they are. Reynolds-number effects (friction)
do not scale this way: jaxship's models have none, so a scaled model is exactly similar.
"""

import dataclasses
import math
import re

import equinox as eqx
import numpy as np

from .._foundation._contract import AbstractComposite, parameter_fields
from .._foundation._state import STATE_FIELDS, Command, ShipState, Trajectory
from .._models._actuators import RudderServo, Shaft
from .._models._effects import family_unit
from .._models._vessel._base import AbstractVessel
from ._data import Experiment


# Froude exponent of each base unit (kg^3, m^1, s^(1/2)); rad, rev and "-" have none
_EXPONENT = {"kg": 3.0, "m": 1.0, "s": 0.5, "N": 3.0, "rad": 0.0, "rev": 0.0, "deg": 0.0,
             "-": 0.0, "1": 0.0}
_TOKEN = re.compile(r"^([A-Za-z-]+|1)(?:\^(-?\d+(?:\.\d+)?))?$")
# the channels of a record and the state of a trajectory: their units
CHANNEL_UNITS = {"t": "s", "delta": "rad", "delta_c": "rad", "psi": "rad", "r": "rad/s",
                 "u": "m/s", "v": "m/s", "x": "m", "y": "m", "n": "rev/s",
                 "wind_speed": "m/s", "wind_dir": "rad"}


def froude_exponent(unit: str) -> float:
    """The power of $\\lambda$ by which a quantity in `unit` (e.g. `"kg m^2"`,
    `"kg s/m^2"`, `"rev/s"`, `"-"`) scales; `ValueError` for a unit it cannot read."""
    text = unit.strip()
    if not text:
        raise ValueError("an empty unit cannot be Froude-scaled.")
    numerator, _, denominator = text.partition("/")
    total = 0.0
    for sign, part in ((1.0, numerator), (-1.0, denominator)):
        for token in part.split():
            match = _TOKEN.match(token)
            if not match or match.group(1) not in _EXPONENT:
                raise ValueError(f"unit {unit!r}: cannot Froude-scale {token!r}.")
            total += sign * _EXPONENT[match.group(1)] * float(match.group(2) or 1.0)
    return total


def _scaled_fields(module, factor_of):
    """`module` with each of its `param` fields multiplied by `factor_of(unit)`."""
    fields = parameter_fields(module)
    names = tuple(fields)
    values = tuple(getattr(module, n) * factor_of(fields[n].unit) for n in names)
    return eqx.tree_at(lambda m: tuple(getattr(m, n) for n in names), module, values)


def _scale_vessel(vessel, scale):
    base = vessel.base if isinstance(vessel, AbstractComposite) else vessel
    factor = lambda unit: scale ** froude_exponent(family_unit(unit, base))
    root = math.sqrt(scale)
    scaled = _scaled_fields(base, factor)
    scaled = eqx.tree_at(lambda v: (v.rudder, v.shaft, v.wind_model), scaled, (
        RudderServo(base.rudder.max_angle, base.rudder.max_rate / root,
                    base.rudder.time_constant * root),
        Shaft(base.shaft.max_rate / root, base.shaft.time_constant * root),
        _scaled_fields(base.wind_model, factor)))
    if not isinstance(vessel, AbstractComposite):
        return scaled
    effects = tuple(_scaled_fields(e, factor) for e in vessel.effects)
    return eqx.tree_at(lambda v: (v.base, v.effects), vessel, (scaled, effects))


def _scale_experiment(record: Experiment, scale, extra_units):
    unknown = sorted(set(record.extra) - set(extra_units))
    if unknown:
        raise ValueError(f"record {record.name!r}: the extra signals {', '.join(unknown)} "
                         "have no unit to scale them by; pass `extra_units={name: unit}`.")
    factor = lambda unit: scale ** froude_exponent(unit)
    given = {c: getattr(record, c) * factor(CHANNEL_UNITS[c])
             for c in ("t", "delta", *record.channels)}
    extra = {k: np.asarray(a) * factor(extra_units[k]) for k, a in record.extra.items()}
    metadata = dict(record.metadata)
    if "lpp" in metadata:
        metadata["lpp"] = float(metadata["lpp"]) * scale
    return Experiment(**given, name=record.name, metadata=tuple(metadata.items()),
                      extra=extra)


def _scale_state(state: ShipState, scale) -> ShipState:
    return ShipState(**{k: getattr(state, k) * scale ** froude_exponent(CHANNEL_UNITS[k])
                        for k in STATE_FIELDS})


def _scale_trajectory(traj: Trajectory, scale):
    root = math.sqrt(scale)
    c = traj.command  # slopes: [rad/s] by 1/sqrt(lambda), [rev/s^2] by 1/lambda
    command = Command(c.delta, c.n / root, None if c.delta_rate is None else c.delta_rate / root,
                      None if c.n_rate is None else c.n_rate / scale)
    return dataclasses.replace(traj, t=traj.t * root, state=_scale_state(traj.state, scale),
                               command=command)


def froude_scale(obj, scale: float, *, extra_units: dict | None = None):
    """`obj` at `scale` times its size, at the same Froude number (module text).

    **Arguments:** `obj`: a vessel (with or without effects), a `Trajectory`, an
    `Experiment` or a `ShipState`; `scale`: $\\lambda = L_{new}/L_{old}$, e.g. 320/7 from
    the 7 m KVLCC2 model to the ship, 7/320 back; `extra_units`: the units of a record's
    `extra` signals (`{name: unit}`), which are scaled with it.

    **Returns:** the same kind of object, scaled. `froude_scale(froude_scale(x, s), 1/s)`
    is `x` to rounding.

    **Raises:** `ValueError` for a non-positive scale, a unit it cannot read, or a
    record's extra signal without a unit.
    """
    scale = float(scale)
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"`scale` must be a positive number, got {scale}.")
    if isinstance(obj, AbstractVessel) or (isinstance(obj, AbstractComposite)
                                           and isinstance(obj.base, AbstractVessel)):
        return _scale_vessel(obj, scale)
    if isinstance(obj, Experiment):
        return _scale_experiment(obj, scale, extra_units or {})
    if isinstance(obj, Trajectory):
        return _scale_trajectory(obj, scale)
    if isinstance(obj, ShipState):
        return _scale_state(obj, scale)
    raise ValueError(f"cannot Froude-scale a {type(obj).__name__}; give a vessel, a "
                     "Trajectory, an Experiment or a ShipState.")
