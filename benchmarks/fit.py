"""Fitting a 3-DOF vessel: jaxship's Levenberg-Marquardt against SciPy.

Problem: the thesis vessel (`get_vessel("thesis")`, a Ross-type 3-DOF model of the
4 m DTMB 5415 model) with 20 free coefficients (`FREE` below: added masses, surge
resistance and propeller, linear and cross-flow hull damping, rudder) identified from
16 experiments, 8 manoeuvres (turns to both sides, 10/10 and 20/20 zig-zags, a
shortened thesis manoeuvre, PRBS, 3-2-1-1 and pull-out) at 200 and 500 rpm, 0.1 s
samples, about 21,000 samples in all. The data are simulated by `jaxship.simulate`
with 4 RK4 substeps per sample (so neither fit's integrator is the data's; the zig-zags
reverse the rudder at the sample nearest the heading crossing,
`switch_at=js.strategies.SwitchAtNearestStep()`, so that the command both fits replay, held over
each sample, is the data's) and get white measurement noise (0.02 deg heading,
0.01 deg/s yaw rate, 1 mm/s in u and v; the windows start from these noisy states, so
the estimates carry a small errors-in-variables bias, the same for both fits).

Both fits minimise the same residuals from the same start (every coefficient 10-30 %
off): prediction error with a 10 s horizon (each window restarts from the measured
u, v, r, psi and rudder angle), the recorded rudder command replayed through the
rudder servo (held over each interval) and the measured propeller rate interpolated
linearly between samples (jaxship's default holds; the rate is constant within each
experiment here), channels psi, r, u, v weighted by 1/std of the measured channel
(within-experiment mean removed, pooled); parameters scaled by their start magnitudes.
The SciPy side rebuilds these windows and weights in plain NumPy (`ScipyProblem`).

- jaxship: `jaxship.fit(vessel, data, estimator=PredictionError(horizon=10.0,
  rudder="delta_c", max_steps=500), free=FREE)`: its default solver, optimistix's LM
  with Nielsen's damping update and MINPACK's cost test
  (`jaxship.LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-10)`: it stops once an
  accepted step lowers the cost by at most 1e-10 relative, SciPy's `ftol` below),
  forward-mode Jacobian through the fixed-step RK4 scan, vmapped over all windows. Timed
  with compilation (first call in the process) and without (second call, same start).
- SciPy: `scipy.optimize.least_squares(method="lm")` (MINPACK LM) with forward finite
  differences (`diff_step=1e-6`), residuals by `scipy.integrate.solve_ivp` (RK45,
  rtol 1e-9, atol 1e-12) on a right-hand side written in NumPy (checked against
  `jaxship.state_derivative` at random states below). To be fair to SciPy, each
  call of `solve_ivp` integrates *all windows at once* (one vectorised state of
  5 x windows) over one sample interval, the rudder command held and the
  propeller rate linear in time (no discontinuities inside a call): 100 calls per
  residual evaluation.
  SciPy gets a wall-clock budget (`--budget`, default 1800 s); if it runs out, the best
  point so far is reported as such.

Prints the timings, final costs (1/2 sum of squared weighted residuals, evaluated
for both estimates with the same residual function), the parameter errors and the
ratios, and the LM step at which jaxship's cost passed SciPy's final cost (a third run
of the fit with a progress callback, compiled again, timed from its start). `--quick`
uses 4 experiments and 10 coefficients. Run:
`python benchmarks/fit.py [--budget 1800] [--quick]`.
"""

import argparse
import time

import jax


jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402
from scipy.optimize import least_squares  # noqa: E402

import jaxship as js  # noqa: E402


DEG = np.pi / 180
FREE = ("x_udot", "y_vdot", "n_rdot", "x_uu", "x_uuu", "x_vv", "y_uv", "y_ur", "y_absv_v",
        "y_absr_v", "n_uv", "n_ur", "n_absv_r", "n_absr_r", "kt0", "kt1", "rudder_area",
        "stall_angle", "flow_straightening", "race_kappa")
QUICK_FREE = ("x_uu", "y_uv", "y_ur", "y_absv_v", "n_uv", "n_ur", "n_absr_r", "kt0",
              "rudder_area", "flow_straightening")
HORIZON = 10.0
NOISE = {"psi": 0.02 * DEG, "r": 0.01 * DEG, "u": 0.001, "v": 0.001}


def manoeuvres(rpm):
    n = rpm / 60.0
    return [
        ("turn35", js.Turn(35 * DEG, duration=120.0, execute=5.0, n=n)),
        ("turn-20", js.Turn(-20 * DEG, duration=120.0, execute=5.0, n=n)),
        ("zigzag10", js.ZigZag(10 * DEG, 10 * DEG, duration=150.0, n=n,
                               switch_at=js.strategies.SwitchAtNearestStep())),
        ("zigzag-20", js.ZigZag(-20 * DEG, 20 * DEG, duration=150.0, n=n,
                                switch_at=js.strategies.SwitchAtNearestStep())),
        ("thesis", js.thesis_manoeuvre((10, 25), hold_per_deg=1.0, ramp_deg_per_s=1.0,
                                       end_hold=20.0, n=n)),
        ("prbs", js.prbs(15 * DEG, 5.0, 150.0, n=n)),
        ("3211", js.multi_step_3211(15 * DEG, 8.0, settle=40.0, n=n)),
        ("pullout", js.pull_out(25 * DEG, 60.0, 60.0, n=n)),
    ]


def make_data(vessel, quick, seed=0):
    rng = np.random.default_rng(seed)
    sim = js.Simulator(substeps=4)
    out = []
    for rpm in (200, 500):
        for name, man in manoeuvres(rpm):
            if quick and name not in ("zigzag-20", "prbs"):
                continue
            tr = js.simulate(vessel, man, js.straight_run(vessel, n=rpm / 60.0), simulator=sim)
            e = js.Experiment.from_trajectory(tr, name=f"{name}@{rpm}")
            noisy = {c: getattr(e, c) + s * rng.standard_normal(e.num_samples)
                     for c, s in NOISE.items()}
            out.append(js.Experiment(e.t, e.delta, delta_c=e.delta_c, n=e.n, name=e.name,
                                     **noisy))
    return out


def with_values(vessel, names, values):
    return eqx.tree_at(lambda m: [getattr(m, k) for k in names], vessel,
                       [float(v) for v in values])


# ------------------------------------------------------------------ NumPy model for SciPy


class NumpyRoss:
    """The thesis vessel's equations (jaxship/_vessel/ross.py docstring, Ross 2008 /
    thesis eq. 2.13-2.20) re-written in NumPy, vectorised over the last axis."""

    def __init__(self, vessel, names=(), values=()):
        self.c = {f: getattr(vessel, f) for f in js.RossVessel.__dataclass_fields__
                  if isinstance(getattr(vessel, f), (int, float))}
        self.c.update(dict(zip(names, values)))
        self.servo = vessel.rudder
        c = self.c
        m, xg = c["mass"], c["xg"]
        M = np.array([[m - c["x_udot"], 0, 0],
                      [0, m - c["y_vdot"], m * xg - c["y_rdot"]],
                      [0, m * xg - c["y_rdot"], c["iz"] - c["n_rdot"]]])
        self.minv = np.linalg.inv(M)

    def forces(self, u, v, r, delta, n):
        c = self.c
        m, xg, D, rho = c["mass"], c["xg"], c["prop_diameter"], c["rho"]
        au, av, ar = np.abs(u), np.abs(v), np.abs(r)
        X = m * (v * r + xg * r**2) - (c["y_vdot"] * v + c["y_rdot"] * r) * r
        Y = -m * u * r + c["x_udot"] * u * r
        N = -m * xg * u * r + (c["y_vdot"] - c["x_udot"]) * u * v + c["y_rdot"] * u * r
        X = X + c["x_uu"] * au * u + c["x_uuu"] * u**3 + c["x_vv"] * v**2 * np.tanh(
            u / c["u_sigma"])
        terms = lambda p: (c[p + "uv"] * au * v + c[p + "ur"] * au * r + c[p + "uuv"] * u**2 * v
                           + c[p + "uur"] * u**2 * r + c[p + "vvv"] * v**3
                           + c[p + "rrr"] * r**3 + c[p + "vvr"] * v**2 * r
                           + c[p + "rrv"] * r**2 * v + c[p + "absv_v"] * av * v
                           + c[p + "absr_v"] * ar * v + c[p + "absv_r"] * av * r
                           + c[p + "absr_r"] * ar * r)
        Y, N = Y + terms("y_"), N + terms("n_")
        ua = (1 - c["wake"]) * u
        thrust = rho * D**4 * (c["kt0"] * n * np.abs(n) + c["kt1"] * np.abs(n) * ua / D
                               + c["kt2"] * ua * np.abs(ua) / D**2)
        X = X + c["n_propellers"] * (1 - c["thrust_deduction"]) * thrust
        race = np.sqrt(ua**2 + 8 * np.maximum(thrust, 0) / (np.pi * rho * D**2) + 1e-20)
        u_r = c["race_epsilon"] * ((1 - c["race_kappa"]) * ua + c["race_kappa"] * race)
        v_r = c["flow_straightening"] * (v + c["x_rudder"] * r)
        alpha = delta + np.arctan2(v_r, u_r)
        a_s, w = c["stall_angle"], c["stall_width"]
        s = 0.5 * (1 + np.tanh((alpha**2 - a_s**2) / (2 * a_s * w)))
        cn = np.sin(alpha) * (c["lift_slope"] * (1 - s) + c["normal_force_90"] * s)
        fn = 0.5 * rho * c["rudder_area"] * (u_r**2 + v_r**2) * cn
        X = X - fn * np.sin(delta)
        Y = Y - fn * np.cos(delta)
        N = N - c["x_rudder"] * fn * np.cos(delta)
        return X, Y, N

    def rhs(self, y, delta_c, n):
        """d(u, v, r, psi, delta)/dt, y of shape (5, ...): servo-driven rudder."""
        u, v, r, psi, delta = y
        tau = self.forces(u, v, r, delta, n)
        nudot = [sum(self.minv[i, j] * tau[j] for j in range(3)) for i in range(3)]
        servo = self.servo
        target = np.clip(delta_c, -servo.max_angle, servo.max_angle)
        ddot = np.clip((target - delta) / servo.time_constant, -servo.max_rate, servo.max_rate)
        return np.stack([nudot[0], nudot[1], nudot[2], r, ddot])


def check_rhs(vessel, rng, count=200):
    """Largest relative difference of the NumPy right-hand side from jaxship's."""
    model = NumpyRoss(vessel)
    worst = 0.0
    for _ in range(count):
        s = js.ShipState(u=rng.uniform(-0.5, 2.0), v=rng.uniform(-0.4, 0.4),
                         r=rng.uniform(-0.4, 0.4), x=0.0, y=0.0, psi=rng.uniform(-3, 3),
                         delta=rng.uniform(-0.8, 0.8), n=rng.uniform(-3.0, 10.0))
        cmd = js.Command(delta=rng.uniform(-0.8, 0.8), n=s.n)
        d = js.state_derivative(vessel, s, cmd, js.Environment())
        ref = np.array([d.u, d.v, d.r, d.psi, d.delta], dtype=float)
        y = np.array([s.u, s.v, s.r, s.psi, s.delta])
        got = model.rhs(y, cmd.delta, s.n)
        worst = max(worst, float(np.max(np.abs(got - ref) / (np.abs(ref) + 1e-12))))
    return worst


def channel_weights(data, channels):
    """1/std of each measured channel: the deviations from each experiment's own mean,
    pooled over all samples of all experiments (jaxship's default weights)."""
    out = []
    for c in channels:
        dev = np.concatenate([getattr(e, c) - np.mean(getattr(e, c)) for e in data])
        var = float(np.mean(dev**2))
        out.append(1.0 / np.sqrt(var) if var > 0 else 1.0)
    return np.array(out)


class ScipyProblem:
    """The prediction-error residuals of the fit, with solve_ivp on the NumPy model.

    The windows are jaxship's definition, rebuilt here in NumPy: per experiment of N
    samples at interval dt, L = round(HORIZON / dt) clipped to [1, N - 1]; windows
    start at samples 0, L, 2L, ... while the start is < N - 1; each starts from the
    measured u, v, r, psi and rudder angle delta at its start sample and predicts
    samples start + 1 .. start + L that exist (every sample but the first is predicted
    once). Windows of all experiments are stacked to (B, L_max) with a mask.
    Inputs: the commanded rudder `delta_c` is held over each interval (zero-order
    hold, jaxship's default for a command) and drives the servo; the measured
    propeller rate `n` is interpolated linearly between samples (first-order hold,
    jaxship's default for measured signals) -- constant within each experiment here,
    so the hold makes no difference."""

    CHANNELS = ("psi", "r", "u", "v")
    STATE = ("u", "v", "r", "psi", "delta")  # the NumPy model's state order

    def __init__(self, vessel, data, names, scale):
        self.vessel, self.names, self.scale = vessel, names, np.asarray(scale)
        self.dt = float(data[0].dt)
        assert all(np.isclose(e.dt, self.dt) for e in data), "one sample interval"
        lengths = [min(max(int(round(HORIZON / e.dt)), 1), e.num_samples - 1) for e in data]
        num_l = max(lengths)
        k = np.arange(num_l)
        y0, delta_c, n, targets, mask, where = [], [], [], [], [], []
        for i, (e, length) in enumerate(zip(data, lengths)):
            last = e.num_samples - 1
            for s in range(0, last, length):
                y0.append([getattr(e, c)[s] for c in self.STATE])
                valid = (k < length) & (s + 1 + k <= last)
                target = np.minimum(s + 1 + k, last)  # beyond the end the last sample holds
                delta_c.append(e.delta_c[np.minimum(s + k, last)])  # interval starts
                n.append(e.n[np.minimum(s + np.arange(num_l + 1), last)])  # and its end
                targets.append([getattr(e, c)[target] for c in self.CHANNELS])
                mask.append(valid)
                where.append((i, target))
        self.y0 = np.array(y0).T  # (5, B)
        self.delta_c = np.array(delta_c)  # (B, L)
        self.n = np.array(n)  # (B, L + 1)
        self.targets = np.moveaxis(np.array(targets), 1, 0)  # (4, B, L)
        self.mask = np.array(mask)  # (B, L)
        self.where = where
        self.lengths = [e.num_samples for e in data]
        self.weights = channel_weights(data, self.CHANNELS)
        self.nfev = 0

    def predict(self, values):
        """(5, B, L) predicted states at the window samples."""
        model = NumpyRoss(self.vessel, self.names, values)
        y = self.y0.copy()
        out = np.empty((y.shape[0],) + self.mask.shape)
        size, dt = y.size, self.dt
        for k in range(self.mask.shape[1]):
            dc, n0, n1 = self.delta_c[:, k], self.n[:, k], self.n[:, k + 1]
            sol = solve_ivp(lambda t, z: model.rhs(z.reshape(5, -1), dc,
                                                   n0 + (n1 - n0) * (t / dt)).reshape(-1),
                            (0.0, dt), y.reshape(size), method="RK45", rtol=1e-9,
                            atol=1e-12)
            y = sol.y[:, -1].reshape(5, -1)
            out[:, :, k] = y
        return out

    def timeline(self, values):
        """{channel: (E, N) predictions} on the samples, as jaxship's FitResult."""
        pred = self.predict(values)
        out = {c: np.zeros((len(self.lengths), max(self.lengths))) for c in self.CHANNELS}
        for b, (i, target) in enumerate(self.where):
            m = self.mask[b]
            for c in self.CHANNELS:
                out[c][i, target[m]] = pred[self.STATE.index(c), b, m]
        return out

    def residuals(self, z):
        self.nfev += 1
        pred = self.predict(z * self.scale)
        order = [self.STATE.index(c) for c in self.CHANNELS]
        res = self.weights[:, None, None] * (self.targets - pred[order])
        return res[:, self.mask].reshape(-1)


class Budget(Exception):
    pass


def run_scipy(problem, z0, budget):
    best = {"cost": np.inf, "z": z0, "t": 0.0}
    start = time.perf_counter()

    def fun(z):
        if time.perf_counter() - start > budget:
            raise Budget
        res = problem.residuals(z)
        cost = 0.5 * float(res @ res)
        if cost < best["cost"]:
            best.update(cost=cost, z=z.copy(), t=time.perf_counter() - start)
        return res

    try:
        sol = least_squares(fun, z0, method="lm", diff_step=1e-6, ftol=1e-10, xtol=1e-10,
                            gtol=1e-10, max_nfev=100000)
        return sol.x, time.perf_counter() - start, True, sol.status, best
    except Budget:
        return best["z"], time.perf_counter() - start, False, None, best


def main(args):
    truth_vessel = js.get_vessel("thesis")
    names = QUICK_FREE if args.quick else FREE
    truth = np.array([getattr(truth_vessel, k) for k in names])
    rng = np.random.default_rng(1)
    print(f"NumPy RHS vs jaxship state_derivative, 200 random states: max relative "
          f"difference {check_rhs(truth_vessel, rng):.2e}")
    data = make_data(truth_vessel, args.quick)
    samples = sum(e.num_samples for e in data)
    print(f"{len(data)} experiments, {samples} samples, {len(names)} free coefficients, "
          f"horizon {HORIZON} s")
    factors = 1 + rng.choice([-1, 1], len(names)) * rng.uniform(0.1, 0.3, len(names))
    start = truth * factors
    start_vessel = with_values(truth_vessel, names, start)
    est = js.PredictionError(horizon=HORIZON, rudder="delta_c", max_steps=500)

    def jax_fit(estimator=est):
        t = time.perf_counter()
        res = js.fit(start_vessel, data, estimator=estimator, free=names)
        return res, time.perf_counter() - t

    res, t_first = jax_fit()
    res2, t_second = jax_fit()
    assert np.array_equal(res.values, res2.values)
    print(f"jaxship: {res.message}, {res.num_steps} LM steps; {t_first:.2f} s with "
          f"compilation, {t_second:.2f} s without")
    # the option: geodesic acceleration (a program of its own, so it compiles again)
    geodesic = eqx.tree_at(lambda e: e.solver.geodesic, est, True)
    (res_g, t_g1), (_, t_g2) = jax_fit(geodesic), jax_fit(geodesic)
    print(f"jaxship with LevenbergMarquardt(geodesic=True): {res_g.message}, "
          f"{res_g.num_steps} LM steps, cost {res_g.cost:.9f} (default: {res.cost:.9f}); "
          f"{t_g1:.2f} s with compilation, {t_g2:.2f} s without")

    scale = np.abs(start)
    problem = ScipyProblem(truth_vessel, data, names, scale)
    r_sp = problem.residuals(res.values / scale)
    cost_jax_sp = 0.5 * float(r_sp @ r_sp)
    pred_sp = problem.timeline(res.values)
    worst = max(float(np.max(np.abs(pred_sp[c] - res.predictions[c])[res.predicted]))
                * res.weights[c] for c in ("psi", "r", "u", "v"))
    print(f"same residuals: at the jaxship estimate the SciPy and jaxship predictions differ "
          f"by at most {worst:.2e} (in units of the channel's std; RK45 vs RK4 "
          f"discretisation); cost {res.cost:.6f} (jaxship, RK4) vs {cost_jax_sp:.6f} (SciPy "
          f"residual function, RK45)")
    t = time.perf_counter()
    problem.residuals(start / scale)
    t_eval = time.perf_counter() - t
    print(f"SciPy: one residual evaluation {t_eval:.2f} s; a finite-difference Jacobian "
          f"costs {len(names)} more")
    problem.nfev = 0
    z, t_sp, converged, status, best = run_scipy(problem, start / scale, args.budget)
    values_sp = z * scale
    r = problem.residuals(z)
    cost_sp = 0.5 * float(r @ r)
    state = (f"converged (status {status})" if converged else
             f"did NOT converge within the {args.budget:.0f} s budget (best point so far, "
             f"reached at {best['t']:.0f} s)")
    print(f"SciPy: {state}, {problem.nfev - 1} residual evaluations, {t_sp:.1f} s")

    # the LM steps once more, each accepted step's cost and time recorded (a progress
    # callback: a program of its own, so this run compiles again): when did jaxship pass
    # SciPy's final cost? (own residuals; at the estimate the two residual functions differ
    # by the RK4 / RK45 gap printed above)
    steps = []
    t0 = time.perf_counter()
    js.fit(start_vessel, data, estimator=est, free=names,
           progress=lambda p: p.cost is not None and not p.done and steps.append(
               (time.perf_counter() - t0, p.step, p.cost)))
    passed = next(((t, k) for t, k, c in steps if c <= cost_sp), None)
    if passed:
        print(f"jaxship passed SciPy's final cost ({cost_sp:.6f}) at LM step {passed[1]} of "
              f"{res.num_steps}, {passed[0]:.2f} s into a run with compilation "
              f"({t_sp / passed[0]:.1f}x SciPy's whole fit)")
    else:
        print(f"jaxship's cost stayed above SciPy's final cost ({cost_sp:.6f})")

    err = lambda v: np.abs(v / truth - 1)
    print()
    print(f"{'':26}{'jaxship':>14}{'SciPy':>14}{'SciPy/jaxship':>15}")
    print(f"{'time incl. compilation [s]':26}{t_first:14.2f}{t_sp:14.1f}{t_sp / t_first:15.1f}")
    print(f"{'time excl. compilation [s]':26}{t_second:14.2f}{t_sp:14.1f}"
          f"{t_sp / t_second:15.1f}")
    print(f"{'  geodesic=True, incl.':26}{t_g1:14.2f}{t_sp:14.1f}{t_sp / t_g1:15.1f}")
    print(f"{'  geodesic=True, excl.':26}{t_g2:14.2f}{t_sp:14.1f}{t_sp / t_g2:15.1f}")
    print(f"{'final cost (SciPy resid.)':26}{cost_jax_sp:14.6f}{cost_sp:14.6f}"
          f"{cost_sp / cost_jax_sp:15.4f}")
    print(f"{'final cost (own resid.)':26}{res.cost:14.6f}{cost_sp:14.6f}")
    print(f"{'max rel. param. error':26}{err(res.values).max():14.3e}"
          f"{err(values_sp).max():14.3e}{err(values_sp).max() / err(res.values).max():15.2f}")
    print(f"{'rms rel. param. error':26}{np.sqrt(np.mean(err(res.values) ** 2)):14.3e}"
          f"{np.sqrt(np.mean(err(values_sp) ** 2)):14.3e}")
    print()
    print(f"{'parameter':>18}{'truth':>13}{'start':>13}{'jaxship':>13}{'+- std':>11}"
          f"{'SciPy':>13}")
    for i, k in enumerate(names):
        print(f"{k:>18}{truth[i]:13.5g}{start[i]:13.5g}{res.values[i]:13.5g}"
              f"{res.std[i]:11.2g}{values_sp[i]:13.5g}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budget", type=float, default=1800.0,
                        help="wall-clock budget of the SciPy fit [s]")
    parser.add_argument("--quick", action="store_true", help="4 experiments, 10 coefficients")
    main(parser.parse_args())
