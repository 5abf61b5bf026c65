"""Programs traced and lowered once per installation: `jax.export` keeps a jitted
function's StableHLO on disk, keyed on its static arguments, its argument shapes and the
versions of JAX, jaxship and the libraries it traces through; a later process loads it
and calls it, so it neither traces nor lowers the function again, and the persistent
compilation cache supplies XLA's compiled program.

`persistent(fn)` wraps an `equinox.filter_jit` function. The store is off until
`enable_compilation_cache` turns it on beside the compilation cache (`exported/` in the
same folder); off, inside a trace, or wherever a step fails (a static argument that
cannot be pickled, a program `jax.export` refuses, an unreadable file), the call is the
plain `fn(*args)`: the store only ever saves time."""

import functools
import hashlib
import importlib.metadata
import inspect
import io
import os
import pathlib
import pickle
import re
import tempfile

import equinox as eqx
import jax


try:  # equinox's sentinel for absent fields, inside its modules' tree definitions
    from equinox._module._flatten import MISSING as _EQX_MISSING
except ImportError:  # another equinox layout: nothing to translate
    _EQX_MISSING = object()


_FOLDER: list[pathlib.Path | None] = [None]
_LOADED: dict[str, tuple] = {}  # key -> (jitted call, output's static part, output treedef)
_LIBRARIES = ("jax", "jaxlib", "equinox", "optimistix", "diffrax", "lineax", "numpy")


def use_store(folder: pathlib.Path | None) -> None:
    """Keep exported programs in `folder` (None: off)."""
    _FOLDER[0] = folder


def persistent(fn):
    """`fn` (an `equinox.filter_jit` function), its program exported to the store on
    its first call with each static configuration and argument shapes, and loaded from
    there by later processes. `__wrapped__` is `fn`'s own Python function."""
    raw = getattr(fn, "__wrapped__", fn)
    signature = inspect.signature(raw)

    @functools.wraps(fn)
    def call(*args, **kwargs):
        folder = _FOLDER[0]
        if folder is None:
            return fn(*args, **kwargs)
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()  # every argument by position, as the key sees it
        if bound.kwargs:  # keyword-only arguments: not for the store
            return fn(*args, **kwargs)
        args = bound.args
        dynamic, static = eqx.partition(args, eqx.is_array)
        leaves, treedef = jax.tree.flatten(dynamic)
        if any(isinstance(leaf, jax.core.Tracer) for leaf in leaves):
            return fn(*args)
        try:
            key = _key(raw, treedef, static, leaves)
        except Exception:  # a static argument that does not pickle
            return fn(*args)
        program = _LOADED.get(key)
        if program is None:
            program = _read(folder / f"{key}.jaxexport") \
                or _export(fn, treedef, static, leaves, folder / f"{key}.jaxexport")
            if program is None:
                return fn(*args)
            # jitted once: `Exported.call` alone lowers its module again at every call
            # (8-12 ms each, 268 calls in `reproduce --quick`; issue 70)
            exported, out_static, out_treedef = program
            program = _LOADED[key] = (jax.jit(exported.call), out_static, out_treedef)
        caller, out_static, out_treedef = program
        return eqx.combine(jax.tree.unflatten(out_treedef, caller(*leaves)), out_static)

    call.__wrapped__ = raw
    return call


def _key(fn, treedef, static, leaves) -> str:
    """The store's key: the function, its static arguments and argument tree, each
    argument's shape and dtype, and the code that traces it."""
    digest = hashlib.sha256(_dumps((fn.__module__, fn.__qualname__, treedef, static)))
    for leaf in leaves:
        digest.update(repr((leaf.shape, str(leaf.dtype),
                            bool(getattr(leaf, "weak_type", False)))).encode())
    digest.update(_code_version().encode())
    digest.update(repr((jax.config.jax_enable_x64, jax.default_backend())).encode())
    return digest.hexdigest()[:40]


@functools.cache
def _code_version() -> str:
    """The versions of the libraries a trace runs through, and jaxship's own source
    files (path, size, modification time): an edited file is a new program."""
    versions = []
    for name in _LIBRARIES:
        try:
            versions.append(f"{name}={importlib.metadata.version(name)}")
        except importlib.metadata.PackageNotFoundError:
            versions.append(f"{name}=?")
    package = pathlib.Path(__file__).resolve().parents[1]
    for path in sorted(package.rglob("*.py")):
        stat = path.stat()
        versions.append(f"{path.relative_to(package)}:{stat.st_size}:{stat.st_mtime_ns}")
    return "\n".join(versions)


def _export(fn, treedef, static, leaves, path: pathlib.Path):
    """Export `fn` at these arguments, write it to `path` (atomically) and return the
    program, or None where `jax.export` or the file fails."""
    out = {}

    def flat(*dynamic):
        result = fn(*eqx.combine(jax.tree.unflatten(treedef, dynamic), static))
        out_dynamic, out["static"] = eqx.partition(result, eqx.is_array)
        out_leaves, out["treedef"] = jax.tree.flatten(out_dynamic)
        return out_leaves

    flat.__name__ = flat.__qualname__ = fn.__name__  # as JAX's logs name its trace
    try:
        jitted = jax.jit(flat)
        try:
            exported = jax.export.export(jitted, disabled_checks=_lapack_checks())(*leaves)
        except ValueError as error:  # another custom call without compatibility
            if "custom call" not in str(error):  # guarantees: found in the lowered
                raise  # text (a second lowering, rare)
            text = jitted.lower(*leaves).as_text()
            checks = [jax.export.DisabledSafetyCheck.custom_call(t)
                      for t in sorted(set(re.findall(r"custom_call @([\w.]+)", text)))]
            exported = jax.export.export(jitted, disabled_checks=checks)(*leaves)
        blob = _dumps((bytes(exported.serialize()), out["static"], out["treedef"]))
    except Exception:
        return None
    _write(path, blob)
    return exported, out["static"], out["treedef"]


@functools.cache
def _lapack_checks() -> list:
    """The compatibility checks of jaxlib's LAPACK custom calls, off: `jax.export`
    guarantees only some across jaxlib versions, but the store is keyed on the exact
    jaxlib, so each is safe here (found up front, without lowering a program twice)."""
    operations = ("getrf", "geqrf", "geqp3", "orgqr", "ungqr", "ormqr", "unmqr", "potrf",
                  "gesdd", "gesvd", "syevd", "heevd", "geev", "gees", "gehrd", "sytrd",
                  "hetrd", "trsm", "gtsv")
    return [jax.export.DisabledSafetyCheck.custom_call(f"lapack_{kind}{operation}{suffix}")
            for kind in "sdcz" for operation in operations for suffix in ("_ffi", "")]


def _write(path: pathlib.Path, blob: bytes) -> None:
    """`blob` to `path` whole or not at all (a folder that cannot be written: nothing)."""
    temporary = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path.parent, delete=False) as file:
            temporary = file.name
            file.write(blob)
        os.replace(temporary, path)
    except OSError:
        if temporary is not None:
            pathlib.Path(temporary).unlink(missing_ok=True)


def _read(path: pathlib.Path):
    """The program stored at `path`, or None (absent or unreadable)."""
    try:
        serialized, out_static, out_treedef = _loads(path.read_bytes())
        return jax.export.deserialize(bytearray(serialized)), out_static, out_treedef
    except Exception:
        return None


class _Pickler(pickle.Pickler):
    def persistent_id(self, obj):
        return "equinox.MISSING" if obj is _EQX_MISSING else None


class _Unpickler(pickle.Unpickler):
    def persistent_load(self, pid):
        if pid != "equinox.MISSING":
            raise pickle.UnpicklingError(f"unknown persistent id {pid!r}")
        return _EQX_MISSING


def _dumps(obj) -> bytes:
    buffer = io.BytesIO()
    _Pickler(buffer, protocol=4).dump(obj)
    return buffer.getvalue()


def _loads(data: bytes):
    return _Unpickler(io.BytesIO(data)).load()
