"""XLA compiler flags for many small programs (the `jaxship` command, the test suite, a
notebook or script of short runs), set only where they hold: `compile_for_small_programs`,
beside `enable_compilation_cache`.

XLA reads `$XLA_FLAGS` once, when JAX starts its backend, and a flag the running XLA does
not know ends the process there (`Unknown flag in XLA_FLAGS`: a fatal error that no
Python code can catch). So a flag is added only when (1) JAX will compile for the CPU,
judged without starting it, and (2) the installed jaxlib is a version known to accept
the flag (`FLAG_VERSIONS`); any other version, a newer one included, gets XLA's own
setting. Nothing here starts XLA.
"""

import importlib.metadata
import importlib.util
import os

import jax


# XLA's CPU compiler set for many small programs: the loop emitters instead of the MLIR
# fusion emitters. Each command says whether it compiles many programs that run briefly
# (`small_programs(args)`, set in its `register`): 1.08-1.29x faster commands with
# jaxlib 0.10.2 (docs/results.md). LLVM's optimisation stays on: with `RK4`'s stages in a
# loop, turning it off as well gave wrong forward and reverse derivatives of a
# closed-loop Mariner run (0.00286 against 0.00363 by central differences,
# tests/test_contracts.py's user controller; either flag alone is right).
SMALL_PROGRAMS = ("--xla_cpu_use_fusion_emitters=false",)

# The jaxlib versions (first, last, inclusive) on which each flag was seen accepted: each
# CPU wheel from PyPI, 0.4.30 to 0.12.0.1, started with the flag in $XLA_FLAGS
# (2026-11-28). The fusion emitters' switch is unknown up to 0.5.1 and from 0.11.1 on (the
# loop emitters gone); a version outside a flag's range, a newer one included, gets no flag.
FLAG_VERSIONS = {
    "--xla_cpu_use_fusion_emitters": ((0, 5, 3), (0, 11, 0)),
    "--xla_backend_optimization_level": ((0, 4, 30), (0, 12, 0, 1)),
}


def jaxlib_version() -> tuple[int, ...]:
    """The installed jaxlib's version as numbers (`0.12.0.1` -> `(0, 12, 0, 1)`)."""
    text = importlib.metadata.version("jaxlib")
    return tuple(int(part) for part in text.split("+")[0].split(".") if part.isdigit())


def compiles_for_cpu() -> bool:
    """Whether JAX will compile for the CPU, judged without starting its backend:
    `JAX_PLATFORMS` (or `jax.config.jax_platforms`) names the CPU first, or it names
    nothing and no accelerator plugin is installed (CUDA or ROCm `jax_plugins`, or
    libtpu). With a plugin but no device JAX falls back to the CPU without the flags:
    slower to compile, never wrong."""
    platforms = requested_platforms()
    return platforms[0] == "cpu" if platforms else not accelerator_plugins()


def requested_platforms() -> list[str]:
    """The platforms `JAX_PLATFORMS` (or `jax.config.jax_platforms`) asks for, in order."""
    return [p.strip() for p in (jax.config.jax_platforms or "").split(",") if p.strip()]


def accelerator_plugins() -> list[str]:
    """The accelerator plugins JAX would load: the entry points of group `jax_plugins`
    (jax-cuda12-plugin, jax-cuda13-plugin, jax-rocm-plugin) and libtpu."""
    names = [entry.name for entry in importlib.metadata.entry_points(group="jax_plugins")]
    return names + (["tpu"] if importlib.util.find_spec("libtpu") else [])


def known_flags(flags, version=None) -> tuple[str, ...]:
    """The `flags` (`--name=value`) that jaxlib `version` (default: the installed one)
    is known to accept (`FLAG_VERSIONS`)."""
    version = jaxlib_version() if version is None else version

    def known(flag):
        first, last = FLAG_VERSIONS.get(flag.split("=")[0], ((), ()))
        return bool(first) and first <= version <= last

    return tuple(flag for flag in flags if known(flag))


def compile_for_small_programs(flags=SMALL_PROGRAMS) -> tuple[str, ...]:
    """Set XLA's CPU compiler for many small programs: add `flags` (default
    `compile_for_small_programs.SMALL_PROGRAMS`, the loop emitters instead of the MLIR
    fusion emitters: `("--xla_cpu_use_fusion_emitters=false",)`) to $XLA_FLAGS where they
    hold: on the CPU, each one the installed jaxlib is known to accept (`FLAG_VERSIONS`)
    and $XLA_FLAGS does not set already. XLA reads them when JAX starts its backend (at
    the first computation), so call it before any: later calls change nothing. The
    `jaxship` command calls it for the commands that compile many programs and run each
    briefly (1.08-1.29x faster with jaxlib 0.10.2, docs/results.md); the numbers are the
    same to rounding. Returns the flags added (none on a GPU, or on a jaxlib not known to
    accept them)."""
    if not compiles_for_cpu():
        return ()
    given = os.environ.get("XLA_FLAGS", "").split()
    named = {f.split("=")[0] for f in given}
    added = tuple(f for f in known_flags(flags) if f.split("=")[0] not in named)
    os.environ["XLA_FLAGS"] = " ".join(given + list(added))
    return added


compile_for_small_programs.SMALL_PROGRAMS = SMALL_PROGRAMS  # its default, documented above
