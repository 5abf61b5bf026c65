"""Named simulation state and actuator commands (SI units, radians)."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ._frames import trajectory_to_dataframe
from ._results import RESULTS


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


# The order of `ShipState.to_vector`: the state travels through the integrator as one
# vector, far fewer (and larger) XLA operations per step than a pytree of eight scalars,
# which is what makes the fast path fast on CPU (see benchmarks/README.md).
STATE_FIELDS = ("u", "v", "r", "x", "y", "psi", "delta", "n")


def to_vector(state: "ShipState"):
    """The state as one vector in the order of `STATE_FIELDS`."""
    return jnp.stack([jnp.asarray(getattr(state, k), dtype=float) for k in STATE_FIELDS])


def from_vector(y) -> "ShipState":
    """The inverse of `to_vector` (also for arrays with the fields on the last axis)."""
    return ShipState(*(y[..., i] for i in range(len(STATE_FIELDS))))


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
    """What the helm and engine are asked for over one control step, from its start:
    $\\delta_c(t_k + \\tau) = \\delta + \\dot\\delta\\,\\tau$, likewise $n_c$. The slopes are
    zero for a held command (zero-order hold) and the record's slope for a replayed
    signal interpolated between samples (first-order hold)."""

    delta: ArrayLike  # commanded rudder angle [rad]
    n: ArrayLike  # commanded propeller rate [rev/s]
    delta_rate: ArrayLike | None = None  # slope of the rudder command [rad/s]; None: 0
    n_rate: ArrayLike | None = None  # slope of the propeller command [rev/s^2]; None: 0

    def at(self, tau: ArrayLike) -> "Command":
        """The command `tau` seconds after the start of the step (slopes kept)."""
        ramp = lambda value, rate: value if rate is None else value + rate * tau
        return Command(ramp(self.delta, self.delta_rate), ramp(self.n, self.n_rate),
                       self.delta_rate, self.n_rate)


class Switched(eqx.Module):
    """Inputs that change once inside a control step: `before` from its start to `at`
    seconds into it, `after` from there to its end (`at` >= the step: no change).
    `integrate` takes two solver steps split at `at`, so that a switch on an event
    predicted inside the step (a zig-zag's heading crossing) acts at the event, not at
    the nearest step boundary."""

    before: object
    after: object
    at: ArrayLike  # [s] into the step

    def at_start(self):
        """The inputs at the step's start (`after` where the switch is at the start)."""
        return jax.tree.map(lambda b, a: jnp.where(self.at > 0, b, a), self.before, self.after)


def tree_axpy(a: ArrayLike, x, y):
    """Return `a * x + y` leaf by leaf for two pytrees of the same structure."""
    return jax.tree.map(lambda xi, yi: a * xi + yi, x, y)


class Trajectory(eqx.Module):
    """Result of `simulate`: states and commands at the sample times, for a vessel or a
    steering model alike.

    `state.*` and `command.*` have shape `(num_samples,)` (plus any batch axes in
    front). `valid` marks samples inside the manoeuvre's duration (padding beyond it
    is simulated but should be ignored); `result` is the `RESULTS` code: `successful`,
    the code of the first failed solver step (diffrax's, passed through), or
    `simulation_blew_up` when a state became non-finite; `success` is `result ==
    successful` (an array for a batch). A steering model's trajectory has its heading, yaw
    rate and actual rudder in `state`, the replayed auxiliary inputs in `state.u`,
    `state.v`, `state.n` (zeros where none), no track (`state.x = state.y = 0`: a
    response model has no position), the ordered rudder in `command.delta`, and the
    model's own state vector in `internal`, shape `(num_samples, num_states)`
    (`None` for a vessel).
    """

    t: Array
    state: ShipState
    command: Command
    valid: Array
    result: RESULTS
    internal: Array | None = None

    @property
    def success(self) -> Array:
        return self.result == RESULTS.successful

    def to_dataframe(self):
        """One row per valid sample (pandas, an optional dependency): t, the state, and
        the commands `delta_c`, `n_c`. Index one run of a batch first."""
        return trajectory_to_dataframe(self)

    @property
    def speed(self) -> Array:
        """Speed through water $U = \\sqrt{u^2 + v^2}$ [m/s]."""
        return jnp.hypot(self.state.u, self.state.v)
