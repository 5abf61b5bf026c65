"""Reproduction of Astrom & Kallstrom (1979): the Sea Stratus cross-flow model identified
from zig-zag trials with disturbances, prediction error with a horizon against output
error.

The "measured" trials are simulations of the `sea_stratus_nonlinear` vessel (Table 3,
nonlinear column, C = 0.63) through closed-loop 5/5 and 20/20 zig-zags with

- **process noise**: a random yaw moment $N_w = \\tfrac12\\rho L^3 V^2 N'_\\delta w(t)$,
  i.e. the moment of an unmeasured rudder angle $w$ [rad], a first-order Gauss-Markov
  sequence (standard deviation `yaw_noise`, time constant `yaw_noise_time`) held over
  each sample interval (a stand-in for the wind and wave moments of section 2,
  "Disturbances");
- **measurement noise**: white Gaussian noise on the heading, yaw rate and sway
  velocity; the rudder angle and the surge speed are recorded exactly.

The steering model `NorrbinCrossFlow` (the same equations as the vessel, eq. 3 plus
the cross-flow drag) is then fitted to psi, r and v with the report's start values
(Table 3, "Initial estim."; N'_delta is missing there and starts at -0.00100) and the
mass terms frozen at the vessel's, by output error and by prediction error with the
report's horizon $T_p = 60$ s. The report's findings (section 4) are that prediction
error with a suitable horizon is superior to output error under disturbances.
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxship as js


DEG = math.pi / 180.0
FREE = ("y_v", "y_r", "n_v", "n_r", "y_delta", "n_delta", "cross_flow")
# Table 3, "Initial estim." column (jaxship rudder sign); N'_delta is not in the scan
TABLE3_START = dict(y_v=-0.00687, y_r=-0.00724, n_v=-0.00254, n_r=-0.00161,
                    y_delta=-0.00201, n_delta=0.00100, cross_flow=0.7)


def simulate_disturbed(vessel, manoeuvre, x0, yaw_moment, *, sway_force=None,
                       simulator=js.Simulator()):
    """`jaxship.simulate` of `vessel` with a disturbance force `sway_force[k]` [N] and
    moment `yaw_moment[k]` [N m] held over sample interval k (arrays of
    `manoeuvre.num_samples`): the vessel with a `RecordedDisturbance` effect."""
    yaw_moment = jnp.asarray(yaw_moment, dtype=float)
    sway_force = jnp.zeros_like(yaw_moment) if sway_force is None else jnp.asarray(
        sway_force, dtype=float)
    disturbance = js.effects.RecordedDisturbance(manoeuvre.dt, yaw_moment, sway_force,
                                         start=manoeuvre.start)
    return js.simulate(js.augment(vessel, disturbance), manoeuvre, x0, simulator=simulator)


@dataclasses.dataclass(frozen=True)
class NoiseLevels:
    """Disturbance and sensor noise of the synthetic trials (see the module docstring).

    `yaw_noise` [rad]: standard deviation of the equivalent rudder angle of the random
    yaw moment; `yaw_noise_time` [s]: its correlation time; `psi`, `r`, `v`: standard
    deviations of the white measurement noise [rad, rad/s, m/s]."""

    yaw_noise: float = 0.5 * DEG
    yaw_noise_time: float = 20.0
    psi: float = 0.05 * DEG
    r: float = 0.002 * DEG
    v: float = 0.01


def zigzag_trial(vessel, angle: float, *, duration: float, dt: float = 1.0,
                 noise: NoiseLevels = NoiseLevels(), seed: int = 0, name: str | None = None,
                 oversample: int = 10) -> js.Experiment:
    """A `angle`/`angle` zig-zag [rad] of `vessel` from its straight run at the nominal
    speed, with the process and measurement noise of `noise` drawn from `seed`, sampled
    every `dt` [s].

    The ship is simulated (`simulate_disturbed`, RK4) at `dt / oversample` with the
    rudder servo of the vessel (rate-limited, so the rudder ramps); the yaw moment is
    held over each record interval. The recorded rudder `delta[k]` is the servo angle
    at the sample times, as a logged angle is; `fit` replays it linearly between the
    samples (first-order hold), which follows the ramps. `delta_c` is the command, the
    extra signal `yaw_disturbance` the equivalent rudder angle $w$ [rad] of the moment.
    """
    rng = np.random.default_rng(seed)
    fine_dt = dt / oversample
    man = js.ZigZag(angle=angle, heading=angle, duration=duration, dt=fine_dt)
    num = int(round(duration / dt)) + 1
    a = math.exp(-dt / noise.yaw_noise_time)
    e = rng.standard_normal(num)
    w = np.empty(num)
    w[0] = noise.yaw_noise * e[0]
    for k in range(1, num):
        w[k] = a * w[k - 1] + math.sqrt(1 - a * a) * noise.yaw_noise * e[k]
    V, L = vessel.nominal_speed, vessel.length
    moment = 0.5 * vessel.rho * L**3 * V**2 * vessel.n_delta * w
    fine_moment = np.repeat(moment, oversample)[: man.num_samples]
    x0 = js.straight_run(vessel)
    traj = simulate_disturbed(vessel, man, x0, jnp.asarray(fine_moment))
    every = slice(0, (num - 1) * oversample + 1, oversample)
    s = jax.tree.map(lambda a: np.asarray(a)[every], traj.state)
    t, delta = np.asarray(traj.t)[every], s.delta
    noisy = lambda x, sd: np.asarray(x) + sd * rng.standard_normal(num)
    return js.Experiment(
        t, delta, psi=noisy(s.psi, noise.psi),
        r=noisy(s.r, noise.r), u=np.asarray(s.u), v=noisy(s.v, noise.v),
        delta_c=np.asarray(traj.command.delta)[every],
        name=name or f"zigzag {angle / DEG:g}/{angle / DEG:g}",
        metadata=dict(seed=seed), extra={"yaw_disturbance": w},
    )


@dataclasses.dataclass(frozen=True)
class AstromRow:
    """One fit of the reproduction: data, method, estimates with both standard errors,
    the errors in standard errors, fit % per channel of the simulated model, loss."""

    data: str
    method: str
    success: bool
    values: np.ndarray
    std: np.ndarray  # from fit: white-residual covariance
    robust_std: np.ndarray  # from fit: Newey-West (HAC) standard errors
    z: np.ndarray  # (estimate - truth) / std
    z_robust: np.ndarray  # (estimate - truth) / robust_std
    simulation_fit: dict  # {channel: fit %} of the fitted model simulated from the start
    validation_fit: dict  # {channel: fit %} simulated on a noise-free 10/10 zig-zag
    fit: dict  # {channel: fit %} of the estimator's own predictions
    loss: dict  # {channel: V_N} of the estimator's own residuals


def _simulate_fit(model, exp: js.Experiment) -> dict:
    """Fit % of the fitted model simulated over the whole record (replayed rudder and
    speed) against the noisy measurements, psi, r and v."""
    x0 = dataclasses.replace(js.straight_state(0.0, psi=exp.psi[0]), r=exp.r[0], v=exp.v[0])
    tr = js.simulate(model, js.Replay(exp.delta, dt=exp.dt,
                                              delta_hold=js.strategies.FirstOrderHold()), x0,
                     aux=js.AuxInputs(u=exp.u, v=exp.v, n=exp.n),
                     simulator=js.Simulator(max_step=math.inf))
    return {"psi": js.fit_percent(exp.psi, np.asarray(tr.state.psi)),
            "r": js.fit_percent(exp.r, np.asarray(tr.state.r)),
            "v": js.fit_percent(exp.v, np.asarray(tr.internal[:, 1]))}


def astrom_kallstrom(*, noise: NoiseLevels = NoiseLevels(), seed: int = 0, dt: float = 1.0,
                     horizon: float = 60.0, start: dict | None = None,
                     durations=(1800.0, 1800.0), max_steps: int = 200) -> dict:
    """Run the reproduction; returns `{"truth": dict, "rows": [AstromRow], "data":
    {name: Experiment}}`.

    Fits `NorrbinCrossFlow` (free: the six derivatives and C) to the 5/5 zig-zag, the
    20/20 zig-zag and both together, by output error (`horizon=None`) and prediction
    error (`horizon` [s]), channels psi, r, v, from `start` (default: Table 3's initial
    estimates, `TABLE3_START`).
    """
    vessel = js.get_vessel("sea_stratus_nonlinear")
    truth_model = js.NorrbinCrossFlow.from_vessel(vessel)
    truth = np.array([getattr(truth_model, k) for k in FREE])
    start_model = eqx.tree_at(lambda m: tuple(getattr(m, k) for k in FREE), truth_model,
                              tuple(float((start or TABLE3_START)[k]) for k in FREE))
    five = zigzag_trial(vessel, 5 * DEG, duration=durations[0], dt=dt, noise=noise,
                        seed=seed, name="zigzag 5/5")
    twenty = zigzag_trial(vessel, 20 * DEG, duration=durations[1], dt=dt, noise=noise,
                          seed=seed + 1, name="zigzag 20/20")
    quiet = NoiseLevels(yaw_noise=0.0, psi=0.0, r=0.0, v=0.0)
    validation = zigzag_trial(vessel, 10 * DEG, duration=durations[0], dt=dt, noise=quiet,
                              name="zigzag 10/10 (noise-free validation)")
    sets = {"5/5": [five], "20/20": [twenty], "both": [five, twenty]}
    rows = []
    for label, exps in sets.items():
        ds = js.Dataset.from_experiments(exps)
        for method, h in (("output error", None), (f"PE T_p = {horizon:g} s", horizon)):
            est = js.PredictionError(horizon=h, channels=("psi", "r", "v"),
                                     max_steps=max_steps)
            res = js.fit(start_model, ds, estimator=est, free=FREE)
            robust = res.parameters.std_robust
            sim = [_simulate_fit(res.model, e) for e in exps]
            rows.append(AstromRow(
                data=label, method=method, success=res.success, values=res.values,
                std=res.std, robust_std=robust, z=(res.values - truth) / res.std,
                z_robust=(res.values - truth) / robust,
                simulation_fit={c: float(np.mean([s[c] for s in sim])) for c in sim[0]},
                validation_fit=_simulate_fit(res.model, validation),
                fit={c: m.fit_percent for c, m in res.metrics.items()},
                loss={c: m.loss for c, m in res.metrics.items()},
            ))
    return {"truth": dict(zip(FREE, truth)), "rows": rows,
            "data": {e.name: e for e in (five, twenty, validation)}}


def table(result: dict) -> str:
    """The reproduction as a Markdown table: estimate ± standard error of `fit`
    [HAC standard error] per parameter; the largest |estimate - truth| in HAC
    standard errors; fit % of psi of the
    estimator's own predictions, of the fitted model simulated over the training
    records and over the noise-free 10/10 validation zig-zag; and the loss of psi."""
    names = list(result["truth"])
    head = ("| data | method | " + " | ".join(names) + " | max abs error / std | fit % psi "
            "(estimator) | fit % psi (simulation) | fit % psi (validation) | loss psi |")
    lines = [head, "|" + " --- |" * (len(names) + 7)]
    lines.append("| truth | Table 3 | " + " | ".join(f"{result['truth'][k]:.5g}"
                                                  for k in names) + " | | | | | |")
    for row in result["rows"]:
        cells = []
        for v, s, rs in zip(row.values, row.std, row.robust_std):
            extra = "" if not np.isfinite(rs) else f" [{rs:.2g}]"
            cells.append(f"{v:.5g} ± {s:.2g}{extra}")
        z = row.z_robust if np.all(np.isfinite(row.z_robust)) else row.z
        lines.append(
            f"| {row.data} | {row.method}{'' if row.success else ' (not converged)'} | "
            + " | ".join(cells) + f" | {np.max(np.abs(z)):.2f} | {row.fit['psi']:.2f} | "
            f"{row.simulation_fit['psi']:.2f} | {row.validation_fit['psi']:.2f} | "
            f"{row.loss['psi']:.3g} |")
    return "\n".join(lines)
