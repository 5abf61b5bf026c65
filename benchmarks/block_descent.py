"""Fits with estimated window starts: each Levenberg-Marquardt step solved window by
window (`LevenbergMarquardt(blockwise=True)`, the default) against one QR of the whole
stacked matrix (`blockwise=False`, optimistix's `DampedNewtonDescent`).

Problem: `discover`'s base fit on the Esso Osaka split of `notebooks/discovery.ipynb`
(measured data, `../shared/data`): Nomoto 1 (K, T) from the start the notebook uses
(a 20 s prediction-error fit), on the 8 random runs at 2 Hz, 60 s windows each starting
from estimated corrections of its measured r and psi (`EstimatedStarts`), channels psi
and r; 8 x 18 windows (padded to the longest run): 290 parameters, 34,560 residuals.
Both fits run once to compile, then `--repeat` times each, interleaved, in one process;
prints the median times, the ratio, the LM steps and the costs. Run:
`python benchmarks/block_descent.py [--repeat 3]`.
"""

import argparse
import time

import jax


jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaxship as js  # noqa: E402
from jaxship.studies.real_data import esso_osaka_split  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    train, _ = esso_osaka_split()
    start = js.fit(js.Nomoto1(K=0.1, T=10.0), train,
                   estimator=js.PredictionError(horizon=20.0)).model

    def run(blockwise):
        solver = js.LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=1e-7, blockwise=blockwise)
        estimator = js.PredictionError(horizon=60.0, initial=js.EstimatedStarts(),
                                       solver=solver)
        t0 = time.perf_counter()
        out = js.fit(start, train, estimator=estimator)
        return time.perf_counter() - t0, out

    first = {b: run(b) for b in (True, False)}
    times = {True: [], False: []}
    for _ in range(args.repeat):
        for b in (True, False):
            times[b].append(run(b)[0])
    print(f"Esso Osaka, discover's base fit ({len(train)} random runs, 60 s windows, "
          f"estimated starts), median of {args.repeat} after a compiling run:")
    for b, label in ((False, "one QR of the whole matrix (blockwise=False)"),
                     (True, "window by window (blockwise=True, default)")):
        t, out = first[b]
        print(f"  {label:46s} {np.median(times[b]):6.2f} s ({t:5.2f} s compiling run), "
              f"{out.num_steps} steps, cost {out.cost:.10g}, {out.code_name}")
    print(f"  ratio {np.median(times[False]) / np.median(times[True]):.1f}x "
          f"({first[False][0] / first[True][0]:.1f}x for the compiling runs)")


if __name__ == "__main__":
    main()
