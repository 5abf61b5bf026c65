"""`Simulator` strategy and `simulate()`: the only place that integrates."""

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from ._environment import Environment
from ._state import Command, ShipState, Trajectory
from ._vessel._base import AbstractVessel, _state_derivative, inverse3


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
        mass_inverse = inverse3(vessel.mass_matrix())
        rhs = lambda y: _flatten(
            _state_derivative(vessel, _unflatten(y), command, environment, mass_inverse)
        )
        y, success = self._integrate(rhs, _flatten(state), t0, dt)
        return _unflatten(y), success

    def _integrate(self, rhs, y, t0, dt):
        """Advance the flat state vector `y` over `[t0, t0 + dt]` under `dy/dt = rhs(y)`."""
        if self.solver is None:
            h = dt / self.substeps

            def rk4(y, _):
                k1 = rhs(y)
                k2 = rhs(y + (h / 2) * k1)
                k3 = rhs(y + (h / 2) * k2)
                k4 = rhs(y + h * k3)
                return y + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4), None

            y, _ = jax.lax.scan(rk4, y, None, length=self.substeps, unroll=self.substeps <= 8)
            return y, jnp.array(True)
        sol = dfx.diffeqsolve(
            dfx.ODETerm(lambda t, y, args: rhs(y)),
            self.solver,
            t0,
            t0 + dt,
            dt / self.substeps,
            y,
            stepsize_controller=self.stepsize_controller,
            adjoint=self.adjoint,
            max_steps=self.max_steps,
            throw=False,
        )
        return sol.ys[-1], sol.result == dfx.RESULTS.successful


# The state travels through the integrator as one vector: far fewer (and larger) XLA
# operations per step than a pytree of eight scalars, which is what makes the fast path
# fast on CPU (see benchmarks/README.md).
_FIELDS = ("u", "v", "r", "x", "y", "psi", "delta", "n")


def _flatten(state: ShipState):
    return jnp.stack([jnp.asarray(getattr(state, k), dtype=float) for k in _FIELDS])


def _unflatten(y) -> ShipState:
    return ShipState(*(y[..., i] for i in range(len(_FIELDS))))


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
    wind = not _is_static_zero(environment.wind.speed)
    return _simulate(*_as_arrays((vessel, manoeuvre, x0, environment)), simulator, wind=wind)


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


@eqx.filter_jit
def _simulate(vessel, manoeuvre, x0, environment, simulator, wind=True, per_field=False):
    """The jitted body of `simulate`.

    Static options: `wind=False` skips the wind loads (a static zero wind speed);
    `per_field=True` has the time loop emit each state and command component as its own
    output, which saves a strided copy of the whole batch when the call is vmapped
    (the batching layer uses it) but costs a little per step for a single run.
    """
    t0 = manoeuvre.start
    y0 = _flatten(x0)
    memory = manoeuvre.init(_unflatten(y0))
    dt = jnp.asarray(manoeuvre.dt, dtype=float)
    mass_inverse = inverse3(vessel.mass_matrix())  # once per run, outside the time loop
    num = manoeuvre.num_samples

    def step(carry, k):
        y, memory, ok = carry
        t = t0 + k * dt
        command, memory = manoeuvre.command(t, _unflatten(y), memory)
        delta, n = jnp.asarray(command.delta, float), jnp.asarray(command.n, float)
        held = Command(delta, n)
        rhs = lambda z: _flatten(
            _state_derivative(vessel, _unflatten(z), held, environment, mass_inverse, wind=wind)
        )
        new_y, success = simulator._integrate(rhs, y, t, dt)
        # the last sample's step is integrated but thrown away: no concatenation
        # (a copy of the whole output) after the loop
        ok = ok & (success | (k == num - 1))
        if per_field:
            out = tuple(y[i] for i in range(len(_FIELDS))) + (delta, n)
        else:
            out = jnp.concatenate([y, jnp.stack([delta, n])])
        return (new_y, memory, ok), out

    (_, _, ok), out = jax.lax.scan(step, (y0, memory, jnp.array(True)), jnp.arange(num))
    if not per_field:
        out = tuple(out[:, i] for i in range(len(_FIELDS) + 2))
    state, command = ShipState(*out[:-2]), Command(*out[-2:])
    t = t0 + jnp.arange(num) * dt
    finite = jnp.all(jnp.stack([jnp.all(jnp.isfinite(a)) for a in out[:-2]]))
    return Trajectory(
        t=t,
        state=state,
        command=command,
        valid=t - t0 <= manoeuvre.duration + 1e-9 * dt,
        success=ok & finite,
    )
