"""`jaxship reproduce`: the thesis pipeline end to end on the built-in thesis vessel."""

import pathlib

from ._common import check_out
from .reproduction.reproduce import reproduce


def register(sub) -> None:
    rep = sub.add_parser("reproduce", help="the thesis pipeline on the built-in thesis vessel")
    rep.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/reproduce"))
    rep.add_argument("--quick", action="store_true", help="fewer trials (for smoke tests)")
    rep.add_argument("--quiet", action="store_true", help="no progress bars")
    # the small-program setting: first run 124 s against 169 s (XLA's defaults), a second
    # one (programs from the cache) 104 s against 74 s (docs/results.md, section 1)
    rep.set_defaults(run=run, small_programs=lambda args: True)


def run(args) -> int:
    check_out(args.out, writes=("report.md", "figures/", "trials/"))
    reproduce(args.out, quick=args.quick, progress=not args.quiet)
    return 0
