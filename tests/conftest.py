import gc
import os
import pathlib

import jax
import pytest

import jaxship as js
from jaxship.cli import compile_for_small_programs


jax.config.update("jax_enable_x64", True)
# one compilation cache for the run, inside the checkout (a fresh clone starts empty):
# programs compiled in one test module, by the other xdist worker, by a `jaxship`
# subprocess or a notebook kernel are read back, not compiled again
os.environ.setdefault("JAXSHIP_CACHE_DIR", str(pathlib.Path(__file__).parent.parent
                                              / ".pytest_cache" / "jax-compilation"))
js.enable_compilation_cache()


def pytest_configure(config):
    """XLA's CPU compiler set for many small programs, before JAX starts its backend
    (`jaxship` subprocesses and notebook kernels inherit it): the loop emitters instead
    of the MLIR fusion emitters, as the `jaxship` command's `SMALL_PROGRAMS`. Most of a
    test's time is compiling. LLVM's optimisation stays on: turned off as well (the
    setting until 2026-11-27) it gave wrong derivatives once `RK4`'s stages became a
    loop, and long computations ran slower (with the loop and the optimisation on, the
    slow tier went from 1407 to 876 s on 2026-11-27, about 120 s of it from two studies
    that ran twice; the fast tier 571 -> 594 s). The numbers are the same to rounding
    (`helpers.assert_equal_to_rounding`)."""
    # the `jaxship` command's own setting (LLVM's optimisation level 1 of 0-3 was tried
    # on 2026-11-27: programs compiled 13 % faster, but a batch of 128 KVLCC2 zig-zags
    # ran 1.47x slower, and the fast tier gained too little to tell)
    compile_for_small_programs()


def pytest_sessionstart(session):
    """Under CI the measured data are always beside the checkout: a missing
    `../shared/data` fails the run instead of skipping the tests that need it."""
    if os.environ.get("CI") and js.shared_data_dir() is None:
        raise pytest.UsageError("CI is set but ../shared/data was not found (set "
                                "JAXSHIP_DATA or put shared/ beside the checkout).")


# The modules that take longest (worker-seconds of a fast-tier run, 2026-11-26), longest
# first: xdist hands each worker one module at a time in collection order, so these go
# first and the short ones fill in at the end, and both workers finish together
# (alphabetical order left test_real_data and test_low_speed_sway_yaw, 4-5 min together,
# to one worker at the end while the other idled).
LONGEST_FIRST = ("test_contracts", "test_discover", "test_real_data", "test_effects",
                 "test_low_speed_sway_yaw", "test_kalman", "test_autopilot",
                 "test_ross_autopilot", "test_sway_yaw_fit", "test_autopilot_cli",
                 "test_vessel_fit", "test_bands", "test_identify", "test_cli", "test_mariner",
                 "test_architecture", "test_reproduce", "test_joint_search", "test_estimate")


def pytest_collection_modifyitems(session, config, items):
    """Run the longest modules first (`LONGEST_FIRST`); the others keep their order, and
    so do the tests within each module."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.stem, len(rank)))


MAX_MAPS = 30_000  # the kernel's default vm.max_map_count is 65,530


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
