"""`jaxship discover`: find, name and add the effect a model is missing."""

import pathlib
import sys

from .. import DiscoveryOptions
from ._common import (
    VELOCITIES,
    ProgressBar,
    add_sample_interval,
    add_velocities,
    check_out,
    note,
)
from ._discovery import run_discovery
from ._vessel import VESSEL_HELP
from .identify import start_model


def register(sub) -> None:
    disc = sub.add_parser(
        "discover", help="find, name and add the effect a model is missing",
        description="Fit a registered model to the training records (as `identify` does), "
        "score the catalogue of physically named effects at the fit, add those that pass "
        "calibrated tests and improve the held-out records, and report; writes "
        "discovery.json, report.md and figures/ into --out.")
    disc.add_argument("train", nargs="+", type=pathlib.Path,
                      help="training records: trial CSV or measurement files, or folders")
    disc.add_argument("--holdout", nargs="+", type=pathlib.Path, default=None, metavar="TEST",
                      help="held-out records (other manoeuvres) the effects must improve")
    disc.add_argument("--model", default=None, help="a registered model (see `jaxship "
                      "identify --help`; this or --vessel)")
    disc.add_argument("--vessel", default=None,
                      help="the model to start from, in place of --model: " + VESSEL_HELP)
    disc.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    disc.add_argument("--max-effects", type=int, default=3, help="most effects added")
    disc.add_argument("--alpha", type=float, default=0.01,
                      help="family-wise false-alarm rate")
    add_sample_interval(disc)
    add_velocities(disc)
    disc.add_argument("--quiet", action="store_true", help="no progress messages")
    # as fast either way (305 s): XLA's defaults
    disc.set_defaults(run=run, small_programs=lambda args: False)


def run(args) -> int:
    model, name = start_model(args)
    check_out(args.out, writes=("discovery.json", "report.md", "figures/"),
              inputs=[*args.train, *(args.holdout or [])])
    report = run_discovery(args.train, args.holdout, model=model, name=name, out=args.out,
                           options=DiscoveryOptions(max_effects=args.max_effects,
                                                    alpha=args.alpha),
                           reading=dict(sample_interval=args.sample_interval,
                                        over_ground=VELOCITIES.get(args.velocities),
                                        note=note),
                           progress=ProgressBar(not args.quiet))
    print(report.to_markdown())
    print(f"wrote {args.out}/discovery.json, {args.out}/report.md"
          + f", {args.out}/figures/" * (args.out / "figures").is_dir())
    if report.why:  # Verdict.cannot_judge: results written, the reason on stderr
        print(f"jaxship: cannot judge: {report.why}", file=sys.stderr)
        return 3
    return 0
