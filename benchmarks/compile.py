"""Compilation: the cost of the first call of `simulate`, and proof that new values reuse it.

For each case the script calls the same entry point three times: the first call traces
and compiles, the second and third pass *new parameter values* of the same shapes
(vessel coefficients, rudder angle, initial speed). Counted for every call:

- traces of the jitted body (`eqx.debug.assert_max_traces` around it, which also raises
  if it is traced more than once);
- XLA compilations and their time, from JAX's own monitoring events
  (`/jax/core/compile/backend_compile_duration`; every jitted call that compiles emits one).

Cases: `simulate` of a 600 s 20/20 zig-zag of the Mariner (0.1 s samples, RK4), the same
for the thesis vessel, and `simulate_batch` of 64 Mariner zig-zags. Prints the wall time
of each call and the counts; float64.

Run: `python benchmarks/compile.py`.
"""

import time

import jax


jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import jax.monitoring  # noqa: E402
import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402
import jaxship._batch as jb  # noqa: E402
import jaxship._simulate as jsim  # noqa: E402
from jaxship._vessel.catalogue import get_vessel  # noqa: E402


DEG = np.pi / 180
COMPILES = []  # durations of the XLA compilations seen so far [s]


def _listen(event, duration, **_):
    if event == "/jax/core/compile/backend_compile_duration":
        COMPILES.append(duration)


jax.monitoring.register_event_duration_secs_listener(_listen)


ORIGINAL = {(jsim, "_simulate"): jsim._simulate, (jb, "_batched"): jb._batched}


def count_traces(module, name):
    """Replace the jitted `module.name` by a fresh copy that counts (and limits) its traces."""
    counted = eqx.debug.assert_max_traces(ORIGINAL[module, name].__wrapped__, max_traces=1)
    setattr(module, name, eqx.filter_jit(counted))
    return lambda: eqx.debug.get_num_traces(counted)


def calls(label, run, values, traces):
    print(f"\n{label}")
    print("| call | new values | wall time [s] | traces so far | XLA compilations (time [s]) |")
    print("| ---: | --- | ---: | ---: | --- |")
    for k, value in enumerate(values, start=1):
        before = len(COMPILES)
        start = time.perf_counter()
        jax.block_until_ready(run(value))
        wall = time.perf_counter() - start
        new = COMPILES[before:]
        what = f"{len(new)} ({sum(new):.2f})" if new else "0"
        print(f"| {k} | {value['note']} | {wall:.3f} | {traces()} | {what} |")


def main():
    print(f"jax {jax.__version__}, {jax.default_backend()}, float64")
    for name in ("mariner", "thesis"):
        simulate_traces = count_traces(jsim, "_simulate")
        base = get_vessel(name)
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
        calls(f"simulate, {name}: 600 s a/a zig-zag at 0.1 s", run, values, simulate_traces)

    batch_traces = count_traces(jb, "_batched")
    base = get_vessel("mariner")

    def run_batch(value):
        vessel = eqx.tree_at(lambda v: v.n_r, base, base.n_r * value["f"])
        angles = np.linspace(10, 30, 64) * DEG * value["f"]
        man = js.ZigZag(angles, angles, duration=600.0, dt=0.1)
        return jb.simulate_batch(vessel, man, js.straight_state(np.full(64, 7.0 * value["f"])))

    calls("simulate_batch, 64 Mariner zig-zags", run_batch, [
        dict(f=1.0, note="first call"),
        dict(f=1.1, note="n_r, angles, speeds x1.1"),
        dict(f=0.9, note="n_r, angles, speeds x0.9"),
    ], batch_traces)


if __name__ == "__main__":
    main()
