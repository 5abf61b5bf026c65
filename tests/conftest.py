import gc
import os
import pathlib

import jax
import pytest

import jaxship as js
from jaxship._foundation import _exported


jax.config.update("jax_enable_x64", True)
# one compilation cache for the run, inside the checkout (a fresh clone starts empty):
# programs compiled in one test module, by the other xdist worker, by a `jaxship`
# subprocess or a notebook kernel are read back, not compiled again
os.environ.setdefault("JAXSHIP_CACHE_DIR", str(pathlib.Path(__file__).parent.parent
                                              / ".pytest_cache" / "jax-compilation"))
js.enable_compilation_cache()
# ... but not the exported-program store in this process (`_foundation/_exported.py`):
# exporting costs about 60 ms a new program on top of its compilation, and nearly every
# test program is new in a fresh clone (CI's clean-clone run took 32.7 min with it,
# 26.0 min before it). Its own tests (`test_exported.py`) turn it on; the command's
# subprocesses keep it through `$JAXSHIP_CACHE_DIR`.
_exported.use_store(None)


# the fast tier's addition: LLVM's optimisation at level 1 (XLA's default 3). Its tests
# compile many programs and run each briefly: on 2026-11-27 the whole tier took 465 s
# instead of 518 s (895 against 992 worker-seconds), each run from a fresh clone. The slow
# tier keeps XLA's level: its notebooks run long computations (a batch of 128 KVLCC2
# zig-zags ran 1.47x slower at level 1). Level 0 with the loop emitters gave wrong
# derivatives of a closed-loop run (benchmarks/README.md section 5); level 1 gives the
# central differences' value.
FAST_TIER = ("--xla_backend_optimization_level=1",)


def pytest_configure(config):
    """XLA's CPU compiler set for many small programs, before JAX starts its backend
    (`jaxship` subprocesses and notebook kernels inherit it): the loop emitters instead
    of the MLIR fusion emitters, as the `jaxship` command's
    (`jaxship.compile_for_small_programs.SMALL_PROGRAMS`), and in the
    fast tier (`-m 'not slow'`, the default) `FAST_TIER` as well. Most of a test's time
    is compiling. The numbers are the same to rounding
    (`helpers.assert_equal_to_rounding`)."""
    fast = "not slow" in (config.getoption("markexpr", "") or "")
    js.compile_for_small_programs(js.compile_for_small_programs.SMALL_PROGRAMS
                                  + (FAST_TIER if fast else ()))


def pytest_sessionstart(session):
    """Under CI the measured data are always beside the checkout: a missing
    `../shared/data` fails the run instead of skipping the tests that need it."""
    if os.environ.get("CI") and js.shared_data_dir() is None:
        raise pytest.UsageError("CI is set but ../shared/data was not found (set "
                                "JAXSHIP_DATA or put shared/ beside the checkout).")


# The modules that take longest (worker-seconds of a fast-tier run, 2026-11-27), longest
# first: each worker takes one module at a time in this order (`--no-loadscope-reorder`
# in pyproject.toml: xdist would otherwise start with the modules of most tests), so the
# long ones go first and the short ones fill in at the end, and both workers finish
# together.
LONGEST_FIRST = ("test_contracts", "test_discover", "test_kalman", "test_cli", "test_effects",
                 "test_low_speed_sway_yaw", "test_simulate", "test_autopilot",
                 "test_manoeuvres", "test_bands", "test_estimate", "test_identify",
                 "test_batch", "test_ross_autopilot", "test_reproduce", "test_architecture",
                 "test_sway_yaw", "test_joint_search", "test_autopilot_cli", "test_vessel_fit",
                 "test_sway_yaw_fit", "test_mmg", "test_lm", "test_real_data", "test_readme",
                 "test_mariner")


# The slow tier's order: the notebooks (half its time, each in a kernel of its own) on one
# worker while the other takes the remaining modules, longest first (2026-11-28, one
# process: notebooks 629 s, test_discover about 330 s, the rest about 270 s).
SLOW_LONGEST_FIRST = ("test_notebooks", "test_discover", "test_reproduce", "test_autopilot_cli",
                      "test_sharding", "test_autopilot", "test_low_speed_sway_yaw", "test_cli",
                      "test_vessel_fit")


def pytest_collection_modifyitems(session, config, items):
    """Run the longest modules first (`LONGEST_FIRST`, in the slow tier
    `SLOW_LONGEST_FIRST`); the others keep their order, and so do the tests within each
    module."""
    slow = (config.getoption("markexpr", "") or "").strip() == "slow"
    rank = {name: i for i, name in enumerate(SLOW_LONGEST_FIRST if slow else LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.stem, len(rank)))


# the kernel's default vm.max_map_count is 65,530; the most one module added in a
# fast-tier run was 19,737 (test_contracts, 2026-11-27), so a module that starts
# below this limit ends below the kernel's
MAX_MAPS = 40_000


def _memory_maps() -> int:
    try:
        with open("/proc/self/maps", "rb") as maps:
            return sum(1 for _ in maps)
    except OSError:  # not Linux: no such limit to watch
        return 0


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_code():
    """Free the compiled executables when a test module ends with the process holding
    more than `MAX_MAPS` memory mappings. Every XLA CPU executable holds some, and a
    whole test run would otherwise pass the kernel's limit (vm.max_map_count) and crash
    in the compiler; clearing only then keeps the traced and compiled programs that the
    next modules share (the same fits and simulations on the same shapes)."""
    yield
    if _memory_maps() > MAX_MAPS:
        jax.clear_caches()
        gc.collect()
