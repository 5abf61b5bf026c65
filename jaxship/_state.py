"""Named simulation state and actuator commands (SI units, radians)."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike


class ShipState(eqx.Module):
    """Horizontal-plane state of a vessel, Fossen (2021) notation.

    Velocities are body-fixed at the vessel's reference point (midship for every
    catalogue vessel) and relative to the water; positions are earth-fixed
    (north-east), so with a current the track adds the current's drift.
    """

    u: ArrayLike  # surge velocity through water [m/s]
    v: ArrayLike  # sway velocity through water [m/s]
    r: ArrayLike  # yaw rate [rad/s], positive turning to starboard
    x: ArrayLike  # north position [m]
    y: ArrayLike  # east position [m]
    psi: ArrayLike  # heading [rad], not wrapped
    delta: ArrayLike  # actual rudder angle [rad], positive turns the ship to starboard
    n: ArrayLike  # actual propeller rate [rev/s]


def straight_state(u: ArrayLike, n: ArrayLike = 0.0, psi: ArrayLike = 0.0) -> ShipState:
    """Steady straight-ahead state at surge speed `u` [m/s] and propeller rate `n` [rev/s]."""
    zero = jnp.zeros_like(jnp.asarray(u, dtype=float))
    return ShipState(
        u=jnp.asarray(u, dtype=float),
        v=zero,
        r=zero,
        x=zero,
        y=zero,
        psi=zero + psi,
        delta=zero,
        n=zero + n,
    )


class Command(eqx.Module):
    """What the helm and engine are asked for, held constant over one sample interval."""

    delta: ArrayLike  # commanded rudder angle [rad]
    n: ArrayLike  # commanded propeller rate [rev/s]


def tree_axpy(a: ArrayLike, x, y):
    """Return `a * x + y` leaf by leaf for two pytrees of the same structure."""
    return jax.tree.map(lambda xi, yi: a * xi + yi, x, y)


class Trajectory(eqx.Module):
    """Result of `simulate`: states and commands at the sample times.

    `state.*` and `command.*` have shape `(num_samples,)` (plus any batch axes in
    front). `valid` marks samples inside the manoeuvre's duration (padding beyond it
    is simulated but should be ignored); `success` is False when the solver failed or
    a state became non-finite.
    """

    t: Array
    state: ShipState
    command: Command
    valid: Array
    success: Array

    @property
    def speed(self) -> Array:
        """Speed through water $U = \\sqrt{u^2 + v^2}$ [m/s]."""
        return jnp.hypot(self.state.u, self.state.v)
