"""The GPU table in one command: the sweep at 10^5 and 10^6 turning circles,
`simulation.py`'s ratios (the Mariner and thesis batches of 16,384 and the single run),
`fit.py`, the README's KVLCC2 `discover`, then a GPU test subset (simulate, batch,
sharding and the CLI's simulate cases). Each part runs in a process of its own, with a
time limit, and the lines that carry its numbers are printed as they come, under the
device and the versions; a part that fails or runs out of time says so and the rest go
on. Budget: 5 minutes on one H200 (issue 56).

Run: `python benchmarks/gpu.py [--quick]` on the machine with the GPU (`pip install
-U "jax[cuda12]"` first). `--quick` shrinks every part to check the script itself on a
CPU in about 3 minutes (the numbers then mean nothing).
"""

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path


HERE = Path(__file__).parent
# the lines of each script's output that carry its numbers
KEEP = re.compile(r"^(\||first call|runs that|jaxship:|SciPy:|time (incl|excl)|\d+ (passed|failed)"
                  r"|.*(passed|failed|error).* in [\d.]+s|jaxship: |held-out|verdict)")


def parts(quick: bool, out: Path) -> list[tuple[str, list[str], float]]:
    """(name, command, time limit [s]) of each part, in order."""
    py = [sys.executable]
    sweep = py + [str(HERE / "sweep.py"), "--repeats", "1", "--chunk-size", "1000000"]
    data = os.environ.get("JAXSHIP_DATA") or next(
        (str(p / "shared" / "data") for p in HERE.resolve().parents
         if (p / "shared" / "data").is_dir()), None)
    found = []
    if data:
        hsva = sorted(Path(data, "kvlcc2_simman2008_hsva").glob("*_Z_*.dat"))
        held = [str(p) for p in hsva if "_Z_10_10_" in p.name]
        train = [str(p) for p in hsva if str(p) not in held]
        found = [("discover (README's KVLCC2)",
                  ["jaxship", "discover", *(train[:2] if quick else train), "--holdout",
                   *held, "--model", "kvlcc2", "--sample-interval", "0.2", "--out",
                   str(out / "disc"), "--quiet"], 240.0)]
    tests = ["tests/test_simulate.py", "tests/test_batch.py", "tests/test_hosts.py",
             "tests/test_sharding.py", "tests/test_cli.py"]
    return [
        ("sweep, 10^5 thesis turning circles",
         sweep + ["--perturbations", "10" if quick else "1000"], 120.0),
        ("sweep, 10^6 thesis turning circles",
         sweep + ["--perturbations", "20" if quick else "10000"], 120.0),
        ("simulation.py, batches of 16,384",
         py + [str(HERE / "simulation.py"), "--batches", "64" if quick else "16384",
               "--repeats", "3", "--scipy-subset", "2", "--duration",
               "60" if quick else "600"], 240.0),
        ("fit.py", py + [str(HERE / "fit.py"), "--budget", "20"]
         + (["--quick"] if quick else []), 240.0),
        *found,
        ("GPU test subset", py + ["-m", "pytest", "-q", "-n", "0", "-m", "slow or not slow",
                                  "-k", "not Ctrl and not ctrl and not interrupt",
                                  *tests], 300.0),
    ]


def versions() -> str:
    code = ("import sys, jax, jaxlib, diffrax, equinox, optimistix; d = jax.devices(); "
            "print(f'{d[0].device_kind} x {len(d)} ({jax.default_backend()}); jax '"
            "f'{jax.__version__}, jaxlib {jaxlib.__version__}, diffrax {diffrax.__version__},'"
            "f' equinox {equinox.__version__}, optimistix {optimistix.__version__}, python '"
            "f'{sys.version.split()[0]}')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    return done.stdout.strip() or done.stderr.strip().splitlines()[-1]


def main(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"{time.strftime('%Y-%m-%d %H:%M')}; {versions()}", flush=True)
    failed = 0
    start = time.perf_counter()
    for name, command, limit in parts(args.quick, out):
        print(f"\n## {name}\n", flush=True)
        began = time.perf_counter()
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=limit,
                                  cwd=HERE.parent)
            lines, status = done.stdout.splitlines(), done.returncode
        except subprocess.TimeoutExpired as stop:
            text = stop.stdout.decode() if isinstance(stop.stdout, bytes) else stop.stdout or ""
            lines, status = text.splitlines(), f"out of time ({limit:.0f} s)"
        print("\n".join(line for line in lines if KEEP.match(line)))
        if status != 0:
            failed += 1
            tail = done.stderr.strip().splitlines()[-3:] if isinstance(status, int) else []
            print(f"FAILED: {status}", *tail, sep="\n")
        print(f"({time.perf_counter() - began:.1f} s)", flush=True)
    print(f"\nall parts: {time.perf_counter() - start:.0f} s, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes: a check on a CPU")
    parser.add_argument("--out", default="out/gpu", help="where discover writes its folder")
    sys.exit(main(parser.parse_args()))
