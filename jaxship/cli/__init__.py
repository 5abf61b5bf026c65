"""The `jaxship` command: a thin layer over the public API (float64 is enabled here).
Each command is one module of this package, owning its parser (`register`) and its run
function (`run`); `main` registers them and turns errors into exit statuses."""

import argparse
import difflib
import multiprocessing
import os
import signal
import sys
import threading
import time
import warnings

import jax

from .. import (  # noqa: E402
    FitError,
    __version__,
    compile_for_small_programs,
    enable_compilation_cache,
)
from ..identification import FitDivergedError  # noqa: E402
from . import autopilot, discover, identify, reproduce, simulate, vessels  # noqa: E402
from ._common import CLOCK, one_line  # noqa: E402
from ._files import discard_open_stages  # noqa: E402


EXIT_STATUS = """exit status: 0 done; 2 bad input (arguments, records, an --out that cannot be
written: one line on stderr, nothing written); 1 a file-system failure while writing;
3 the fit did not converge, blew up, never moved, ended on a parameter bound or left a
parameter undetermined, a closed loop blew up or did not settle, or discover's records
cannot judge (results written, the reason on stderr), or a fit diverged (nothing written); 130
interrupted (Ctrl-C), 143 terminated (SIGTERM): earlier results left as they were.
JAXSHIP_CACHE_DIR: where compiled programs are kept for later runs (default
~/.cache/jaxship/jax; "off" disables)."""

COMMANDS = (vessels, simulate, reproduce, identify, autopilot, discover)
GRACE = 5.0  # [s] after Ctrl-C or SIGTERM, the longest the process takes to end
ENDINGS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}  # exit 128 + signal
_INTERRUPTED = threading.Event()  # Ctrl-C was pressed (or SIGTERM came)
_SIGNAL = [signal.SIGINT]  # the first of them
_RAISED = threading.Event()  # and raised as KeyboardInterrupt in the main thread
_RETURNED = threading.Event()  # `main` has returned: the process is ending


class _ShowsDefaults:
    """`--help` of every command: each option's default (where it has one), and
    "(required)" on those that must be given."""

    def _get_help_string(self, action):
        text = action.help or ""
        default = action.default
        if (action.option_strings and default not in (None, False, argparse.SUPPRESS)
                and "%(default)" not in text):
            shown = " ".join(map(str, default)) if isinstance(default, (list, tuple)) \
                else default
            text += f" (default: {shown})".replace("%", "%%")
        if action.required and action.option_strings:
            text += " (required)"
        return text


class HelpFormatter(_ShowsDefaults, argparse.HelpFormatter):
    pass


class RawHelpFormatter(_ShowsDefaults, argparse.RawDescriptionHelpFormatter):
    """For commands whose description or epilog is laid out by hand (a list)."""


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="jaxship", description=__doc__.split("\n")[0],
                                     epilog=EXIT_STATUS,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version",
                        version=f"jaxship {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.register(sub)
    for command_parser in sub.choices.values():
        raw = issubclass(command_parser.formatter_class, argparse.RawDescriptionHelpFormatter)
        command_parser.formatter_class = RawHelpFormatter if raw else HelpFormatter
    _refuse_unknown_options(sub, sys.argv[1:] if argv is None else list(argv))
    args = parser.parse_args(argv)
    if args.small_programs(args):
        compile_for_small_programs()
    jax.config.update("jax_enable_x64", True)
    enable_compilation_cache()  # second runs skip compilation ($JAXSHIP_CACHE_DIR moves it)
    CLOCK.mark("parsing")
    try:
        with warnings.catch_warnings(record=True) as caught:  # the filters as they are
            try:
                return args.run(args)
            finally:
                _tell(caught)
    except (FitDivergedError, FitError) as error:
        print(f"jaxship: error: {one_line(error)}", file=sys.stderr)
        return 3
    except ValueError as error:
        print(f"jaxship: error: {one_line(error)}", file=sys.stderr)
        return 2
    except OSError as error:  # the file system failed under us (disk full, a folder removed)
        where = f"{error.filename}: " if error.filename else ""
        print(f"jaxship: error: {where}{error.strerror or error}.", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        _say(_SIGNAL[0])
        return 128 + _SIGNAL[0]


def _refuse_unknown_options(sub, argv):
    """A misspelt `--option` refused by name, with the nearest known one: argparse checks
    the required options first and would only say that `--manoeuvre` is missing."""
    command = next((a for a in argv if not a.startswith("-")), None)
    if command not in sub.choices:
        return  # argparse's own message
    known = [o for o in sub.choices[command]._option_string_actions if o.startswith("--")]
    for token in argv[argv.index(command) + 1:]:
        if token == "--":
            break
        name = token.split("=", 1)[0]
        if name.startswith("--") and not any(o.startswith(name) for o in known):
            near = difflib.get_close_matches(name, known, n=1)
            sub.choices[command].error(f"unrecognized option {name}"
                                       + (f" (did you mean {near[0]}?)" if near else ""))


def _tell(caught):
    """One line on stderr for the warnings of the numerical libraries (NumPy's overflow,
    ...) that the run met, in place of their text with source paths."""
    messages = dict.fromkeys(one_line(w.message) for w in caught)
    numbers = any(issubclass(w.category, RuntimeWarning) for w in caught)
    meaning = (": values beyond the floating-point range, often from a record unlike the "
               "others (another vessel, other units)." if numbers else ".")
    if messages:
        print(f"jaxship: warning: {'; '.join(messages)} (from the numerical libraries)"
              f"{meaning}", file=sys.stderr)


def run(started: float | None = None) -> None:
    """The console entry point (`_jaxship_cli.run` calls it after the imports, with the
    `time.perf_counter()` of its first line, `started`, from which `CLOCK` times the
    imports): `main`, then exit with its status. After Ctrl-C (or SIGTERM, handled alike)
    the process ends with status 130 (143) without the interpreter's teardown, which crashed
    (SIGSEGV) while XLA's threads were still running; and since an interrupt raised
    inside a garbage-collection callback is swallowed, a watchdog ends the process
    `GRACE` seconds after the signal whatever the main thread is doing. Results are
    committed whole or not at all (`staged_folder`), so ending there loses nothing."""
    # the command writes files and never opens a window; set here, not on import, so a
    # notebook that calls `main` keeps its own backend (its inline figures)
    os.environ["MPLBACKEND"] = "Agg"  # read when matplotlib is imported (figures only)
    if started is not None:
        CLOCK.last = started
    CLOCK.mark("imports")
    _handle_interrupts()
    try:
        status = main()
    except KeyboardInterrupt:  # raised before `main` reached its own handler (parsing)
        _say(_SIGNAL[0])
        status = 128 + _SIGNAL[0]
    _RETURNED.set()
    if _INTERRUPTED.is_set():
        _end(128 + _SIGNAL[0])
    CLOCK.mark("summary")
    CLOCK.report()
    _leave(status)


def _leave(status: int):
    """Exit with `status` without the interpreter's teardown, which only frees memory
    (JAX's backends and caches cleared, every module's objects collected: 0.4-0.45 s of
    the README's identify example, `benchmarks/results/latency.md`): by now every result
    is written whole and closed (`staged_folder`), every child process joined, and JAX's
    ordered effects are waited for here (`jax.effects_barrier`, as JAX's exit hook
    does). Under a profiler, a debugger or coverage, which write their results at exit,
    the usual exit."""
    if sys.getprofile() or sys.gettrace() or "coverage" in sys.modules:
        sys.exit(status)  # a profiler, debugger or coverage writes its results at exit
    jax.effects_barrier()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except OSError:  # a closed pipe (`jaxship ... | head`): nothing more to say
            pass
    os._exit(status)


def _say(signum):
    print(f"jaxship: {ENDINGS[signum]}.", file=sys.stderr)


def _listen_for_interrupts():
    """Start the watchdog from the byte the C-level signal handler writes (the wakeup
    fd) as soon as SIGINT or SIGTERM arrives: Python's own handler runs only when the
    main thread is back in Python, which a long XLA computation can delay by many
    seconds."""
    read, write = os.pipe()
    os.set_blocking(write, False)
    signal.set_wakeup_fd(write, warn_on_full_buffer=False)

    def listen():
        while not (got := [s for s in os.read(read, 64) if s in ENDINGS]):
            pass
        _watchdog(got[0])

    threading.Thread(target=listen, daemon=True).start()


def _handle_interrupts():
    """Ctrl-C and SIGTERM: the watchdog, `_interrupt` as their handler, and
    `_raise_again` for an interrupt Python swallowed."""
    _listen_for_interrupts()
    for signum in ENDINGS:
        signal.signal(signum, _interrupt)
    sys.unraisablehook = _raise_again


def _interrupt(signum, frame):
    if _RAISED.is_set():
        return  # a second Ctrl-C: the watchdog is already on its way
    if not _INTERRUPTED.is_set():
        _SIGNAL[0] = signum
    _INTERRUPTED.set()
    if _RETURNED.is_set():  # in the interpreter's teardown, where raising would kill
        _say(_SIGNAL[0])  # the process by the signal
        _end(128 + _SIGNAL[0])
    _RAISED.set()
    raise KeyboardInterrupt


def _raise_again(unraisable):
    """`sys.unraisablehook`: an interrupt raised where Python swallows exceptions (a
    garbage-collection callback, as XLA has; a weakref callback; a finaliser), which it
    would print as "Exception ignored in ..." with a traceback and go on from, is raised
    again once the main thread is out of there. Anything else is printed as usual."""
    if not (isinstance(unraisable.exc_value, KeyboardInterrupt) and _INTERRUPTED.is_set()):
        sys.__unraisablehook__(unraisable)
        return
    _RAISED.clear()
    threading.Timer(0.05, os.kill, (os.getpid(), _SIGNAL[0])).start()


def _watchdog(signum):
    time.sleep(GRACE)
    _say(signum)
    _end(128 + signum)


def _end(status: int):
    """Leave now with `status`: the staging folders removed, and every child process
    killed first. A child still starting (`reproduce`'s worker, unpickling its
    arguments) would otherwise outlive this process, meet the semaphores it shares
    unlinked by the resource tracker and print a traceback after "interrupted"."""
    sys.stdout.flush()
    sys.stderr.flush()
    discard_open_stages()  # unwinding would have removed them
    for child in multiprocessing.active_children():
        child.kill()
    os._exit(status)
