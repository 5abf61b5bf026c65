"""The `jaxship` command: a thin layer over the public API (float64 is enabled here).
Each command is one module of this package, owning its parser (`register`) and its run
function (`run`); `main` registers them and turns errors into exit statuses."""

import argparse
import importlib.metadata
import sys

import jax
import matplotlib


matplotlib.use("Agg")  # the command writes files; it never opens a window

from .._foundation._cache import enable_compilation_cache  # noqa: E402
from . import autopilot, discover, identify, reproduce, simulate, vessels  # noqa: E402
from ._common import one_line  # noqa: E402
from ._identification.workflow import FitDivergedError  # noqa: E402


EXIT_STATUS = """exit status: 0 done; 2 bad input (arguments, records, an --out that cannot be
written: one line on stderr, nothing written); 1 a file-system failure while writing;
3 the fit did not converge, blew up, never moved, ended on a parameter bound, or a closed
loop blew up (results written, the reason on stderr) or diverged (nothing written); 130
interrupted. JAXSHIP_CACHE_DIR: where compiled programs are kept for later runs (default
~/.cache/jaxship/jax; "off" disables)."""

COMMANDS = (vessels, simulate, reproduce, identify, autopilot, discover)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="jaxship", description=__doc__.split("\n")[0],
                                     epilog=EXIT_STATUS,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version",
                        version=f"jaxship {importlib.metadata.version('jaxship')}")
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.register(sub)
    args = parser.parse_args(argv)
    jax.config.update("jax_enable_x64", True)
    enable_compilation_cache()  # second runs skip compilation ($JAXSHIP_CACHE_DIR moves it)
    try:
        return args.run(args)
    except FitDivergedError as error:
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
        print("jaxship: interrupted.", file=sys.stderr)
        return 130
