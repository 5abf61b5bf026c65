"""The `jaxship` command's entry point, outside the package so that it runs before the
package's imports (seconds: jax's among them): Ctrl-C or SIGTERM in that time ends the
command with its line and status (130, 143), as `jaxship.cli.run` does later, not with
a traceback. Nothing is written before those imports end. `python -m jaxship.cli` goes
through the same door: the package installs these handlers first when Python imports
it to run that module (`jaxship/__init__.py`), and `jaxship/cli/__main__.py` calls
`run`."""

import time


STARTED = time.perf_counter()  # the command's first line: its imports are timed from here

import os  # noqa: E402
import signal  # noqa: E402
import sys  # noqa: E402


def _end(signum, frame):
    print("jaxship: interrupted." if signum == signal.SIGINT else "jaxship: terminated.",
          file=sys.stderr, flush=True)
    os._exit(128 + signum)


def install() -> None:
    """The handlers of the imports' time: the line and status of the signal."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _end)


def run() -> None:
    install()
    from jaxship.cli import run as command  # `command` installs its own handlers

    command(started=STARTED)


if __name__ == "__main__":
    run()
