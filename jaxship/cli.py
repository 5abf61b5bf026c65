"""The `jaxship` command: a thin layer over the public API (float64 is enabled here)."""

import argparse
import json
import pathlib
import sys


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="jaxship", description=__doc__)
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

    args = parser.parse_args(argv)
    import jax

    jax.config.update("jax_enable_x64", True)
    import matplotlib

    matplotlib.use("Agg")
    try:
        return {"vessels": _vessels, "simulate": _simulate, "reproduce": _reproduce}[args.command](
            args
        )
    except ValueError as error:
        print(f"jaxship: error: {error}", file=sys.stderr)
        return 2


def _vessels(args) -> int:
    from ._vessel.catalogue import VESSELS

    width = max(map(len, VESSELS))
    for name, entry in VESSELS.items():
        print(f"{name:<{width}}  {entry.description}")
    return 0


def _simulate(args) -> int:
    from ._trials import simulate_to_folder
    from ._vessel.catalogue import get_vessel

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
    from ._reproduce import reproduce

    reproduce(args.out, quick=args.quick, progress=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
