"""What the commands share: one-line errors, checks of arguments and of `--out`, the
progress bar of a fit and notes on stderr."""

import math
import os
import pathlib
import sys
import tempfile
import time

from tqdm import tqdm  # the terminal bar (tqdm.auto warns in a kernel without ipywidgets)

from ._files import read_manifest


def one_line(error) -> str:
    return " ".join(str(error).split())


def add_sample_interval(parser) -> None:
    """The `--sample-interval` option of the commands that fit records."""
    parser.add_argument("--sample-interval", type=float, default=None, metavar="SECONDS",
                        help="resample each record to about this interval (every k-th "
                        "sample) before fitting: fewer samples, a faster fit (default: as "
                        "recorded)")


VELOCITIES = {"through-water": False, "over-ground": True}


def add_velocities(parser) -> None:
    """The `--velocities` option of the commands that fit records: the reference of the
    trial CSVs' u, v (`read_experiments`' `over_ground`)."""
    parser.add_argument("--velocities", choices=VELOCITIES, default=None,
                        help="the trial CSVs' u, v: through-water (default) or over-ground "
                        "(a GNSS track, a basin's carriage: a fitted current is added to "
                        "the predicted u, v); the measured data sets' readers state their "
                        "own (over ground)")


def positive(option, value):
    """`value` (a float or None) checked: finite and positive."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise ValueError(f"{option} {value:g}: must be a positive number.")
    return value


def numbers(option, texts) -> list[float]:
    values = []
    for text in texts:
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{option} {text!r}: not a number.") from None
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{option} {text!r}: must be a positive number.")
        values.append(value)
    return values


def check_out(out: pathlib.Path, writes: tuple[str, ...] = (), inputs=()):
    """`ValueError` unless `out` is (or can be made) a folder we can write into (not under
    a symbolic link that leads nowhere), none of the results the command always `writes`
    there is in the way (`check_writes`), and none of its `inputs` (paths) is, or is
    a folder holding, a file of jaxship's earlier run in `out`, which the commit
    replaces or removes: told before the work, not at the commit; writes nothing that
    stays."""
    for folder in (out, *out.parents):
        if folder.is_symlink() and not folder.exists():
            raise ValueError(f"--out {out}: {folder} is a symbolic link to "
                             f"{os.readlink(folder)}, which is missing or loops; give a "
                             "folder, or make the link's target first.")
        if folder.exists():
            break
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} is a file, not a folder; give a folder (it is made if "
                         "need be).")
    parent = out
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"--out {out}: {parent} is a file, not a folder.")
    try:
        with tempfile.TemporaryFile(dir=parent):
            pass
    except OSError as error:
        raise ValueError(f"--out {out}: cannot write in {parent} "
                         f"({error.strerror or error}).") from None
    check_writes(out, writes)
    ours = [os.path.realpath(out / p) for p in read_manifest(out)] if out.is_dir() else []
    for path in inputs:
        real = os.path.realpath(path)
        if any(p == real or p.startswith(real.rstrip(os.sep) + os.sep) for p in ours):
            raise ValueError(f"{path} is an input of this run and holds results of "
                             f"jaxship's earlier run in --out {out}, which this run replaces; "
                             "copy it out of that folder first or choose another --out.")


def check_writes(out: pathlib.Path, writes: tuple[str, ...]):
    """`ValueError` if a result the command writes into `out` (a path relative to `out`;
    a folder as `"name/"`) is in the way as a file of the user's (not in jaxship's
    manifest)."""
    ours = set(read_manifest(out)) if out.is_dir() else set()
    for name in writes:
        target = out / name.rstrip("/")
        if name.endswith("/") and (target.is_file() or target.is_symlink()
                                   and not target.is_dir()):
            raise ValueError(f"{target} is a file of yours where jaxship writes its {name} "
                             "folder; move it or choose another --out.")
        if not name.endswith("/") and os.path.lexists(target) and name not in ours:
            raise ValueError(f"{target} exists and jaxship did not write it; move it or "
                             "choose another --out (jaxship replaces only its own files).")


def note(sentence: str) -> None:
    print(f"jaxship: note: {sentence}", file=sys.stderr)


class StageClock:
    """The wall time of the command's stages (imports, reading, each `Progress` stage,
    figures, writing), printed on stderr at the end when $JAXSHIP_TIMES is set
    (`benchmarks/latency.py` reads them): `mark(stage)` charges the time since the last
    mark to `stage`."""

    def __init__(self):
        self.last, self.seconds = time.perf_counter(), {}

    def mark(self, stage: str):
        now = time.perf_counter()
        self.seconds[stage] = self.seconds.get(stage, 0.0) + now - self.last
        self.last = now

    def report(self):
        if os.environ.get("JAXSHIP_TIMES"):
            for stage, seconds in self.seconds.items():
                print(f"jaxship: time: {stage} {seconds:.4f}", file=sys.stderr)


CLOCK = StageClock()


class ProgressBar:
    """Turns `identify`'s `Progress` reports into tqdm bars on stderr (and `CLOCK`'s
    stages: the time up to a stage's first report is the stage before it)."""

    def __init__(self, enabled):
        self.enabled, self.bar, self.stage = enabled, None, None

    def __call__(self, event):
        if event.stage != self.stage:
            CLOCK.mark(self.stage or "before the fit")
            self.stage = event.stage
        if not self.enabled:
            return
        if event.stage != "fit":
            if not event.done:
                tqdm.write(f"jaxship: {event.message} ...", file=sys.stderr)
            return
        if self.bar is None:
            self.bar = tqdm(total=event.total, desc=event.message, unit="step", leave=False,
                            file=sys.stderr)
        self.bar.n = min(int(event.step), event.total)
        if event.cost is not None:
            self.bar.set_postfix(cost=f"{event.cost:.5g}", refresh=False)
        self.bar.refresh()
        if event.done:
            self.bar.close()
            self.bar = None
            tqdm.write(f"jaxship: {event.message}: {event.step} steps, cost {event.cost:.6g}",
                       file=sys.stderr)
