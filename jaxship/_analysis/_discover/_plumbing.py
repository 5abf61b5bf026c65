"""Small pieces the discovery search shares: a model's base and effects, an effect's
fitted parameter names, its estimates with their intervals, and the plausibility of
an estimate's size."""

import math

from ..._foundation._contract import AbstractComposite, parameter_fields, rebuild
from ..._models._effects import family_unit
from ._plausible import rudder_equivalent
from ._report import EffectParameter


def split(model):
    """(base, effects) of a model with or without effects."""
    if isinstance(model, AbstractComposite):
        return model.base, tuple(model.effects)
    return model, ()


def free_names(entry, effect) -> tuple[str, ...]:
    fields = parameter_fields(effect)
    return tuple(f"{entry.id}.{k}" for k, info in fields.items() if info.free)


def parameters(result, names) -> dict[str, EffectParameter]:
    """`{name: EffectParameter}` with the robust standard error (the white one where it
    was not computed) and the interval of `EffectParameter`, in the unit the parameter
    has on this base model."""
    index = {n: i for i, n in enumerate(result.names)}
    fields = parameter_fields(result.model)
    base = split(result.model)[0]
    robust = result.parameters.std_robust

    def std(i):
        s = float(robust[i]) if robust is not None else math.nan
        return s if math.isfinite(s) else float(result.parameters.std[i])

    return {n: EffectParameter.with_interval(float(result.values[index[n]]), std(index[n]),
                                             family_unit(fields[n].unit, base))
            for n in names}


def at_edge(result, names) -> tuple[str, ...]:
    """The parameters among `names` whose estimate is not strictly inside its plausible
    range: one pinned at a bound is where the data want it beyond the range (a range
    with two bounds is mapped by a sigmoid, which reaches a bound only in the limit: a
    pinned estimate stops within about 1e-6 of the span, so within 1e-3 counts)."""
    fields = parameter_fields(result.model)
    values = dict(zip(result.names, result.values))

    def inside(n):
        lower, upper = fields[n].lower, fields[n].upper
        edge = 1e-3 * (upper - lower) if math.isfinite(upper - lower) else -1e-12
        return lower + edge < values[n] < upper - edge

    return tuple(n for n in names if not inside(n))


def rudder_size(result, candidate, names, data, wind):
    """`(rudder-equivalent angle, its plausible limit)` [rad] of a candidate whose
    parameters have family units (no bounds) and a `rudder_range`; None for others
    (their parameters' own ranges apply)."""
    fields = parameter_fields(result.model)
    unbounded = all(math.isinf(fields[n].lower) and math.isinf(fields[n].upper) for n in names)
    if candidate.rudder_range is None or not unbounded:
        return None
    return rudder_equivalent(result.model, candidate.id, data, wind), candidate.rudder_range


def points_outside(model, names, step) -> bool:
    """Whether the score's Gauss-Newton step from zero leaves a parameter's plausible
    range (a one-sided parameter asked to go negative: no evidence for the effect)."""
    fields = parameter_fields(model)
    return any(fields[n].lower == 0.0 and d < 0 for n, d in zip(names, step))


def set_value(model, name, value):
    return rebuild(model, (name,), (float(value),))


def delta_bic(cost0, cost1, n, dof) -> float:
    """$\\Delta BIC = N\\ln(V_1/V_0) + k\\ln N$ (Gaussian errors, unknown variance;
    negative favours the effect)."""
    return float(n * math.log(max(cost1, 1e-300) / max(cost0, 1e-300)) + dof * math.log(n))
