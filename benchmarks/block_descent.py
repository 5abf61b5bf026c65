"""One Levenberg-Marquardt step with estimated window starts: the block elimination of
`BlockDampedNewtonDescent` against optimistix's `DampedNewtonDescent` (one QR of the
whole stacked matrix), on the shape of `discover`'s base fit on the Esso Osaka split
of its notebook: Nomoto 1 (2 parameters) on 8 random runs at 2 Hz, 60 s windows,
psi and r, 8 x 18 windows (padded to the longest run) with 2 start corrections each:
34,560 residuals x 290 parameters. The Jacobian is random with that block structure
(the step's cost does not depend on its values). Both steps are compiled first, then
timed over `--repeat` calls each, interleaved; prints both, the ratio and the largest
difference of the two steps. Run: `python benchmarks/block_descent.py`.
"""

import argparse
import time

import jax


jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import lineax as lx  # noqa: E402
import numpy as np  # noqa: E402
import optimistix as optx  # noqa: E402

from jaxship._estimate._lm import BlockDampedNewtonDescent  # noqa: E402


SHARED, PER_BLOCK, BLOCKS, CHANNELS, WINDOW = 2, 2, (8, 18), 2, 120


def problem(seed=0):
    """`(y, f_info)`: residuals and a Jacobian with the block structure above."""
    rng = np.random.default_rng(seed)
    count = int(np.prod(BLOCKS))
    shape = (CHANNELS,) + BLOCKS + (WINDOW,)
    shared = rng.standard_normal(shape + (SHARED,))
    own = rng.standard_normal(shape + (PER_BLOCK,))
    eye = np.eye(count).reshape((1,) + BLOCKS + (1, count, 1))
    jac = jnp.asarray(np.concatenate(
        [shared, (own[..., None, :] * eye).reshape(shape + (count * PER_BLOCK,))], axis=-1))
    operator = lx.FunctionLinearOperator(lambda t: jac @ t,
                                         jax.ShapeDtypeStruct((jac.shape[-1],), jac.dtype))
    info = optx.FunctionInfo.ResidualJac(jnp.asarray(rng.standard_normal(shape)), operator)
    return jnp.zeros(jac.shape[-1]), info


def timed_step(descent, y, info):
    state = descent.query(y, info, descent.init(y, info))
    step = jax.jit(lambda lam: descent.step(1 / lam, state)[0])
    step(1e-3).block_until_ready()  # compiled
    return step


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    y, info = problem()
    dense = timed_step(optx.DampedNewtonDescent(), y, info)
    block = timed_step(BlockDampedNewtonDescent(SHARED, BLOCKS), y, info)
    times = {"dense": [], "block": []}
    for _ in range(args.repeat):
        for name, step in (("dense", dense), ("block", block)):
            t0 = time.perf_counter()
            step(1e-3).block_until_ready()
            times[name].append(time.perf_counter() - t0)
    diff = float(jnp.max(jnp.abs(block(1e-3) - dense(1e-3))) / jnp.max(jnp.abs(dense(1e-3))))
    rows, cols = info.residual.size, y.size
    print(f"one damped Gauss-Newton step, {rows} residuals x {cols} parameters, median of "
          f"{args.repeat}:")
    for name, label in (("dense", "optimistix DampedNewtonDescent (one QR)"),
                        ("block", "jaxship BlockDampedNewtonDescent")):
        print(f"  {label:42s} {1e3 * np.median(times[name]):8.1f} ms")
    print(f"  ratio {np.median(times['dense']) / np.median(times['block']):.1f}x; largest "
          f"difference of the steps {diff:.1e} (relative to the largest component)")


if __name__ == "__main__":
    main()
