"""`Simulator` strategy and `simulate()`: the only place that integrates."""

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp

from ._environment import Environment
from ._state import Command, ShipState, Trajectory, tree_axpy
from ._vessel._base import AbstractVessel, state_derivative


class Simulator(eqx.Module):
    """Numerics of `simulate`.

    The command is held constant over each sample interval (zero-order hold) and the
    closed-loop logic of a manoeuvre runs at the sample times. Within an interval:

    - `solver=None` (default, the fast path): `substeps` classic Runge-Kutta 4 steps
      in a `jax.lax.scan`; exact in forward and reverse mode.
    - a diffrax solver, e.g. `diffrax.Tsit5()`: one `diffeqsolve` per interval, with
      `stepsize_controller` (adaptive by default: `PIDController(rtol, atol)`) and
      `adjoint` (use `diffrax.ForwardMode()` for forward-mode Jacobians).
    """

    solver: dfx.AbstractSolver | None = None
    substeps: int = eqx.field(static=True, default=1)
    stepsize_controller: dfx.AbstractStepSizeController = dfx.PIDController(rtol=1e-8, atol=1e-8)
    adjoint: dfx.AbstractAdjoint = dfx.RecursiveCheckpointAdjoint()
    max_steps: int = eqx.field(static=True, default=4096)

    def advance(self, vessel, environment, state, command, t0, dt):
        """Integrate one sample interval `[t0, t0 + dt]` with a held `command`."""
        rhs = lambda y: state_derivative(vessel, y, command, environment)
        if self.solver is None:
            h = dt / self.substeps

            def rk4(y, _):
                k1 = rhs(y)
                k2 = rhs(tree_axpy(h / 2, k1, y))
                k3 = rhs(tree_axpy(h / 2, k2, y))
                k4 = rhs(tree_axpy(h, k3, y))
                incr = jax.tree.map(lambda a, b, c, d: (a + 2 * b + 2 * c + d) / 6, k1, k2, k3, k4)
                return tree_axpy(h, incr, y), None

            y, _ = jax.lax.scan(rk4, state, None, length=self.substeps, unroll=self.substeps <= 8)
            return y, jnp.array(True)
        sol = dfx.diffeqsolve(
            dfx.ODETerm(lambda t, y, args: rhs(y)),
            self.solver,
            t0,
            t0 + dt,
            dt / self.substeps,
            state,
            stepsize_controller=self.stepsize_controller,
            adjoint=self.adjoint,
            max_steps=self.max_steps,
            throw=False,
        )
        return jax.tree.map(lambda leaf: leaf[-1], sol.ys), sol.result == dfx.RESULTS.successful


def simulate(
    vessel: AbstractVessel,
    manoeuvre,
    x0: ShipState,
    *,
    environment: Environment = Environment(),
    simulator: Simulator = Simulator(),
) -> Trajectory:
    """Simulate `vessel` through `manoeuvre` from the initial state `x0`.

    **Arguments:**

    - `vessel`: any `AbstractVessel`.
    - `manoeuvre`: an `AbstractManoeuvre`; it sets the sample interval, the number of
      samples and the rudder/propeller commands (open or closed loop).
    - `x0`: initial `ShipState` (e.g. from `straight_run(vessel)`).
    - `environment`: current and wind; calm water by default.
    - `simulator`: the numerics; see `Simulator`.

    **Returns:** a `Trajectory` with `manoeuvre.num_samples` samples.

    Parameter values are traced, never baked in: changing them does not recompile.
    """
    return _simulate(*_as_arrays((vessel, manoeuvre, x0, environment)), simulator)


def _as_arrays(tree):
    """Turn Python numbers in a pytree into arrays so that `filter_jit` traces them."""
    is_number = lambda x: isinstance(x, (float, int)) and not isinstance(x, bool)
    return jax.tree.map(lambda x: jnp.asarray(x, dtype=float) if is_number(x) else x, tree)


@eqx.filter_jit
def _simulate(vessel, manoeuvre, x0, environment, simulator):
    t0 = manoeuvre.start
    x0 = jax.tree.map(lambda a: jnp.asarray(a, dtype=float), x0)
    memory = manoeuvre.init(x0)
    dt = jnp.asarray(manoeuvre.dt, dtype=float)

    def step(carry, k):
        state, memory, ok = carry
        t = t0 + k * dt
        command, memory = manoeuvre.command(t, state, memory)
        command = Command(jnp.asarray(command.delta, float), jnp.asarray(command.n, float))
        new_state, success = simulator.advance(vessel, environment, state, command, t, dt)
        return (new_state, memory, ok & success), (state, command)

    num = manoeuvre.num_samples
    (last, memory, ok), (states, commands) = jax.lax.scan(
        step, (x0, memory, jnp.array(True)), jnp.arange(num - 1)
    )
    last_command, _ = manoeuvre.command(t0 + (num - 1) * dt, last, memory)
    last_command = Command(
        jnp.asarray(last_command.delta, float), jnp.asarray(last_command.n, float)
    )
    append = lambda seq, item: jax.tree.map(lambda a, b: jnp.concatenate([a, b[None]]), seq, item)
    states, commands = append(states, last), append(commands, last_command)
    t = t0 + jnp.arange(num) * dt
    finite = jnp.all(jnp.stack([jnp.all(jnp.isfinite(leaf)) for leaf in jax.tree.leaves(states)]))
    return Trajectory(
        t=t,
        state=states,
        command=commands,
        valid=t - t0 <= manoeuvre.duration + 1e-9 * dt,
        success=ok & finite,
    )
