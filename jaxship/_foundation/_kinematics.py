"""Planar kinematics: angle wrapping and body-to-earth rotation (Fossen 2021, eq. 2.40)."""

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike


def ssa(angle: ArrayLike) -> Array:
    """Smallest signed angle: wrap `angle` [rad] to $[-\\pi, \\pi)$."""
    return (jnp.asarray(angle) + jnp.pi) % (2 * jnp.pi) - jnp.pi


def body_to_earth(u: ArrayLike, v: ArrayLike, psi: ArrayLike) -> tuple[Array, Array]:
    """North/east velocity of a body-fixed velocity `(u, v)` at heading `psi`.

    $\\dot x = u\\cos\\psi - v\\sin\\psi$, $\\dot y = u\\sin\\psi + v\\cos\\psi$.
    """
    c, s = jnp.cos(psi), jnp.sin(psi)
    return u * c - v * s, u * s + v * c


def earth_to_body(vn: ArrayLike, ve: ArrayLike, psi: ArrayLike) -> tuple[Array, Array]:
    """Body-fixed components of an earth-fixed (north, east) vector at heading `psi`."""
    c, s = jnp.cos(psi), jnp.sin(psi)
    return vn * c + ve * s, -vn * s + ve * c
