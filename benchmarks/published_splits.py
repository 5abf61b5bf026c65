"""Esso Osaka on the data owners' published splits, by a protocol that makes every choice
on training runs only: the lab's simulator against `jaxship identify --model esso_osaka`.

Run: python benchmarks/published_splits.py [--select-only] [--sets Train-R ...]
     python benchmarks/published_splits.py --tables   (the tables of the results file)

1. **Selection** (`select`). Each candidate setting of the fit (free set, prediction
   horizon, sample interval, wind-load model, the scale of a prior on the lab's
   coefficients, from none to 0, the lab's coefficients unfitted: `FACTORS`) is scored
   by leave-one-run-out cross-validation on Miyauchi's Train-R, the training set the
   preset's defaults come from: `jaxship identify` on three of its four runs, a free
   simulation of the fourth (`free_run_score`, 10 Hz), the r RMSE divided by the lab
   simulator's on that run, averaged over the four folds. A coordinate search starts
   from the command's settings and tries each factor's values in turn, keeping the best,
   pass after pass until a pass changes nothing, so the free set and the prior are
   chosen together. Every candidate's score is printed; the run reader refuses every
   test run's name while this runs (`Reader`).
2. **Headline** (`headline`). `jaxship identify --model esso_osaka` with no option (its
   defaults are the selection: `jaxship.VESSELS["esso_osaka"].fit_settings`, checked
   against the results file by `tests/test_published_splits.py`) on each training set of
   both papers; every model and both lab columns are scored on the test runs:
   - `lab (Fujiwara wind)`: the lab's simulator as published (its coefficients and
     Fujiwara et al.'s wind loads);
   - `lab (jaxship wind)`: the lab's coefficients with jaxship's generic wind loads.
   Goals are judged against the stronger of the two on each run (`GOALS`).
3. **One source.** Everything lands in `benchmarks/results/published_splits.json`;
   `--tables` prints the Markdown tables that README.md, docs/results.md and
   benchmarks/README.md carry (a test checks they match the file).

Berthing runs are scored as measured: their bow and stern thrusters are not logged, so
no model fed these logs can follow them.
"""

import argparse
import json
import pathlib
import sys

import jax


ROOT = pathlib.Path(__file__).resolve().parents[1]

import jaxship as js  # noqa: E402
from jaxship.studies.published_splits import (  # noqa: E402
    FACTORS,
    SELECTION_SET,
    SPLITS,
    Reader,
    discovered,
    goals,
    headline,
    key,
    scores,
    select,
    tables,
)


RESULTS = ROOT / "benchmarks" / "results" / "published_splits.json"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--select-only", action="store_true", help="the selection only")
    parser.add_argument("--tables", action="store_true",
                        help="print the tables of the results file, run nothing")
    parser.add_argument("--discover", action="store_true",
                        help="add `discover` on Train-R's runs (point 5) as a column")
    parser.add_argument("--without", nargs="*", default=[], metavar="FACTOR=VALUE",
                        help="leave a candidate value out of the search (e.g. wind=fujiwara)")
    args = parser.parse_args(argv)
    if args.tables:
        print(tables(json.loads(RESULTS.read_text())))
        return
    jax.config.update("jax_enable_x64", True)
    js.enable_compilation_cache()
    for item in args.without:
        factor, value = item.split("=")
        FACTORS[factor] = tuple(v for v in FACTORS[factor] if str(v) != value)
    results = json.loads(RESULTS.read_text()) if RESULTS.is_file() else {}
    known = {c["setting_key"]: c for c in results.get("selection", {}).get("candidates", [])}
    say = lambda text: print(text, file=sys.stderr, flush=True)
    reader = Reader()
    names = SPLITS[SELECTION_SET[0]][SELECTION_SET[1]]
    results["selection"] = select(reader, names, say=say, known=known)
    write(results)
    say(f"chosen on {' '.join(SELECTION_SET)}: {key(results['selection']['chosen'])}")
    if args.select_only:
        return
    results["headline"] = headline(reader, say=say)
    if args.discover:
        results["discover"], model = discovered(reader, say=say)
    if args.discover and results["discover"]["named"]:  # a column for what it adds
        label = "Train-R + discover (" + " + ".join(results["discover"]["named"]) + ")"
        block = results["headline"][SELECTION_SET[0]]
        test = reader.runs(block["test"])
        block["columns"][label] = scores(model, test)
        block["goals"][label] = goals(block["columns"], label)
    write(results)
    print(tables(results))


def write(results) -> None:
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
