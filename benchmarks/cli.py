"""First and second runs of the `jaxship` command, each in a new process, with and without
the persistent compilation cache.

Every run is a new `jaxship` process (import, compilation, the work, the files), timed
end to end from outside. For each command the script runs it twice with the cache off
(`JAXSHIP_CACHE_DIR=off`: every process compiles again, as before the cache) and twice
with an empty cache folder of its own (the first run fills it, the second reads it), and
prints the four wall times and the ratio first / second with the cache.

Commands (the README's examples):
- `jaxship simulate --vessel kvlcc2 --manoeuvre turn:35` (goal: second run <= 2 s);
- `jaxship identify` of Nomoto 1 on the Esso Osaka zig-zags, five to train and two held out
  (goal: second run <= half the first), when `../shared/data` is found.

Also `python -c "import jaxship"` (the import alone), for the part no cache can save.

Run: `python benchmarks/cli.py [--repeats N]` (the median of N runs of each; default 1).
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import jaxship as js


def timed(command, env, out):
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode not in (0, 3):
        sys.exit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    return seconds


def commands(out: Path) -> dict:
    found = {"simulate kvlcc2 turn:35": ["jaxship", "simulate", "--vessel", "kvlcc2",
                                         "--manoeuvre", "turn:35", "--out", str(out / "sim")]}
    data = js.shared_data_dir()
    if data is not None:
        records = sorted((data / "esso_osaka_frt" / "zigzag").glob("*.csv"))
        found["identify nomoto1 (Esso zig-zags)"] = [
            "jaxship", "identify", *map(str, records[:5]), "--model", "nomoto1", "--horizon",
            "10", "--validate", *map(str, records[5:7]), "--out", str(out / "fit"),
            "--quiet"]
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        off = os.environ | {"JAXSHIP_CACHE_DIR": "off"}
        importing = [timed([sys.executable, "-c", "import jaxship"], off, tmp)
                     for _ in range(args.repeats)]
        print(f"import jaxship: {statistics.median(importing):.2f} s")
        print("| command | no cache, 1st | no cache, 2nd | cache, 1st | cache, 2nd | "
              "1st / 2nd with the cache |")
        print("|---|---:|---:|---:|---:|---:|")
        for name, command in commands(tmp).items():
            runs = {key: [] for key in ("off1", "off2", "on1", "on2")}
            for k in range(args.repeats):
                cache = {"JAXSHIP_CACHE_DIR": str(tmp / f"cache-{name[:8]}-{k}")}
                runs["off1"].append(timed(command, off, tmp))
                runs["off2"].append(timed(command, off, tmp))
                runs["on1"].append(timed(command, os.environ | cache, tmp))
                runs["on2"].append(timed(command, os.environ | cache, tmp))
            t = {key: statistics.median(v) for key, v in runs.items()}
            print(f"| `{name}` | {t['off1']:.1f} s | {t['off2']:.1f} s | {t['on1']:.1f} s | "
                  f"{t['on2']:.1f} s | {t['on1'] / t['on2']:.1f}x |")


if __name__ == "__main__":
    main()
