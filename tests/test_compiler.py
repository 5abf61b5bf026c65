"""XLA's compiler flags (`jaxship.compile_for_small_programs`, issue 56): set only on the
CPU and only where the installed jaxlib knows them, so that no version of XLA ends the process on an
unknown flag; the user's own $XLA_FLAGS kept."""

import os
import subprocess
import sys

import pytest

from jaxship import compile_for_small_programs
from jaxship._foundation import _compiler
from jaxship._foundation._compiler import FLAG_VERSIONS, SMALL_PROGRAMS


@pytest.fixture
def cpu_jaxlib(monkeypatch):
    """A CPU machine with jaxlib 0.10.2, which knows every flag of the table."""
    monkeypatch.setattr(_compiler, "jaxlib_version", lambda: (0, 10, 2))
    monkeypatch.setattr(_compiler, "requested_platforms", lambda: [])
    monkeypatch.setattr(_compiler, "accelerator_plugins", lambda: [])
    monkeypatch.delenv("XLA_FLAGS", raising=False)


def test_the_public_default_is_the_commands_setting():
    """`js.compile_for_small_programs()` adds its documented attribute `SMALL_PROGRAMS`,
    the loop emitters instead of the MLIR fusion emitters."""
    import inspect

    import jaxship as js

    assert js.compile_for_small_programs is compile_for_small_programs
    default = inspect.signature(compile_for_small_programs).parameters["flags"].default
    assert default == compile_for_small_programs.SMALL_PROGRAMS == SMALL_PROGRAMS == (
        "--xla_cpu_use_fusion_emitters=false",)


def test_the_users_xla_flags_are_kept(cpu_jaxlib, monkeypatch):
    monkeypatch.setenv("XLA_FLAGS", "--xla_dump_to=x")
    assert compile_for_small_programs() == SMALL_PROGRAMS
    assert os.environ["XLA_FLAGS"].split() == [
        "--xla_dump_to=x", "--xla_cpu_use_fusion_emitters=false"]
    monkeypatch.setenv("XLA_FLAGS", "--xla_cpu_use_fusion_emitters=true --xla_dump_to=x")
    assert compile_for_small_programs() == ()
    assert os.environ["XLA_FLAGS"].split() == [
        "--xla_cpu_use_fusion_emitters=true", "--xla_dump_to=x"]


@pytest.mark.parametrize("version, added", [
    ((0, 5, 1), ("--xla_backend_optimization_level=1",)),  # before the fusion emitters
    ((0, 5, 3), ("--xla_cpu_use_fusion_emitters=false", "--xla_backend_optimization_level=1")),
    ((0, 11, 0), ("--xla_cpu_use_fusion_emitters=false", "--xla_backend_optimization_level=1")),
    ((0, 11, 1), ("--xla_backend_optimization_level=1",)),  # the loop emitters gone
    ((0, 12, 0, 1), ("--xla_backend_optimization_level=1",)),
    ((0, 13, 0), ()),  # newer than any tested version: no flag assumed
])
def test_a_flag_only_where_the_jaxlib_version_knows_it(cpu_jaxlib, monkeypatch, version, added):
    monkeypatch.setattr(_compiler, "jaxlib_version", lambda: version)
    flags = SMALL_PROGRAMS + ("--xla_backend_optimization_level=1",)
    assert compile_for_small_programs(flags) == added
    assert os.environ["XLA_FLAGS"].split() == list(added)


@pytest.mark.parametrize("platforms, plugins, cpu", [
    ([], [], True),
    ([], ["cuda"], False),  # jax-cuda12-plugin installed: the GPU backend by default
    ([], ["tpu"], False),
    (["cuda"], [], False),
    (["cpu"], ["cuda"], True),  # JAX_PLATFORMS=cpu on a GPU machine
    (["gpu", "cpu"], ["cuda"], False),
])
def test_flags_only_when_jax_compiles_for_the_cpu(cpu_jaxlib, monkeypatch, platforms, plugins,
                                                  cpu):
    monkeypatch.setattr(_compiler, "requested_platforms", lambda: platforms)
    monkeypatch.setattr(_compiler, "accelerator_plugins", lambda: plugins)
    assert _compiler.compiles_for_cpu() is cpu
    assert compile_for_small_programs() == (SMALL_PROGRAMS if cpu else ())
    assert os.environ.get("XLA_FLAGS", "") == (" ".join(SMALL_PROGRAMS) if cpu else "")


def test_the_installed_jaxlib_starts_with_every_flag_it_is_said_to_know():
    """The table checked against the running jaxlib (each CI environment has its own): a
    new process starts XLA with every flag `known_flags` lets through and computes."""
    flags = _compiler.known_flags([f"{name}={value}" for name, value in zip(
        FLAG_VERSIONS, ("false", "1"))])
    env = dict(os.environ, XLA_FLAGS=" ".join(flags), JAX_PLATFORMS="cpu")
    code = "import jax.numpy as jnp; print(float(jnp.arange(3.0).sum()))"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "3.0", (flags, done.stderr[-500:])


def test_jaxlib_version_reads_the_installed_one():
    version = _compiler.jaxlib_version()
    assert len(version) >= 3 and version >= (0, 4)
