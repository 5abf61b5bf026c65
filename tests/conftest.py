import gc
import os
import pathlib

import jax
import pytest

import jaxship as js


jax.config.update("jax_enable_x64", True)
# one compilation cache for the run, inside the checkout (a fresh clone starts empty):
# programs compiled in one test module, by the other xdist worker, by a `jaxship`
# subprocess or a notebook kernel are read back, not compiled again
os.environ.setdefault("JAXSHIP_CACHE_DIR", str(pathlib.Path(__file__).parent.parent
                                              / ".pytest_cache" / "jax-compilation"))
js.enable_compilation_cache()


def pytest_sessionstart(session):
    """Under CI the measured data are always beside the checkout: a missing
    `../shared/data` fails the run instead of skipping the tests that need it."""
    if os.environ.get("CI") and js.shared_data_dir() is None:
        raise pytest.UsageError("CI is set but ../shared/data was not found (set "
                                "JAXSHIP_DATA or put shared/ beside the checkout).")


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_code():
    """Free the compiled executables of each test module when it ends. Every XLA CPU
    executable holds memory mappings, and a whole test run would otherwise pass the
    kernel's limit of 65,530 (vm.max_map_count) and crash in the compiler."""
    yield
    jax.clear_caches()
    gc.collect()
