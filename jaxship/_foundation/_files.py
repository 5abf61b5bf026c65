"""Results written whole: a file through a temporary file renamed into place, a
folder of results through a temporary folder whose entries are renamed in at the end,
so that an error or an interrupt never leaves half a result (POSIX `rename` is atomic
within a file system)."""

import contextlib
import os
import pathlib
import shutil
import tempfile


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
    """A temporary folder inside `out` (made if need be) to write results into: when the
    block ends, each of its folders replaces the one of that name in `out` and each file
    is renamed into `out` (folders first, files in name order); after an error nothing is
    moved, the temporary folder is removed, and so is `out` if it was made here and is
    empty."""
    made = [folder for folder in (out, *out.parents) if not folder.exists()]
    out.mkdir(parents=True, exist_ok=True)
    stage = pathlib.Path(tempfile.mkdtemp(dir=out, prefix=".jaxship."))
    try:
        yield stage
        entries = sorted(stage.iterdir(), key=lambda p: (not p.is_dir(), p.name))
        for entry in entries:
            target = out / entry.name
            if entry.is_dir() and target.is_dir():
                os.replace(target, stage / f".old.{entry.name}")
            os.replace(entry, target)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
        for folder in made:  # innermost first; each only while empty
            with contextlib.suppress(OSError):
                folder.rmdir()
