"""`simulate()`: the one door to simulate a model through a manoeuvre.

A vessel (`AbstractVessel`) is integrated here (`vessel_field`, the jitted body
`_simulate`); a steering model (`AbstractSteeringModel`) goes to `_simulate_steering`,
which replays a `Replay`'s rudder record or runs any other manoeuvre's logic on the
model's heading. Both return one `Trajectory`; both run `_integrate.integrate`.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._foundation._exported import persistent
from .._foundation._results import raise_unless_successful
from .._foundation._state import (
    STATE_FIELDS,
    Command,
    ShipState,
    Trajectory,
    from_vector,
    to_vector,
)
from .._models._environment import Environment
from .._models._steering._base import AbstractSteeringModel, AuxInputs
from .._models._vessel._base import (
    AbstractVessel,
    _state_derivative,
    inverse3,
    straight_run,
)
from ._integrate import Simulator, integrate
from ._simulate_steering import simulate_steering_model


def simulate(
    model: AbstractVessel | AbstractSteeringModel,
    manoeuvre,
    x0: ShipState | None = None,
    *,
    environment: Environment = Environment(),
    simulator: Simulator = Simulator(),
    aux: AuxInputs | None = None,
    throw: bool = False,
) -> Trajectory:
    """Simulate `model` through `manoeuvre` from the initial state `x0`.

    **Arguments:**

    - `model`: an `AbstractVessel` or an `AbstractSteeringModel`.
    - `manoeuvre`: an `AbstractManoeuvre`: its controller orders the rudder (and
      propeller) at every control step; its `dt` is the output interval. A trial
      spec is a manoeuvre (`Turn`, `ZigZag`, ...), a record replay is a manoeuvre
      (`Replay`).
    - `x0`: initial `ShipState`. A vessel starts from it (default
      `straight_run(model)`: the nominal straight run); a steering model takes its
      heading `psi` and yaw rate `r` (the model's steady state `initial_state(r)`)
      and, where it has a sway state, `v`; default at rest with $\\psi = 0$.
    - `environment`: current and wind of a vessel; calm water by default.
    - `simulator`: the numerics; see `Simulator`.
    - `aux`: steering models only: the measured `AuxInputs` (u, v, n, apparent
      wind) replayed beside a `Replay`'s rudder, leaves of shape `(N,)` or scalars
      (zeros, calm, by default), with the rudder's hold.
    - `throw`: raise (an `equinox` runtime error with the code's sentence) unless the
      simulation succeeded; default False: the outcome is `Trajectory.result`.

    A steering model through a `Replay` replays the rudder record (`delta_hold`;
    its `n_record` is not used: a response model takes a measured propeller rate
    through `aux`); through any other manoeuvre the manoeuvre sees the model's
    heading and yaw rate at every control step (zig-zag switching, heading control)
    and orders the rudder, which moves towards the order by at most
    `manoeuvre.rudder_rate * h` per control step of `h` seconds (no limit when
    None) and is held over the step; its propeller order is not used.

    **Returns:** a `Trajectory` with `manoeuvre.num_samples` samples. For a steering
    model its `state` holds `psi`, `r` and the actual rudder `delta` from the
    simulation, `u`, `v`, `n` the replayed auxiliary inputs (zeros where none) and
    `x = y = 0` (a response model has no track); `command.delta` is the ordered
    rudder and `internal` the model's own state vector, shape `(N, num_states)`.

    Parameter values are traced, never baked in: changing them does not recompile.
    """
    if isinstance(model, AbstractSteeringModel):
        return raise_unless_successful(
            simulate_steering_model(model, manoeuvre, x0, aux=aux, simulator=simulator), throw)
    if not isinstance(model, AbstractVessel):
        raise TypeError(f"`model` must be an AbstractVessel or an AbstractSteeringModel, got "
                        f"{type(model).__name__}.")
    if aux is not None:
        raise ValueError("`aux` replays measured inputs of a steering model; a vessel "
                         "simulates its own speeds.")
    x0 = straight_run(model) if x0 is None else x0
    wind = not _is_static_zero(environment.wind.speed)
    steps = simulator.steps_per_sample(manoeuvre.dt)
    return raise_unless_successful(
        _simulate(*_as_arrays((model, manoeuvre, x0, environment)), simulator, steps,
                  wind=wind), throw)


def _is_static_zero(x) -> bool:
    """A plain Python (or NumPy) zero: known before tracing, so the work it zeroes is skipped."""
    return isinstance(x, (int, float, np.number)) and not isinstance(x, bool) and x == 0


def _as_arrays(tree):
    """Turn Python numbers in a pytree into arrays so that `filter_jit` traces them."""
    # NumPy scalars, not `jnp.asarray`: a device transfer per number costs ~25 us, i.e.
    # milliseconds per call for a vessel with 60 coefficients; jit transfers them at once.
    dtype = jax.dtypes.canonicalize_dtype(np.float64)
    is_number = lambda x: isinstance(x, (float, int)) and not isinstance(x, bool)
    return jax.tree.map(lambda x: np.asarray(x, dtype=dtype) if is_number(x) else x, tree)


def initial_vector(vessel, x0: ShipState):
    """The state vector at `x0`: its eight fields, then the vessel's effect states in
    their steady state at the rudder angle of `x0`."""
    y0 = to_vector(x0)
    if vessel.effect_state_size:
        y0 = jnp.concatenate([y0, vessel.effect_initial(x0.delta)])
    return y0


def vessel_field(vessel, environment, *, wind=True, rudder_rate=None):
    """The vector field of `integrate` for a vessel driven by a `Command` policy: the
    flat state `(u, v, r, x, y, psi, delta, n)` (then any effect states) and the
    command at time `t`; `rudder_rate` [rad/s]: a manoeuvre's rudder-rate limit on
    top of the vessel's servo (None: the servo's own)."""
    mass_inverse = inverse3(vessel.mass_matrix())  # once per run, outside the time loop
    size = len(STATE_FIELDS)

    def field(t, y, args):
        command, t_k = args
        return to_vector(_state_derivative(vessel, from_vector(y), command.at(t - t_k),
                                          environment, mass_inverse, wind=wind, t=t,
                                          rudder_rate=rudder_rate))

    def field_with_effects(t, y, args):
        command, t_k = args
        z = y[size:]
        y_dot = _state_derivative(vessel.holding(z), from_vector(y), command.at(t - t_k),
                                  environment, mass_inverse, wind=wind, t=t,
                                  rudder_rate=rudder_rate)
        return jnp.concatenate([to_vector(y_dot), vessel.rudder_path(y[6], z)[1]])

    return field_with_effects if vessel.effect_state_size else field


@persistent  # traced once per installation
@eqx.filter_jit
def _simulate(vessel, manoeuvre, x0, environment, simulator, steps, wind=True, per_field=False):
    """The jitted body of `simulate`.

    Static options: `wind=False` skips the wind loads (a static zero wind speed);
    `per_field=True` has the time loop emit each state and command component as its own
    output, which saves a strided copy of the whole batch when the call is vmapped
    (the batching layer uses it) but costs a little per step for a single run.
    """
    t0 = manoeuvre.start
    y0 = initial_vector(vessel, x0)
    dt = jnp.asarray(manoeuvre.dt, dtype=float)
    num = manoeuvre.num_samples

    def policy(t, y, memory, h):
        return manoeuvre.command(t, from_vector(y), memory, h)

    def observe(y, command):
        delta, n = jnp.asarray(command.delta, float), jnp.asarray(command.n, float)
        if per_field:
            return tuple(y[i] for i in range(len(STATE_FIELDS))) + (delta, n)
        return jnp.concatenate([y[:len(STATE_FIELDS)], jnp.stack([delta, n])])

    field = vessel_field(vessel, environment, wind=wind, rudder_rate=manoeuvre.rudder_rate)
    out, result = integrate(field, y0, (policy, manoeuvre.init(x0)), (t0, dt, num),
                            simulator, steps, observe)
    if not per_field:
        out = tuple(out[:, i] for i in range(len(STATE_FIELDS) + 2))
    state, command = ShipState(*out[:-2]), Command(*out[-2:])
    t = t0 + jnp.arange(num) * dt
    return Trajectory(
        t=t,
        state=state,
        command=command,
        valid=t - t0 <= manoeuvre.duration + 1e-9 * dt,
        result=result,
    )
