"""KVLCC2: the MMG standard method (`kvlcc2()`) against the SIMMAN 2008 free-running tests
(the study is `jaxship.studies.kvlcc2_simman`, whose docstring gives the definitions).

Run: `python benchmarks/kvlcc2_simman.py [--data DIR]`; prints a markdown table.
"""

import argparse
from pathlib import Path

import jax


jax.config.update("jax_enable_x64", True)

import jaxship as js  # noqa: E402
from jaxship.studies.kvlcc2_simman import (  # noqa: E402
    compare_hsva,
    compare_marin_turn,
    compare_marin_zigzag,
    markdown,
    self_propulsion_n,
)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=None,
                        help="measured-data folder (default: jaxship's shared data folder)")
    args = parser.parse_args()
    data = args.data or js.shared_data_dir()
    if data is None or not (data / "kvlcc2_simman2008_hsva").is_dir():
        raise SystemExit("measured data not found: give --data DIR (the shared/data folder)")
    vessel = js.get_vessel("kvlcc2")
    rows = []
    for path in sorted((data / "kvlcc2_simman2008_hsva").glob("*.dat")):
        rows += compare_hsva(path, vessel)
    marin = data / "kvlcc2_simman2008_marin"
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_tc_*.dat")):
        rows += compare_marin_turn(path, vessel)
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_zz_*.dat")):
        rows += compare_marin_zigzag(path, vessel)
    print(f"KVLCC2 L7, MMG standard method vs SIMMAN 2008 (self-propulsion n of the MMG model at "
          f"1.179 m/s: {self_propulsion_n(vessel, 1.179):.2f} rps)\n")
    print(markdown(rows))


if __name__ == "__main__":
    main()
