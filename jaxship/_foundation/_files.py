"""Results written whole: a file through a temporary file renamed into place, a
folder of results through a temporary folder whose files are renamed in at the end,
so that an error or an interrupt never leaves half a result (POSIX `rename` is atomic
within a file system), and a manifest of the files jaxship wrote into a results folder,
so that a later run replaces those and nothing else."""

import contextlib
import json
import os
import pathlib
import shutil
import tempfile


MANIFEST = ".jaxship-manifest.json"  # the files of the last run in a results folder
_STAGE = ".jaxship."  # staging folders: .jaxship.<pid>.<random>


def write_whole(path: pathlib.Path, write):
    """Write `path` through a temporary file in its folder (`write(temporary path)`),
    then rename it into place."""
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
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
    and so is `out` if it was made here and is empty. Staging folders of runs that died
    (their process is gone) are removed first."""
    made = [folder for folder in (out, *out.parents) if not folder.exists()]
    out.mkdir(parents=True, exist_ok=True)
    _remove_stale(out)
    stage = pathlib.Path(tempfile.mkdtemp(dir=out, prefix=f"{_STAGE}{os.getpid()}."))
    try:
        yield stage
        commit(stage, out)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
        for folder in made:  # innermost first; each only while empty
            with contextlib.suppress(OSError):
                folder.rmdir()


def commit(stage: pathlib.Path, out: pathlib.Path):
    """Move every file under `stage` to the same place under `out`, replacing the files
    that `out`'s manifest lists (jaxship's earlier run) and removing those of them that
    are not written again, then write the new manifest. Whole or not at all: an error
    at any step moves back what was moved (the old set stays, the new files return to
    `stage`) and is raised again. A file in the way that the manifest does not list
    (the user's) is a `ValueError` before anything moves."""
    new = sorted(p.relative_to(stage).as_posix() for p in stage.rglob("*") if p.is_file())
    old = [p for p in read_manifest(out) if (out / p).is_file()]
    theirs = [p for p in new if (out / p).exists() and p not in old]
    if theirs:
        raise ValueError(f"{out / theirs[0]} exists and jaxship did not write it; move it or "
                         "choose another --out (jaxship replaces only its own files).")
    backup = pathlib.Path(tempfile.mkdtemp(dir=out, prefix=f"{_STAGE}{os.getpid()}.old."))
    moved = []  # (from, to) in order, to undo
    try:
        for p in old:  # the earlier run's files aside
            _move(out / p, backup / p, moved)
        for p in new:
            _move(stage / p, out / p, moved)
        write_whole(out / MANIFEST, lambda path: path.write_text(json.dumps(
            {"written_by": "jaxship", "files": new}, indent=1) + "\n"))
    except BaseException:
        for source, target in reversed(moved):
            os.replace(target, source)
        raise
    finally:
        shutil.rmtree(backup, ignore_errors=True)
    for p in old:  # folders the earlier run's files leave empty
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
    inside = lambda p: not pathlib.PurePosixPath(p).is_absolute() and ".." not in p.split("/")
    return [p for p in files if isinstance(p, str) and inside(p)] if isinstance(files, list) \
        else []


def _move(source: pathlib.Path, target: pathlib.Path, moved: list):
    target.parent.mkdir(parents=True, exist_ok=True)
    os.replace(source, target)
    moved.append((source, target))


def _remove_stale(out: pathlib.Path):
    """Remove the staging folders in `out` of jaxship processes that no longer run."""
    for folder in out.glob(f"{_STAGE}*"):
        pid = folder.name[len(_STAGE):].split(".")[0]
        if folder.is_dir() and pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(folder, ignore_errors=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True
