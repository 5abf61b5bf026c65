"""Sweep: 10,000 turning circles with advance, transfer and tactical diameter for all.

A grid of rudder angle x propeller rate x parameter perturbation, each run a turning
circle from its own straight run, simulated with `simulate_batch` and reduced to its
indices inside the same compiled call (`output=batch_turning_indices`), in chunks of
`--chunk-size` runs per device to bound memory; float64.

- thesis vessel (default): 10 rudder angles (10-35 deg) x 10 rates (400-600 rpm) x
  100 perturbations of the sway/yaw damping (Y_uv, Y_ur, N_uv, N_ur each scaled by a
  random factor in [0.8, 1.2], seed 0; the straight run, a surge equilibrium, does
  not change).
- `--vessel mariner`: the Mariner has no propeller term, so the approach speed U_0
  (5-10 m/s) takes the place of the rate; perturbed: Y_v, Y_r, N_v, N_r.

Duration and step: the run lasts until the slowest turn of the grid has passed 180 deg
(checked: the script reports any run that did not), sampled every `--dt` with
`--substeps` RK4 steps per sample (`Simulator(substeps=..., max_step=inf)`: the library's
default would split each sample into control steps of at most 0.1 s, five RK4 steps per
0.5 s sample). The accuracy of that step is reported against a reference with 10x finer
samples and steps on a few runs of the grid.

Prints runs/s, the wall time (first call with compilation, then the best of
`--repeats`), the peak resident memory of the process (`resource.getrusage`) and a
summary of the indices.

Run: `python benchmarks/sweep.py [--vessel thesis|mariner] [--devices N]`.
"""

import argparse
import math
import os
import resource
import sys
import time


def _parse():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vessel", default="thesis", choices=("thesis", "mariner"))
    parser.add_argument("--angles", type=int, default=10)
    parser.add_argument("--rates", type=int, default=10)
    parser.add_argument("--perturbations", type=int, default=100)
    parser.add_argument("--duration", type=float, default=None, help="[s], default per vessel")
    parser.add_argument("--dt", type=float, default=None, help="sample interval [s]")
    parser.add_argument("--substeps", type=int, default=None, help="RK4 steps per sample")
    parser.add_argument("--chunk-size", type=int, default=2500, help="runs per device at once")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--devices", type=int, default=1, help="XLA CPU devices to split into")
    return parser.parse_args()


ARGS = _parse() if __name__ == "__main__" else None
if ARGS is not None and ARGS.devices > 1:
    os.environ["XLA_FLAGS"] = (
        os.environ.get("XLA_FLAGS", "") + f" --xla_force_host_platform_device_count={ARGS.devices}"
    )

import jax  # noqa: E402


jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402


DEG = np.pi / 180

# duration [s], sample interval [s], RK4 substeps per sample, perturbed fields, second axis
SETUP = {
    "thesis": dict(duration=100.0, dt=0.5, substeps=1, fields=("y_uv", "y_ur", "n_uv", "n_ur")),
    "mariner": dict(duration=800.0, dt=2.0, substeps=2, fields=("y_v", "y_r", "n_v", "n_r")),
}


def peak_rss_mb() -> float:
    """Peak resident set size of this process [MiB] (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def build(args, dt):
    """The batched vessel, manoeuvre and initial state of the whole grid."""
    setup = SETUP[args.vessel]
    vessel = js.get_vessel(args.vessel)
    angles = np.linspace(10, 35, args.angles) * DEG
    rng = np.random.default_rng(0)
    factors = rng.uniform(0.8, 1.2, (args.perturbations, len(setup["fields"])))
    a, k, j = np.meshgrid(
        angles, np.arange(args.rates), np.arange(args.perturbations), indexing="ij"
    )
    a, k, j = a.ravel(), k.ravel(), j.ravel()
    if args.vessel == "thesis":
        rates = np.linspace(400, 600, args.rates) / 60  # [rev/s]
        starts = js.straight_run(vessel, n=rates)
        u0, n0 = np.asarray(starts.u)[k], rates[k]
        second = rates[k] * 60
    else:
        speeds = np.linspace(5.0, 10.0, args.rates)  # approach speed U_0 [m/s]
        u0, n0 = speeds[k], np.zeros(k.size)
        vessel = eqx.tree_at(lambda v: v.nominal_speed, vessel, u0)
        second = speeds[k]
    for i, name in enumerate(setup["fields"]):
        vessel = eqx.tree_at(lambda v, n=name: getattr(v, n), vessel,
                             getattr(vessel, name) * factors[j, i])
    manoeuvre = js.Turn(a, duration=args.duration, dt=dt,
                        n=None if args.vessel == "mariner" else n0)
    return vessel, manoeuvre, js.straight_state(u0, n0), dict(angle=a, second=second, pert=j)


def main(args):
    setup = SETUP[args.vessel]
    for key in ("duration", "dt", "substeps"):
        if getattr(args, key) is None:
            setattr(args, key, setup[key])
    devices = jax.devices()
    vessel, manoeuvre, x0, grid = build(args, args.dt)
    runs = grid["angle"].size
    simulator = js.Simulator(substeps=args.substeps, max_step=math.inf)  # module text
    print(f"jax {jax.__version__}, {jax.default_backend()}, {len(devices)} device(s), float64, "
          f"python {sys.version.split()[0]}")
    print(f"{runs} turning circles of the {args.vessel} vessel: {args.angles} rudder angles x "
          f"{args.rates} {'rates' if args.vessel == 'thesis' else 'speeds'} x "
          f"{args.perturbations} perturbations of {', '.join(setup['fields'])}; "
          f"{args.duration:g} s at dt = {args.dt:g} s, {args.substeps} RK4 substeps "
          f"({manoeuvre.num_samples} samples), chunks of {args.chunk_size} runs per device")
    print(f"peak memory before the sweep: {peak_rss_mb():.0f} MiB")

    def sweep():
        return js.simulate_batch(
            vessel, manoeuvre, x0, simulator=simulator, in_axes=(0, 0, 0, None),
            output=js.indices.batch_turning_indices, chunk_size=args.chunk_size,
        )

    start = time.perf_counter()
    out = jax.block_until_ready(sweep())
    first = time.perf_counter() - start
    times = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        out = jax.block_until_ready(sweep())
        times.append(time.perf_counter() - start)
    best = min(times)
    out = {k: np.asarray(v) for k, v in out.items()}
    missing = int(np.sum(~np.isfinite(out["tactical_diameter"])))
    print(f"\nfirst call (with compilation): {first:.1f} s; best of {args.repeats} further "
          f"calls: {best:.1f} s = {runs / best:,.0f} runs/s "
          f"({runs * (manoeuvre.num_samples - 1) * args.substeps / best / 1e6:.2f} M RK4 "
          f"steps/s); peak memory (maxrss): {peak_rss_mb():.0f} MiB")
    print(f"runs that did not reach 180 deg: {missing} of {runs}")
    length = float(js.get_vessel(args.vessel).length)
    for name in ("advance", "transfer", "tactical_diameter"):
        v = out[name] / length
        print(f"  {name} / L: min {np.nanmin(v):.2f}, median {np.nanmedian(v):.2f}, "
              f"max {np.nanmax(v):.2f}")

    # accuracy of the chosen sample interval and step on a few runs of the grid, against
    # samples and RK4 steps 10x finer (the indices interpolate between samples)
    pick = np.unique(np.linspace(0, runs - 1, 8).astype(int))
    take = lambda tree: jax.tree.map(lambda a: a[pick] if np.ndim(a) else a, tree)
    coarse = js.simulate_batch(take(vessel), take(manoeuvre), take(x0), simulator=simulator,
                            in_axes=(0, 0, 0, None), output=js.indices.batch_turning_indices)
    fine_dt = args.dt / 10
    v_f, m_f, x_f, _ = build(args, fine_dt)
    fine = js.simulate_batch(take(v_f), take(m_f), take(x_f),
                          simulator=js.Simulator(substeps=1, max_step=math.inf),
                          in_axes=(0, 0, 0, None), output=js.indices.batch_turning_indices)
    print(f"\naccuracy on {pick.size} runs of the grid against dt = {fine_dt:g} s "
          f"(one RK4 step per sample), max relative difference:")
    for name in ("advance", "transfer", "tactical_diameter", "time_to_180"):
        rel = np.abs(np.asarray(coarse[name]) / np.asarray(fine[name]) - 1)
        print(f"  {name}: {np.nanmax(rel):.1e}")


if __name__ == "__main__":
    main(ARGS)
