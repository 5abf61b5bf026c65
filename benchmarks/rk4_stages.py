"""RK4's stages in one loop (`jaxship.RK4(rolled=True)`, the default) against the four
stages written out (`rolled=False`): XLA compiles the vector field once instead of four
times, and the loop costs some speed once compiled.

For each vessel: a 20/20 zig-zag of 60 L/U (one simulation), the forward derivative of
its final heading with respect to the sway derivative y_v (`jax.jvp`), and a batch of
64 turning circles (5-35 deg rudder, `simulate_batch`); each timed on its first call
(compiling and running) and as the median of `--repeat` later calls, both ways in one
process, under the compiler setting of the `jaxship` command and the tests
(`jaxship.compile_for_small_programs()`; `--xla-defaults` for XLA's own). Run:
`python benchmarks/rk4_stages.py [--repeat 5] [--xla-defaults]`.
"""

import argparse
import time

import equinox as eqx
import jax


jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402


DEG = np.pi / 180
VESSELS = ("mariner", "kvlcc2", "esso_osaka")


def cases(vessel, simulator):
    """`{case: callable}` of the three computations on `vessel` with `simulator`."""
    duration = 60 * float(vessel.length / vessel.nominal_speed)
    x0 = js.straight_run(vessel)
    zigzag = js.ZigZag(20 * DEG, 20 * DEG, duration=duration, dt=0.5)
    turns = js.stack([js.Turn(a, duration=duration, dt=0.5)
                      for a in np.linspace(5, 35, 64) * DEG])
    p0 = float(vessel.y_v)

    def final_heading(p):
        moved = eqx.tree_at(lambda v: v.y_v, vessel, p)
        return js.simulate(moved, zigzag, x0, simulator=simulator).state.psi[-1]

    return {
        "one simulation": lambda: js.simulate(vessel, zigzag, x0,
                                              simulator=simulator).state.psi,
        "its derivative (jvp)": lambda: jax.jvp(final_heading, (p0,), (1.0,))[1],
        "64 turning circles": lambda: js.simulate_batch(
            vessel, turns, x0, simulator=simulator, in_axes=(None, 0, None, None)).state.psi,
    }


def timed(f):
    t0 = time.perf_counter()
    jax.block_until_ready(f())
    return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--xla-defaults", action="store_true",
                        help="XLA's own compiler setting instead of the command's")
    args = parser.parse_args()
    if not args.xla_defaults:
        js.compile_for_small_programs()
    print(f"compiler setting: {'XLA defaults' if args.xla_defaults else 'SMALL_PROGRAMS'}; "
          f"median of {args.repeat} after the first call")
    print("| vessel | computation | first call, rolled | written out | ratio | "
          "later calls, rolled | written out | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in VESSELS:
        vessel = js.get_vessel(name)
        ways = {rolled: cases(vessel, js.Simulator(solver=js.RK4(rolled=rolled)))
                for rolled in (True, False)}
        for case in ways[True]:
            first = {rolled: timed(ways[rolled][case]) for rolled in (True, False)}
            later = {True: [], False: []}
            for _ in range(args.repeat):
                for rolled in (True, False):
                    later[rolled].append(timed(ways[rolled][case]))
            med = {k: float(np.median(v)) for k, v in later.items()}
            print(f"| {name} | {case} | {first[True]:.2f} s | {first[False]:.2f} s | "
                  f"{first[False] / first[True]:.2f}x | {med[True] * 1e3:.0f} ms | "
                  f"{med[False] * 1e3:.0f} ms | {med[False] / med[True]:.2f}x |", flush=True)


if __name__ == "__main__":
    main()
