"""Response (autopilot) models: the interface and their simulation.

A steering model maps the rudder angle to the yaw rate with a few states; the heading
is the integral of the yaw rate. Unlike a vessel (`jaxship.AbstractVessel`) it has no
sway or surge dynamics of its own: measured speeds, when a model needs them, come in
as the auxiliary inputs `AuxInputs(u, v, n)` of the current sample.

Simulation replays sampled inputs with a zero-order hold (held over each sample
interval, as recorded data are) and integrates the model and the heading with
classic Runge-Kutta 4 in a `jax.lax.scan`: exact in forward and reverse mode, no
adaptive stepping, so Levenberg-Marquardt's forward-mode Jacobians are cheap.
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from .._estimate._params import as_arrays


class AuxInputs(eqx.Module):
    """Measured quantities a response model may use besides the rudder, held over the
    sample interval: surge `u` and sway `v` velocity [m/s] at midship (through the
    water) and the propeller rate `n` [rev/s]. Unused by the Nomoto models."""

    u: ArrayLike = 0.0
    v: ArrayLike = 0.0
    n: ArrayLike = 0.0


class WindowStart(eqx.Module):
    """What a record says at the first sample $t_s$ of a prediction window, for
    `AbstractSteeringModel.window_state`: the measured yaw rate `r` [rad/s] and
    heading `psi` [rad] there, the rudder `delta` [rad] held over the next
    interval, the auxiliary inputs `aux` there, and, from the start $t_0$ of the
    experiment, `r_first`, `psi_first`, the rudder integral
    `delta_integral` $= \\int_{t_0}^{t_s}\\delta\\,dt$ [rad s] (exact for the held
    rudder) and `elapsed` $= t_s - t_0$ [s]."""

    r: ArrayLike
    psi: ArrayLike
    delta: ArrayLike
    r_first: ArrayLike
    psi_first: ArrayLike
    delta_integral: ArrayLike
    elapsed: ArrayLike
    aux: AuxInputs


class AbstractSteeringModel(eqx.Module):
    """A response model $\\dot x = f(x, \\delta, a)$, $r = h(x)$, $\\dot\\psi = r$.

    Subclasses (final) declare their coefficients as fields with
    `jaxship.param` metadata (free/frozen default, bounds, scale, unit) and provide:

    - `state_names`: class variable, the names of the state entries; the first is
      always `"r"`;
    - `rhs(state, delta, aux)`: the continuous-time derivative of the state (1-D
      array) at rudder angle `delta` [rad] (positive turns to starboard) and the
      auxiliary inputs `aux` (`AuxInputs`);
    - `output(state)`: the yaw rate r [rad/s];
    - `initial_state(r)`: the state of a steady turn (or straight run, r = 0) at
      yaw rate `r`; simulations start from `initial_state(0.0)` by default;
    - `window_state(start)`: the state at the first sample of a prediction window,
      reconstructed from the record (`WindowStart`): the measured r for
      first-order models; hidden states from measured signals as each model
      documents.

    The model never integrates itself: `simulate_steering` and `fit` own the numerics.
    """

    state_names: eqx.AbstractClassVar[tuple[str, ...]]

    @abc.abstractmethod
    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        """Time derivative of `state` (same shape) at rudder `delta` [rad]."""

    @abc.abstractmethod
    def output(self, state: Array) -> Array:
        """Yaw rate r [rad/s] of `state`."""

    @abc.abstractmethod
    def initial_state(self, r: ArrayLike) -> Array:
        """The state of a steady turn at yaw rate `r` [rad/s]."""

    @abc.abstractmethod
    def window_state(self, start: WindowStart) -> Array:
        """The state at a window start, reconstructed from the record."""


def _rk4_interval(model, state, psi, delta, aux, dt, substeps):
    """Integrate (state, psi) over one sample interval with the inputs held."""
    h = dt / substeps

    def f(y):
        x, _ = y
        return model.rhs(x, delta, aux), model.output(x)

    def step(y, _):
        add = lambda a, k, c: jax.tree.map(lambda yi, ki: yi + c * ki, a, k)
        k1 = f(y)
        k2 = f(add(y, k1, h / 2))
        k3 = f(add(y, k2, h / 2))
        k4 = f(add(y, k3, h))
        incr = jax.tree.map(lambda a, b, c, d: (a + 2 * b + 2 * c + d) / 6, k1, k2, k3, k4)
        return add(y, incr, h), None

    (state, psi), _ = jax.lax.scan(step, (state, psi), None, length=substeps,
                                   unroll=substeps <= 8)
    return state, psi


def propagate(model: AbstractSteeringModel, state0, psi0, delta, aux: AuxInputs, dt,
              substeps: int = 1):
    """Predict the `L` samples after a start: `delta` and the `aux` leaves have shape
    `(L,)` (the inputs held over intervals 0..L-1); returns `(psi, r, states)` at the
    ends of the intervals, shapes `(L,)`, `(L,)`, `(L, num_states)`."""

    def step(carry, inputs):
        state, psi = carry
        d, a = inputs
        state, psi = _rk4_interval(model, state, psi, d, a, dt, substeps)
        return (state, psi), (psi, model.output(state), state)

    _, (psi, r, states) = jax.lax.scan(step, (state0, psi0), (delta, aux))
    return psi, r, states


class SteeringTrajectory(eqx.Module):
    """Result of `simulate_steering`: `t` [s], heading `psi` [rad], yaw rate `r`
    [rad/s], the model `state` (shape `(N, num_states)`) and the rudder angle `delta`
    [rad] at the N sample times (sample 0 is the initial state)."""

    t: Array
    psi: Array
    r: Array
    state: Array
    delta: Array


def simulate_steering(
    model: AbstractSteeringModel,
    delta: ArrayLike,
    dt: ArrayLike,
    *,
    state0: ArrayLike | None = None,
    psi0: ArrayLike = 0.0,
    aux: AuxInputs | None = None,
    start: ArrayLike = 0.0,
    substeps: int = 1,
) -> SteeringTrajectory:
    """Simulate a response model driven by sampled rudder angles.

    **Arguments:**

    - `model`: any `AbstractSteeringModel`.
    - `delta`: rudder angles [rad], shape `(N,)`; `delta[k]` is held over
      $[t_k, t_{k+1})$ (zero-order hold).
    - `dt`: sample interval [s].
    - `state0`: initial model state (default `model.initial_state(0.0)`: at rest).
    - `psi0`: initial heading [rad].
    - `aux`: `AuxInputs` with leaves of shape `(N,)` (or scalars), for models that
      use measured speeds; zeros by default.
    - `start`: time of sample 0 [s].
    - `substeps`: RK4 steps per sample interval (RK4 is stable for
      `dt / substeps` below about 2.8 times the smallest time constant).

    **Returns:** a `SteeringTrajectory` with N samples.

    Parameter values are traced: changing them does not recompile.
    """
    delta = jnp.asarray(delta, dtype=float)
    if delta.ndim != 1 or delta.shape[0] < 2:
        raise ValueError(f"`delta` must be a 1-D array of at least 2 samples, got shape "
                         f"{delta.shape}.")
    if int(substeps) < 1:
        raise ValueError(f"`substeps` must be a positive integer, got {substeps}.")
    num = delta.shape[0]
    aux = AuxInputs() if aux is None else aux
    aux = jax.tree.map(lambda a: jnp.broadcast_to(jnp.asarray(a, dtype=float), (num,)), aux)
    return _simulate_steering(as_arrays(model), delta, jnp.asarray(dt, float),
                              None if state0 is None else jnp.asarray(state0, float),
                              jnp.asarray(psi0, float), aux, jnp.asarray(start, float),
                              int(substeps))


@eqx.filter_jit
def _simulate_steering(model, delta, dt, state0, psi0, aux, start, substeps):
    if state0 is None:
        state0 = model.initial_state(jnp.zeros_like(psi0))
    head = lambda a: a[:-1]
    psi, r, states = propagate(model, state0, psi0, delta[:-1], jax.tree.map(head, aux), dt,
                               substeps)
    first = lambda a0, a: jnp.concatenate([jnp.asarray(a0)[None], a])
    return SteeringTrajectory(
        t=start + dt * jnp.arange(delta.shape[0]),
        psi=first(psi0, psi),
        r=first(model.output(state0), r),
        state=jnp.concatenate([state0[None], states]),
        delta=delta,
    )
