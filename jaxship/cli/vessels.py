"""`jaxship vessels`: the vessel presets with their size, speed, rpm and source."""

from .._models._vessel.catalogue import VESSELS, get_vessel


def register(sub) -> None:
    vessels = sub.add_parser("vessels", help="list the vessel presets and their sources")
    vessels.set_defaults(run=run, small_programs=lambda args: False)


def run(args) -> int:
    width = max(map(len, VESSELS))
    print(f"{'name':<{width}}  {'L [m]':>7}  {'U [m/s]':>7}  {'n [rpm]':>7}  source")
    for name, entry in VESSELS.items():
        vessel = get_vessel(name)
        rpm = 60.0 * float(vessel.nominal_n)
        print(f"{name:<{width}}  {float(vessel.length):7.4g}  {float(vessel.nominal_speed):7.4g}"
              f"  {f'{rpm:7.4g}' if rpm else '      -'}  {entry.description}")
    return 0
