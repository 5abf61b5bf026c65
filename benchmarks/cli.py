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

Also `python -c "import jaxship"` (the import alone), for the part no cache can save, and
the import of the libraries `simulate` loads before any jaxship code runs (`DEPENDENCIES`),
the floor that no change to jaxship lowers.

`--table` times every example of the README's command table instead, as written there
(the placeholders filled with the data they stand for: the first Esso Osaka zig-zags for
`$1`-`$5`, the 11 HSVA KVLCC2 zig-zags other than the 10/10 runs for `TRAIN...` and the two
10/10 runs for `TEST...`), each twice in a new process with an empty cache folder of its
own: the first run compiles (the README's time), the second reads the cache. It prints the
table's time column with the date and the number of CPU cores.

`--flags` times the first run (empty cache) of every example of the table twice, with the
command's own XLA compiler setting (`jaxship.compile_for_small_programs()`: the loop emitters
instead of the MLIR fusion emitters) and with XLA's defaults (set in `$XLA_FLAGS`, which
the command then leaves as they are), and prints the ratio default / own.

Run: `python benchmarks/cli.py [--repeats N] [--table | --flags] [--only TEXT]` (the median
of N runs of each, default 1; `--only`: the table's rows whose name contains TEXT, e.g.
`--only discover` after a change to `discover` alone; the `autopilot` rows read the
`identify (nomoto1)` row's result, the `simulate imo` row the `identify (esso_osaka 3-DOF)`
row's: `--only esso` times both).
"""

import argparse
import importlib.metadata
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import jaxship as js


# what `jaxship simulate` imports besides jaxship itself
DEPENDENCIES = "import jax, equinox, diffrax, optimistix, matplotlib.pyplot"
# XLA's own values of the flags `js.compile_for_small_programs()` sets
XLA_DEFAULTS = {"--xla_backend_optimization_level": "3", "--xla_cpu_use_fusion_emitters": "true"}


def command_flags() -> tuple[str, ...]:
    """The flags the command adds on this machine: `js.compile_for_small_programs()` with
    $XLA_FLAGS empty (this process starts no computation; $XLA_FLAGS is restored)."""
    given = os.environ.pop("XLA_FLAGS", None)
    try:
        return js.compile_for_small_programs()
    finally:
        os.environ.pop("XLA_FLAGS", None)
        if given is not None:
            os.environ["XLA_FLAGS"] = given


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


def table_commands(out: Path) -> dict:
    """The README's command table, in its order, placeholders filled (module text)."""
    data = js.shared_data_dir()
    if data is None:
        sys.exit("--table needs ../shared/data (set JAXSHIP_DATA).")
    esso = sorted((data / "esso_osaka_frt" / "zigzag").glob("*.csv"))
    hsva = sorted((data / "kvlcc2_simman2008_hsva").glob("*_Z_*.dat"))
    held = [p for p in hsva if "_Z_10_10_" in p.name]
    identify = ["jaxship", "identify", *map(str, esso[:3]), "--horizon", "10", "--validate",
                *map(str, esso[3:5]), "--quiet"]
    autopilot = ["jaxship", "autopilot", "--model", str(out / "fit" / "result.json"),
                 "--vessel", "thesis", "--rpm", "300", "400", "--quiet"]
    return {
        "vessels": ["jaxship", "vessels"],
        "simulate": ["jaxship", "simulate", "--vessel", "mariner", "--manoeuvre",
                     "zigzag:20/20", "--out", str(out / "zz")],
        "identify (nomoto1)": identify + ["--model", "nomoto1", "--out", str(out / "fit")],
        "identify (esso_osaka 3-DOF)": identify + ["--model", "esso_osaka", "--out",
                                                   str(out / "esso")],
        "simulate imo (the esso_osaka fit)": ["jaxship", "simulate", "--vessel",
                                              str(out / "esso" / "result.json"),
                                              "--manoeuvre", "imo", "--out", str(out / "imo")],
        "autopilot": autopilot + ["--out", str(out / "ap")],
        "autopilot --tune": autopilot + ["--tune", "--out", str(out / "ap-tune")],
        "discover (kvlcc2)": ["jaxship", "discover", *map(str, (p for p in hsva
                                                               if p not in held)),
                              "--holdout", *map(str, held), "--model", "kvlcc2",
                              "--sample-interval", "0.2", "--out", str(out / "disc"),
                              "--quiet"],
        "reproduce --quick": ["jaxship", "reproduce", "--quick", "--out", str(out / "rq")],
        "reproduce": ["jaxship", "reproduce", "--out", str(out / "r")],
    }


def table(repeats: int, tmp: Path, only: str | None = None) -> None:
    """The README's time column: first run (empty cache) and second (the cache read), of
    the rows whose name contains `only` (None: all)."""
    commands = {name: command for name, command in table_commands(tmp).items()
                if only is None or only in name}
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    print(f"{time.strftime('%Y-%m-%d')}, {cores} CPU cores, each command in a new process")
    print("| command | first run (compiles) | second run (cache) |")
    print("|---|---:|---:|")
    for i, (name, command) in enumerate(commands.items()):
        first, second = [], []
        for k in range(repeats):  # an empty cache folder of its own
            cache = os.environ | {"JAXSHIP_CACHE_DIR": str(tmp / f"table-cache-{i}-{k}")}
            first.append(timed(command, cache, tmp))
            second.append(timed(command, cache, tmp))
        print(f"| `{name}` | {statistics.median(first):.0f} s | "
              f"{statistics.median(second):.0f} s |", flush=True)


def flags(repeats: int, tmp: Path) -> None:
    """Each table command's first run with XLA's defaults and with the command's setting."""
    default = " ".join(f.split("=")[0] + "=" + XLA_DEFAULTS[f.split("=")[0]]
                       for f in command_flags())  # none this jaxlib lacks
    if not default:
        sys.exit(f"--flags: here the command adds none of "
                 f"{js.compile_for_small_programs.SMALL_PROGRAMS} (jaxlib "
                 f"{importlib.metadata.version('jaxlib')}, or not the CPU), so there is "
                 "nothing to compare.")
    print(f"{time.strftime('%Y-%m-%d')}, first runs (empty cache), each in a new process")
    print("| command | XLA's defaults | jaxship's setting | ratio |")
    print("|---|---:|---:|---:|")
    for i, (name, command) in enumerate(table_commands(tmp).items()):
        times = {}
        for label, xla in (("default", default), ("own", "")):
            runs = []
            for k in range(repeats):
                env = os.environ | {"JAXSHIP_CACHE_DIR": str(tmp / f"flags-{i}-{label}-{k}"),
                                    "XLA_FLAGS": xla}
                runs.append(timed(command, env, tmp))
            times[label] = statistics.median(runs)
        print(f"| `{name}` | {times['default']:.1f} s | {times['own']:.1f} s | "
              f"{times['default'] / times['own']:.2f}x |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1)
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--table", action="store_true",
                       help="time every example of the README's command table")
    which.add_argument("--flags", action="store_true",
                       help="the table's first runs with XLA's defaults and with jaxship's")
    parser.add_argument("--only", help="with --table: the rows whose name contains this text")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if args.table:
            return table(args.repeats, tmp, args.only)
        if args.flags:
            return flags(args.repeats, tmp)
        off = os.environ | {"JAXSHIP_CACHE_DIR": "off"}
        importing = [timed([sys.executable, "-c", "import jaxship"], off, tmp)
                     for _ in range(args.repeats)]
        libraries = [timed([sys.executable, "-c", DEPENDENCIES], off, tmp)
                     for _ in range(args.repeats)]
        print(f"import jaxship: {statistics.median(importing):.2f} s; `{DEPENDENCIES}` "
              f"alone: {statistics.median(libraries):.2f} s")
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
