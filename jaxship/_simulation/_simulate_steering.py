"""Response (steering) models through a manoeuvre, by `integrate`: the steering half of
`jaxship.simulate`.

The simulated state of a steering model is its own state with the heading appended,
$y = (x, \\psi)$, $\\dot y = (f(x, \\delta, a), h(x))$; the rudder and the measured
auxiliary inputs $a = (u, v, n)$ are replayed between samples with a zero- or
first-order hold (a `jaxship.Replay`), or the rudder is ordered by a manoeuvre's
controller that sees the model's heading and yaw rate.
"""

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._foundation._exported import persistent
from .._foundation._params import as_arrays
from .._foundation._state import Command, ShipState, Trajectory
from .._models._manoeuvres import Replay, ZigZag
from .._models._steering._base import AbstractSteeringModel, AuxInputs
from ._integrate import Held, Simulator, integrate, replay_policy


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
    return _propagate(model, state0, psi0, records, dt, holds, simulator, steps)[0]


def _propagate(model, state0, psi0, records, dt, holds, simulator, steps):
    """`propagate`, and whether every step succeeded and stayed finite."""
    y0 = jnp.concatenate([state0, jnp.reshape(psi0, (1,))])
    num = records["delta"].shape[0] - 1
    observe = lambda y, _: (y[-1], model.output(y[:-1]), y[:-1])
    return integrate(steering_field(model), y0, (replay_policy(records, dt, holds), None),
                     (0.0, dt, num), simulator, steps, observe, emit="end")


def at_rest(dtype=float) -> ShipState:
    """The default start of a steering model: at rest, heading 0."""
    zero = jnp.zeros((), dtype)
    return ShipState(*(zero,) * 8)


def start_state(model: AbstractSteeringModel, x0: ShipState) -> Array:
    """The model state at `x0`: the steady turn at its yaw rate (`initial_state(r)`),
    with its sway velocity `v` where the model has a sway state (sway-yaw models)."""
    state = model.initial_state(x0.r)
    if "v" in model.state_names:
        state = state.at[model.state_names.index("v")].set(x0.v)
    return state


def simulate_steering_model(model: AbstractSteeringModel, manoeuvre, x0: ShipState | None,
                            *, aux: AuxInputs | None, simulator: Simulator) -> Trajectory:
    """`jaxship.simulate` for a steering model (see there): `_replay` for a `Replay`,
    `_steer` (the closed loop) for any other manoeuvre."""
    x0 = at_rest() if x0 is None else x0
    x0 = jax.tree.map(lambda a: jnp.asarray(a, float), x0)
    steps = simulator.steps_per_sample(manoeuvre.dt)
    if isinstance(manoeuvre, Replay):
        if np.ndim(manoeuvre.delta_record) != 1 or np.shape(manoeuvre.delta_record)[0] < 2:
            raise ValueError("`delta_record` must be a 1-D array of at least 2 samples, got "
                             f"shape {np.shape(manoeuvre.delta_record)}.")
        return _replay(as_arrays(model), as_arrays(manoeuvre), x0, aux, simulator, steps)
    if aux is not None:
        raise ValueError("`aux` is replayed beside a `Replay`'s rudder record; a closed-loop "
                         f"{type(manoeuvre).__name__} has no measured inputs.")
    return _steer(as_arrays(model), as_arrays(manoeuvre), x0, simulator, steps)


def replay_records(manoeuvre: Replay, aux: AuxInputs | None) -> tuple[dict, dict]:
    """The records `{"delta", "u", "v", "n"}` (and the apparent wind, where given) of a
    steering model's replay, `manoeuvre.num_samples` long (the last sample held
    beyond the record), and their holds: all the rudder's."""
    delta = jnp.asarray(manoeuvre.delta_record, dtype=float)
    num = manoeuvre.num_samples
    if delta.shape[0] < num:
        delta = jnp.pad(delta, (0, num - delta.shape[0]), mode="edge")
    delta = delta[:num]
    aux = AuxInputs() if aux is None else aux
    aux = jax.tree.map(lambda a: jnp.broadcast_to(jnp.asarray(a, dtype=float), (num,)), aux)
    records = {"delta": delta, "u": aux.u, "v": aux.v, "n": aux.n}
    records.update({k: getattr(aux, k) for k in ("wind_u", "wind_v")
                    if getattr(aux, k) is not None})  # the apparent wind, where given
    return records, dict.fromkeys(records, manoeuvre.delta_hold)


def steering_trajectory(manoeuvre, psi, r, internal, delta, ordered, result,
                        aux: dict | None = None) -> Trajectory:
    """A steering model's `Trajectory`: heading, yaw rate, actual and ordered rudder and
    the model state at the samples; the aux inputs `aux` `{"u", "v", "n"}` (zeros where
    None); no track (x = y = 0)."""
    zero = jnp.zeros_like(psi)
    aux = {} if aux is None else aux
    u, v, n = (aux.get(k, zero) for k in ("u", "v", "n"))
    dt = jnp.asarray(manoeuvre.dt, float)
    t = manoeuvre.start + dt * jnp.arange(psi.shape[0])
    return Trajectory(
        t=t,
        state=ShipState(u=u, v=v, r=r, x=zero, y=zero, psi=psi, delta=delta, n=n),
        command=Command(ordered, n),
        valid=t - manoeuvre.start <= manoeuvre.duration + 1e-9 * dt,
        result=result,
        internal=internal,
    )


@persistent  # traced once per installation
@eqx.filter_jit
def _replay(model, manoeuvre, x0, aux, simulator, steps):
    """The jitted body of a steering model's replay of a rudder record."""
    records, holds = replay_records(manoeuvre, aux)
    dt = jnp.asarray(manoeuvre.dt, float)
    state0, psi0 = start_state(model, x0), x0.psi
    (psi, r, states), result = _propagate(model, state0, psi0, records, dt, holds, simulator,
                                      steps)
    first = lambda a0, a: jnp.concatenate([jnp.asarray(a0)[None], a])
    return steering_trajectory(manoeuvre, first(psi0, psi), first(model.output(state0), r),
                               jnp.concatenate([state0[None], states]), records["delta"],
                               records["delta"], result,
                               {k: records[k] for k in ("u", "v", "n")})


@persistent  # traced once per installation
@eqx.filter_jit
def _steer(model, manoeuvre, x0, simulator, steps):
    """The jitted body of a steering model through a closed-loop manoeuvre: the rudder
    moves towards the order by at most `manoeuvre.rudder_rate * h` per control step
    (so a zig-zag reverses it at the step nearest to the crossing)."""
    if isinstance(manoeuvre, ZigZag):
        manoeuvre = dataclasses.replace(manoeuvre, switch_at=manoeuvre.switch_at.sampled())
    dt = jnp.asarray(manoeuvre.dt, float)
    psi0 = x0.psi
    zero = jnp.zeros_like(psi0)
    rate = jnp.inf if manoeuvre.rudder_rate is None else jnp.asarray(manoeuvre.rudder_rate,
                                                                     float)

    def ship(y, delta):
        return ShipState(u=zero, v=zero, r=model.output(y[:-1]), x=zero, y=zero, psi=y[-1],
                         delta=delta, n=zero)

    def policy(t, y, carry, h):
        delta, memory = carry
        command, memory = manoeuvre.command(t, ship(y, delta), memory, h)
        move = jnp.clip(command.delta - delta, -rate * h, rate * h)
        delta = jnp.where(jnp.isfinite(rate), delta + move, command.delta)
        held = dict(zip(INPUTS, (delta, zero, zero, zero)))
        held["ordered"] = jnp.asarray(command.delta, float)  # recorded, not an input
        return Held(held, jax.tree.map(jnp.zeros_like, held)), (delta, memory)

    state0 = start_state(model, x0)
    y0 = jnp.concatenate([state0, jnp.reshape(psi0, (1,))])
    memory = manoeuvre.init(ship(y0, zero))
    observe = lambda y, held: (y[-1], model.output(y[:-1]), y[:-1], held.value["delta"],
                               held.value["ordered"])
    (psi, r, states, delta, ordered), result = integrate(
        steering_field(model), y0, (policy, (zero, memory)),
        (manoeuvre.start, dt, manoeuvre.num_samples), simulator, steps, observe)
    return steering_trajectory(manoeuvre, psi, r, states, delta, ordered, result)
