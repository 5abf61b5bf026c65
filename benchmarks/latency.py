"""The README's `identify` example against the SciPy script a user would write instead
(`benchmarks/scipy_identify.py`), side by side, each run a new process (issue 70).

The example: `jaxship identify $1 $2 $3 --model nomoto1 --horizon 10 --validate $4 $5
--out ...` on the first five Esso Osaka zig-zags (`ls $JAXSHIP_DATA/esso_osaka_frt/
zigzag/*.csv`: three to train, two held out), with its figures and with `--no-figures`;
the script the same with `--figures` and without. The command is this checkout's
(`_jaxship_cli.py`, the console script's entry). A warm-up run of each fills the
compilation cache (a temporary folder, `$JAXSHIP_CACHE_DIR`) and the file cache; then
`--rounds` rounds (default 3) run the four in turn, the order reversed every other round.

Prints the median wall time of each, the ratios jaxship / SciPy with and without
figures, the script's K, T and cost against jaxship's result.json, and jaxship's stage
table: the command's own stage times (`$JAXSHIP_TIMES`: imports, parsing, reading, start
values, fit, validation, figures, writing, summary), the rest of the wall time
(interpreter start and exit), and the largest top-level imports (`python -X importtime`,
one extra run without figures).

Run: `python benchmarks/latency.py [--rounds N]` (with `$JAXSHIP_DATA` set, or
`../shared/data` beside the checkout).
"""

import argparse
import datetime
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("JAXSHIP_DATA", ROOT.parent / "shared" / "data"))


def records():
    found = sorted((DATA / "esso_osaka_frt" / "zigzag").glob("*.csv"))
    if len(found) < 5:
        sys.exit(f"the Esso Osaka zig-zags are not in {DATA}: set $JAXSHIP_DATA.")
    return [str(p) for p in found[:5]]


def commands(out: Path) -> dict:
    r = records()
    jaxship = [sys.executable, str(ROOT / "_jaxship_cli.py"), "identify", *r[:3], "--model",
               "nomoto1", "--horizon", "10", "--validate", *r[3:5]]
    scipy = [sys.executable, str(ROOT / "benchmarks" / "scipy_identify.py"), *r[:3],
             "--validate", *r[3:5]]
    return {"jaxship": jaxship + ["--out", str(out / "jaxship")],
            "SciPy": scipy + ["--figures", "--out", str(out / "scipy")],
            "jaxship --no-figures": jaxship + ["--no-figures", "--out", str(out / "jn")],
            "SciPy without figures": scipy + ["--out", str(out / "sn")]}


def timed(command, env) -> tuple[float, str]:
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=ROOT)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    return seconds, done.stdout + done.stderr


def stages(output: str) -> dict:
    return {m[1]: float(m[2]) for m in re.finditer(r"jaxship: time: (.+) ([0-9.]+)\n",
                                                   output)}


def top_imports(command, env, count=8) -> list[tuple[str, float]]:
    """The packages' cumulative import times [s] of one run (`-X importtime`): each
    package's own import line (nested ones included, so they overlap: jax holds
    ml_dtypes)."""
    done = subprocess.run([command[0], "-X", "importtime", *command[1:]], env=env,
                          capture_output=True, text=True, cwd=ROOT)
    totals = {}
    for line in done.stderr.splitlines():
        m = re.match(r"import time:\s+\d+ \|\s+(\d+) \|(.*)$", line)
        if m and "." not in m[2].strip() and not m[2].strip().startswith("_"):
            name = m[2].strip()
            totals[name] = max(totals.get(name, 0.0), int(m[1]) * 1e-6)
    return sorted(totals.items(), key=lambda item: -item[1])[:count]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        env = dict(os.environ, JAXSHIP_CACHE_DIR=str(folder / "cache"), JAXSHIP_TIMES="1")
        runs = commands(folder)
        for command in runs.values():  # warm-up: the compilation cache, the file cache
            timed(command, env)
        times = {name: [] for name in runs}
        table = {name: [] for name in runs if name.startswith("jaxship")}
        for round_ in range(args.rounds):
            for name in (list(runs) if round_ % 2 == 0 else list(runs)[::-1]):
                seconds, output = timed(runs[name], env)
                times[name].append(seconds)
                if name in table:
                    table[name].append(dict(stages(output), total=seconds))
        check = subprocess.run(runs["SciPy without figures"] + [
            "--check", str(folder / "jaxship" / "result.json")], capture_output=True,
            text=True, cwd=ROOT).stdout
        imports = top_imports(runs["jaxship --no-figures"], env)
    load = os.getloadavg()
    print(f"# {datetime.date.today()}, {os.cpu_count()} cores, load average "
          f"{load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; median of {args.rounds} alternated "
          "rounds, warm compilation cache, each run a new process\n")
    print("| run | median [s] | runs [s] |\n|---|---|---|")
    for name, values in times.items():
        print(f"| {name} | {statistics.median(values):.2f} | "
              f"{', '.join(f'{v:.2f}' for v in values)} |")
    median = {name: statistics.median(values) for name, values in times.items()}
    print(f"\nratio jaxship / SciPy: {median['jaxship'] / median['SciPy']:.2f} with figures "
          f"(goal 1.5), {median['jaxship --no-figures'] / median['SciPy without figures']:.2f}"
          " without (goal 3)\n")
    print("SciPy against jaxship's result.json:\n" + "\n".join(
        f"    {line}" for line in check.splitlines()) + "\n")
    names = list(dict.fromkeys(s for rows in table.values() for row in rows for s in row
                               if s != "total"))
    print("jaxship's stages (median [s] over the rounds):\n")
    print("| stage | " + " | ".join(table) + " |\n|---|" + "---|" * len(table))
    for stage in ["interpreter start and exit"] + names + ["total"]:
        cells = []
        for rows in table.values():
            values = [row["total"] - sum(v for k, v in row.items() if k != "total")
                      if stage.startswith("interpreter") else row.get(stage, 0.0)
                      for row in rows]
            cells.append(f"{statistics.median(values):.2f}")
        print(f"| {stage} | " + " | ".join(cells) + " |")
    print("\nlargest imports of `jaxship identify --no-figures` (cumulative, one run with "
          "`-X importtime`; nested packages counted in their importers too): "
          + ", ".join(f"{n} {s:.2f} s" for n, s in imports))


if __name__ == "__main__":
    main()
