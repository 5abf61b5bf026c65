"""JAX's persistent compilation cache for jaxship: compiled programs kept on disk, so that a
second process running the same call shapes skips XLA compilation (5-9 s a shape).

Nothing happens on import: the CLI turns the cache on, and a library user does so with one
call of `enable_compilation_cache`. Where: `$JAXSHIP_CACHE_DIR` if set (`off`, `0` or an
empty value disables it), else `jaxship/jax` under the user's cache folder
(`$XDG_CACHE_HOME`, by default `~/.cache`)."""

import os
import pathlib

import jax

from ._exported import use_store


ENV = "JAXSHIP_CACHE_DIR"
_OFF = ("", "0", "off", "none", "false")


def compilation_cache_dir() -> pathlib.Path | None:
    """The folder `enable_compilation_cache()` uses by default, or None where
    `$JAXSHIP_CACHE_DIR` disables the cache."""
    if ENV in os.environ:
        value = os.environ[ENV].strip()
        return None if value.lower() in _OFF else pathlib.Path(value).expanduser()
    home = os.environ.get("XDG_CACHE_HOME") or pathlib.Path.home() / ".cache"
    return pathlib.Path(home) / "jaxship" / "jax"


def enable_compilation_cache(path: str | os.PathLike | None = None, *,
                             min_compile_time: float = 0.0) -> pathlib.Path | None:
    """Keep compiled XLA programs in `path` (default: `compilation_cache_dir()`), so that
    later processes reuse them. Programs that compiled in less than `min_compile_time`
    seconds are not stored; by default every one is, the single operations run outside
    `jit` too (each compiles for 20-80 ms in every new process otherwise: a second
    `jaxship simulate --vessel kvlcc2 --manoeuvre turn:35` took 4.42 s instead of 5.18 s,
    means of 6 alternated runs, 2026-11-28). Returns the folder, or None where the cache
    is disabled (by `$JAXSHIP_CACHE_DIR`) or the folder cannot be created (then nothing
    changes: a missing cache only costs time). The traced programs are kept too, in
    `exported/` there (`_exported`: traced and lowered once per installation). This
    sets JAX's global configuration: call it from an application or a notebook, not
    from a library."""
    folder = compilation_cache_dir() if path is None else pathlib.Path(path).expanduser()
    if folder is None:
        return None
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    jax.config.update("jax_compilation_cache_dir", str(folder))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", float(min_compile_time))
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    use_store(folder / "exported")  # and the traced programs (`_exported`)
    return folder
