"""The README's KVLCC2 `jaxship discover`, this checkout against another one, side by side.

Each run is a new `jaxship discover` process (the README's command table row `discover
(kvlcc2)` of `benchmarks/cli.py`: the 11 HSVA zig-zags other than the 10/10 runs to train,
both 10/10 runs held out, 5 Hz), with the compilation cache off, its `jaxship` package taken
from `PYTHONPATH` (this checkout, or `--old`, e.g. a `git worktree` of an earlier commit).
Runs alternate (old, new, new, old, ...) so a change of the machine's load falls on both,
or with `--together` each pair runs at the same time (on a machine loaded by others, both
then see the same load). Absolute times on a shared machine are noisy: the ratios new / old
of the medians of the wall time and of the process's CPU time (user + system, which a
machine's load changes far less) are the result. From each run's `discovery.json` it
also prints the named effects with their +-3 standard-error intervals and the share of
the two HSVA 10/10 runs' first-overshoot error closed (summed |predicted - measured|
before and after discovery).

    git worktree add /tmp/old <commit>
    python benchmarks/discover_against.py --old /tmp/old --pairs 2 [--together]
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


def start(root: Path, out: Path) -> tuple:
    """Start one `jaxship discover` (README row) with the `jaxship` package of `root`."""
    command = table_commands(out)["discover (kvlcc2)"]
    env = os.environ | {"PYTHONPATH": str(root), "JAXSHIP_CACHE_DIR": "off"}
    out.mkdir(parents=True)
    errors = open(out / "stderr.txt", "w")
    return subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=errors), \
        time.perf_counter(), out


def finish(run: tuple) -> tuple[float, float, dict]:
    """Wait for a started run: `(wall s, CPU s (user + system), discovery.json)`."""
    process, began, out = run
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - began
    if os.waitstatus_to_exitcode(status) not in (0, 3):
        sys.exit(f"{out}: failed:\n{(out / 'stderr.txt').read_text()}")
    return seconds, usage.ru_utime + usage.ru_stime, json.loads(
        (out / "disc" / "discovery.json").read_text())


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
    parser.add_argument("--together", action="store_true",
                        help="run each pair's two at the same time")
    args = parser.parse_args()
    times = {"old": [], "new": []}
    cpu = {"old": [], "new": []}
    roots = {"old": args.old.resolve(), "new": HERE}
    for which, root in roots.items():  # the package each run imports (run from elsewhere)
        where = subprocess.run([sys.executable, "-c", "import jaxship; print(jaxship.__file__)"],
                               env=os.environ | {"PYTHONPATH": str(root)}, cwd="/",
                               capture_output=True, text=True).stdout.strip()
        print(f"{which}: {where} ({root})")
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.pairs):
            order = ("old", "new") if k % 2 == 0 else ("new", "old")
            groups = [order] if args.together else [(w,) for w in order]
            for group in groups:
                started = {w: start(roots[w], Path(tmp) / f"{w}{k}") for w in group}
                for which, run in started.items():
                    seconds, used, report = finish(run)
                    times[which].append(seconds)
                    cpu[which].append(used)
                    print(f"{time.strftime('%H:%M:%S')} pair {k + 1} {which} ({roots[which]}): "
                          f"{seconds:.1f} s wall, {used:.1f} s CPU; {summary(report)}",
                          flush=True)
    wall = {w: statistics.median(v) for w, v in times.items()}
    used = {w: statistics.median(v) for w, v in cpu.items()}
    print(f"median wall old {wall['old']:.1f} s, new {wall['new']:.1f} s: new / old = "
          f"{wall['new'] / wall['old']:.2f}; CPU old {used['old']:.1f} s, new "
          f"{used['new']:.1f} s: new / old = {used['new'] / used['old']:.2f} ({args.pairs} "
          f"pairs{', each at the same time' if args.together else ''}, "
          f"{time.strftime('%Y-%m-%d')}, {len(os.sched_getaffinity(0))} CPU cores)")


if __name__ == "__main__":
    main()
