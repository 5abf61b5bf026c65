"""`jaxship vessels`: the vessel presets with their size, speed, rpm and source; with
`--show NAME`, a preset as a vessel file (TOML) to start one's own ship from; with
`--from-particulars FILE`, the MMG vessel computed from a ship's main particulars."""

import pathlib
import tomllib

from .. import VESSELS, get_vessel, load_vessel, save_vessel


def register(sub) -> None:
    vessels = sub.add_parser("vessels", help="list the vessel presets and their sources")
    vessels.add_argument("--show", metavar="NAME", default=None,
                         help="print the preset NAME as a vessel file (TOML: the model class "
                         "and every coefficient with its unit), e.g. `jaxship vessels --show "
                         "esso_osaka > my_ship.toml`, then `--vessel my_ship.toml`")
    vessels.add_argument("--from-particulars", metavar="FILE", default=None,
                         help="print the MMG vessel of the main particulars in the vessel file "
                         "FILE (its table [particulars]: L, B, d, C_b, speed, propeller and "
                         "rudder) as a vessel file with every coefficient, computed by "
                         "published empirical formulas (see docs/usage.md, Vessel files)")
    vessels.set_defaults(run=run, small_programs=lambda args: False)


def run(args) -> int:
    if args.show is not None and args.from_particulars is not None:
        raise ValueError("give --show NAME or --from-particulars FILE, not both.")
    if args.from_particulars is not None:
        path = pathlib.Path(args.from_particulars)
        vessel = load_vessel(path)  # a bad file: one line naming it and the field
        if "particulars" not in tomllib.loads(path.read_text(encoding="utf-8")):
            raise ValueError(f"{path}: no table [particulars]: give the main particulars "
                             f"(the fields of jaxship.MainParticulars) under [particulars].")
        print(save_vessel(vessel, source=f"computed from the main particulars in {path} "
                          f"(MMGVessel.from_particulars)"), end="")
        return 0
    if args.show is not None:
        vessel = get_vessel(args.show)
        key = args.show.strip().lower().replace("-", "_")
        print(save_vessel(vessel, source=f"the preset {key}: {VESSELS[key].description}"),
              end="")
        return 0
    width = max(map(len, VESSELS))
    print(f"{'name':<{width}}  {'L [m]':>7}  {'U [m/s]':>7}  {'n [rpm]':>7}  source")
    for name, entry in VESSELS.items():
        vessel = get_vessel(name)
        rpm = 60.0 * float(vessel.nominal_n)
        print(f"{name:<{width}}  {float(vessel.length):7.4g}  {float(vessel.nominal_speed):7.4g}"
              f"  {f'{rpm:7.4g}' if rpm else '      -'}  {entry.description}")
    return 0
