"""Results written whole: a file through a temporary file renamed into place, a
folder of results through a temporary folder whose files are renamed in at the end,
so that an error or an interrupt never leaves half a result (POSIX `rename` is atomic
within a file system; a journal lets the next run finish or undo the commit of a
process killed in it), and a manifest of the files jaxship wrote into a results
folder, so that a later run replaces those and nothing else. Runs on one folder take
turns at its commit (a lock that the kernel releases when its holder dies)."""

import contextlib
import errno
import fcntl
import json
import os
import pathlib
import secrets
import shutil
import tempfile


MANIFEST = ".jaxship-manifest.json"  # the files of the last run in a results folder
JOURNAL = ".jaxship-commit.json"  # a commit under way: its moves, to finish or undo
LOCK = ".jaxship.lock"  # held while a run prepares its stage or commits, removed after
_STAGE = ".jaxship."  # staging folders and temporary files: .jaxship.<pid>.<...>
_OPEN = set()  # this process' staging folders being written


def write_whole(path: pathlib.Path, write):
    """Write `path` through a temporary file in its folder (`write(temporary path)`),
    then rename it into place."""
    handle, temporary = tempfile.mkstemp(dir=path.parent, suffix=".tmp",
                                         prefix=f"{_STAGE}{os.getpid()}.{path.name}.")
    os.close(handle)
    umask = os.umask(0)
    os.umask(umask)
    try:
        write(pathlib.Path(temporary))
        os.chmod(temporary, 0o666 & ~umask)  # as an ordinary new file (mkstemp makes 0600)
        os.replace(temporary, path)
    except BaseException:
        pathlib.Path(temporary).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def staged_folder(out: pathlib.Path):
    """A temporary folder inside `out` (made if need be) to write results into. When the
    block ends the files written there replace the files of jaxship's earlier run in
    `out` (its manifest), those of the earlier run that this one did not write are
    removed, and no other file is touched (`commit`): a file of the user's in the way
    is a `ValueError`. After an error nothing is moved, the temporary folder is removed,
    and so is `out` if it was made here and is empty. First a commit that a killed run
    left half done is finished or undone (`recover`), and staging folders of runs that
    died (their process is gone) are removed. Both under `out`'s lock (`locked`), so
    that the commits of concurrent runs never mix: the one that commits last wins
    whole."""
    made = [folder for folder in (out, *out.parents) if not folder.exists()]
    out.mkdir(parents=True, exist_ok=True)
    with locked(out):
        recover(out)
        _remove_stale(out)
        stage = pathlib.Path(tempfile.mkdtemp(dir=out, prefix=f"{_STAGE}{os.getpid()}."))
    _OPEN.add(stage)
    try:
        yield stage
        _OPEN.discard(stage)
        with locked(out):
            commit(stage, out)
    finally:
        _OPEN.discard(stage)
        shutil.rmtree(stage, ignore_errors=True)
        for folder in made:  # innermost first; each only while empty
            with contextlib.suppress(OSError):
                folder.rmdir()


@contextlib.contextmanager
def locked(out: pathlib.Path):
    """Hold the lock of the folder `out` (an exclusive `flock` on its `LOCK` file, waiting
    for another process holding it); the file is removed on release. A killed holder
    releases it with its file descriptors; a file system without locks goes unlocked."""
    path = out / LOCK
    while True:
        handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX)
        except BaseException as error:  # Ctrl-C while waiting, or no locks here
            if isinstance(error, OSError) and error.errno in (errno.ENOLCK, errno.EOPNOTSUPP):
                break
            os.close(handle)
            raise
        with contextlib.suppress(FileNotFoundError):
            if os.path.samestat(os.fstat(handle), os.stat(path)):
                break  # else its holder removed it as we waited: lock the new one
        os.close(handle)
    try:
        yield
    finally:
        path.unlink(missing_ok=True)  # while held: a waiter then locks a new file
        os.close(handle)


def discard_open_stages():
    """Remove the staging folders of this process that are still being written (not
    those of a commit under way): for a process about to end without unwinding."""
    for stage in list(_OPEN):
        shutil.rmtree(stage, ignore_errors=True)


def commit(stage: pathlib.Path, out: pathlib.Path):
    """Move every file under `stage` to the same place under `out`, replacing the files
    that `out`'s manifest lists (jaxship's earlier run) and removing those of them that
    are not written again, then write the new manifest. Whole or not at all: a journal
    written first names the moves, so an error at any step moves back what was moved
    (the old set stays, the new files return to `stage`) and is raised again, and a
    process killed mid-way is undone, or finished once its manifest is written, by the
    next run on `out` (`recover`). A file in the way that the manifest does not list
    (the user's) is a `ValueError` before anything moves."""
    new = sorted(p.relative_to(stage).as_posix() for p in stage.rglob("*") if p.is_file())
    old = [p for p in read_manifest(out) if (out / p).is_file()]
    theirs = [p for p in new if os.path.lexists(out / p) and p not in old]
    if theirs:
        raise ValueError(f"{out / theirs[0]} exists and jaxship did not write it; move it or "
                         "choose another --out (jaxship replaces only its own files).")
    backup = pathlib.Path(tempfile.mkdtemp(dir=out, prefix=f"{_STAGE}{os.getpid()}.old."))
    journal = {"pid": os.getpid(), "commit": secrets.token_hex(8), "stage": stage.name,
               "backup": backup.name, "old": old, "new": new}
    try:
        _write_json(out / JOURNAL, journal)
        for p in old:  # the earlier run's files aside, all of them before any new one
            _move(out / p, backup / p)
        for p in new:
            _move(stage / p, out / p)
        _write_json(out / MANIFEST, {"written_by": "jaxship", "commit": journal["commit"],
                                     "files": new})  # the commit point
    except BaseException:
        _undo(out, journal)
        raise
    _finish(out, journal)


def recover(out: pathlib.Path):
    """Complete or undo the commit into `out` of a jaxship process that died in it (its
    journal is there and the process is gone): finished if its manifest was written,
    else the old files come back from their backup and the new ones leave."""
    try:
        journal = json.loads((out / JOURNAL).read_text(encoding="utf-8"))
        pid, token = int(journal["pid"]), journal["commit"]
        names = [journal["stage"], journal["backup"], *journal["old"], *journal["new"]]
    except FileNotFoundError:
        return
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        raise ValueError(f"{out / JOURNAL} is not a journal jaxship can read; move it "
                         "away after checking the folder's files.") from None
    folders = names[:2]
    if not (all(isinstance(n, str) and _inside(n) for n in names)
            and all(n.startswith(_STAGE) and "/" not in n for n in folders)):
        raise ValueError(f"{out / JOURNAL} names files outside {out}; move it away.")
    if pid != os.getpid() and _alive(pid):  # a commit under way in another process
        return
    try:
        done = json.loads((out / MANIFEST).read_text(encoding="utf-8")).get("commit") == token
    except (OSError, ValueError, AttributeError):
        done = False
    _finish(out, journal) if done else _undo(out, journal)


def _undo(out: pathlib.Path, journal: dict):
    """The commit of `journal` moved back: new files that reached `out` to the stage
    (old files were all set aside before any new one moved in), old ones from the
    backup; the journal goes last, so an undo cut short is taken up again."""
    stage, backup = out / journal["stage"], out / journal["backup"]
    for p in journal["new"]:
        if not (stage / p).exists() and (out / p).is_file():
            _move(out / p, stage / p)
    for p in journal["old"]:
        if (backup / p).is_file():
            _move(backup / p, out / p)
    _prune(out, journal["new"])
    (out / JOURNAL).unlink(missing_ok=True)
    shutil.rmtree(backup, ignore_errors=True)


def _finish(out: pathlib.Path, journal: dict):
    """The commit of `journal` done: its journal and the old files' backup removed, and
    the folders the old files leave empty."""
    (out / JOURNAL).unlink(missing_ok=True)
    shutil.rmtree(out / journal["backup"], ignore_errors=True)
    _prune(out, journal["old"])


def _prune(out: pathlib.Path, paths: list[str]):
    """Remove the folders under `out` holding `paths` that are left empty."""
    for p in paths:
        for folder in (out / p).parents:
            if folder == out or not folder.is_relative_to(out):
                break
            with contextlib.suppress(OSError):
                folder.rmdir()


def read_manifest(out: pathlib.Path) -> list[str]:
    """The files (relative paths) jaxship wrote into `out` in its last run; none where
    there is no readable manifest."""
    try:
        files = json.loads((out / MANIFEST).read_text(encoding="utf-8"))["files"]
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        return []
    return [p for p in files if isinstance(p, str) and _inside(p)] if isinstance(files, list) \
        else []


def _inside(path: str) -> bool:
    """A relative path that stays inside its folder."""
    return not pathlib.PurePosixPath(path).is_absolute() and ".." not in path.split("/")


def _write_json(path: pathlib.Path, content: dict):
    write_whole(path, lambda p: p.write_text(json.dumps(content, indent=1) + "\n"))


def _move(source: pathlib.Path, target: pathlib.Path):
    target.parent.mkdir(parents=True, exist_ok=True)
    os.replace(source, target)


def _remove_stale(out: pathlib.Path):
    """Remove the staging folders and temporary files in `out` of jaxship processes that
    no longer run."""
    for path in out.glob(f"{_STAGE}*"):
        pid = path.name[len(_STAGE):].split(".")[0]
        if pid.isdigit() and not _alive(int(pid)):
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)
            else:
                path.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    """Whether process `pid` runs: a killed process that its parent has not yet reaped
    (a zombie, Linux's /proc state Z) no longer does, and its leftovers go now, not a
    run later."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    try:
        stat = pathlib.Path(f"/proc/{pid}/stat").read_text()
    except OSError:  # no /proc (macOS): a zombie counts as alive until reaped
        return True
    return stat[stat.rindex(")") + 2:][:1] != "Z"
