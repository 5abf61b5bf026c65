"""The batching layer: many simulations in one compiled call, sharded over all devices.

`simulate_batch` vmaps `simulate` (a vessel's or a steering model's jitted body) over a
leading batch axis of any of its inputs and
splits that axis across the devices of a `jax.sharding.Mesh` with `jax.shard_map`
(`_sharding`; one device: plain vmap). Multi-host runs use the same code after
`jax.distributed.initialize()`; see `benchmarks/README.md`.
"""

from collections.abc import Callable, Sequence
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import PartitionSpec as P

from .._foundation._sharding import AXIS, batch_mesh, gathered, pad_batch
from .._foundation._state import Trajectory
from .._models._environment import Environment
from .._models._manoeuvres import Replay
from .._models._steering._base import AbstractSteeringModel
from .._models._vessel._base import straight_run
from ._integrate import RK4, WRITTEN_OUT_BATCH, Simulator
from ._simulate import _as_arrays, _is_static_zero, _simulate
from ._simulate_steering import _replay, _steer, at_rest


def stack(modules: Sequence) -> eqx.Module:
    """Stack modules of one structure (vessels, manoeuvres, states...) along a new leading axis.

    Numbers and arrays become arrays with a leading batch axis; everything else (static
    fields, `None`) must be equal across the modules. Manoeuvres of different durations
    stack when they share `num_samples` (pass it explicitly to pad them to one length).
    """
    modules = list(modules)
    if not modules:
        raise ValueError("`stack` needs at least one module.")
    leaves0, treedef = jax.tree.flatten(modules[0])
    for i, m in enumerate(modules[1:], start=1):
        if jax.tree.structure(m) != treedef:
            raise ValueError(
                f"module {i} differs in structure (type, static fields such as `num_samples`, "
                f"or which fields are None) from module 0:\n{jax.tree.structure(m)}\nvs\n{treedef}"
            )
    columns = zip(*(jax.tree.leaves(m) for m in modules))

    def stack_leaf(xs):
        if any(isinstance(x, jax.Array) for x in xs):
            return jnp.stack([jnp.asarray(x) for x in xs])
        if all(isinstance(x, (int, float, complex, np.ndarray, np.generic)) for x in xs):
            return np.stack([np.asarray(x) for x in xs])
        raise ValueError(f"cannot stack leaves of type {type(xs[0]).__name__}.")

    return jax.tree.unflatten(treedef, [stack_leaf(xs) for xs in columns])


def simulate_batch(
    model,
    manoeuvre,
    x0=None,
    *,
    environment: Environment = Environment(),
    simulator: Simulator = Simulator(),
    in_axes=(None, 0, 0, None),
    output: Callable | None = None,
    chunk_size: int | None = None,
    devices: Sequence | None = None,
):
    """Simulate a batch of runs in one compiled call, split across devices.

    **Arguments:**

    - `model`, `manoeuvre`, `x0`, `environment`, `simulator`: as for `simulate` (a
      vessel or a steering model; `x0=None`: a vessel's `straight_run`, which needs an
      unbatched vessel, or a steering model at rest); the batched ones carry a
      leading batch axis on their array leaves (build them with `stack`, or with
      arrays in place of numbers, e.g. `straight_state(speeds)`). A steering model
      takes no `aux` here: its replays run in calm water with zero speeds. With the
      default `RK4()`, a batch of 32 runs or more (`WRITTEN_OUT_BATCH`) takes its
      stages written out (see `RK4`).
    - `in_axes`: which of `(model, manoeuvre, x0, environment)` are batched: `0` for
      a leading batch axis, `None` for shared by all runs, as in `jax.vmap`; each entry
      may also be a pytree prefix of its argument (e.g. a vessel with `0` on some
      fields and `None` on the rest). The default batches the manoeuvre and the initial
      state, with one vessel in one environment. All batched leaves must share the
      batch size; 0-d leaves of a batched argument are shared by all runs (so
      `ZigZag(angles, 20 * DEG, duration=600.0)` batches the angle only).
    - `output`: optional function of one run's `Trajectory` returning what to keep
      (e.g. `batch_turning_indices`); computed inside the compiled call, so the full
      trajectories of a large sweep need never leave it.
    - `chunk_size`: simulate at most this many runs at a time on each device
      (`jax.lax.map` with `batch_size`), to bound the memory of large batches; `None`
      runs each device's share at once.
    - `devices`: the devices to split the batch over (default: `jax.devices()`, all
      devices of all processes). The batch is padded to a multiple of their number by
      repeating the last run, and the padding trimmed from the result.

    **Returns:** the `Trajectory` (or `output`) of every run, with the batch axis in front.

    Values never trigger recompilation; the batch size, the shapes and the static
    structure (manoeuvre type, `num_samples`, `simulator`) do.
    """
    if not (isinstance(in_axes, tuple) and len(in_axes) == 4):
        raise ValueError("`in_axes` must be a 4-tuple for (model, manoeuvre, x0, environment).")
    if x0 is None and isinstance(model, AbstractSteeringModel):
        x0 = at_rest()
    elif x0 is None:
        if in_axes[0] is not None:
            raise ValueError("a batch of vessels needs its initial states `x0` (e.g. "
                             "`straight_run` of arrays).")
        x0 = straight_run(model)
    wind = not _is_static_zero(getattr(getattr(environment, "wind", None), "speed", None))
    batched, shared, size = _split_batch(in_axes,
                                         _as_arrays((model, manoeuvre, x0, environment)))
    mesh = batch_mesh(devices)
    b_dyn, b_static = eqx.partition(batched, eqx.is_array)
    s_dyn, s_static = eqx.partition(shared, eqx.is_array)
    if isinstance(simulator.solver, RK4) and simulator.solver.rolled is None \
            and size >= WRITTEN_OUT_BATCH:
        simulator = eqx.tree_at(lambda s: s.solver, simulator, RK4(rolled=False))
    steps = simulator.steps_per_sample(manoeuvre.dt)
    return _batched(b_dyn, s_dyn, b_static, s_static, _Runs(simulator, steps, output, wind),
                    _Spread(size, mesh, chunk_size))


def _split_batch(in_axes, args):
    """`(batched, shared, size)`: the leaves of `args` (model, manoeuvre, x0, environment)
    with a batch axis by `in_axes` (None elsewhere), the shared ones (None where
    batched), and the batch size they agree on; `ValueError` if none is batched or their
    sizes differ."""
    names = ("model", "manoeuvre", "x0", "environment")
    axes = tuple(_resolve_axes(a, arg, name) for a, arg, name in zip(in_axes, args, names))
    is_none = lambda x: x is None
    # a 0-d leaf cannot carry a batch axis: it is shared even inside a batched argument
    axes = jax.tree.map(
        lambda ax, x: None if np.ndim(x) == 0 else ax, axes, args, is_leaf=is_none
    )
    batched = jax.tree.map(lambda ax, x: x if ax == 0 else None, axes, args, is_leaf=is_none)
    shared = jax.tree.map(lambda ax, x: None if ax == 0 else x, axes, args, is_leaf=is_none)
    sizes = {np.shape(leaf)[0] for leaf in jax.tree.leaves(batched)}
    if not sizes:
        raise ValueError("nothing is batched: set an entry of `in_axes` to 0.")
    if len(sizes) > 1:
        detail = {
            name: sorted({np.shape(x)[0] for x in jax.tree.leaves(b)})
            for name, b in zip(names, batched)
            if jax.tree.leaves(b)
        }
        raise ValueError(f"batched inputs disagree on the batch size: {detail}.")
    return batched, shared, sizes.pop()


def _resolve_axes(prefix, tree, name):
    """Per-leaf batch axes (0 or None) from a `vmap`-style prefix."""
    def broadcast(ax, sub):
        if ax not in (0, None):
            raise ValueError(f"`in_axes` for {name} may only hold 0 or None, got {ax!r}.")
        return jax.tree.map(lambda _: ax, sub)

    try:
        return jax.tree.map(broadcast, prefix, tree, is_leaf=lambda x: x is None)
    except ValueError as e:
        raise ValueError(f"`in_axes` for {name} is not a prefix of it: {e}") from None


class _Runs(NamedTuple):
    """How each run is simulated: the simulator, its steps per sample, the `output`
    applied to each trajectory (or None) and whether the wind loads are on."""

    simulator: Simulator
    steps: int
    output: Callable | None
    wind: bool


class _Spread(NamedTuple):
    """How the batch is spread: its `size`, the device `mesh` (None: one device) and the
    `chunk_size` of `lax.map` (None: all runs of a device vmapped at once)."""

    size: int
    mesh: object
    chunk_size: int | None


@eqx.filter_jit
def _batched(b_dyn, s_dyn, b_static, s_static, runs: _Runs, spread: _Spread):
    """The batched runs (`b_dyn`, `b_static`: the batched leaves' arrays and the rest;
    `s_dyn`, `s_static`: the shared ones), vmapped or mapped in chunks on each device of
    the mesh."""
    simulator, steps, output, wind = runs
    size, mesh, chunk_size = spread

    def one(b, s):
        model, manoeuvre, x0, environment = eqx.combine(b, b_static, s, s_static)
        if isinstance(model, AbstractSteeringModel) and isinstance(manoeuvre, Replay):
            traj = _replay.__wrapped__(model, manoeuvre, x0, None, simulator, steps)
        elif isinstance(model, AbstractSteeringModel):
            traj = _steer.__wrapped__(model, manoeuvre, x0, simulator, steps)
        else:
            traj = _simulate.__wrapped__(
                model, manoeuvre, x0, environment, simulator, steps, wind=wind, per_field=True
            )
        return traj if output is None else output(traj)

    def local(b, s):  # the runs of one device (all runs without a mesh)
        if chunk_size is None:
            return jax.vmap(one, in_axes=(0, None))(b, s)
        return jax.lax.map(lambda bi: one(bi, s), b, batch_size=chunk_size)

    if mesh is None:
        return local(b_dyn, s_dyn)
    count = mesh.devices.size
    padded = -(-size // count) * count
    out = jax.shard_map(
        local, mesh=mesh, in_specs=(P(AXIS), P()), out_specs=P(AXIS), check_vma=False
    )(pad_batch(b_dyn, size, padded), s_dyn)
    out = gathered(out, mesh)  # several processes: each gets the whole result
    # trimming the padding gathers the result (XLA shards only evenly): choose batch
    # sizes divisible by the device count to keep large outputs split over the devices
    return out if padded == size else jax.tree.map(lambda a: a[:size], out)


# --------------------------------------------------------------------------- indices


def batch_turning_indices(traj: Trajectory) -> dict:
    """Advance, transfer, tactical diameter and more of turning circles, in JAX.

    The jit- and vmap-friendly counterpart of `jaxship.indices.turning_indices` (same
    definitions: rudder order at the first sample whose rudder command leaves the
    initial rudder angle, positions rotated into the course frame there, 90 and 180 deg
    heading change located by linear interpolation between samples; steady diameter
    $2U/|r|$ and speed loss from the last valid sample). Works on any leading batch axes;
    indices that are not reached are NaN. Returns a dict of arrays in SI units:
    `advance`, `transfer`, `tactical_diameter`, `steady_turning_diameter` [m],
    `time_to_90`, `time_to_180`, `execute_time` [s], `speed_loss` [-].
    """
    s, t = traj.state, jnp.broadcast_to(traj.t, traj.state.psi.shape)
    take = lambda a, i: jnp.take_along_axis(a, i[..., None], axis=-1)[..., 0]
    num = s.psi.shape[-1]
    valid = traj.valid & jnp.isfinite(s.psi)
    moved = (jnp.abs(traj.command.delta - s.delta[..., :1]) > 1e-9) & valid
    i_e = jnp.argmax(moved, axis=-1)
    i_last = jnp.sum(valid, axis=-1) - 1
    psi_e, t_e = take(s.psi, i_e), take(t, i_e)
    c, sn = jnp.cos(psi_e)[..., None], jnp.sin(psi_e)[..., None]
    dx, dy = s.x - take(s.x, i_e)[..., None], s.y - take(s.y, i_e)[..., None]
    along, athwart = c * dx + sn * dy, -sn * dx + c * dy
    change = s.psi - psi_e[..., None]
    side = jnp.sign(take(change, i_last))
    h = side[..., None] * change
    after = (jnp.arange(num) >= i_e[..., None]) & valid

    def at_heading(level):
        hit = (h >= level) & after
        j = jnp.argmax(hit, axis=-1)
        jm = jnp.maximum(j - 1, 0)
        h0, h1 = take(h, jm), take(h, j)
        w = jnp.where(j > i_e, (level - h0) / jnp.where(h1 > h0, h1 - h0, 1.0), 1.0)
        found = jnp.any(hit, axis=-1) & (side != 0)
        return lambda a: jnp.where(found, take(a, jm) + w * (take(a, j) - take(a, jm)), jnp.nan)

    at90, at180 = at_heading(jnp.pi / 2), at_heading(jnp.pi)
    speed = jnp.hypot(s.u, s.v)
    u_end, r_end = take(speed, i_last), take(s.r, i_last)
    return dict(
        advance=at90(along),
        transfer=side * at90(athwart),
        tactical_diameter=side * at180(athwart),
        steady_turning_diameter=2 * u_end / jnp.abs(r_end),
        speed_loss=1 - u_end / take(speed, i_e),
        time_to_90=at90(t) - t_e,
        time_to_180=at180(t) - t_e,
        execute_time=t_e,
    )
