"""The GPU table in one command: the sweep at 10^5 and 10^6 turning circles,
`simulation.py`'s ratios (the Mariner and thesis batches of 16,384 and the single run),
`fit.py`, the README's KVLCC2 `discover`, then a GPU test subset (simulate, batch,
sharding and the CLI's simulate cases). Each part runs in a process of its own, with a
time limit, and the lines that carry its numbers are printed as each ends, under the
device and the versions; a part that fails or runs out of time says so and the rest go
on. The timed parts run one after another; the `discover` (bound by compilation on the
host's cores) runs beside the test subset. Budget: 5 minutes on one H200 (issue 56).

Run: `python benchmarks/gpu.py [--quick]` on the machine with the GPU (`pip install
-U "jax[cuda12]"` first). `--quick` shrinks every part to check the script itself on a
CPU in about 5 minutes (the numbers then mean nothing).
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


def parts(quick: bool, out: Path) -> tuple[list, list]:
    """(name, command, time limit [s]) of each part: those timed one after the other,
    then those run side by side (the README's `discover`, compile-bound on the host's
    cores, beside the GPU test subset), each list in order."""
    py = [sys.executable]
    sweep = py + [str(HERE / "sweep.py"), "--repeats", "1", "--chunk-size", "1000000"]
    timed = [
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
    ]
    tests = ["tests/test_simulate.py", "tests/test_batch.py"] + ([] if quick else [
        "tests/test_hosts.py", "tests/test_sharding.py", "tests/test_cli.py"])
    side_by_side = [("GPU test subset", py + [
        "-m", "pytest", "-q", "-n", "2" if quick else "4", "-m", "slow or not slow",
        "-k", "simulate or not cli", *tests], 300.0)]
    data = os.environ.get("JAXSHIP_DATA") or next(
        (str(p / "shared" / "data") for p in HERE.resolve().parents
         if (p / "shared" / "data").is_dir()), None)
    if data:
        hsva = sorted(Path(data, "kvlcc2_simman2008_hsva").glob("*_Z_*.dat"))
        held = [str(p) for p in hsva if "_Z_10_10_" in p.name]
        train = [str(p) for p in hsva if str(p) not in held]
        side_by_side.insert(0, ("discover (README's KVLCC2)", [
            "jaxship", "discover", *(train[-4:] if quick else train), "--holdout", *held,
            "--model", "kvlcc2", "--sample-interval", "0.2", "--out", str(out / "disc"),
            "--quiet"], 240.0))
    return timed, side_by_side


def versions() -> str:
    code = ("import sys, jax, jaxlib, diffrax, equinox, optimistix; d = jax.devices(); "
            "print(f'{d[0].device_kind} x {len(d)} ({jax.default_backend()}); jax '"
            "f'{jax.__version__}, jaxlib {jaxlib.__version__}, diffrax {diffrax.__version__},'"
            "f' equinox {equinox.__version__}, optimistix {optimistix.__version__}, python '"
            "f'{sys.version.split()[0]}')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    return done.stdout.strip() or done.stderr.strip().splitlines()[-1]


def report(name, lines, status, stderr, seconds) -> bool:
    """Print a part's lines that carry numbers; whether it succeeded."""
    print(f"\n## {name}\n")
    print("\n".join(line for line in lines if KEEP.match(line)))
    if status != 0:
        print(f"FAILED: {status}", *stderr.strip().splitlines()[-3:], sep="\n")
    print(f"({seconds:.1f} s)", flush=True)
    return status == 0


def finish(process, limit, began) -> tuple:
    """(stdout lines, status, stderr, seconds) of a started part, killed at `limit`."""
    try:
        stdout, stderr = process.communicate(timeout=max(limit - (time.perf_counter() - began),
                                                         1.0))
        status = process.returncode
    except subprocess.TimeoutExpired:
        process.kill()
        stdout, stderr = process.communicate()
        status = f"out of time ({limit:.0f} s)"
    return stdout.splitlines(), status, stderr, time.perf_counter() - began


def main(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"{time.strftime('%Y-%m-%d %H:%M')}; {versions()}", flush=True)
    start = time.perf_counter()
    timed, side_by_side = parts(args.quick, out)
    start_part = lambda command, env=None: subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=HERE.parent,
        env=env)
    ok = []
    for name, command, limit in timed:
        began = time.perf_counter()
        ok.append(report(name, *finish(start_part(command), limit, began)))
    # side by side, each process takes GPU memory as it needs it (JAX's default takes 75 %)
    shared = os.environ | {"XLA_PYTHON_CLIENT_PREALLOCATE": "false"}
    began = time.perf_counter()
    running = [(name, start_part(command, shared), limit) for name, command, limit
               in side_by_side]
    for name, process, limit in running:
        ok.append(report(name, *finish(process, limit, began)))
    print(f"\nall parts: {time.perf_counter() - start:.0f} s, {ok.count(False)} failed")
    return 0 if all(ok) else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes: a check on a CPU")
    parser.add_argument("--out", default="out/gpu", help="where discover writes its folder")
    sys.exit(main(parser.parse_args()))
