"""A steering model through a (closed-loop) manoeuvre: zig-zags, turns, schedules."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import ArrayLike

from .._estimate._params import as_arrays
from .._state import ShipState
from ._base import AbstractSteeringModel, AuxInputs, SteeringTrajectory, _rk4_interval


def steer_manoeuvre(model: AbstractSteeringModel, manoeuvre, *, psi0: ArrayLike = 0.0,
                    r0: ArrayLike = 0.0, rudder_rate: ArrayLike | None = None,
                    substeps: int = 1) -> SteeringTrajectory:
    """Simulate a response model through `manoeuvre` with the manoeuvre's own logic
    (zig-zag switching on the model's heading, open-loop schedules as they are).

    At each sample the manoeuvre sees the model's heading and yaw rate (the other
    `ShipState` fields are zero) and orders a rudder angle; the actual rudder moves
    towards it by at most `rudder_rate * dt` [rad/s x s] per sample (no limit by
    default) and is held over the interval (zero-order hold, as `simulate_steering`).
    The propeller command of the manoeuvre is ignored: a response model has no
    speed. `psi0` [rad], `r0` [rad/s]: initial heading and steady yaw rate;
    `substeps`: RK4 steps per interval.

    **Returns:** a `SteeringTrajectory` of `manoeuvre.num_samples` samples; `delta`
    is the actual rudder held from each sample.
    """
    if int(substeps) < 1:
        raise ValueError(f"`substeps` must be a positive integer, got {substeps}.")
    if rudder_rate is not None and not float(rudder_rate) > 0:
        raise ValueError(f"`rudder_rate` must be positive [rad/s] or None, got {rudder_rate}.")
    rate = jnp.inf if rudder_rate is None else jnp.asarray(rudder_rate, float)
    return _steer(as_arrays(model), as_arrays(manoeuvre), jnp.asarray(psi0, float),
                  jnp.asarray(r0, float), rate, int(substeps))


@eqx.filter_jit
def _steer(model, manoeuvre, psi0, r0, rate, substeps):
    dt = jnp.asarray(manoeuvre.dt, float)
    zero = jnp.zeros_like(psi0)

    def ship(x, psi, delta):
        return ShipState(u=zero, v=zero, r=model.output(x), x=zero, y=zero, psi=psi,
                         delta=delta, n=zero)

    x0 = model.initial_state(r0)
    memory = manoeuvre.init(ship(x0, psi0, zero))

    def step(carry, k):
        x, psi, delta, memory = carry
        t = manoeuvre.start + k * dt
        command, memory = manoeuvre.command(t, ship(x, psi, delta), memory)
        move = jnp.clip(command.delta - delta, -rate * dt, rate * dt)
        delta = jnp.where(jnp.isfinite(rate), delta + move, command.delta)
        out = (t, psi, model.output(x), x, delta)
        x, psi = _rk4_interval(model, x, psi, delta, AuxInputs(), dt, substeps)
        return (x, psi, delta, memory), out

    _, (t, psi, r, states, delta) = jax.lax.scan(
        step, (x0, psi0, zero, memory), jnp.arange(manoeuvre.num_samples))
    return SteeringTrajectory(t=t, psi=psi, r=r, state=states, delta=delta)
