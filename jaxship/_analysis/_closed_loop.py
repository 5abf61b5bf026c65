"""Closed-loop runs of heading autopilots on a plant (a truth vessel or a steering
model), batched over autopilots x speeds, and their metrics (Odegard 2009, sec. 5.4)."""

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._foundation._exported import persistent
from .._foundation._kinematics import ssa
from .._foundation._results import RESULTS, raise_unless_successful
from .._foundation._state import ShipState, from_vector
from .._models._control import HeadingAutopilot
from .._models._effects import RecordedDisturbance, augment
from .._models._environment import Environment
from .._models._steering._base import AbstractSteeringModel
from .._models._vessel._base import AbstractVessel, straight_run
from .._simulation._batch import stack
from .._simulation._data import sampling_tolerance
from .._simulation._integrate import Held, Simulator, integrate
from .._simulation._simulate import _as_arrays, initial_vector, vessel_field
from .._simulation._simulate_steering import steering_field


class YawDisturbance(eqx.Module):
    """A slowly varying yaw moment (a sea-state stand-in): first-order filtered white
    noise (a first-order Gauss-Markov process), $x_{k+1} = a x_k +
    \\sqrt{1 - a^2}\\,\\sigma w_k$, $a = e^{-\\Delta/T}$, stationary standard deviation
    $\\sigma$ = `rudder_std` [rad] expressed as the rudder angle whose yaw moment it
    equals at the vessel's nominal straight run, time constant `time_constant` [s],
    held over `sample_interval` [s], drawn from `seed` (NumPy). Vessels only; added
    with `RecordedDisturbance` through `augment` (see `HeadingAutopilot.wave_filter`)."""

    rudder_std: float = float(np.deg2rad(2.0))
    time_constant: float = 30.0
    sample_interval: float = 1.0
    seed: int = eqx.field(static=True, default=0)

    def effect(self, vessel: AbstractVessel, duration: float) -> RecordedDisturbance:
        """The `RecordedDisturbance` covering `duration` [s] for `vessel`."""
        rng = np.random.default_rng(self.seed)
        count = int(np.ceil(duration / self.sample_interval)) + 2
        a = np.exp(-self.sample_interval / self.time_constant)
        noise = rng.standard_normal(count)
        x = np.empty(count)
        x[0] = noise[0]
        for k in range(1, count):
            x[k] = a * x[k - 1] + np.sqrt(1 - a * a) * noise[k]
        s0 = straight_run(vessel)
        per_rad = jax.grad(lambda d: vessel.forces(s0.u, s0.v, s0.r, d, s0.n)[2])(0.0)
        moment = self.rudder_std * float(per_rad) * x
        return RecordedDisturbance(dt=self.sample_interval, yaw_moment=jnp.asarray(moment),
                                   sway_force=jnp.zeros(count))


class ClosedLoop(eqx.Module):
    """Closed-loop runs: `t` [s] (N,); heading `psi`, desired heading `psi_d` (the
    reference model's output), ordered heading `psi_ref` [rad], yaw rate `r`, desired
    rate `r_d` [rad/s], actual rudder `delta` and rudder command `delta_c` [rad], each
    (autopilots, speeds, N); `speed` (speeds,) the initial surge speed [m/s];
    `max_rate` [rad/s] and `control_period` [s] of each autopilot; `result`, the `RESULTS`
    code of each run (as `Trajectory.result`), and `success`, `result == successful`."""

    t: Array
    psi: Array
    psi_d: Array
    psi_ref: Array
    r: Array
    r_d: Array
    delta: Array
    delta_c: Array
    speed: Array
    max_rate: Array
    control_period: Array
    result: RESULTS

    @property
    def success(self) -> Array:
        return self.result == RESULTS.successful


def _autopilot_batch(autopilots) -> HeadingAutopilot:
    """One autopilot, a list of them, or a `stack` of them, as a stack."""
    if isinstance(autopilots, (list, tuple)):
        return stack(_one_structure(list(autopilots)))
    if not isinstance(autopilots, HeadingAutopilot):
        raise ValueError(f"`autopilots` must be HeadingAutopilot(s), got "
                         f"{type(autopilots).__name__}.")
    return autopilots if np.ndim(autopilots.kp) == 1 else stack([autopilots])


def _one_structure(autopilots: list) -> list:
    """`autopilots` of one tree structure for `stack`: where some have a feed-forward and
    others none (issue 68: "pid+ff" beside "pid"), those without take the first one's
    `Feedforward` with both gains zero, $\\delta_{ff} = 0\\cdot(\\ldots) + 0\\cdot
    \\delta_s = 0$ (its Newton steps clip the model's rudder to the rudder's limit, so the
    product is an exact zero and the command that of no feed-forward)."""
    present = [a.feedforward for a in autopilots if a.feedforward is not None]
    if not present or len(present) == len(autopilots):
        return autopilots
    zero = lambda x: jnp.zeros_like(jnp.asarray(x, dtype=float))
    off = eqx.tree_at(lambda f: (f.gain, f.steady_gain), present[0],
                      (zero(present[0].gain), zero(present[0].steady_gain)))
    return [a if a.feedforward is not None else dataclasses.replace(a, feedforward=off)
            for a in autopilots]


def initial_states(plant, speeds=None, rpm=None) -> ShipState:
    """Straight runs of `plant` at `speeds` [m/s] or `rpm` (one of them, or neither:
    the nominal approach of a vessel, rest for a steering model), batched. A steering
    model keeps u = speed and n = rpm/60 as constant auxiliary inputs."""
    if speeds is not None and rpm is not None:
        raise ValueError("give `speeds` or `rpm`, not both.")
    n = None if rpm is None else np.atleast_1d(np.asarray(rpm, dtype=float)) / 60.0
    speeds = None if speeds is None else np.atleast_1d(np.asarray(speeds, dtype=float))
    if isinstance(plant, AbstractVessel):
        if speeds is None and n is None:
            return jax.tree.map(lambda a: jnp.asarray(a)[None], straight_run(plant))
        return straight_run(plant, speed=speeds, n=n)
    if not isinstance(plant, AbstractSteeringModel):
        raise ValueError(f"`plant` must be a vessel or a steering model, got "
                         f"{type(plant).__name__}.")
    size = len(speeds if speeds is not None else n if n is not None else [0.0])
    zero = jnp.zeros(size)
    u = zero if speeds is None else jnp.asarray(speeds)
    return ShipState(u=u, v=zero, r=zero, x=zero, y=zero, psi=zero, delta=zero,
                     n=zero if n is None else jnp.asarray(n))


def closed_loop(plant, autopilots, *, speeds=None, rpm=None, duration: float = 300.0,
                dt: float = 0.1, disturbance: YawDisturbance | None = None,
                simulator: Simulator = Simulator(), throw: bool = False) -> ClosedLoop:
    """Run each autopilot on `plant` from straight runs at each of `speeds` [m/s] or
    `rpm` (see `initial_states`) for `duration` [s], output every `dt` [s].

    - `plant`: a vessel (the autopilot's command goes through its rudder servo) or a
      steering model (ideal rudder: the command is the angle; constant auxiliary
      inputs u = speed, v = 0, n = rpm/60).
    - `autopilots`: a `HeadingAutopilot`, a list of them (with and without feed-forward
      alike) or a `jaxship.stack` of them.
    - `disturbance`: an optional `YawDisturbance` (vessels only), one realisation
      shared by all runs.

    One compiled call, vmapped over autopilots x speeds; differentiable in the
    autopilots' gains. `throw`: raise unless every run succeeded (default False: the
    codes in `ClosedLoop.result`). **Returns:** a `ClosedLoop` with axes (autopilots,
    speeds, N).
    """
    setup = _setup(plant, speeds, rpm, duration, dt, disturbance, simulator)
    runs = _closed_loop(setup[0], _as_arrays(_autopilot_batch(autopilots)), *setup[1:])
    return raise_unless_successful(runs, throw)


def _setup(plant, speeds, rpm, duration, dt, disturbance, simulator):
    """What `_closed_loop` needs besides the autopilots: `(plant, x0, dt, num,
    simulator, steps)`, the plant with the disturbance added."""
    x0 = initial_states(plant, speeds, rpm)
    if disturbance is not None:
        if not isinstance(plant, AbstractVessel):
            raise ValueError("`disturbance` acts on vessels only (a yaw moment).")
        plant = augment(plant, disturbance.effect(plant, duration))
    num = int(round(duration / dt)) + 1
    return (_as_arrays(plant), x0, jnp.asarray(dt, float), num, simulator,
            simulator.steps_per_sample(dt))


@persistent  # traced once per installation
@eqx.filter_jit
def _closed_loop(plant, batch, x0, dt, num, simulator, steps):
    one = lambda autopilot, state0: _run(plant, autopilot, state0, dt, num, simulator, steps)
    runs = jax.vmap(jax.vmap(one, in_axes=(None, 0)), in_axes=(0, None))(batch, x0)
    psi, psi_d, psi_ref, r, r_d, delta, delta_c, result = runs
    return ClosedLoop(t=jnp.arange(num) * dt, psi=psi, psi_d=psi_d, psi_ref=psi_ref, r=r,
                      r_d=r_d, delta=delta, delta_c=delta_c, speed=jnp.asarray(x0.u),
                      max_rate=jnp.asarray(batch.max_rate) + 0.0 * batch.kp,
                      control_period=jnp.maximum(batch.interval, dt / steps) + 0.0 * batch.kp,
                      result=result)


def _run(plant, autopilot, x0, dt, num, simulator, steps):
    """One closed-loop run from `x0` at t = 0: the records of `ClosedLoop` and the
    `RESULTS` code."""
    vessel = isinstance(plant, AbstractVessel)
    if vessel:
        y0, base = initial_vector(plant, x0), vessel_field(plant, Environment(), wind=False)
        ship = lambda y, memory: from_vector(y)
    else:
        y0 = jnp.concatenate([plant.initial_state(x0.r), jnp.reshape(x0.psi, (1,))])
        base, zero = steering_field(plant), jnp.zeros_like(x0.u)

        def ship(y, memory):  # ideal rudder: the actual angle is the held command
            return ShipState(u=x0.u, v=zero, r=plant.output(y[:-1]), x=zero, y=zero,
                             psi=y[-1], delta=memory.command, n=x0.n)

    def policy(t, y, memory, h):
        command, new = autopilot.command(t, ship(y, memory), memory, h)
        record = (memory.reference[0], memory.reference[1],
                  memory.origin + autopilot.steps(t + 0.5 * h), command.delta)
        if not vessel:
            held = dict(delta=command.delta, u=x0.u, v=zero, n=x0.n)
            command = Held(held, jax.tree.map(jnp.zeros_like, held))
        return (command, record), new

    def field(t, y, args):
        (inputs, _), t_k = args
        return base(t, y, (inputs, t_k))

    def observe(y, inputs):
        psi_d, r_d, psi_ref, delta_c = inputs[1]
        if vessel:
            return y[5], psi_d, psi_ref, y[2], r_d, y[6], delta_c
        return y[-1], psi_d, psi_ref, plant.output(y[:-1]), r_d, delta_c, delta_c

    out, result = integrate(field, y0, (policy, autopilot.init(x0)), (0.0, dt, num),
                            simulator, steps, observe)
    return (*out, result)


class ClosedLoopMetrics(eqx.Module):
    """Metrics of closed-loop runs, SI units, one value per run (autopilots, speeds):

    - `residual_sum`: thesis eq. 3.19, $\\sum_k|\\psi_d(t_k) - \\psi(t_k)|$ [rad] over the
      samples every `sample_interval` in the window; it scales with 1/`sample_interval`
      (the thesis does not state its sampling; its Tables 5.2-5.7 give 17-185,
      plausibly degrees summed at 1 s over 100-200 s, i.e. `to_dict_deg` with
      `sample_interval=1.0, window=(100, 200)`);
    - `rms_error`: $\\sqrt{\\overline{(\\psi_d - \\psi)^2}}$ [rad] over the same samples;
    - `overshoot`: the largest heading past the final ordered heading after the last
      step, in the direction of the step [rad] (0 if none);
    - `settling_time`: from the last step until the heading stays within 2 % of the
      step size of the final ordered heading [s] (inf if it never does);
    - `mean_abs_rudder` $\\overline{|\\delta|}$ and `rudder_travel` $\\sum|\\Delta\\delta|$
      [rad] of the actual rudder over the window;
    - `time_at_rate_limit` [s]: time the command moved at the autopilot's rate limit
      (from the command's changes between output samples).
    """

    residual_sum: Array
    rms_error: Array
    overshoot: Array
    settling_time: Array
    mean_abs_rudder: Array
    rudder_travel: Array
    time_at_rate_limit: Array
    sample_interval: float = eqx.field(static=True, default=1.0)

    def to_dict_deg(self) -> dict:
        """The metrics as lists, angles in degrees, times in seconds (for JSON)."""
        deg = lambda a: np.degrees(np.asarray(a)).tolist()
        return dict(residual_sum_deg=deg(self.residual_sum), rms_error_deg=deg(self.rms_error),
                    overshoot_deg=deg(self.overshoot),
                    settling_time_s=np.asarray(self.settling_time).tolist(),
                    mean_abs_rudder_deg=deg(self.mean_abs_rudder),
                    rudder_travel_deg=deg(self.rudder_travel),
                    time_at_rate_limit_s=np.asarray(self.time_at_rate_limit).tolist(),
                    sample_interval_s=self.sample_interval)


def closed_loop_metrics(run: ClosedLoop, sample_interval: float = 1.0,
                        window: tuple[float, float] | None = None) -> ClosedLoopMetrics:
    """`ClosedLoopMetrics` of `run`; `sample_interval` [s] (a multiple of the run's
    output interval) samples eq. 3.19, `window` = (start, end) [s] limits the
    residual, RMS and rudder metrics (default: the whole run)."""
    t = np.asarray(run.t)
    dt = float(t[1] - t[0])
    every = int(round(sample_interval / dt))
    # to the rounding of JAX's float type (float32 holds 0.1 s as 0.10000000149 s)
    if every < 1 or abs(every * dt - sample_interval) > every * sampling_tolerance(t, 1e-9):
        raise ValueError(f"`sample_interval` ({sample_interval} s) must be a multiple of the "
                         f"run's output interval ({dt} s).")
    start, end = (t[0], t[-1]) if window is None else window
    inside = (t >= start - 1e-9 * dt) & (t <= end + 1e-9 * dt)
    first = int(np.argmax(inside))
    sampled = np.zeros_like(inside)
    sampled[first::every] = True
    sampled &= inside
    # on the host in NumPy: op by op in JAX, each operation was a program of its own to
    # lower and look up in the compilation cache (55 in `reproduce --quick`; issue 70)
    psi, psi_ref, delta_c = (np.asarray(x, dtype=np.float64)
                             for x in (run.psi, run.psi_ref, run.delta_c))
    error = np.mod(np.asarray(run.psi_d, dtype=np.float64) - psi + np.pi, 2 * np.pi) - np.pi
    pick = lambda a, mask: a[..., np.flatnonzero(mask)]
    final = psi_ref[..., -1:]
    changed = np.abs(np.diff(psi_ref, axis=-1)) > 0
    last = np.max(np.where(changed, np.arange(1, t.size), 0), axis=-1, keepdims=True)
    size = final - np.take_along_axis(psi_ref, np.maximum(last - 1, 0), axis=-1)
    after = np.arange(t.size) >= last
    past = np.where(after, np.sign(size) * (psi - final), 0.0)
    outside = after & (np.abs(psi - final) > 0.02 * np.abs(size))
    j = np.max(np.where(outside, np.arange(t.size), -1), axis=-1)
    t_last = t[last[..., 0]]
    settle = np.where(j < 0, 0.0, t[np.minimum(j + 1, t.size - 1)] - t_last)
    delta = pick(np.asarray(run.delta, dtype=np.float64), inside)
    command = pick(delta_c, inside)
    period = np.maximum(dt, np.asarray(run.control_period, dtype=np.float64))
    limit = (np.asarray(run.max_rate, dtype=np.float64) * period)[:, None, None]
    moved = np.abs(np.diff(command, axis=-1)) >= (1 - 1e-6) * limit
    return ClosedLoopMetrics(
        residual_sum=np.sum(np.abs(pick(error, sampled)), axis=-1),
        rms_error=np.sqrt(np.mean(pick(error, sampled) ** 2, axis=-1)),
        overshoot=np.maximum(np.max(past, axis=-1), 0.0),
        settling_time=np.where(j >= t.size - 1, np.inf, settle),
        mean_abs_rudder=np.mean(np.abs(delta), axis=-1),
        rudder_travel=np.sum(np.abs(np.diff(delta, axis=-1)), axis=-1),
        time_at_rate_limit=np.sum(moved, axis=-1) * period[:, None],
        sample_interval=float(sample_interval),
    )


def tracking_objective(run: ClosedLoop, rudder_weight: float = 0.1) -> Array:
    """The tuning objective of `tune_autopilot`: $\\overline{\\tilde\\psi^2} + w\\,
    \\overline{\\delta_c^2}$ [rad^2], means over all runs and samples, $\\tilde\\psi =
    \\mathrm{ssa}(\\psi_d - \\psi)$, $w$ = `rudder_weight`."""
    return jnp.mean(ssa(run.psi_d - run.psi) ** 2) + rudder_weight * jnp.mean(run.delta_c**2)
