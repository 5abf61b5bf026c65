"""The README's KVLCC2 `jaxship discover`, this checkout against another one, side by side.

Each run is a new `jaxship discover` process (the README's command table row `discover
(kvlcc2)` of `benchmarks/cli.py`: the 11 HSVA zig-zags other than the 10/10 runs to train,
both 10/10 runs held out, 5 Hz), with the compilation cache off, its `jaxship` package taken
from `PYTHONPATH` (this checkout, or `--old`, e.g. a `git worktree` of an earlier commit).
Runs alternate (old, new, new, old, ...) so a change of the machine's load falls on both;
absolute times on a shared machine are noisy, the ratio new / old of the medians is the
result. From each run's `discovery.json` it also prints the named effects with their
+-3 standard-error intervals and the share of the two HSVA 10/10 runs' first-overshoot
error closed (summed |predicted - measured| before and after discovery).

    git worktree add /tmp/old <commit>
    python benchmarks/discover_against.py --old /tmp/old --pairs 2
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.cli import table_commands


HERE = Path(__file__).resolve().parents[1]


def one_run(root: Path, out: Path) -> tuple[float, dict]:
    """One `jaxship discover` (README row) with the `jaxship` package of `root`."""
    command = table_commands(out)["discover (kvlcc2)"]
    env = os.environ | {"PYTHONPATH": str(root), "JAXSHIP_CACHE_DIR": "off"}
    began = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - began
    if done.returncode not in (0, 3):
        sys.exit(f"{root}: {' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    return seconds, json.loads((out / "disc" / "discovery.json").read_text())


def summary(report: dict) -> str:
    """Named effects with intervals and the HSVA 10/10 first-overshoot error closed."""
    named = []
    for e in report["effects"]:
        for name, p in e["parameters"].items():
            named.append(f"{name} {p['value']:.4g} +- {3 * p['std']:.2g}")
    picked = [idx["overshoot_1_deg"] for idx in report["holdout_indices"].values()
              if "overshoot_1_deg" in idx]
    error = {w: sum(abs(v[w] - v["measured"]) for v in picked) for w in ("before", "after")}
    closed = 100 * (1 - error["after"] / error["before"])
    return (f"named {[e['id'] for e in report['effects']]} ({'; '.join(named)}); first-overshoot "
            f"error {error['before']:.2f} -> {error['after']:.2f} deg, {closed:.1f} % closed")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", type=Path, required=True, help="the other checkout's root")
    parser.add_argument("--pairs", type=int, default=2)
    args = parser.parse_args()
    times = {"old": [], "new": []}
    roots = {"old": args.old.resolve(), "new": HERE}
    for which, root in roots.items():  # the package each run imports (run from elsewhere)
        where = subprocess.run([sys.executable, "-c", "import jaxship; print(jaxship.__file__)"],
                               env=os.environ | {"PYTHONPATH": str(root)}, cwd="/",
                               capture_output=True, text=True).stdout.strip()
        print(f"{which}: {where} ({root})")
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.pairs):
            for which in (("old", "new") if k % 2 == 0 else ("new", "old")):
                seconds, report = one_run(roots[which], Path(tmp) / f"{which}{k}")
                times[which].append(seconds)
                print(f"{time.strftime('%H:%M:%S')} pair {k + 1} {which} ({roots[which]}): "
                      f"{seconds:.1f} s; {summary(report)}", flush=True)
    old, new = statistics.median(times["old"]), statistics.median(times["new"])
    print(f"median old {old:.1f} s, new {new:.1f} s: new / old = {new / old:.2f} "
          f"({args.pairs} pairs, {time.strftime('%Y-%m-%d')}, "
          f"{len(os.sched_getaffinity(0))} CPU cores)")


if __name__ == "__main__":
    main()
