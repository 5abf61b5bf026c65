"""Splitting a batch axis across devices with JAX's own sharding.

A one-axis `jax.sharding.Mesh` over the devices (all of `jax.devices()` by default: the
local CPU or GPUs, or every host's devices after `jax.distributed.initialize()`) and
`jax.shard_map` over it. XLA shards only evenly, so a batch is padded to a multiple of the
device count by repeating its last entry (a valid, finite run) and trimmed afterwards.
With one device everything is a plain `jax.vmap`. A mesh that spans several processes
(`jax.distributed.initialize`) hands every process the whole result (`gathered`).
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P


AXIS = "batch"  # name of the mesh axis a batch is split over


def batch_mesh(devices=None) -> Mesh | None:
    """A one-axis mesh over `devices` (default all), or None for a single device."""
    devices = tuple(jax.devices() if devices is None else devices)
    return Mesh(np.array(devices), (AXIS,)) if len(devices) > 1 else None


def gathered(tree, mesh: Mesh | None):
    """`tree` (inside `jit`) replicated on every device of `mesh` where the mesh spans
    several processes, so that each process can read the whole result; else as it is
    (a result that stays split keeps large batches off any one device)."""
    if mesh is None or len({d.process_index for d in mesh.devices.flat}) == 1:
        return tree
    return jax.lax.with_sharding_constraint(tree, NamedSharding(mesh, P()))


def pad_batch(tree, size: int, padded: int):
    """Pad the leading axis of every leaf from `size` to `padded` by repeating the last entry."""
    if padded == size:
        return tree
    return jax.tree.map(
        lambda a: jnp.concatenate([a, jnp.repeat(a[-1:], padded - size, axis=0)]), tree
    )


def sharded_vmap(f, *args, batch_dims: int = 1):
    """`f` mapped over the leading `batch_dims` axes of every leaf of `args` (a nested
    `jax.vmap`), those axes flattened into one batch that is split across all devices.
    Values `f` closes over are replicated. Same numbers on any number of devices."""
    leaves = jax.tree.leaves(args)
    lead = leaves[0].shape[:batch_dims]
    size = int(np.prod(lead))
    flat = jax.tree.map(lambda a: jnp.reshape(a, (size,) + a.shape[batch_dims:]), args)
    mesh = batch_mesh()
    if mesh is None:
        out = jax.vmap(f)(*flat)
    else:
        padded = -(-size // mesh.devices.size) * mesh.devices.size
        out = jax.shard_map(jax.vmap(f), mesh=mesh, in_specs=P(AXIS), out_specs=P(AXIS),
                            check_vma=False)(*pad_batch(flat, size, padded))
        out = jax.tree.map(lambda a: a[:size], gathered(out, mesh))
    return jax.tree.map(lambda a: jnp.reshape(a, lead + a.shape[1:]), out)
