"""`jaxship reproduce`: the thesis pipeline end to end on the built-in thesis vessel."""

import pathlib

from ._common import check_out
from ._studies.reproduce import reproduce


def register(sub) -> None:
    rep = sub.add_parser("reproduce", help="the thesis pipeline on the built-in thesis vessel")
    rep.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/reproduce"))
    rep.add_argument("--quick", action="store_true", help="fewer trials (for smoke tests)")
    # its first run is 1.3x shorter with the small-program setting, but a second run
    # (programs from the cache) runs them slower: XLA's defaults
    rep.set_defaults(run=run, small_programs=lambda args: False)


def run(args) -> int:
    check_out(args.out, writes=("report.md", "figures/", "trials/"))
    reproduce(args.out, quick=args.quick, progress=True)
    return 0
