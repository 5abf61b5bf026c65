"""`jaxship identify`: estimate a registered model from measured records and validate
it."""

import argparse
import math
import pathlib
import sys

import jaxship as js

from .. import VESSELS, identify
from ..identification import AUTO, CANDIDATES, MODELS, fit_settings, read_experiments
from ..plotting import identification_figure_names, save_identification_figures
from ._common import (
    CLOCK,
    VELOCITIES,
    ProgressBar,
    add_sample_interval,
    add_velocities,
    check_out,
    check_writes,
    note,
    one_line,
)
from ._files import staged_folder
from ._vessel import VESSEL_HELP, read_vessel_option


def register(sub) -> None:
    ident = sub.add_parser(
        "identify", help="estimate a steering model from measured trials and validate it",
        description="Estimate a steering model from training records (trial CSV files, "
        "measurement files or folders of them) and validate it; writes result.json and "
        "figures into --out.",
        epilog="models (--model):\n" + "\n".join(
            f"  {name:<24} {entry.description}" for name, entry in MODELS.items())
        + f"\n  {AUTO:<24} " + AUTO_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ident.add_argument("train", nargs="+", type=pathlib.Path,
                       help="training records: trial CSV or measurement files, or folders")
    ident.add_argument("--model", default=None,
                       help="a registered model (listed below): a steering model, armax or a "
                       "vessel preset name, or auto: the steering model chosen by its BIC on "
                       "the training records (this or --vessel)")
    ident.add_argument("--vessel", default=None,
                       help="the model to start from, in place of --model: " + VESSEL_HELP)
    ident.add_argument("--horizon", default=None,
                       help="prediction horizon [s]; none: output error, "
                       "0: equation error (default: none; a preset's own where it has one)")
    ident.add_argument("--free", default=None, metavar="NAMES",
                       help="the estimated coefficients, comma separated; a leading + adds "
                       "them to the default set (default: the model's default free set; a "
                       "preset's own where it has one)")
    ident.add_argument("--prior", default=None, metavar="SCALE",
                       help="a Gaussian prior on the estimated coefficients centred on the "
                       "start (--model's preset, --vessel's file or result.json), with a "
                       "standard deviation of SCALE times each start value (e.g. 0.3): the "
                       "fit is the maximum a posteriori estimate; inf or none: no prior "
                       "(default: none; a preset's own where it has one)")
    ident.add_argument("--validate", nargs="+", type=pathlib.Path, default=None,
                       metavar="TEST", help="held-out records to validate on")
    ident.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    ident.add_argument("--rudder", default="delta", help="replayed rudder: delta or delta_c")
    ident.add_argument("--channels", default=None,
                       help="fitted outputs, e.g. psi,r or r, or psi,r,u,v,x,y to fit a "
                       "vessel's track (default: psi,r; psi,r,u,v for vessel presets; r for "
                       "armax)")
    ident.add_argument("--initial", default="auto",
                       help="window start states: measured, estimate or auto (estimate for "
                       "output error, else measured)")
    ident.add_argument("--max-steps", type=int, default=256, help="optimiser step limit")
    add_sample_interval(ident)
    add_velocities(ident)
    ident.add_argument("--no-figures", action="store_true", help="write result.json only")
    ident.add_argument("--quiet", action="store_true", help="no progress bar")
    # a vessel's fit runs long programs, which XLA's defaults compile to run faster
    ident.set_defaults(run=run, small_programs=lambda args: args.vessel is None
                       and args.model not in VESSELS)


AUTO_HELP = (f"a steering model chosen among {', '.join(CANDIDATES)}: each fitted, the one "
             "with the least BIC of its fit criterion on the training records kept (N log "
             "det of the channels' losses + d log N, d estimated parameters, N samples per "
             "channel; held-out records never enter the choice); result.json's selection "
             "and the printed note give each candidate's BIC and Akaike's FPE")


def _horizon(text):
    if text is None or text.strip().lower() in ("none", "oe", "output-error"):
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"--horizon {text!r}: the horizon must be a non-negative number of "
                         "seconds (e.g. 10; 0: equation error) or 'none' (output error).")
    return value


def start_model(args):
    """`(model, name)` of `--model` or `--vessel` (one of them), as `identify` takes them:
    a catalogue name (or auto) and None, or the model `--vessel` names and the catalogue
    name it is fitted as (a preset's, an earlier result's; None for a vessel file)."""
    if (args.model is None) == (args.vessel is None):
        raise ValueError("give --model (a registered model) or --vessel (a preset, a vessel "
                         "file or a result.json to start from), one of them.")
    if args.vessel is None:
        return args.model, None
    chosen = read_vessel_option(args.vessel)
    return chosen.model, chosen.name


def settings(args):
    """The `jaxship.identification.fit_settings` of the command's options (unknown models
    fail here, before any file): `(model, name, settings)`."""
    model, name = start_model(args)
    horizon = ... if args.horizon is None else _horizon(args.horizon)
    return model, name, fit_settings(model, name=name, horizon=horizon,
                                     sample_interval=args.sample_interval, free=args.free,
                                     prior=... if args.prior is None else args.prior)


def run(args) -> int:
    # every check before the fit; the files appear in --out only when all are written
    model, name, chosen = settings(args)  # unknown ones fail before any file
    if args.max_steps < 1:
        raise ValueError(f"--max-steps {args.max_steps}: give a positive number of optimiser "
                         "steps (default 256).")
    vessel = isinstance(chosen.start, js.AbstractVessel) or chosen.name in VESSELS
    check_out(args.out, writes=("result.json",) + (("vessel.toml",) if vessel else ())
              + (() if args.no_figures else ("figures/",)),
              inputs=[*args.train, *(args.validate or [])])
    reading = dict(note=note, sample_interval=chosen.sample_interval,
                   over_ground=VELOCITIES.get(args.velocities))
    train = read_experiments(args.train, role="training", **reading)
    held_out = None if args.validate is None else read_experiments(
        args.validate, role="validation", **reading)
    if not args.no_figures:  # their names follow the records'
        names = identification_figure_names(
            [e.name for e in train], None if held_out is None else [e.name for e in held_out])
        check_writes(args.out, tuple(f"figures/{name}" for name in names))
    CLOCK.mark("reading")
    progress = ProgressBar(not args.quiet)
    result = identify(model, train, validate=held_out, name=name,
                      horizon=... if args.horizon is None else chosen.horizon,
                      sample_interval=args.sample_interval, free=args.free,
                      rudder=args.rudder, channels=args.channels, initial=args.initial,
                      max_steps=args.max_steps, progress=progress,
                      prior=... if args.prior is None else args.prior)
    CLOCK.mark(progress.stage or "identify")
    written = ["result.json"]
    with staged_folder(args.out) as stage:
        if not args.no_figures:
            paths = save_identification_figures(result, stage / "figures")
            written.append(f"figures/ ({len(paths)} figures)")
            CLOCK.mark("figures")
        (stage / "result.json").write_text(result.checked_json() + "\n")
        # `--vessel out/vessel.toml` later; a vessel file holds no effects (result.json does)
        if isinstance(result.model, js.AbstractVessel) and not isinstance(
                result.model, js.effects.AugmentedVessel):
            js.save_vessel(result.model, stage / "vessel.toml",
                           source=f"jaxship identify --model {result.model_name} "
                           f"({result.fit.code_name})")
            written.append("vessel.toml")
    CLOCK.mark("writing")
    head, *lines = result.summary().splitlines()
    undetermined = result.fit.code == js.RESULTS.undetermined
    if undetermined:  # the optimiser converged, on data that are noise to the model
        head = (f"{result.model_name}: {type(result.model).__name__}, UNDETERMINED (the fit "
                f"explains almost nothing, after {result.fit.num_steps} steps)")
    elif not result.fit.success:  # the optimiser's own words are on stderr, in plain ones
        head = (f"{result.model_name}: {type(result.model).__name__}, NOT converged "
                f"({result.fit.code_name}, after {result.fit.num_steps} steps)")
    print("\n".join([head, *lines]))
    for text in result.notes:
        print(f"note: {text}")
    for message in dict.fromkeys(result.warnings):
        print(f"jaxship: warning: {one_line(message)}", file=sys.stderr)
    print(f"wrote {args.out}/" + f", {args.out}/".join(written))
    if undetermined:
        print("jaxship: the fit explains almost nothing and leaves parameters undetermined "
              "(undetermined: see the warnings above); the results were written for "
              "inspection.", file=sys.stderr)
        return 3
    if not result.fit.success:
        print(f"jaxship: the fit is not a converged estimate ({result.fit.code_name}: see "
              "the warnings above); the results were written for inspection.",
              file=sys.stderr)
        return 3
    return 0
