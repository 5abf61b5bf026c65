"""Gradients: the forward-mode Jacobian of a trajectory w.r.t. 20 Mariner coefficients.

The trajectory is the 600 s 20/20 zig-zag of the Mariner at 0.1 s samples (RK4, the
fast path), all of u, v, r, x, y, psi at the 6001 samples (36,006 outputs); the
parameters are 20 hydrodynamic coefficients (listed below). Measured side by side,
each compiled once and timed as the best of `--repeats` interleaved calls:

- one simulation, `simulate` (jitted);
- the Jacobian by `jax.jacfwd` (20 tangents pushed through the scan together);
- the baseline users would pick: forward finite differences, i.e. 21 simulations, as
  a loop of `simulate` calls and as one `simulate_batch` call.

Prints the times, the Jacobian's cost as a multiple of one simulation, and its
agreement with central differences on a few columns. float64.

Run: `python benchmarks/gradients.py [--repeats 5]`.
"""

import argparse
import time

import jax


jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402


DEG = np.pi / 180
PARAMS = (  # 20 coefficients of the Mariner model
    "x_u", "x_uu", "x_vv", "x_rr", "x_dd", "x_rv",
    "y_v", "y_r", "y_vvv", "y_vvr", "y_d", "y_ddd", "y_vvd",
    "n_v", "n_r", "n_vvv", "n_vvr", "n_d", "n_ddd", "n_vvd",
)


def with_params(vessel, theta):
    return eqx.tree_at(lambda v: [getattr(v, k) for k in PARAMS], vessel,
                       [theta[i] for i in range(len(PARAMS))])


def main(args):
    vessel = js.get_vessel("mariner")
    theta0 = jnp.array([getattr(vessel, k) for k in PARAMS])
    man = js.ZigZag(20 * DEG, 20 * DEG, duration=600.0, dt=0.1)
    x0 = js.straight_run(vessel)

    def trajectory(theta):
        s = js.simulate(with_params(vessel, theta), man, x0).state
        return jnp.stack([s.u, s.v, s.r, s.x, s.y, s.psi], axis=-1)

    sim = jax.jit(trajectory)
    jac = jax.jit(jax.jacfwd(trajectory))
    steps = np.abs(np.asarray(theta0)) * 1e-6
    thetas = np.asarray(theta0) + np.vstack([np.zeros(len(PARAMS)), np.diag(steps)])

    def fd_loop():
        return [sim(t) for t in thetas]

    batched = with_params(vessel, jnp.asarray(thetas).T)  # 0-d leaves stay shared

    def fd_batch():
        return js.simulate_batch(batched, man, x0, in_axes=(0, None, None, None))

    functions = {
        "one simulation": lambda: sim(theta0),
        "jax.jacfwd (20 parameters)": lambda: jac(theta0),
        "finite differences, loop of 21 simulate": fd_loop,
        "finite differences, simulate_batch of 21": fd_batch,
    }
    for f in functions.values():
        jax.block_until_ready(f())
    times = {k: [] for k in functions}
    for _ in range(args.repeats):
        for k, f in functions.items():
            start = time.perf_counter()
            jax.block_until_ready(f())
            times[k].append(time.perf_counter() - start)
    best = {k: min(v) for k, v in times.items()}
    one = best["one simulation"]
    print(f"jax {jax.__version__}, {jax.default_backend()}, float64; Mariner 600 s 20/20 "
          f"zig-zag at 0.1 s, outputs (6001 samples x 6 states), {len(PARAMS)} parameters: "
          f"{', '.join(PARAMS)}\n")
    print("| computation | time [ms] | multiple of one simulation |")
    print("| --- | ---: | ---: |")
    for k, t in best.items():
        print(f"| {k} | {1e3 * t:.1f} | {t / one:.1f} |")

    # check: the Jacobian against central differences on a few columns
    J = np.asarray(jac(theta0))
    worst = 0.0
    for i in (0, 7, 14, 19):
        h = abs(float(theta0[i])) * 1e-5
        e = np.zeros(len(PARAMS))
        e[i] = h
        fd = (np.asarray(sim(theta0 + e)) - np.asarray(sim(theta0 - e))) / (2 * h)
        scale = np.max(np.abs(fd), axis=0) + 1e-300
        worst = max(worst, float(np.max(np.abs(J[..., i] - fd) / scale)))
    print(f"\njacfwd vs central differences (columns {PARAMS[0]}, {PARAMS[7]}, {PARAMS[14]}, "
          f"{PARAMS[19]}): max difference relative to each state's largest sensitivity "
          f"{worst:.1e}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    main(parser.parse_args())
