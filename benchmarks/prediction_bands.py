"""Prediction bands on real held-out runs, judged run by run against a yardstick: the
coverage a correct model and noise model would give on runs of these lengths (issue 58,
point 4).

Run: python benchmarks/prediction_bands.py [--case esso-miyauchi esso-wakita kvlcc2]

For each case a model is fitted on the training runs, its disturbance (`jaxship.Disturbance`,
a Gauss-Markov output disturbance of the yaw rate, integrated into the heading) is
calibrated on those same runs (`calibrate_disturbance`: its std and correlation time such
that the band covers 90 % of their r and of their psi samples), and the bands
(`prediction_bands`: the robust parameter covariance, the disturbance and the sensor noise,
200 runs) of a free simulation of each held-out run from its first measured state are
scored by the fraction of its measured r and psi samples inside them. The yardstick of
each run is `PredictionBands.coverage_range`: the central 90 % of the coverage its 200
draws get (each draw a record the model would produce if it and its noise model were
right). A run passes when both its r and its psi coverage fall inside their ranges; the
goal is 10 of the 12 non-berthing held-out runs.

- `esso-miyauchi`, `esso-wakita`: the `esso_osaka` preset fitted as `jaxship identify
  --model esso_osaka` fits it (the preset's `fit_settings`, the command's estimator) on
  Miyauchi's Train-R and Wakita's Train-TZRB, the logged wind replayed; the berthing runs
  (unlogged thrusters) scored but outside the goal;
- `kvlcc2`: the `kvlcc2` preset's default free set fitted (60 s windows) on the 11 HSVA
  zig-zags other than the two 10/10 runs, which are held out with MARIN's four zig-zags
  (Froude-scaled), all at 5 Hz (`real_data.kvlcc2_discovery_split`).

The sensor noise of each channel is estimated from the training runs as the standard
deviation of the second difference divided by sqrt(6) (white noise on a smooth signal).
The numbers land in `benchmarks/results/published_splits.json` under "bands".
"""

import argparse
import json
import math
import pathlib
import sys
import time

import jax
import numpy as np
import optimistix as optx


sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))  # benchmarks.*

import jaxship as js  # noqa: E402
from benchmarks.published_splits import RESULTS, bands_table, write  # noqa: E402
from jaxship.studies.published_splits import SPLITS, read_runs  # noqa: E402
from jaxship.studies.real_data import kvlcc2_discovery_split  # noqa: E402


LEVEL = 0.9



def sensor_std(runs, channels=("psi", "r")) -> dict:
    """White sensor noise from the second differences: var(d2 y) = 6 sigma^2."""
    return {c: float(np.sqrt(np.mean(np.concatenate([np.diff(getattr(e, c), 2) ** 2
                                                      for e in runs]) / 6.0)))
            for c in channels}


def esso_case(paper, train_set):
    """The `esso_osaka` preset fitted as `jaxship identify --model esso_osaka` does: its
    `fit_settings` (horizon, sample interval, free set) and the command's estimator."""
    split, settings = SPLITS[paper], js.VESSELS["esso_osaka"].fit_settings
    step = round(settings.sample_interval / 0.1)  # the runs are logged at 10 Hz
    train = [r.decimate(step) for r in read_runs(split[train_set])]
    test = [r.decimate(step) for r in read_runs(split["Test"])]
    estimator = js.PredictionError(horizon=settings.horizon, channels=("psi", "r", "u", "v"),
                                   wind=True, max_steps=256,
                                   simulator=js.Simulator(max_step=math.inf, substeps=1),
                                   solver=js.LevenbergMarquardt(rtol=1e-9, atol=1e-9))
    fit = js.fit(js.get_vessel("esso_osaka"), train, estimator=estimator, free=settings.free)
    replay = js.PredictionError(horizon=None, wind=True, channels=("psi", "r"))
    return f"Esso Osaka, {paper}, {train_set}", fit, train, test, replay


def kvlcc2_case():
    train, test = kvlcc2_discovery_split()
    estimator = js.PredictionError(horizon=60.0, max_steps=100,
                                   solver=optx.LevenbergMarquardt(rtol=1e-6, atol=1e-6))
    fit = js.fit(js.get_vessel("kvlcc2"), train, estimator=estimator)
    replay = js.PredictionError(horizon=None, channels=("psi", "r"))
    return "KVLCC2, HSVA zig-zags (10/10 held out, MARIN's four)", fit, train, test, replay


CASES = {"esso-miyauchi": lambda: esso_case("Miyauchi 2022", "Train-R"),
         "esso-wakita": lambda: esso_case("Wakita 2022", "Train-TZRB"),
         "kvlcc2": kvlcc2_case}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--case", nargs="+", choices=sorted(CASES), default=sorted(CASES))
    args = parser.parse_args(argv)
    jax.config.update("jax_enable_x64", True)
    js.enable_compilation_cache()
    results = json.loads(RESULTS.read_text()) if RESULTS.is_file() else {}
    for case in args.case:
        results.setdefault("bands", {})[case] = one_case(case)
    print("\n".join(bands_table(results["bands"])))
    write(results)


def one_case(case) -> dict:
    t0 = time.perf_counter()
    title, fit, train, test, replay = CASES[case]()
    noise = sensor_std(train)
    options = dict(estimator=replay, measurement_std=noise)
    disturbance = js.calibrate_disturbance(fit, train, level=LEVEL, **options)
    bands = js.prediction_bands(fit, test, level=LEVEL, disturbance=disturbance, **options)
    coverage, ranges = bands.coverage(test), bands.coverage_range(0.9)
    print(f"\n## {title}\n\nfit: {fit.code_name} after {fit.num_steps} steps; sensor "
          f"noise psi {np.degrees(noise['psi']):.3f} deg, r {np.degrees(noise['r']):.4f} "
          f"deg/s; disturbance calibrated on the training runs: std "
          f"{np.degrees(disturbance.std):.3f} deg/s, tau {disturbance.tau:.0f} s; "
          f"{bands.num_dropped} of {bands.num_samples} runs dropped; "
          f"{time.perf_counter() - t0:.0f} s\n")
    rows = []
    for i, run in enumerate(test):
        row = {"run": run.name, "scored": not run.name.startswith("berthing"),
               "samples": int(bands.predicted[i].sum())}
        for c in ("r", "psi"):
            row[c] = float(coverage[c][i])
            row[c + "_range"] = [float(x) for x in ranges[c][i]]
        row["inside"] = all(row[c + "_range"][0] <= row[c] <= row[c + "_range"][1]
                            for c in ("r", "psi"))
        rows.append(row)
    return {"title": title, "fit": fit.code_name, "disturbance_std": disturbance.std,
            "disturbance_tau": disturbance.tau, "runs": rows}


if __name__ == "__main__":
    main()
