"""Results folders: jaxship replaces only the files it wrote itself (its manifest), the
whole new set appears or none of it, and files of its own earlier run that a new run does
not write are removed."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import jaxship as js
from jaxship.cli import _files, main
from jaxship.cli._files import MANIFEST, read_manifest, staged_folder


def files(folder):
    """{relative path: text} of the files under `folder`, the manifest and staging
    folders left out."""
    return {p.relative_to(folder).as_posix(): p.read_text() for p in folder.rglob("*")
            if p.is_file() and p.name != MANIFEST and not any(
                part.startswith(".jaxship.") for part in p.relative_to(folder).parts)}


def write(out, contents):
    with staged_folder(out) as stage:
        for name, text in contents.items():
            (stage / name).parent.mkdir(parents=True, exist_ok=True)
            (stage / name).write_text(text)


OLD = {"result.json": "old", "figures/a.png": "old a", "figures/b.png": "old b"}
NEW = {"result.json": "new", "figures/a.png": "new a", "notes.txt": "new"}
MINE = {"figures/mine.png": "the user's", "mine.txt": "the user's"}


def test_a_run_replaces_its_own_files_and_nothing_else(tmp_path):
    """The trust audit: `--out p` with the user's `p/figures/mine.png` deleted it (the
    figures folder was replaced whole), and a figure of an earlier run stayed beside
    results that had none."""
    for name, text in MINE.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    write(tmp_path, OLD)
    assert files(tmp_path) == OLD | MINE
    write(tmp_path, NEW)
    assert files(tmp_path) == NEW | MINE  # b.png, of the earlier run only, is gone
    assert sorted(read_manifest(tmp_path)) == sorted(NEW)
    write(tmp_path, {"result.json": "newer"})
    assert files(tmp_path) == {"result.json": "newer"} | MINE


def test_a_file_of_the_users_in_the_way_is_refused_and_kept(tmp_path):
    (tmp_path / "result.json").write_text("the user's")
    with pytest.raises(ValueError, match="result.json exists and jaxship did not write it"):
        write(tmp_path, NEW)
    assert files(tmp_path) == {"result.json": "the user's"}
    assert not list(tmp_path.glob(".jaxship.*"))


@pytest.mark.parametrize("fail_at", range(9))
def test_a_failure_at_any_step_of_the_commit_leaves_one_whole_set(tmp_path, monkeypatch,
                                                                  fail_at):
    """Fault injection: the k-th rename of the commit raises (the journal's, every move,
    the manifest's); afterwards `out` holds the whole old set with its manifest,
    the user's files untouched, and no staging folder."""
    for name, text in MINE.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    write(tmp_path, OLD)
    manifest = (tmp_path / MANIFEST).read_text()
    calls = []
    replace = os.replace

    def failing(source, target):
        calls.append(target)
        if len(calls) == fail_at + 1:
            raise OSError(28, "No space left on device")
        return replace(source, target)

    monkeypatch.setattr(_files.os, "replace", failing)
    steps = 1 + len(OLD) + len(NEW) + 1  # journal, old files aside, new ones in, manifest
    if fail_at < steps:
        with pytest.raises(OSError, match="No space left"):
            write(tmp_path, NEW)
        assert files(tmp_path) == OLD | MINE
        assert (tmp_path / MANIFEST).read_text() == manifest
    else:  # no step left to fail
        write(tmp_path, NEW)
        assert files(tmp_path) == NEW | MINE
    assert not list(tmp_path.glob(".jaxship.*"))


KILLED_COMMIT = """
import importlib.util, json, os, pathlib, signal, sys
spec = importlib.util.spec_from_file_location("files", sys.argv[1])
files = importlib.util.module_from_spec(spec)
spec.loader.exec_module(files)
out, kill_at = pathlib.Path(sys.argv[2]), int(sys.argv[3])
calls, replace = [], os.replace

def killed(source, target):  # SIGKILL before (even kill_at) or after (odd) a rename
    calls.append(target)
    if len(calls) == kill_at // 2 + 1 and kill_at % 2 == 0:
        os.kill(os.getpid(), signal.SIGKILL)
    replace(source, target)
    if len(calls) == kill_at // 2 + 1:
        os.kill(os.getpid(), signal.SIGKILL)

files.os.replace = killed
with files.staged_folder(out) as stage:
    for name, text in json.loads(sys.argv[4]).items():
        (stage / name).parent.mkdir(parents=True, exist_ok=True)
        (stage / name).write_text(text)
"""


@pytest.mark.parametrize("kill_at", range(2 * (1 + len(OLD) + len(NEW) + 1)))
def test_a_run_killed_at_any_step_of_the_commit_is_finished_or_undone_by_the_next(
        tmp_path, kill_at):
    """SIGKILL (no handler runs) just before or just after each rename of the commit
    (journal, old files aside, new ones in, manifest): the next run on the folder finds
    the whole old set, or the whole new set once the manifest was written, the user's
    files untouched, and then commits its own results as usual."""
    for name, text in MINE.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    write(tmp_path, OLD)
    run = subprocess.run([sys.executable, "-c", KILLED_COMMIT, _files.__file__, str(tmp_path),
                          str(kill_at), json.dumps(NEW)], capture_output=True, text=True)
    assert run.returncode == -signal.SIGKILL, run.stderr
    manifest_written = kill_at == 2 * (1 + len(OLD) + len(NEW)) + 1
    _files.recover(tmp_path)
    whole = NEW if manifest_written else OLD
    assert files(tmp_path) == whole | MINE
    assert sorted(read_manifest(tmp_path)) == sorted(whole)
    assert not (tmp_path / _files.JOURNAL).exists()
    write(tmp_path, {"result.json": "newer"})
    assert files(tmp_path) == {"result.json": "newer"} | MINE
    assert not list(tmp_path.glob(".jaxship.*"))


def test_a_journal_that_is_not_jaxships_stops_the_run_and_is_kept(tmp_path):
    (tmp_path / _files.JOURNAL).write_text(json.dumps(
        {"pid": 1 << 30, "commit": "x", "stage": ".jaxship.1", "backup": "..", "old": [],
         "new": []}))
    with pytest.raises(ValueError, match="names files outside"):
        write(tmp_path, NEW)
    assert files(tmp_path) == {_files.JOURNAL: (tmp_path / _files.JOURNAL).read_text()}


def test_staging_folders_of_dead_runs_are_removed(tmp_path):
    """A run killed with SIGKILL leaves its staging folder; the next run removes it (the
    process that made it is gone) but not that of a run still going."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    (tmp_path / f".jaxship.{dead}.abc").mkdir()
    (tmp_path / f".jaxship.{os.getpid()}.xyz").mkdir()
    write(tmp_path, {"result.json": "new"})
    assert [p.name for p in tmp_path.glob(".jaxship.*")] == [f".jaxship.{os.getpid()}.xyz"]


def test_identify_keeps_the_users_figure_and_drops_its_own_stale_ones(tmp_path, capsys):
    """`jaxship identify` into a folder with the user's figure, then again with
    `--no-figures`: its own figures of the first run go, the user's stays."""
    (tmp_path / "trial").mkdir()
    assert main(["simulate", "--vessel", "thesis", "--manoeuvre", "zigzag:20/20", "--duration",
                 "60", "--out", str(tmp_path / "trial")]) == 0
    out = tmp_path / "p"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "mine.png").write_text("keep")
    assert main(["identify", str(tmp_path / "trial" / "trial.csv"), "--model", "nomoto1",
                 "--out", str(out), "--quiet"]) == 0
    assert (out / "figures" / "mine.png").read_text() == "keep"
    assert main(["identify", str(tmp_path / "trial" / "trial.csv"), "--model", "nomoto1",
                 "--out", str(out), "--quiet", "--no-figures"]) == 0
    assert sorted(p.name for p in (out / "figures").iterdir()) == ["mine.png"]
    capsys.readouterr()


def test_a_file_of_the_users_in_the_way_is_refused_before_the_work(tmp_path, capsys,
                                                                   monkeypatch):
    """The trust audit: a user's `report.md` in `discover`'s --out, or a file named
    `figures` in `identify`'s, was found only at the commit, after the whole run (and
    the second ended with exit 1, "File exists"). Now: exit 2, one line, before any
    record is read, and the file kept."""
    def never(*args, **kwargs):
        raise AssertionError("the work started")

    monkeypatch.setattr("jaxship.cli.identify.read_experiments", never)
    monkeypatch.setattr("jaxship.cli.discover.run_discovery", never)
    cases = {"discover": ("report.md", "exists and jaxship did not write it"),
             "identify": ("figures", "is a file of yours where jaxship writes its figures/")}
    for command, (name, message) in cases.items():
        out = tmp_path / command
        out.mkdir()
        (out / name).write_text("mine")
        assert main([command, "any.csv", "--model", "nomoto1", "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1, err
        assert files(out) == {name: "mine"}
    # where jaxship wrote it itself (its manifest), the same name is its to replace
    write(tmp_path / "ours", {"report.md": "old"})
    with pytest.raises(AssertionError, match="the work started"):
        main(["discover", "any.csv", "--model", "nomoto1", "--out", str(tmp_path / "ours")])


def test_a_file_of_the_users_among_the_figures_is_refused_before_the_work(tmp_path, capsys,
                                                                          monkeypatch):
    """Issue 57: a file of the user's in `figures/` under a name jaxship draws was refused
    only at the commit, after the whole fit or discovery. Now: exit 2, one line, after
    the records are read (the names follow them) and before the fit, the file kept;
    other files of the user's there stay allowed
    (`test_identify_keeps_the_users_figure_and_drops_its_own_stale_ones`)."""
    def never(*args, **kwargs):
        raise AssertionError("the work started")

    monkeypatch.setattr("jaxship.cli.identify.identify", never)
    monkeypatch.setattr("jaxship.cli._discovery.identify", never)
    monkeypatch.setattr("jaxship.cli.autopilot.js.evaluate_autopilot", never)
    record = tmp_path / "zz.csv"
    t = np.arange(200) * 0.5
    js.write_trial_csv(record, js.Experiment(t, np.full_like(t, 0.1), name="zz",
                                             r=0.01 * (1 - np.exp(-t / 20))))
    result = tmp_path / "fit" / "result.json"
    result.parent.mkdir()
    result.write_text(json.dumps({"model": "nomoto1", "model_class": "Nomoto1", "frozen": {},
                                  "parameters": {"K": {"value": 0.1}, "T": {"value": 20.0}}}))
    cases = {"identify": [str(record), "--model", "nomoto1"],
             "discover": [str(record), "--model", "nomoto1"],
             "autopilot": ["--model", str(result), "--vessel", "thesis", "--rpm", "300"]}
    names = {"identify": ("fit_train_00_zz.png", "correlation.png"),
             "discover": ("residuals_00.png",), "autopilot": ("heading_300rpm.png",)}
    for command, args in cases.items():
        for name in names[command]:
            out = tmp_path / command / name
            (out / "figures").mkdir(parents=True)
            (out / "figures" / name).write_text("mine")
            assert main([command, *args, "--out", str(out)]) == 2
            err = capsys.readouterr().err
            assert f"figures/{name} exists and jaxship did not write it" in err, err
            assert len(err.strip().splitlines()) == 1, err
            assert files(out) == {f"figures/{name}": "mine"}


RACING_RUN = """
import importlib.util, os, pathlib, sys, time
spec = importlib.util.spec_from_file_location("files", sys.argv[1])
files = importlib.util.module_from_spec(spec)
spec.loader.exec_module(files)
out, tag = pathlib.Path(sys.argv[2]), sys.argv[3]
replace = os.replace

def slow(source, target):  # a slow or network file system
    time.sleep(0.1)
    replace(source, target)

files.os.replace = slow
if tag == "holder":  # takes the lock and waits to be killed
    with files.locked(out):
        print("locked", flush=True)
        time.sleep(60)
with files.staged_folder(out) as stage:
    for name in ("trial.csv", "indices.json", "trial.png", "figures/a.png"):
        (stage / name).parent.mkdir(parents=True, exist_ok=True)
        (stage / name).write_text(tag)
    while not (out / "go").exists():  # both commit at once
        time.sleep(0.01)
"""


def _racing(out, tag):
    return subprocess.Popen([sys.executable, "-c", RACING_RUN, _files.__file__, str(out), tag],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_concurrent_runs_on_one_folder_take_turns_and_never_mix(tmp_path):
    """Issue 57, case 6: two runs on one --out, each rename slowed (a network file
    system), left the trial.csv of one beside the figure of the other under one
    manifest. The commits now take turns under the folder's lock: the folder holds the
    whole set of one run (the later), its manifest lists exactly those files, and
    nothing of the staging is left."""
    write(tmp_path, OLD)
    runs = [_racing(tmp_path, tag) for tag in ("first", "second")]
    deadline = time.monotonic() + 60
    while len(list(tmp_path.glob(".jaxship.*.*"))) < 2 and time.monotonic() < deadline:
        time.sleep(0.01)  # both staged
    (tmp_path / "go").write_text("go")
    for run in runs:
        err = run.communicate(timeout=60)[1]
        assert run.returncode == 0, err
    (tmp_path / "go").unlink()
    written = files(tmp_path)
    assert len(set(written.values())) == 1, written
    assert sorted(written) == sorted(read_manifest(tmp_path)) == sorted(
        ["trial.csv", "indices.json", "trial.png", "figures/a.png"])
    assert not list(tmp_path.glob(".jaxship.*"))


def test_a_killed_run_not_yet_reaped_leaves_nothing_for_the_next(tmp_path):
    """Issue 72: a run SIGKILLed while holding the lock in its commit left its stage and
    backup folders hidden in --out until a third run: its parent had not reaped it, and
    a zombie passed for alive. The next run finishes or undoes its commit and removes
    its folders at once."""
    write(tmp_path, OLD)
    run = subprocess.Popen([sys.executable, "-c", KILLED_COMMIT, _files.__file__,
                            str(tmp_path), "3", json.dumps(NEW)])
    stat = pathlib.Path(f"/proc/{run.pid}/stat")
    for _ in range(600):  # killed by itself mid-commit, and left unreaped
        if stat.exists() and stat.read_text().rsplit(")", 1)[1].split()[0] == "Z":
            break
        time.sleep(0.1)
    assert (tmp_path / _files.JOURNAL).exists() and list(tmp_path.glob(".jaxship.*.old.*"))
    write(tmp_path, {"result.json": "newer"})
    assert files(tmp_path) == {"result.json": "newer"}
    assert not list(tmp_path.glob(".jaxship.*")), list(tmp_path.iterdir())
    assert run.wait(timeout=60) == -signal.SIGKILL


def test_a_killed_holder_of_the_lock_leaves_it_free(tmp_path):
    """The lock is the kernel's (`flock`): a run killed while it holds it (SIGKILL, no
    handler runs) leaves no lock behind, and the next run commits at once."""
    holder = _racing(tmp_path, "holder")
    assert holder.stdout.readline().strip() == "locked"
    holder.kill()
    holder.communicate(timeout=60)
    write(tmp_path, NEW)  # would wait for ever on a lock left behind
    assert files(tmp_path) == NEW
    assert not list(tmp_path.glob(".jaxship.*"))
