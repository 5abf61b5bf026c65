"""Prediction-error identification of 3-DOF vessels (`fit` with an `AbstractVessel`).

The free parameters are scalar coefficient fields of the vessel, chosen by name
(vessels carry no `param` metadata): `fit(vessel, data, free=("y_uv", "n_ur"))` or
`free={"y_uv": Free(value=..., scale=...)}`; `free=None` takes the preset's default
set, `default_free(vessel)`. Each parameter's scale is its nominal magnitude
$|p_0|$; a coefficient that starts at zero gets the scale that makes its column of
the residual Jacobian as large as the median scaled column of the others (the
column scaling of MINPACK's `lmder`, More 1978, applied once at the start), unless
`Free(scale=...)` says otherwise.

Estimation replays the measured inputs (open loop, as for steering models): the
recorded rudder angle and propeller rate are held over each sample interval as the
*actual* rudder and propeller state (no servo or shaft dynamics: they are measured),
and optionally the measured true wind (`PredictionError(wind=True)`). With
`PredictionError(rudder="delta_c")` the recorded *command* is held instead and the
rudder angle follows the vessel's servo from its measured value at each window
start (this reproduces `jaxship.simulate` exactly at a constant propeller rate). Every
`horizon` seconds each experiment restarts from its measured state $(u, v, r, \\psi)$;
the positions x, y do not enter the forces of any catalogue vessel without current,
so they are neither integrated nor fitted. The state $(u, v, r, \\psi)$ is advanced by
the simulator's fast RK4 path (`Simulator._integrate`, `substeps` steps per sample)
and the residuals of the channels psi, r, u, v (weighted by 1/std of each measured
channel by default) are minimised by Levenberg-Marquardt with forward-mode Jacobians,
vmapped over the windows of all experiments (padded and masked). The covariance,
correlation and identifiability flags are those of the steering-model fit.
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._environment import Wind
from .._sharding import sharded_vmap
from .._simulate import Simulator
from .._vessel._base import AbstractVessel, inverse3
from ._lm import solve_least_squares
from ._params import Free, ParameterSpec, Transform, as_arrays, rebuild, select_free
from ._windows import Windows, as_dataset, build_windows, check_data


# state of the fit-time integration and where each fitted channel lives in it
_STATE = ("u", "v", "r", "psi")
_INDEX = {name: i for i, name in enumerate(_STATE)}

# default free coefficients per vessel class (names of float fields), used by
# `fit(vessel, data)` with `free=None` and by `jaxship identify --model PRESET`
_DEFAULT_FREE = {
    # thesis vessel: linear and cross-flow hull damping in sway and yaw, the surge
    # resistance and induced drag, and the rudder area (the rudder force scale;
    # lift slope and area enter only as a product, so only one is free)
    "RossVessel": ("x_uu", "x_vv", "y_uv", "y_ur", "y_absv_v", "y_absr_v", "n_uv", "n_ur",
                   "n_absv_r", "n_absr_r", "rudder_area"),
    # Esso Osaka low-speed MMG: the hull's linear derivatives and cross-flow drag, the
    # resistance ahead, and the rudder's inflow and flow-straightening factors
    "LowSpeedMMGVessel": ("x_0f", "y_v", "y_r", "n_v", "n_r", "c_d", "c_ry", "c_rn",
                          "epsilon", "gamma_n", "gamma_p"),
    # MMG standard method (KVLCC2): linear and cubic hull derivatives, resistance
    # and the rudder inflow factor
    "MMGVessel": ("r_0", "y_v", "y_r", "n_v", "n_r", "y_vvv", "n_rrr", "epsilon"),
    "Mariner": ("x_u", "y_v", "y_r", "n_v", "n_r", "y_d", "n_d"),
    "SwayYawVessel": ("y_v", "y_r", "n_v", "n_r", "y_delta", "n_delta"),
    "NomotoVessel": ("gain", "time_constant"),
}


def default_free(vessel: AbstractVessel) -> tuple[str, ...]:
    """The default free coefficients of `vessel`'s class (what `fit(vessel, data)`
    estimates with `free=None`). Raises `ValueError` for a class without defaults."""
    kind = type(vessel).__name__
    if kind not in _DEFAULT_FREE:
        raise ValueError(f"no default set of free coefficients for {kind}; pass `free=` with "
                         f"names of its coefficients: {', '.join(vessel_coefficients(vessel))}.")
    names = _DEFAULT_FREE[kind]
    return tuple(n for n in vessel_coefficients(vessel) if n in names)  # field order


def vessel_coefficients(vessel: AbstractVessel) -> dict[str, float]:
    """The scalar (float) fields of `vessel` with their values, in field order: the
    names `fit(vessel, ..., free=...)` accepts."""
    out = {}
    for f in dataclasses.fields(vessel):
        value = getattr(vessel, f.name, None)
        if isinstance(value, bool):
            continue
        if isinstance(value, (int, float, np.number)) or (
            isinstance(value, (np.ndarray, jax.Array)) and np.ndim(value) == 0
        ):
            out[f.name] = float(value)
    return out


def resolve_vessel_free(vessel: AbstractVessel, free=None) -> tuple[ParameterSpec, ...]:
    """`ParameterSpec`s of the free coefficients of `vessel` (see the module docstring).

    `free`: None (the class default), a sequence of field names or a dict
    `{name: Free(...) or None}`. A spec's scale of 0 marks "from the Jacobian"."""
    fields = vessel_coefficients(vessel)
    kind = type(vessel).__name__
    default = default_free(vessel) if free is None else ()
    chosen = select_free(free, default, fields, kind, "scalar coefficient")
    specs = []
    for name in fields:  # field order
        if name not in chosen:
            continue
        spec = chosen[name] or Free()
        if not isinstance(spec, Free):
            raise ValueError(f"`free[{name!r}]` must be a jaxship Free(...) spec or None, got "
                             f"{type(spec).__name__}.")
        start = fields[name] if spec.value is None else float(spec.value)
        lower = -math.inf if spec.lower is None else float(spec.lower)
        upper = math.inf if spec.upper is None else float(spec.upper)
        if not math.isfinite(start):
            raise ValueError(f"start value of {kind}.{name} is {start}; it must be finite.")
        if not lower < upper:
            raise ValueError(f"bounds of {kind}.{name}: lower {lower} must be below upper {upper}.")
        if not lower < start < upper:
            raise ValueError(f"start value {start!r} of {kind}.{name} must lie strictly inside "
                             f"its bounds ({lower}, {upper}).")
        if spec.scale is not None:
            scale = float(spec.scale)
            if not (scale > 0 and math.isfinite(scale)):
                raise ValueError(f"scale of {kind}.{name} must be positive and finite, got "
                                 f"{scale}.")
        elif math.isfinite(lower) and math.isfinite(upper):
            scale = upper - lower
        elif math.isfinite(lower) or math.isfinite(upper):
            scale = abs(start - (lower if math.isfinite(lower) else upper))
        else:
            scale = abs(start)  # 0: from the Jacobian
        specs.append(ParameterSpec(name, start, lower, upper, scale, ""))
    return tuple(specs)


# ------------------------------------------------------------------------- prediction


def _rhs(vessel, y, delta, n, mass_inverse, wind, servo):
    """d(u, v, r, psi)/dt with the rudder angle and propeller rate held (measured);
    with `servo`, d(u, v, r, psi, delta)/dt with `delta` the held rudder command and
    the actual angle y[4] following the vessel's rudder servo."""
    u, v, r, psi = y[0], y[1], y[2], y[3]
    command = delta
    if servo:
        delta = y[4]
    tau = vessel.forces(u, v, r, delta, n)
    if wind is not None:  # calm water otherwise; no current: ground = water velocity
        speed, direction = wind
        loads = Wind(speed=speed, direction=direction).loads(
            u, v, psi, vessel.frontal_wind_area, vessel.lateral_wind_area, vessel.length)
        tau = tau + jnp.stack(jnp.broadcast_arrays(*loads))
    nudot = mass_inverse[:, 0] * tau[0] + mass_inverse[:, 1] * tau[1] + mass_inverse[:, 2] * tau[2]
    out = [nudot[0], nudot[1], nudot[2], r]
    if servo:
        out.append(vessel.rudder.rate(delta, command))
    return jnp.stack(out)


class VesselInputs(eqx.Module):
    """Per-window arrays the vessel fit needs besides `Windows`: the start state
    `start` (E, W, 4) = (u, v, r, psi), or (E, W, 5) with the measured rudder angle
    when `servo` (the replayed rudder channel is the command `delta_c`), the held
    propeller rate `n` (E, W, L) and the measured true wind `(speed, direction)`
    (E, W, L) or None."""

    start: jax.Array
    n: jax.Array
    wind: tuple | None
    servo: bool = eqx.field(static=True, default=False)


def _predict(vessel, w: Windows, x: VesselInputs):
    """Model outputs (C, E, W, L) of every window, integrated by the fast RK4 path."""
    mass_inverse = inverse3(vessel.mass_matrix())  # once per evaluation
    simulator = Simulator(substeps=w.substeps)

    def one(y0, delta, n, wind, dt):
        def step(y, inputs):
            d, nn, wd = inputs
            y, _ = simulator._integrate(
                lambda z: _rhs(vessel, z, d, nn, mass_inverse, wd, x.servo), y, 0.0, dt)
            return y, y

        _, ys = jax.lax.scan(step, y0, (delta, n, wind))
        return ys  # (L, 4)

    ys = sharded_vmap(one, x.start, w.delta, x.n, x.wind, w.dt, batch_dims=2)
    return jnp.stack([ys[..., _INDEX[c]] for c in w.channels])


def _residuals(vessel, w, x):
    diff = w.weights[:, None, None, None] * (w.targets - _predict(vessel, w, x))
    return jnp.where(w.mask[None], diff, 0.0)


def _residual_fn(z, args):
    vessel, transform, w, x = args
    return _residuals(rebuild(vessel, transform.names, transform.to_physical(z)), w, x)


@eqx.filter_jit
def _solve(z0, vessel, transform, windows, inputs, solver, max_steps):
    """LM from z0; the estimate z, result, steps, physical parameters, predictions
    (C, E, W, L) and the Jacobian with respect to the physical parameters."""
    z, result, steps, p, residual, jac = solve_least_squares(
        _residual_fn, solver, z0, (vessel, transform, windows, inputs), max_steps,
        transform.to_physical)
    pred = windows.targets - residual / windows.weights[:, None, None, None]
    return z, result, steps, p, pred, jac


@eqx.filter_jit
def _jacobian(p, vessel, transform, windows, inputs):
    """Forward-mode Jacobian (C, E, W, L, d) of the weighted residuals with respect to
    the physical parameters p."""
    f = lambda q: _residuals(rebuild(vessel, transform.names, q), windows, inputs)
    return jax.jacfwd(f)(p)


# ------------------------------------------------------------------------------- data


def _vessel_inputs(ds, vessel, layout, wind: bool, rudder: str) -> VesselInputs:
    """Start states, held propeller rates and winds at the window samples."""
    target = layout["target"]
    num = ds.num_samples
    step = np.clip(target - 1, 0, num - 1)  # the sample whose inputs are held (E, W, L)
    start = step[..., 0]  # (E, W): window start samples (valid windows; clipped padding)
    rows = np.arange(ds.num_experiments)[:, None]
    rows3 = rows[..., None]
    get = lambda name: np.asarray(getattr(ds, name), dtype=np.float64)
    n = get("n").copy()
    for i in range(ds.num_experiments):
        if "n" not in ds.experiment_channels[i]:
            n[i] = float(vessel.nominal_n)
    f = lambda a: jnp.asarray(a, dtype=float)
    servo = rudder == "delta_c"
    names = _STATE + (("delta",) if servo else ())
    state = np.stack([get(c)[rows, start] for c in names], axis=-1)
    wind_arrays = None
    if wind:
        wind_arrays = (f(get("wind_speed")[rows3, step]), f(get("wind_dir")[rows3, step]))
    return VesselInputs(start=f(state), n=f(n[rows3, step]), wind=wind_arrays, servo=servo)


def _check_vessel_data(ds, estimator):
    for i, name in enumerate(ds.names):
        measured = ds.experiment_channels[i]
        missing = [c for c in ("u", "v") if c not in measured]
        if estimator.rudder == "delta_c" and "delta" not in measured:
            missing.append("delta")
        if missing:
            raise ValueError(
                f"experiment {name!r} (dataset entry {i}): no measured {missing[0]!r}; a vessel "
                "fit restarts every window from the measured state (u, v, r, psi; and the "
                "rudder angle when replaying the command 'delta_c'), so these must be "
                "measured (or fit a steering model instead).")
        if estimator.wind and not {"wind_speed", "wind_dir"} <= set(measured):
            raise ValueError(f"experiment {name!r} (dataset entry {i}): `wind=True` needs the "
                             "measured channels 'wind_speed' and 'wind_dir'.")


def fit_vessel(vessel: AbstractVessel, dataset, *, estimator, free=None, verbose=False):
    """`fit` for a 3-DOF vessel (see `jaxship.fit` and this module's docstring)."""
    from ._fit import _progress, _report

    ds = as_dataset(dataset)
    channels = ("psi", "r", "u", "v") if estimator.channels is None else tuple(
        estimator.channels)
    check_data(ds, estimator.rudder, channels)
    _check_vessel_data(ds, estimator)
    if int(estimator.substeps) < 1:
        raise ValueError(f"`substeps` must be a positive integer, got {estimator.substeps}.")
    if estimator.initial != "measured":
        raise ValueError("vessel fits restart every window from the measured state; "
                         f"`initial={estimator.initial!r}` is for steering models.")
    specs = resolve_vessel_free(vessel, free)
    windows, layout = build_windows(ds, horizon=estimator.horizon, channels=channels,
                                    weights=estimator.weights, rudder=estimator.rudder,
                                    substeps=int(estimator.substeps))
    inputs = _vessel_inputs(ds, vessel, layout, bool(estimator.wind), estimator.rudder)
    base = as_arrays(vessel)
    start = np.array([s.start for s in specs])

    # scales of coefficients that start at zero: from the Jacobian's column norms
    zero = np.array([s.scale == 0.0 for s in specs])
    if zero.any():
        provisional = [dataclasses.replace(s, scale=s.scale or 1.0) for s in specs]
        transform = Transform.from_specs(provisional)
        jac = _jacobian(jnp.asarray(start, dtype=float), base, transform, windows, inputs)
        norms = np.sqrt(np.sum(np.asarray(jac, dtype=np.float64).reshape(-1, len(specs)) ** 2,
                               axis=0))
        scaled = norms * np.array([s.scale for s in provisional])
        nonzero_start = np.array([s.start != 0.0 for s in specs])
        reference = np.median(scaled[nonzero_start]) if nonzero_start.any() else 1.0
        specs = tuple(
            dataclasses.replace(s, scale=float(reference / norms[i]) if norms[i] > 0 else 1.0)
            if zero[i] else s for i, s in enumerate(specs))
    transform = Transform.from_specs(specs)
    z0 = jnp.asarray(transform.to_unconstrained(start), dtype=float)
    solver = estimator.solver
    if verbose and hasattr(solver, "verbose"):
        solver = eqx.tree_at(lambda s: s.verbose, solver, verbose if callable(verbose)
                             else _progress)
    _, result, num_steps, p, pred, jac = _solve(z0, base, transform, windows, inputs, solver,
                                                int(estimator.max_steps))
    return _report(vessel, ds, estimator, specs, transform, windows, layout, p, pred, jac,
                   result, num_steps, verbose=verbose, stacklevel=4)
