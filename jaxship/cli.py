"""The `jaxship` command: a thin layer over the public API (float64 is enabled here)."""

import argparse
import importlib.metadata
import json
import pathlib
import sys
import warnings

import jax
import matplotlib
from tqdm.auto import tqdm


matplotlib.use("Agg")  # the command writes files; it never opens a window

from ._models._vessel.catalogue import VESSELS, get_vessel  # noqa: E402
from ._trials import simulate_to_folder  # noqa: E402
from .identification import MODELS, get_model_entry, identify, read_experiments  # noqa: E402
from .plotting import save_identification_figures  # noqa: E402
from .studies.reproduce import reproduce  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="jaxship", description=__doc__)
    parser.add_argument("--version", action="version",
                        version=f"jaxship {importlib.metadata.version('jaxship')}")
    sub = parser.add_subparsers(dest="command", required=True)

    sub.add_parser("vessels", help="list the vessel presets and their sources")

    sim = sub.add_parser("simulate", help="simulate a standard trial")
    sim.add_argument("--vessel", required=True, help="preset name (see `jaxship vessels`)")
    sim.add_argument("--manoeuvre", required=True, help="e.g. turn:35, zigzag:-10/10, thesis")
    sim.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    sim.add_argument("--speed", type=float, help="approach speed [m/s]")
    sim.add_argument("--rpm", type=float, help="propeller rate [rpm]")
    sim.add_argument("--duration", type=float, help="duration [s]")
    sim.add_argument("--dt", type=float, help="sample interval [s]")

    rep = sub.add_parser("reproduce", help="the thesis pipeline on the built-in thesis vessel")
    rep.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/reproduce"))
    rep.add_argument("--quick", action="store_true", help="fewer trials (for smoke tests)")

    ident = sub.add_parser(
        "identify", help="estimate a steering model from measured trials and validate it",
        description="Estimate a steering model from training records (trial CSV files, "
        "measurement files or folders of them) and validate it; writes result.json and "
        "figures into --out.",
        epilog="models (--model):\n" + "\n".join(
            f"  {name:<24} {entry.description}" for name, entry in MODELS.items()),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ident.add_argument("train", nargs="+", type=pathlib.Path,
                       help="training records: trial CSV or measurement files, or folders")
    ident.add_argument("--model", required=True,
                       help="a registered model (listed below): a steering model, armax or a "
                       "vessel preset name")
    ident.add_argument("--horizon", default=None,
                       help="prediction horizon [s]; 'none' (default): output error, "
                       "0: equation error")
    ident.add_argument("--validate", nargs="+", type=pathlib.Path, default=None,
                       metavar="TEST", help="held-out records to validate on")
    ident.add_argument("--out", required=True, type=pathlib.Path, help="output folder")
    ident.add_argument("--rudder", default="delta", help="replayed rudder: delta or delta_c")
    ident.add_argument("--channels", default=None,
                       help="fitted outputs, e.g. psi,r or r (default: psi,r; psi,r,u,v for "
                       "vessel presets; r for armax)")
    ident.add_argument("--initial", default="auto",
                       help="window start states: measured, estimate or auto (default: "
                       "estimate for output error, else measured)")
    ident.add_argument("--max-steps", type=int, default=256, help="optimiser step limit")
    ident.add_argument("--no-figures", action="store_true", help="write result.json only")
    ident.add_argument("--quiet", action="store_true", help="no progress bar")

    args = parser.parse_args(argv)
    jax.config.update("jax_enable_x64", True)
    try:
        commands = {"vessels": _vessels, "simulate": _simulate, "reproduce": _reproduce,
                    "identify": _identify}
        return commands[args.command](args)
    except ValueError as error:
        print(f"jaxship: error: {error}", file=sys.stderr)
        return 2


def _vessels(args) -> int:
    width = max(map(len, VESSELS))
    for name, entry in VESSELS.items():
        print(f"{name:<{width}}  {entry.description}")
    return 0


def _simulate(args) -> int:
    vessel = get_vessel(args.vessel)
    indices = simulate_to_folder(
        vessel,
        args.manoeuvre,
        args.out,
        speed=args.speed,
        rpm=args.rpm,
        duration=args.duration,
        dt=args.dt,
        title=f"{args.vessel} {args.manoeuvre}",
    )
    print(json.dumps(indices, indent=2))
    print(f"wrote {args.out}/trial.csv, indices.json, trial.png")
    return 0


def _reproduce(args) -> int:
    reproduce(args.out, quick=args.quick, progress=True)
    return 0


def _horizon(text):
    if text is None or text.strip().lower() in ("none", "oe", "output-error"):
        return None
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"--horizon {text!r}: give seconds (e.g. 10), 0 (equation error) or "
                         "'none' (output error).") from None


class _ProgressBar:
    """Turns `identify`'s `Progress` reports into tqdm bars on stderr."""

    def __init__(self, enabled):
        self.enabled, self.bar = enabled, None

    def __call__(self, event):
        if not self.enabled:
            return
        if event.stage != "fit":
            if not event.done:
                tqdm.write(f"jaxship: {event.message} ...", file=sys.stderr)
            return
        if self.bar is None:
            self.bar = tqdm(total=event.total, desc=event.message, unit="step", leave=False,
                            file=sys.stderr)
        self.bar.n = min(int(event.step), event.total)
        if event.cost is not None:
            self.bar.set_postfix(cost=f"{event.cost:.5g}", refresh=False)
        self.bar.refresh()
        if event.done:
            self.bar.close()
            self.bar = None
            tqdm.write(f"jaxship: {event.message}: {event.step} steps, cost {event.cost:.6g}",
                       file=sys.stderr)


def _identify(args) -> int:
    get_model_entry(args.model)  # unknown models fail before reading any file
    horizon = _horizon(args.horizon)
    train = read_experiments(args.train, role="training")
    held_out = None if args.validate is None else read_experiments(args.validate,
                                                                   role="validation")
    bar = _ProgressBar(not args.quiet)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = identify(train, model=args.model, horizon=horizon, validate=held_out,
                          rudder=args.rudder, channels=args.channels, initial=args.initial,
                          max_steps=args.max_steps, progress=bar)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "result.json").write_text(result.to_json() + "\n")
    written = ["result.json"]
    if not args.no_figures:
        paths = save_identification_figures(result, args.out / "figures")
        written.append(f"figures/ ({len(paths)} figures)")
    print(result.summary())
    for note in result.notes:
        print(f"note: {note}")
    for message in dict.fromkeys(str(w.message) for w in caught):
        print(f"jaxship: warning: {message}", file=sys.stderr)
    print(f"wrote {args.out}/" + f", {args.out}/".join(written))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
