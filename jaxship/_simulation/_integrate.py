"""`Simulator` strategy and `integrate`: the one place that integrates.

Every time loop of jaxship (vessel simulation, steering-model simulation, the
prediction windows of a fit, the Kalman filter's prediction step) is `integrate`:
a `jax.lax.scan` over output samples, each split into control steps of at most
`Simulator.max_step` seconds. At the start of each control step a *policy* (a
controller, a trial's logic or a replay of recorded inputs) returns the inputs for
that step as a value and a slope (zero-order hold: slope 0; first-order hold:
recorded signals interpolated linearly), and the vector field sees them at every
stage time of the solver. The solver is any diffrax solver, stepped with its
`init`/`step` methods inside the scan (diffrax's manual-stepping API; the fast path,
default `RK4`), or `diffrax.diffeqsolve` with a step-size controller per control
step for accuracy-critical work. `jaxship.simulate` (`_simulate`) is its public door.
"""

import math
from typing import ClassVar

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._foundation._results import RESULTS, as_code
from .._foundation._state import Switched
from .._models._manoeuvres import interpolate


# the batch size from which `simulate_batch` writes out `RK4`'s stages (`rolled=None`).
# Written out, 64 Mariner 600 s zig-zags ran at 78 % of a hand-written scan against 49 %
# rolled, and compiled in 1.07 s against 0.96 s (`benchmarks/simulation.py`, 2026-12-07);
# 64 KVLCC2 turning circles compiled 0.5 s slower and ran 0.13 s faster. A sweep runs its
# program more than once, and the compilation cache (on in the command) compiles it once
# per installation, so from 32 runs the faster runs win
WRITTEN_OUT_BATCH = 32


class RK4(dfx.AbstractSolver):
    """The classical fourth-order Runge-Kutta method (Kutta 1901) as a diffrax solver.

    $k_1 = f(t, y)$, $k_2 = f(t + h/2, y + hk_1/2)$, $k_3 = f(t + h/2, y + hk_2/2)$,
    $k_4 = f(t + h, y + hk_3)$, $y_1 = y + h(k_1 + 2k_2 + 2k_3 + k_4)/6$ (Hairer,
    Norsett & Wanner 1993, sec. II.1). Fixed steps (no error estimate); written here
    rather than through diffrax's general Runge-Kutta stage loop, whose per-step
    overhead dominates on a six-state ship, so it is the fast path's default. Works in
    `diffrax.diffeqsolve` with `ConstantStepSize` too.

    `rolled=True`: the four stages are one loop, $k_i = f(t + c_i h,
    y + c_i h k_{i-1})$, so XLA compiles the vector field once instead of four times.
    On the Mariner, KVLCC2 and Esso Osaka a first simulation or derivative took
    1.7-3.3x less time, later ones 1.3-2.9x less, and a batch of 64 turning circles
    1.4x more once compiled (`python benchmarks/rk4_stages.py`, 2026-11-27). `False`:
    the stages written out. `None` (default): on the CPU rolled, except in
    `simulate_batch` of `WRITTEN_OUT_BATCH` runs or more, where the written-out stages'
    faster runs repay their longer compilation within one call; on an accelerator
    written out (`stages_rolled_by_default`).
    """

    rolled: bool | None = eqx.field(static=True, default=None)
    term_structure: ClassVar = dfx.ODETerm
    interpolation_cls: ClassVar = dfx.LocalLinearInterpolation

    def order(self, terms):
        return 4

    def init(self, terms, t0, t1, y0, args):
        return None

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        del solver_state, made_jump
        h = t1 - t0
        f = lambda t, y: terms.vf(t, y, args)
        axpy = lambda a, x, y: jax.tree.map(lambda xi, yi: yi + a * xi, x, y)
        if self.rolled or (self.rolled is None and stages_rolled_by_default()):
            c, b = jnp.array([0.0, 0.5, 0.5, 1.0]), jnp.array([1.0, 2.0, 2.0, 1.0]) / 6

            def stage(i, carry):  # k_i and the weighted sum of k_1 .. k_i
                k, incr = carry
                k = f(t0 + c[i] * h, axpy(c[i] * h, k, y0))
                return k, axpy(b[i], k, incr)

            zero = jax.tree.map(jnp.zeros_like, y0)
            _, incr = jax.lax.fori_loop(0, 4, stage, (zero, zero))
        else:
            k1 = f(t0, y0)
            k2 = f(t0 + h / 2, axpy(h / 2, k1, y0))
            k3 = f(t0 + h / 2, axpy(h / 2, k2, y0))
            k4 = f(t1, axpy(h, k3, y0))
            incr = jax.tree.map(lambda a, b, c, d: (a + 2 * b + 2 * c + d) / 6, k1, k2, k3, k4)
        y1 = axpy(h, incr, y0)
        return y1, None, dict(y0=y0, y1=y1), None, dfx.RESULTS.successful

    def func(self, terms, t0, y0, args):
        return terms.vf(t0, y0, args)


def stages_rolled_by_default() -> bool:
    """Whether `RK4(rolled=None)` rolls its stages: on the CPU, where XLA then compiles
    the vector field once (see `RK4`); not on an accelerator, where one 600 s Mariner
    zig-zag ran in 192 ms with the stages written out against 773 ms rolled (one H200,
    jax 0.11.2, 2026-11-28, issue 56). Read while tracing, from the default backend."""
    return jax.default_backend() == "cpu"


class Simulator(eqx.Module):
    """Numerics of every simulation and prediction.

    - `solver`: a diffrax solver; default `jaxship.RK4()`.
    - `max_step`: the longest control step [s]: each output sample interval `dt` is
      split into `ceil(dt / max_step)` equal control steps (at least `substeps`), and
      controllers (zig-zag switching, heading control) act at every control step, so trial
      indices do not depend on the output interval. Replayed records are sampled at
      their own interval; set `max_step=inf` to integrate one step per sample.
    - `substeps`: the least number of steps per output sample.
    - `stepsize_controller`: `None` (default): one fixed solver step per control step,
      taken with the solver's `init`/`step` in a `lax.scan` (fast, forward- and
      reverse-mode differentiable). A diffrax controller, e.g.
      `diffrax.PIDController(rtol=1e-8, atol=1e-8)`, runs `diffeqsolve` over each
      control step (use an adaptive solver such as `diffrax.Tsit5()`), with `adjoint`
      (`diffrax.ForwardMode()` for forward-mode Jacobians) and `max_steps`.
    """

    solver: dfx.AbstractSolver = RK4()
    max_step: float = eqx.field(static=True, default=0.1)
    substeps: int = eqx.field(static=True, default=1)
    stepsize_controller: dfx.AbstractStepSizeController | None = None
    adjoint: dfx.AbstractAdjoint = dfx.RecursiveCheckpointAdjoint()
    max_steps: int = eqx.field(static=True, default=4096)

    def __check_init__(self):
        if not self.max_step > 0:
            raise ValueError(f"`max_step` must be positive [s], got {self.max_step}.")
        if int(self.substeps) < 1:
            raise ValueError(f"`substeps` must be a positive integer, got {self.substeps}.")

    def steps_per_sample(self, dt) -> int:
        """Control steps per output interval `dt` [s] (a number or an array of them).

        **Raises:** `ValueError` when `dt` is traced (e.g. `jax.vmap` over manoeuvres),
        so that it cannot be read, unless `max_step` is infinite (`substeps` steps per
        interval): batch with `jaxship.simulate_batch`, which reads it first."""
        if isinstance(dt, jax.core.Tracer):
            if math.isinf(self.max_step):
                return int(self.substeps)
            raise ValueError(
                "the sample interval `dt` is traced (a transformation such as jax.vmap over "
                "manoeuvres), so the simulator cannot split it into control steps of at most "
                f"`max_step` = {self.max_step} s: batch with jaxship.simulate_batch, or use "
                "Simulator(max_step=math.inf, substeps=k) for k steps per sample.")
        longest = float(np.max(np.asarray(dt, dtype=float)))
        if not (longest > 0 and math.isfinite(longest)):
            raise ValueError(f"the sample interval `dt` must be positive and finite, got {dt}.")
        return max(int(self.substeps), math.ceil(longest / self.max_step - 1e-9))

    def step(self, field, t, h, y, args):
        """Advance `y` over `[t, t + h]` under `dy/dt = field(t, y, args)`; returns
        `(y, result)`, `result` diffrax's code of the step (`diffrax.RESULTS`)."""
        term = dfx.ODETerm(field)
        if self.stepsize_controller is None:
            solver = self.solver
            if getattr(solver, "scan_kind", "") is None:
                # diffrax's Runge-Kutta stage loop in its scan form: differentiable in
                # forward and reverse mode and under vmap, as the fast path must be
                solver = eqx.tree_at(lambda s: s.scan_kind, solver, "bounded",
                                     is_leaf=lambda x: x is None)
            state = solver.init(term, t, t + h, y, args)
            y, _, _, _, result = solver.step(term, t, t + h, y, args, state, made_jump=False)
            return y, result
        sol = dfx.diffeqsolve(term, self.solver, t, t + h, h, y, args,
                              stepsize_controller=self.stepsize_controller,
                              adjoint=self.adjoint, max_steps=self.max_steps, throw=False)
        return sol.ys[-1], sol.result


def integrate(field, y0, control, grid, simulator: Simulator, steps: int, observe=None, *,
              emit: str = "start"):
    """The time loop: `grid = (t0, dt, num)`, `num` output samples from `y0` at `t0`
    every `dt`, under `control = (policy, policy_state)`.

    - `field(t, y, (inputs, t_k))`: the vector field, with the inputs held from the
      control step's start `t_k` (evaluate them at `t` with `inputs.at(t - t_k)`).
    - `policy(t, y, policy_state, h) -> (inputs, policy_state)`: called at the start
      of each of the `steps` control steps of length `h = dt / steps` per sample. Inputs
      that change inside the step (`Switched`) split it into two solver steps there.
    - `observe(y, inputs)`: what to record for each sample interval (default
      `(y, inputs)`), with the inputs at the interval's start and the state at its
      start (`emit="start"`: sample 0 is the initial state; the last interval is
      integrated and dropped) or at its end (`emit="end"`: the `num` samples after
      the initial state, as predictions need).

    Returns `(outputs, result)`: the recorded pytree with a leading axis `num`, and the
    `RESULTS` code: the first failed step's (diffrax's code passed through), else
    `simulation_blew_up` when a recorded value is not finite, else `successful`.
    """
    policy, policy_state = control
    t0, dt, num = grid
    h = dt / steps
    observe = (lambda y, inputs: (y, inputs)) if observe is None else observe

    def sample(carry, k):
        t_sample = t0 + k * dt

        def control_step(carry, j):
            y, ps, result = carry
            t = t_sample + j * h
            inputs, ps = policy(t, y, ps, h)
            if isinstance(inputs, Switched):  # two solver steps, split at the switch
                s = jnp.clip(inputs.at, 0.0, h)
                y, before = simulator.step(field, t, s, y, (inputs.before, t))
                y, after = simulator.step(field, t + s, h - s, y, (inputs.after, t))
                return (y, ps, _first_failure(_first_failure(result, before), after)), \
                    inputs.at_start()
            y, step_result = simulator.step(field, t, h, y, (inputs, t))
            return (y, ps, _first_failure(result, step_result)), inputs

        y = carry[0]
        carry, inputs = jax.lax.scan(control_step, carry, jnp.arange(steps),
                                     unroll=steps <= 4)
        y = carry[0] if emit == "end" else y
        return carry, observe(y, jax.tree.map(lambda a: a[0], inputs))

    (_, _, result), out = jax.lax.scan(sample, (y0, policy_state, RESULTS.successful),
                                       jnp.arange(num))
    finite = jnp.all(jnp.stack([jnp.all(jnp.isfinite(a)) for a in jax.tree.leaves(out)]))
    blew_up = (result == RESULTS.successful) & ~finite
    return out, RESULTS.where(blew_up, RESULTS.simulation_blew_up, result)


def _first_failure(result: RESULTS, step) -> RESULTS:
    """`result`, or the code `step` of the next solver step if `result` is `successful`."""
    return RESULTS.where(result == RESULTS.successful, as_code(step), result)


class Held(eqx.Module):
    """Inputs over one control step: their `value` at its start and their `slope`
    (two pytrees of one structure); `at(tau)` is $v + s\\tau$ leaf by leaf."""

    value: object
    slope: object

    def at(self, tau):
        return jax.tree.map(lambda v, s: v + s * tau, self.value, self.slope)


def replay_policy(records: dict, dt, holds: dict):
    """A policy of `integrate` replaying recorded signals: `records` maps a name to
    its samples (the first at the start of the run, every `dt` seconds), `holds` maps
    it to `ZeroOrderHold()` or `FirstOrderHold()` (see `jaxship.Replay`). Returns `Held`
    dictionaries."""

    def policy(t, y, state, h):
        pairs = {k: interpolate(a, dt, t, holds[k]) for k, a in records.items()}
        return Held({k: p[0] for k, p in pairs.items()},
                    {k: p[1] for k, p in pairs.items()}), state

    return policy
