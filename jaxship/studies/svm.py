"""Reproduction of Lu & Zhao (2008; seed 002) on a simulated vessel, and an
experiment-design comparison of standard manoeuvres by Cramer-Rao bounds.

`svm_response_study`: the four discrete response models (eqs. 7-10) fitted by least
squares and by epsilon-SVR to a 20/20 zig-zag of a simulated vessel (the paper's
free-running model test replaced by the simulation), their predicted first and
second overshoots against the "test" (Table 1 form), the consistency of the indices
across the four (Tables 2-4 form) and the prediction of an untrained 10/10 zig-zag
and a turning circle (sec. 3.2).

`design_study`: Fisher information of turning circle, zig-zag, PRBS, 3-2-1-1 and the
thesis manoeuvre for Nomoto 1 and 2 models of a vessel (thesis sec. 3.3.2).
"""

import dataclasses
import math

import equinox as eqx
import numpy as np

import jaxship as js


DEG = np.pi / 180.0
STRUCTURES = ("linear1", "nonlinear1", "linear2", "nonlinear2")  # Lu & Zhao eqs. 7-10


def _run(vessel, manoeuvre, x0):
    traj = js.simulate(vessel, manoeuvre, x0, simulator=js.Simulator(substeps=2))
    if not bool(traj.success):
        raise RuntimeError("vessel simulation failed")
    return js.Experiment.from_trajectory(traj)


def _overshoots(t, psi, delta, switch):
    """First and second overshoot [rad]; NaN where the model never completes them
    (e.g. a fitted gain too small to reach the switch heading)."""
    try:
        zz = js.indices.zigzag_indices(t=np.asarray(t), psi=np.asarray(psi),
                                       delta=np.asarray(delta),
                            heading_switch=switch)
    except ValueError:
        return np.nan, np.nan
    o = list(zz.overshoots) + [np.nan, np.nan]
    return float(o[0]), float(o[1])


def discrete_zigzag(fit, angle, switch, dt, num, *, rudder_rate=None):
    """The discrete model `fit` (`DiscreteResponse.regress`'s, sample interval `dt`) through
    a starboard-first zig-zag `angle`/`switch` [rad] from rest: the rudder order
    reverses when the heading change passes `switch` (as `ZigZag`), the actual
    rudder follows at `rudder_rate` [rad/s] and is held over each interval; heading
    by the trapezoid rule. Returns `(t, psi, delta)` of `num` samples; a fitted model
    that diverges (its cubic term outgrowing its damping) gives non-finite samples from
    there on, and its overshoots are then NaN in the tables (`_overshoots`), not a
    warning."""
    c, s = fit.coefficients, fit.structure
    r = np.zeros(num + 2)  # r[k + 1] is sample k; r[0] the rest before sample 0
    d = np.zeros(num + 1)  # d[k + 1] is held from sample k; d[0] = 0 before
    psi = np.zeros(num)
    side, step = 1.0, np.inf if rudder_rate is None else rudder_rate * dt
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging fit: inf, NaN
        for k in range(num):
            if k:
                psi[k] = psi[k - 1] + 0.5 * dt * (r[k] + r[k + 1])
            if side > 0 and psi[k] >= switch:
                side = -1.0
            elif side < 0 and psi[k] <= -switch:
                side = 1.0
            d[k + 1] = d[k] + np.clip(side * angle - d[k], -step, step)
            if s in ("linear1", "nonlinear1"):
                nl = c["a2"] * r[k + 1] ** 3 if s == "nonlinear1" else 0.0
                lin = c["a3" if s == "nonlinear1" else "a2"] * d[k + 1]
                r[k + 2] = c["a1"] * r[k + 1] + nl + lin + c["b0"]
            else:
                nl = c["c1"] * r[k + 1] ** 3 if s == "nonlinear2" else 0.0
                r[k + 2] = (c["a1"] * r[k + 1] + c["a2"] * r[k] + c["b1"] * d[k + 1]
                            + c["b2"] * d[k] + nl + c["c0"])
    return dt * np.arange(num), psi, d[1:]


def svm_response_study(vessel="mariner", *, rpm=None, dt=0.5, duration_lengths=40.0,
                       noise_r=0.0, seed=0, methods=("ls", "svr"), svr_options=None) -> dict:
    """Fit the four response models of Lu & Zhao to a simulated 20/20 zig-zag and
    predict it, an untrained 10/10 zig-zag and a 20 deg turning circle.

    **Arguments:** `vessel` (name or vessel), `rpm` (None: nominal approach),
    sample interval `dt` [s], record length in units of L/U, white noise `noise_r`
    [rad/s] added to the training yaw rate, `methods`, `svr_options` (keywords of
    `SupportVectorRegression`).

    **Returns** a dict: `"fits"` {(structure, method): the discrete model,
    `DiscreteResponse(method=...).regress(structure, record)`},
    `"table1"` rows (name, o1 [deg], o2 [deg]) for the test and each model (the
    continuous model simulated through the closed-loop zig-zag with the vessel's
    rudder rate; NaN where the fit has no real positive time constants),
    `"table1_discrete"` the same with the fitted difference equations,
    `"consistency"` (the Tables 2-4 quantities per model),
    `"generalisation"` {(structure, method): {trial: fit % of r}} and the records.
    """
    v = js.get_vessel(vessel) if isinstance(vessel, str) else vessel
    x0 = js.straight_run(v, n=None if rpm is None else rpm / 60.0)  # nominal if None
    tau = float(v.length) / float(x0.u)
    duration = duration_lengths * tau
    rate = float(v.rudder.max_rate)
    trials = {
        "zigzag 20/20": js.ZigZag(20 * DEG, 20 * DEG, duration=duration, dt=dt),
        "zigzag 10/10": js.ZigZag(10 * DEG, 10 * DEG, duration=duration, dt=dt),
        "turn 20": js.Turn(20 * DEG, duration=duration, dt=dt),
    }
    records = {k: _run(v, m, x0) for k, m in trials.items()}
    train = records["zigzag 20/20"]
    if noise_r:
        rng = np.random.default_rng(seed)
        train = js.Experiment(train.t, train.delta, psi=train.psi,
                           r=train.r + noise_r * rng.standard_normal(train.r.shape),
                           name="zigzag 20/20 noisy")
    fits = {}
    for method in methods:
        strategy = (js.SupportVectorRegression(**(svr_options or {})) if method == "svr"
                    else js.LeastSquaresRegression())
        for s in STRUCTURES:
            fits[(s, method)] = js.DiscreteResponse(method=strategy).regress(s, train)
    test = records["zigzag 20/20"]
    table1 = [("test",) + _overshoots(test.t, test.psi, test.delta, 20 * DEG)]
    table1_discrete = []
    general = {}
    for key, f in fits.items():
        zz = discrete_zigzag(f, 20 * DEG, 20 * DEG, f.dt, test.num_samples, rudder_rate=rate)
        table1_discrete.append((f"{key[0]} ({key[1]})",) + _overshoots(*zz, 20 * DEG))
        try:
            model = f.to_steering()
        except ValueError:
            table1.append((f"{key[0]} ({key[1]})", np.nan, np.nan))
            continue
        zigzag = dataclasses.replace(trials["zigzag 20/20"], rudder_rate=rate)
        tr = js.simulate(model, zigzag, simulator=js.Simulator(substeps=2))
        o1, o2 = _overshoots(tr.t, tr.state.psi, tr.state.delta, 20 * DEG)
        table1.append((f"{key[0]} ({key[1]})", o1, o2))
        general[key] = {}
        for name, rec in records.items():
            replay = js.Replay(rec.delta, dt=rec.dt, delta_hold=js.strategies.FirstOrderHold())
            sim = js.simulate(model, replay,
                              simulator=js.Simulator(max_step=math.inf, substeps=2))
            general[key][name] = js.fit_percent(rec.r, np.asarray(sim.state.r))
    table1 = [(n, o1 / DEG, o2 / DEG) for n, o1, o2 in table1]
    table1_discrete = [(n, o1 / DEG, o2 / DEG) for n, o1, o2 in table1_discrete]
    consistency = {key: f.parameters for key, f in fits.items()}
    return {"fits": fits, "table1": table1, "table1_discrete": table1_discrete,
            "consistency": consistency,
            "generalisation": general, "records": records, "vessel": v}


def design_study(vessel="thesis", *, rpm=500.0, dt=0.5, noise_r=0.05 * DEG, duration=None
                 ) -> dict:
    """Cramer-Rao bounds of K, T (Nomoto 1) and K, T1, T2, T3 (Nomoto 2) for a
    turning circle (20 deg), zig-zags 20/20 and 10/10, a PRBS (+-10 deg), a 3-2-1-1
    (10 deg) and the thesis manoeuvre, with a rate gyro of white noise `noise_r`
    [rad/s].

    The nominal models are least-squares (zero-order-hold) fits to a noise-free
    20/20 zig-zag and thesis manoeuvre of `vessel` at `rpm`. Each manoeuvre runs for
    `duration` [s] (default: the thesis manoeuvre's own length, so all have the same
    duration); the turn and zig-zags are run on the nominal model with the vessel's
    rudder rate.

    **Returns** `{"nominal": {...}, "reports": {(model, manoeuvre): DesignReport}}`.
    """
    v = js.get_vessel(vessel) if isinstance(vessel, str) else vessel
    x0 = js.straight_run(v, n=None if rpm is None else rpm / 60.0)  # nominal if None
    thesis = js.thesis_manoeuvre(dt=dt)
    duration = float(thesis.duration) if duration is None else float(duration)
    rate = float(v.rudder.max_rate)
    rec = [_run(v, js.ZigZag(20 * DEG, 20 * DEG, duration=600.0, dt=dt), x0),
           _run(v, thesis, x0)]
    n1 = js.DiscreteResponse().regress("linear1", rec).to_steering()
    n2 = js.DiscreteResponse().regress("linear2", rec).to_steering()
    n1 = eqx.tree_at(lambda m: m.delta0, n1, 0.0)
    n2 = eqx.tree_at(lambda m: m.delta0, n2, 0.0)
    manoeuvres = {
        "turn 20": js.Turn(20 * DEG, duration=duration, dt=dt),
        "zigzag 20/20": js.ZigZag(20 * DEG, 20 * DEG, duration=duration, dt=dt),
        "zigzag 10/10": js.ZigZag(10 * DEG, 10 * DEG, duration=duration, dt=dt),
        "PRBS 10": js.prbs(10 * DEG, bit_time=10.0, duration=duration, dt=dt),
        "3211 10": js.multi_step_3211(10 * DEG, unit=10.0, settle=duration - 70.0, dt=dt),
        "thesis": js.thesis_manoeuvre(dt=dt, end_hold=300.0 + duration - float(
            thesis.duration)),
    }
    reports = {}
    for mname, model, free in (("Nomoto1", n1, ("K", "T")),
                               ("Nomoto2", n2, ("K", "T1", "T2", "T3"))):
        for name, m in manoeuvres.items():
            geared = dataclasses.replace(m, rudder_rate=rate)  # the vessel's gear rate
            reports[(mname, name)] = js.fisher_information(model, geared, noise_r, free=free,
                                                        substeps=2)
    return {"nominal": {"Nomoto1": n1, "Nomoto2": n2}, "reports": reports,
            "duration": duration}
