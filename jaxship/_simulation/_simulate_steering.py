"""Response (steering) models through recorded inputs or a manoeuvre, by `integrate`.

The simulated state of a steering model is its own state with the heading appended,
$y = (x, \\psi)$, $\\dot y = (f(x, \\delta, a), h(x))$; the rudder and the measured
auxiliary inputs $a = (u, v, n)$ are replayed between samples with a zero- or
first-order hold (`jaxship.Replay`), or ordered by a manoeuvre's controller.
"""

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from .._foundation._params import as_arrays
from .._foundation._state import ShipState
from .._models._steering._base import AbstractSteeringModel, AuxInputs
from ._simulate import Held, Simulator, integrate, replay_policy


INPUTS = ("delta", "u", "v", "n")  # the replayed signals of a steering model


def steering_field(model: AbstractSteeringModel):
    """The vector field of `integrate` for `y = (x, psi)` under `Held` inputs
    `{"delta", "u", "v", "n"}`: the model's `replay_field`."""
    field = model.replay_field()
    return lambda t, y, args: field(t, y, args[0].at(t - args[1]))


def propagate(model: AbstractSteeringModel, state0, psi0, records: dict, dt, holds: dict,
              simulator: Simulator, steps: int):
    """Predict the `L` samples after a start from `records` (`{"delta", "u", "v",
    "n"}`, each `(L + 1,)`: the samples from the start to the last predicted one,
    replayed with `holds`); returns `(psi, r, states)` at the `L` samples after the
    start, shapes `(L,)`, `(L,)`, `(L, num_states)`."""
    y0 = jnp.concatenate([state0, jnp.reshape(psi0, (1,))])
    num = records["delta"].shape[0] - 1
    observe = lambda y, _: (y[-1], model.output(y[:-1]), y[:-1])
    (psi, r, states), _ = integrate(steering_field(model), y0, replay_policy(records, dt, holds),
                                    None, 0.0, dt, num, simulator, steps, observe, emit="end")
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
    hold: str = "foh",
    simulator: Simulator = Simulator(max_step=float("inf")),
    substeps: int | None = None,
) -> SteeringTrajectory:
    """Simulate a response model driven by sampled rudder angles.

    **Arguments:**

    - `model`: any `AbstractSteeringModel`.
    - `delta`: rudder angles [rad], shape `(N,)`, at the sample times.
    - `dt`: sample interval [s].
    - `state0`: initial model state (default `model.initial_state(0.0)`: at rest).
    - `psi0`: initial heading [rad].
    - `aux`: `AuxInputs` with leaves of shape `(N,)` (or scalars), for models that
      use measured speeds (or the apparent wind); zeros (calm) by default.
    - `start`: time of sample 0 [s].
    - `hold`: `"foh"` (default: linear between samples, as a rudder angle moves and
      as `fit` replays a measured one) or `"zoh"` (`delta[k]` held over
      $[t_k, t_{k+1})$, a piecewise-constant input); the auxiliary inputs follow the
      same hold.
    - `simulator`: the numerics (default: classical RK4, one step per sample).
    - `substeps`: solver steps per sample (shortcut for `Simulator(substeps=...)`).

    **Returns:** a `SteeringTrajectory` with N samples.

    Parameter values are traced: changing them does not recompile.
    """
    delta = jnp.asarray(delta, dtype=float)
    if delta.ndim != 1 or delta.shape[0] < 2:
        raise ValueError(f"`delta` must be a 1-D array of at least 2 samples, got shape "
                         f"{delta.shape}.")
    if substeps is not None:
        simulator = dataclasses.replace(simulator, substeps=int(substeps))
    num = delta.shape[0]
    aux = AuxInputs() if aux is None else aux
    aux = jax.tree.map(lambda a: jnp.broadcast_to(jnp.asarray(a, dtype=float), (num,)), aux)
    records = {"delta": delta, "u": aux.u, "v": aux.v, "n": aux.n}
    records.update({k: getattr(aux, k) for k in ("wind_u", "wind_v")
                    if getattr(aux, k) is not None})  # the apparent wind, where given
    holds = dict.fromkeys(records, hold)
    steps = simulator.steps_per_sample(dt)
    return _simulate_steering(as_arrays(model), records, jnp.asarray(dt, float),
                              None if state0 is None else jnp.asarray(state0, float),
                              jnp.asarray(psi0, float), jnp.asarray(start, float), holds,
                              simulator, steps)


@eqx.filter_jit
def _simulate_steering(model, records, dt, state0, psi0, start, holds, simulator, steps):
    if state0 is None:
        state0 = model.initial_state(jnp.zeros_like(psi0))
    psi, r, states = propagate(model, state0, psi0, records, dt, holds, simulator, steps)
    first = lambda a0, a: jnp.concatenate([jnp.asarray(a0)[None], a])
    return SteeringTrajectory(
        t=start + dt * jnp.arange(records["delta"].shape[0]),
        psi=first(psi0, psi),
        r=first(model.output(state0), r),
        state=jnp.concatenate([state0[None], states]),
        delta=records["delta"],
    )


def steer_manoeuvre(model: AbstractSteeringModel, manoeuvre, *, psi0: ArrayLike = 0.0,
                    r0: ArrayLike = 0.0, rudder_rate: ArrayLike | None = None,
                    simulator: Simulator = Simulator(), substeps: int | None = None
                    ) -> SteeringTrajectory:
    """Simulate a response model through `manoeuvre` with the manoeuvre's own logic
    (zig-zag switching on the model's heading, open-loop schedules as they are).

    At every control step (`simulator.max_step`, 0.1 s by default) the manoeuvre sees
    the model's heading and yaw rate (the other `ShipState` fields are zero) and
    orders a rudder angle; the actual rudder moves towards it by at most
    `rudder_rate * h` [rad/s x s] per control step of `h` seconds (no limit by
    default) and is held over the step. The propeller command of the manoeuvre is
    ignored: a response model has no speed. `psi0` [rad], `r0` [rad/s]: initial
    heading and steady yaw rate.

    **Returns:** a `SteeringTrajectory` of `manoeuvre.num_samples` samples; `delta`
    is the actual rudder at each sample.
    """
    if rudder_rate is not None and not float(rudder_rate) > 0:
        raise ValueError(f"`rudder_rate` must be positive [rad/s] or None, got {rudder_rate}.")
    if substeps is not None:
        simulator = dataclasses.replace(simulator, substeps=int(substeps))
    rate = jnp.inf if rudder_rate is None else jnp.asarray(rudder_rate, float)
    steps = simulator.steps_per_sample(manoeuvre.dt)
    return _steer(as_arrays(model), as_arrays(manoeuvre), jnp.asarray(psi0, float),
                  jnp.asarray(r0, float), rate, simulator, steps)


@eqx.filter_jit
def _steer(model, manoeuvre, psi0, r0, rate, simulator, steps):
    dt = jnp.asarray(manoeuvre.dt, float)
    zero = jnp.zeros_like(psi0)

    def ship(y, delta):
        return ShipState(u=zero, v=zero, r=model.output(y[:-1]), x=zero, y=zero, psi=y[-1],
                         delta=delta, n=zero)

    def policy(t, y, carry, h):
        delta, memory = carry
        command, memory = manoeuvre.command(t, ship(y, delta), memory, h)
        move = jnp.clip(command.delta - delta, -rate * h, rate * h)
        delta = jnp.where(jnp.isfinite(rate), delta + move, command.delta)
        held = dict(zip(INPUTS, (delta, zero, zero, zero)))
        return Held(held, jax.tree.map(jnp.zeros_like, held)), (delta, memory)

    x0 = model.initial_state(r0)
    y0 = jnp.concatenate([x0, jnp.reshape(psi0, (1,))])
    memory = manoeuvre.init(ship(y0, zero))
    observe = lambda y, held: (y[-1], model.output(y[:-1]), y[:-1], held.value["delta"])
    (psi, r, states, delta), _ = integrate(steering_field(model), y0, policy, (zero, memory),
                                           manoeuvre.start, dt, manoeuvre.num_samples,
                                           simulator, steps, observe)
    t = manoeuvre.start + dt * jnp.arange(manoeuvre.num_samples)
    return SteeringTrajectory(t=t, psi=psi, r=r, state=states, delta=delta)
