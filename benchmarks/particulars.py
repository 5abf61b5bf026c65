"""KVLCC2 from its main particulars alone (`MMGVessel.from_particulars`) against the SIMMAN
captive-test coefficients (the `kvlcc2` preset, Yasukawa & Yoshimura 2015) and against the
measured SIMMAN 2008 free-running tests (HSVA zig-zags, MARIN turns and zig-zags; the
definitions are `jaxship.studies.kvlcc2_simman`'s).

Run: `python benchmarks/particulars.py [--data DIR]`; prints two markdown tables. The
output is recorded in `benchmarks/results/particulars.md`.
"""

import argparse
import math
from pathlib import Path

import jax


jax.config.update("jax_enable_x64", True)

import jaxship as js  # noqa: E402
from jaxship.studies.kvlcc2_simman import (  # noqa: E402
    compare_hsva,
    compare_marin_turn,
    compare_marin_zigzag,
)


# KVLCC2 L7 (1:45.714): SIMMAN 2008 L_pp 7.0 m, B 1.2688 m, T 0.455 m, C_b 0.810, x_G
# 0.25 m; propeller D_P, rudder A_R, H_R, K_T and the helm rate as the `kvlcc2` preset
# (Yasukawa & Yoshimura 2015 Tables 1, 4; project notes reference/vessel-models.md sec. 2)
KVLCC2 = js.MainParticulars(
    length=7.0, breadth=1.2688, draft=0.455, block_coefficient=0.810, speed=1.179,
    propeller_diameter=0.216, rudder_area=0.0539, rudder_span=0.345,
    rudder_rate=math.radians(15.8), k_t=(0.2931, -0.2753, -0.1385), x_g=0.25)
HSVA_RUNS = ("Z_10_10", "Z_20_10")  # the HSVA zig-zags of the goals' sizes (no 20/20 there)


def coefficient_table(vessel, preset) -> str:
    """Each coefficient of the formulas beside the preset's (captive tests)."""
    rows = ["| coefficient | from particulars | SIMMAN captive tests (`kvlcc2`) | ratio |",
            "|---|---:|---:|---:|"]
    for name in KVLCC2.coefficients():
        mine, lab = float(getattr(vessel, name)), float(getattr(preset, name))
        ratio = f"{mine / lab:.2f}" if lab else "-"
        rows.append(f"| {name} | {mine:.4g} | {lab:.4g} | {ratio} |")
    rows.append(f"| nominal_n [rev/s] (self-propulsion at 1.179 m/s) | "
                f"{float(vessel.nominal_n):.4g} | {float(preset.nominal_n):.4g} | "
                f"{float(vessel.nominal_n) / float(preset.nominal_n):.2f} |")
    return "\n".join(rows)


def manoeuvres(vessel, data: Path) -> list:
    """Rows (run, quantity, measured, at measured n, at self-propulsion n)."""
    rows = []
    for path in sorted((data / "kvlcc2_simman2008_hsva").glob("*.dat")):
        if any(run in path.stem for run in HSVA_RUNS):
            rows += compare_hsva(path, vessel)
    marin = data / "kvlcc2_simman2008_marin"
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_tc_*.dat")):
        rows += compare_marin_turn(path, vessel)
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_zz_*.dat")):
        rows += compare_marin_zigzag(path, vessel)
    return [row for row in rows if "2nd" not in row[1] and "transfer" not in row[1]]


def index_table(mine: list, lab: list) -> str:
    """Turning and zig-zag indices: measured, from particulars, preset (both n)."""
    def diff(sim, meas, label):
        if math.isnan(sim):
            return "-"
        if "overshoot" in label:
            return f"{sim - meas:+.1f} deg"
        return f"{100 * (sim - meas) / meas:+.0f} %"

    rows = ["| run | quantity | measured | particulars, measured n | diff | particulars, "
            "self-prop. n | diff | preset, measured n | diff | preset, self-prop. n | diff |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for (run, label, meas, p_n, p_sp), (_, _, _, l_n, l_sp) in zip(mine, lab, strict=True):
        cells = [f"{x:.2f} | {diff(x, meas, label)}" for x in (p_n, p_sp, l_n, l_sp)]
        rows.append(f"| {run} | {label} | {meas:.2f} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=None,
                        help="measured-data folder (default: jaxship's shared data folder)")
    args = parser.parse_args()
    data = args.data or js.shared_data_dir()
    if data is None or not (data / "kvlcc2_simman2008_hsva").is_dir():
        raise SystemExit("measured data not found: give --data DIR (the shared/data folder)")
    preset = js.get_vessel("kvlcc2")
    vessel = js.MMGVessel.from_particulars(KVLCC2)
    print("## KVLCC2 L7: coefficients from the main particulars beside the captive tests\n")
    print(coefficient_table(vessel, preset))
    print("\n## Turning (35 deg) and zig-zag indices against the measured runs\n")
    print("Advance and tactical diameter in L_pp (diff in %), first overshoots in deg (diff in"
          " deg); 'measured n' is the test's propeller rate (0.204 m stock propeller), "
          "'self-prop. n' each model's own rate for the approach speed.\n")
    print(index_table(manoeuvres(vessel, data), manoeuvres(preset, data)))


if __name__ == "__main__":
    main()
