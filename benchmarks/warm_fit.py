"""A warm `jaxship.fit` of the README's `identify` example against the SciPy script's fit,
side by side in one process (issue 70's goal: at most half of SciPy's time).

The fit: Nomoto 1 on the first three Esso Osaka zig-zags by prediction error over 10 s
windows, as `jaxship identify ... --model nomoto1 --horizon 10` runs it (its estimator,
its linear least-squares start); SciPy: `benchmarks/scipy_identify.py`'s `fit` (its
equation-error start, `least_squares(method="lm")`, standard errors, whiteness tests),
the simulations left out of both. Each is called once to warm up (jaxship compiles),
then `--rounds` rounds alternate them, each timing `--repeats` calls; prints the median
of each, the ratio and both estimates.

Run: `python benchmarks/warm_fit.py [--rounds 5] [--repeats 10]` (with `$JAXSHIP_DATA`
set, or `../shared/data` beside the checkout).
"""

import argparse
import statistics
import sys
import time
from pathlib import Path

import jax


ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import scipy_identify  # noqa: E402
from latency import records  # noqa: E402

import jaxship as js  # noqa: E402
from jaxship.identification import read_experiments  # noqa: E402


def jaxship_fit(paths):
    """`() -> FitResult`: the command's fit of Nomoto 1 on `paths` (its estimator)."""
    train = js.Dataset.from_experiments(read_experiments(paths, role="training"))
    start = js.LinearStart()(js.Nomoto1(K=1.0, T=1.0), train, None, "delta")
    estimator = js.PredictionError(
        horizon=10.0, channels=("psi", "r"), simulator=js.Simulator(max_step=float("inf")),
        solver=js.LevenbergMarquardt(rtol=1e-9, atol=1e-9), initial=js.MeasuredStates())
    return lambda: js.fit(start, train, estimator=estimator)


def timed(call, repeats: int) -> float:
    began = time.perf_counter()
    for _ in range(repeats):
        call()
    return (time.perf_counter() - began) / repeats


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=10)
    args = parser.parse_args(argv)
    jax.config.update("jax_enable_x64", True)
    paths = records()[:3]
    fits = {"jaxship": jaxship_fit(paths),
            "SciPy": lambda data=[scipy_identify.read(p) for p in paths]:
            scipy_identify.fit(data)}
    result, (report, _) = fits["jaxship"](), fits["SciPy"]()  # warm-up (jaxship compiles)
    times = {name: [] for name in fits}
    for i in range(args.rounds):  # alternated, the order reversed every other round
        for name in (list(fits) if i % 2 == 0 else list(fits)[::-1]):
            times[name].append(timed(fits[name], args.repeats))
    median = {name: statistics.median(t) for name, t in times.items()}
    print(f"warm fit, median of {args.rounds} rounds of {args.repeats} calls, one process "
          f"(jax {jax.__version__}):")
    for name, seconds in median.items():
        print(f"  {name:8s} {1e3 * seconds:8.1f} ms")
    print(f"  ratio jaxship / SciPy: {median['jaxship'] / median['SciPy']:.2f} (goal <= 0.5)")
    print(f"  K, T: jaxship {float(result.model.K):.7g}, {float(result.model.T):.7g} "
          f"({result.code_name}); SciPy {report['K']:.7g}, {report['T']:.7g}")


if __name__ == "__main__":
    main()
