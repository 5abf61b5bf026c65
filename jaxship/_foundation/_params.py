"""Parameter metadata (free/frozen, bounds, scale) and the map to the optimiser's
scaled, unconstrained space.

A model declares its estimable coefficients with `param(...)`, a thin wrapper of
`equinox.field` that stores the defaults (free or frozen, box bounds, scale) in the
field's metadata. `fit(..., free=...)` can override them with `Free(...)` specs.
The optimiser sees one unconstrained vector $z$; the physical value of parameter $i$
is

| bounds | map | inverse |
| --- | --- | --- |
| none | $p = s z$ | $z = p / s$ |
| lower $l$ | $p = l + s\\,\\mathrm{softplus}(z)$ | $z = \\mathrm{softplus}^{-1}((p - l)/s)$ |
| upper $h$ | $p = h - s\\,\\mathrm{softplus}(z)$ | |
| box $[l, h]$ | $p = l + (h - l)\\,\\sigma(z)$ | $z = \\mathrm{logit}((p - l)/(h - l))$ |

with the scale $s$ the parameter's nominal magnitude (by default its distance from
the bound at the start, or its start value, or 1), so that every $z$ is of order one
whatever the units (Ljung 1999, sec. 10.2 on scaling; dynax `boxed_field` and
dynamax `to_unconstrained` for the idea). The model is rebuilt with `eqx.tree_at`.

This module imports nothing from jaxship, so that model modules can use `param`.
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from ._contract import PARAMETER_KEY as _KEY, get_path, parameter_fields


UNBOUNDED, LOWER, UPPER, BOX = 0, 1, 2, 3


@dataclasses.dataclass(frozen=True)
class ParameterInfo:
    """Default estimation metadata of a model field (see `param`)."""

    free: bool = True
    lower: float = -math.inf
    upper: float = math.inf
    scale: float | None = None
    unit: str = ""


def param(default=dataclasses.MISSING, *, free: bool = True, lower: float = -math.inf,
          upper: float = math.inf, scale: float | None = None, unit: str = ""):
    """A model field that `fit` can estimate.

    **Arguments:**

    - `default`: default value (omit for a required field).
    - `free`: estimated by default (`True`) or held at its value (`False`).
    - `lower`, `upper`: bounds [field units]; the estimate stays strictly inside.
    - `scale`: nominal magnitude [field units] for the scaled optimisation variable;
      default: see `Free`.
    - `unit`: the unit, for tables.
    """
    info = ParameterInfo(bool(free), float(lower), float(upper), scale, unit)
    if default is dataclasses.MISSING:
        return eqx.field(metadata={_KEY: info})
    return eqx.field(default=default, metadata={_KEY: info})


@dataclasses.dataclass(frozen=True)
class Free:
    """Estimate a parameter: start `value` (default: the model's), `lower`/`upper`
    bounds and `scale` (default: the model field's `param` metadata, else no bounds
    and a scale of |start - bound| for one bound, |start| without bounds, or 1 if
    that is zero)."""

    value: float | None = None
    lower: float | None = None
    upper: float | None = None
    scale: float | None = None


def default_free(model) -> tuple[str, ...]:
    """The parameters `fit(model, data)` estimates with `free=None`, in field order."""
    names = tuple(n for n, info in parameter_fields(model).items() if info.free)
    if not names:
        raise ValueError(f"no default set of free parameters for {type(model).__name__}; pass "
                         f"`free=` with names of its coefficients: "
                         f"{', '.join(parameter_fields(model))}.")
    return names


@dataclasses.dataclass(frozen=True)
class ParameterSpec:
    """A resolved free parameter: name, start value, bounds, scale, unit."""

    name: str
    start: float
    lower: float
    upper: float
    scale: float
    unit: str

    @property
    def kind(self) -> int:
        lo, hi = math.isfinite(self.lower), math.isfinite(self.upper)
        return BOX if lo and hi else LOWER if lo else UPPER if hi else UNBOUNDED


def select_free(free, default, fields, kind: str, noun: str) -> dict:
    """`{name: Free or None}` chosen by `free` (None: the names `default`; a sequence
    of names; a dict), checked against `fields`, the valid names of `kind`'s `noun`s."""
    if free is None:
        chosen = {name: None for name in default}
    elif isinstance(free, str):
        raise ValueError(f"`free` must be a sequence of field names or a dict, got the "
                         f"string {free!r}; write free=({free!r},).")
    elif isinstance(free, dict):
        chosen = dict(free)
    else:
        chosen = {name: None for name in free}
    unknown = [name for name in chosen if name not in fields]
    if unknown:
        raise ValueError(f"`free` names {unknown[0]!r}, which is not a {noun} of {kind}; its "
                         f"{noun}s are {', '.join(fields)}.")
    if not chosen:
        raise ValueError(f"`free` selects no {noun} of {kind}; choose from {', '.join(fields)}.")
    return chosen


def resolve_free(model, free=None) -> tuple[ParameterSpec, ...]:
    """The free parameters of `model` for `fit(..., free=free)`.

    `free` is `None` (the fields declared `param(free=True)`, or a vessel's
    `param(free=True)`), a sequence of field names, or a dict `{name: Free(...) or
    None}` (None: the field's defaults). A scale of 0 (an unbounded parameter that
    starts at zero, with no scale given) means "from the Jacobian": `fit` sets it.
    Raises `ValueError` for unknown names, start values outside the bounds and
    empty selections.
    """
    fields = parameter_fields(model)
    kind = type(model).__name__
    chosen = select_free(free, default_free(model) if free is None else (), fields, kind,
                         "parameter")
    specs = []
    for name in fields:  # field order, whatever the order of `free`
        if name not in chosen:
            continue
        info, override = fields[name], chosen[name]
        if override is not None and not isinstance(override, Free):
            raise ValueError(
                f"`free[{name!r}]` must be a jaxship Free(...) spec or None, got "
                f"{type(override).__name__}."
            )
        override = override or Free()
        start = override.value if override.value is not None else get_path(model, name)
        try:
            start = float(start)
        except (TypeError, ValueError):
            raise ValueError(f"{kind}.{name} must be a scalar to be estimated, got {start!r}.") \
                from None
        lower = info.lower if override.lower is None else float(override.lower)
        upper = info.upper if override.upper is None else float(override.upper)
        if not math.isfinite(start):
            raise ValueError(f"start value of {kind}.{name} is {start}; it must be finite.")
        if not lower < upper:
            raise ValueError(f"bounds of {kind}.{name}: lower {lower} must be below upper {upper}.")
        if not lower < start < upper:
            raise ValueError(
                f"start value {start!r} of {kind}.{name} must lie strictly inside its bounds "
                f"({lower}, {upper}); pass free={{{name!r}: Free(value=...)}} or change the model."
            )
        scale = override.scale if override.scale is not None else info.scale
        if scale is None:
            if math.isfinite(lower) and math.isfinite(upper):
                scale = upper - lower
            elif math.isfinite(lower):
                scale = start - lower
            elif math.isfinite(upper):
                scale = upper - start
            else:
                scale = abs(start)  # 0: from the Jacobian (`fit`)
        given = override.scale is not None or info.scale is not None
        scale = float(scale)
        if not (math.isfinite(scale) and (scale > 0 or scale == 0 and not given)):
            raise ValueError(f"scale of {kind}.{name} must be positive and finite, got {scale}.")
        specs.append(ParameterSpec(name, start, lower, upper, scale, info.unit))
    return tuple(specs)


def _softplus_inverse(x):
    return x + np.log(-np.expm1(-x))


class Transform(eqx.Module):
    """Map between the optimiser's unconstrained vector $z$ and the physical values
    $p$ of the free parameters (table in the module docstring). Bounds and scales are
    arrays (traced: changing them does not recompile); the names and kinds are static."""

    names: tuple[str, ...] = eqx.field(static=True)
    kinds: tuple[int, ...] = eqx.field(static=True)
    lower: jax.Array
    upper: jax.Array
    scale: jax.Array

    @classmethod
    def from_specs(cls, specs) -> "Transform":
        finite = lambda a: np.where(np.isfinite(a), a, 0.0)  # unused entries: 0, not inf
        return cls(
            names=tuple(s.name for s in specs),
            kinds=tuple(s.kind for s in specs),
            lower=jnp.asarray(finite(np.array([s.lower for s in specs], dtype=float))),
            upper=jnp.asarray(finite(np.array([s.upper for s in specs], dtype=float))),
            scale=jnp.asarray(np.array([s.scale for s in specs], dtype=float)),
        )

    def to_physical(self, z):
        out = []
        for i, kind in enumerate(self.kinds):
            lo, hi, s, zi = self.lower[i], self.upper[i], self.scale[i], z[i]
            if kind == UNBOUNDED:
                out.append(s * zi)
            elif kind == LOWER:
                out.append(lo + s * jax.nn.softplus(zi))
            elif kind == UPPER:
                out.append(hi - s * jax.nn.softplus(zi))
            else:
                out.append(lo + (hi - lo) * jax.nn.sigmoid(zi))
        return jnp.stack(out) if out else jnp.zeros((0,), jnp.result_type(z, float))

    def to_unconstrained(self, p) -> np.ndarray:
        """Host-side inverse map (NumPy, float64)."""
        p = np.asarray(p, dtype=np.float64)
        lower, upper = np.asarray(self.lower, float), np.asarray(self.upper, float)
        scale = np.asarray(self.scale, float)
        z = np.empty_like(p)
        for i, kind in enumerate(self.kinds):
            if kind == UNBOUNDED:
                z[i] = p[i] / scale[i]
            elif kind == LOWER:
                z[i] = _softplus_inverse((p[i] - lower[i]) / scale[i])
            elif kind == UPPER:
                z[i] = _softplus_inverse((upper[i] - p[i]) / scale[i])
            else:
                q = (p[i] - lower[i]) / (upper[i] - lower[i])
                z[i] = np.log(q) - np.log1p(-q)
        return z


def as_arrays(tree):
    """Python numbers in a pytree become float arrays, so that jit traces them."""
    is_number = lambda x: isinstance(x, (float, int)) and not isinstance(x, bool)
    return jax.tree.map(lambda x: jnp.asarray(x, dtype=float) if is_number(x) else x, tree)
