import os

import jax
import pytest

import jaxship as js


jax.config.update("jax_enable_x64", True)


def pytest_sessionstart(session):
    """Under CI the measured data are always beside the checkout: a missing
    `../shared/data` fails the run instead of skipping the tests that need it."""
    if os.environ.get("CI") and js.shared_data_dir() is None:
        raise pytest.UsageError("CI is set but ../shared/data was not found (set "
                                "JAXSHIP_DATA or put shared/ beside the checkout).")
