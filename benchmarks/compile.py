"""Compilation: the cost of the first call of `simulate`, and proof that new values reuse it.

For each case the script calls the same entry point three times: the first call traces
and compiles, the second and third pass *new parameter values* of the same shapes
(vessel coefficients, rudder angle, initial speed). Counted for every call:

- new traces of jitted functions (the entry point's core and anything else the call
  traces), from JAX's own monitoring events (`/jax/core/compile/jaxpr_trace_duration`);
- XLA compilations and their time, from JAX's monitoring events as well
  (`/jax/core/compile/backend_compile_duration`; every jitted call that compiles emits one).

Both are counted through the public API only, so the counts do not depend on how
jaxship names its internal jitted functions.

Cases: `simulate` of a 600 s 20/20 zig-zag of the Mariner (0.1 s samples, RK4), the same
for the thesis vessel, and `simulate_batch` of 64 Mariner zig-zags.

Then one fit, twice over, with `jaxship.fit`: (a) a first-order Nomoto model (K, T free)
on two simulated 20/20 zig-zags of the Mariner, and (b) the thesis vessel with 4 free
coefficients (Y_uv, N_uv, N_ur, rudder area) on a simulated 20/20 zig-zag and a PRBS at
500 rpm, prediction error with a 10 s horizon. Every call of a fit case passes *new data
values* (other rudder angles, other measurement noise, same lengths) and *new start values*;
the data are simulated before the clock starts. The traces and XLA compilations are all
those of the call (the fit's core, the Jacobian for the covariance, and any small eager
operation). The second and third calls must show 0 new traces and 0 new compilations.

Prints the wall time of each call and the counts; float64.

Run: `python benchmarks/compile.py` (`--skip-simulate` for the fit cases only).
"""

import sys
import time
import warnings

import jax


jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import jax.monitoring  # noqa: E402
import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402


DEG = np.pi / 180
COMPILES = []  # durations of the XLA compilations seen so far [s]
TRACES = []  # durations of the traces of jitted functions seen so far [s]


def _listen(event, duration, **_):
    if event == "/jax/core/compile/backend_compile_duration":
        COMPILES.append(duration)
    elif event == "/jax/core/compile/jaxpr_trace_duration":
        TRACES.append(duration)


jax.monitoring.register_event_duration_secs_listener(_listen)


def calls(label, run, values, prepare=None):
    """Time `run(value)` for each value; `prepare(value)` (untimed) builds its inputs.
    Raises when a call after the first traces or compiles anything."""
    print(f"\n{label}")
    print("| call | new values | wall time [s] | new traces | XLA compilations (time [s]) |")
    print("| ---: | --- | ---: | ---: | --- |")
    out = []
    for k, value in enumerate(values, start=1):
        if prepare is not None:
            value = dict(value, inputs=prepare(value))
        traces, compiles = len(TRACES), len(COMPILES)
        start = time.perf_counter()
        result = jax.block_until_ready(run(value))
        wall = time.perf_counter() - start
        new, traced = COMPILES[compiles:], len(TRACES) - traces
        what = f"{len(new)} ({sum(new):.2f})" if new else "0"
        print(f"| {k} | {value['note']} | {wall:.3f} | {traced} | {what} |")
        if k > 1 and (traced or new):
            raise RuntimeError(f"{label}: call {k} with new values retraced or recompiled.")
        out.append(result)
    return out


def noisy(experiment, rng, noise):
    """The experiment with white noise of standard deviation `noise[c]` on channel c."""
    channels = {c: getattr(experiment, c) + s * rng.standard_normal(experiment.num_samples)
                for c, s in noise.items()}
    return js.Experiment(experiment.t, experiment.delta, delta_c=experiment.delta_c,
                         n=experiment.n, name=experiment.name, **channels)


def fit_cases():
    """One fit of a response model and one of a vessel, each called three times with new
    data values and new start values."""
    # (a) Nomoto 1 (K, T) on two Mariner zig-zags
    mariner = js.get_vessel("mariner")

    def nomoto_data(value):
        rng = np.random.default_rng(value["seed"])
        out = []
        for sign in (1, -1):
            angle = sign * value["angle"] * DEG
            tr = js.simulate(mariner, js.ZigZag(angle, abs(angle), duration=300.0, dt=0.5),
                             js.straight_run(mariner))
            e = js.Experiment.from_trajectory(tr, name=f"zigzag{sign * value['angle']:g}")
            out.append(noisy(e, rng, {"psi": 0.05 * DEG, "r": 0.01 * DEG}))
        return out

    def nomoto_fit(value):
        start = js.Nomoto1(K=value["K"], T=value["T"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = js.fit(start, value["inputs"], estimator=js.PredictionError(horizon=20.0))
        return res.values

    results = calls("fit, Nomoto1 (K, T) on two 300 s Mariner zig-zags (0.5 s samples)",
                    nomoto_fit, [
                        dict(seed=0, angle=20.0, K=0.05, T=20.0, note="first call"),
                        dict(seed=1, angle=15.0, K=0.08, T=40.0,
                             note="15/15 zig-zags, new noise, K0 0.08, T0 40"),
                        dict(seed=2, angle=25.0, K=0.03, T=10.0,
                             note="25/25 zig-zags, new noise, K0 0.03, T0 10"),
                    ], prepare=nomoto_data)
    print("estimates (K [1/s], T [s]): " + "; ".join(
        ", ".join(f"{x:.4g}" for x in np.asarray(r)) for r in results))

    # (b) the thesis vessel, 4 coefficients
    thesis = js.get_vessel("thesis")
    free = ("y_uv", "n_uv", "n_ur", "rudder_area")
    truth = np.array([getattr(thesis, k) for k in free])
    n = 500 / 60

    def vessel_data(value):
        rng = np.random.default_rng(value["seed"])
        angle = value["angle"] * DEG
        out = []
        for name, man in (("zigzag", js.ZigZag(angle, angle, duration=60.0, dt=0.1, n=n)),
                          ("prbs", js.prbs(angle, 5.0, 60.0, n=n))):
            tr = js.simulate(thesis, man, js.straight_run(thesis, n=n))
            e = js.Experiment.from_trajectory(tr, name=name)
            out.append(noisy(e, rng, {"psi": 0.02 * DEG, "r": 0.01 * DEG, "u": 0.001,
                                      "v": 0.001}))
        return out

    def vessel_fit(value):
        start = eqx.tree_at(lambda m: [getattr(m, k) for k in free], thesis,
                            [float(x) for x in truth * value["factor"]])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = js.fit(start, value["inputs"], estimator=js.PredictionError(
                horizon=10.0, rudder="delta_c"), free=free)
        return res.values

    results = calls("fit, thesis vessel (Y_uv, N_uv, N_ur, rudder area) on a 60 s zig-zag and "
                    "a 60 s PRBS at 500 rpm (0.1 s samples)", vessel_fit, [
                        dict(seed=0, angle=20.0, factor=np.array([1.2, 0.8, 1.2, 0.8]),
                             note="first call"),
                        dict(seed=1, angle=15.0, factor=np.array([0.8, 1.2, 0.9, 1.1]),
                             note="15 deg, new noise, new start values"),
                        dict(seed=2, angle=25.0, factor=np.array([1.1, 0.9, 0.8, 1.2]),
                             note="25 deg, new noise, new start values"),
                    ], prepare=vessel_data)
    print("estimate / truth - 1: " + "; ".join(
        ", ".join(f"{x:+.1e}" for x in np.asarray(r) / truth - 1) for r in results))


def main(skip_simulate=False):
    print(f"jax {jax.__version__}, {jax.default_backend()}, float64")
    if not skip_simulate:
        simulate_cases()
    fit_cases()


def simulate_cases():
    for name in ("mariner", "thesis"):
        base = js.get_vessel(name)
        coef = "n_r" if name == "mariner" else "n_ur"

        def run(value, base=base, coef=coef):
            scaled = getattr(base, coef) * value["f"]
            vessel = eqx.tree_at(lambda v: getattr(v, coef), base, scaled)
            angle = value["angle"] * DEG
            man = js.ZigZag(angle, angle, duration=600.0, dt=0.1)
            x0 = js.straight_state(base.nominal_speed * value["u"], base.nominal_n)
            return js.simulate(vessel, man, x0)

        values = [
            dict(f=1.0, angle=20.0, u=1.0, note="first call"),
            dict(f=1.1, angle=15.0, u=0.9, note=f"{coef} x1.1, 15 deg, 0.9 U0"),
            dict(f=0.8, angle=25.0, u=1.1, note=f"{coef} x0.8, 25 deg, 1.1 U0"),
        ]
        calls(f"simulate, {name}: 600 s a/a zig-zag at 0.1 s", run, values)

    base = js.get_vessel("mariner")

    def run_batch(value):
        vessel = eqx.tree_at(lambda v: v.n_r, base, base.n_r * value["f"])
        angles = np.linspace(10, 30, 64) * DEG * value["f"]
        man = js.ZigZag(angles, angles, duration=600.0, dt=0.1)
        return js.simulate_batch(vessel, man, js.straight_state(np.full(64, 7.0 * value["f"])))

    calls("simulate_batch, 64 Mariner zig-zags", run_batch, [
        dict(f=1.0, note="first call"),
        dict(f=1.1, note="n_r, angles, speeds x1.1"),
        dict(f=0.9, note="n_r, angles, speeds x0.9"),
    ])


if __name__ == "__main__":
    main(skip_simulate="--skip-simulate" in sys.argv[1:])
