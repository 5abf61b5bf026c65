"""Does the autopilot's reference feed-forward help on vessels jaxship did not fit? (issue 61)

Run as a notebook user would, through the library verbs the command calls: each vessel's
steering model from `jaxship.identify` on that vessel's zig-zags, then
`jaxship.evaluate_autopilot` with its defaults (45 deg step) on a vessel preset, PID with
feed-forward (pid+ff) against the same PID without it (pid). Printed per run: the summed
heading error (thesis eq. 3.19, deg at 1 s over the window after the step), the overshoot
[deg], and the ratio pid+ff / pid; and
the diagnosis of issue 61: at the step's peak desired yaw rate, the steady-turn rudder the
model's feed-forward orders against the one the vessel itself needs there (a reverse-spiral
point flown in closed loop, "feedforward_at_step" of the evaluation, as in autopilot.json).

- Mariner at 7.7 m/s: zig-zags 10/10 and 20/20 of jaxship's `mariner` preset, which
  is also the plant;
- KVLCC2 7 m model at 600 and 711 rpm: HSVA's measured zig-zags 10/5, 20/5, 10/10 P and
  20/10 P (SIMMAN 2008, /work/shared/data or $JAXSHIP_DATA); the plant is the `kvlcc2`
  preset (an MMG model jaxship did not fit to these records);
- the thesis vessel at 300 and 400 rpm: zig-zags 10/10 and 20/20 of the `thesis`
  preset at each rate, merged.

With `--tune` (issue 61 point 2) a second table follows: per run the summed
error against the ordered heading (the step) of pid+ff (untuned) and of the tuned
design (gains, then the reference model's bandwidth: `evaluate_autopilot(..., tune=True)`,
as `autopilot --tune`), the error of
each against its own reference, and the bandwidth before and after with its bound.

`--models auto` fits with `identify("auto", ...)` (issue 61 point 1: the model chosen by
its BIC on the training records); the fit column says which.

`--vessels` chooses the cases: by default the issue's three vessels above; `more` are
checks on other vessels: the Esso Osaka 3 m model (its four
zig-zags at 12 rps, measured, /work/shared/data; the plant the `esso_osaka` preset at 600
and 720 rpm) and the presets `sea_stratus_nonlinear`, `compass_island_nonlinear`,
`sea_swift` and `sea_scout` (zig-zags 10/10 and 20/20 of each at its nominal speed, the
plant the preset itself).

    python benchmarks/autopilot_feedforward.py [--models nomoto1 nomoto1-norrbin auto]
        [--tune] [--vessels issue more]
"""

import argparse
import pathlib
import sys
import tempfile

import jax

import jaxship as js


HSVA = ("HSVA_CPMC_KVLCC2_Z_10_05", "HSVA_CPMC_KVLCC2_Z_20_05",
        "HSVA_CPMC_KVLCC2_Z_10_10_P", "HSVA_CPMC_KVLCC2_Z_20_10_P")
ESSO = ("zigzag_31-Jul-2020_13_29_19", "zigzag_31-Jul-2020_13_50_28",
        "zigzag_31-Jul-2020_14_03_39", "zigzag_31-Jul-2020_14_10_05")  # the 12 rps runs
PRESETS = ("sea_stratus_nonlinear", "compass_island_nonlinear", "sea_swift", "sea_scout")


def zigzags(vessel: str, folder: pathlib.Path, **point) -> list:
    """10/10 and 20/20 zig-zags of a preset at each given `speed` or `rpm`, sized and
    simulated as `jaxship simulate` does (`StandardTrial`), written as trial CSV files."""
    (key, values), = point.items()
    model = js.get_vessel(vessel)
    paths = []
    for value in values:
        for angle in (10, 20):
            trial = js.StandardTrial.parse(f"zigzag:{angle}/{angle}")
            manoeuvre, x0 = trial.sized(model, **{key: value})
            traj = js.simulate(model, manoeuvre, x0, simulator=trial.simulator)
            path = folder / f"{vessel}_{angle}_{value:g}.csv"
            js.write_trial_csv(path, js.Experiment.from_trajectory(traj))
            paths.append(path)
    return paths


def measured(folder: str, names, suffix: str) -> list:
    """The paths of measured records in ../shared/data (empty where absent, said)."""
    data = js.shared_data_dir()
    paths = [] if data is None else [data / folder / f"{n}{suffix}" for n in names]
    if not paths or not all(p.is_file() for p in paths):
        print(f"{folder}: data not found (set $JAXSHIP_DATA); skipped", file=sys.stderr)
        return []
    return paths


def cases(folder: pathlib.Path, which=("issue",)) -> list:
    """(name, training records, plant preset, run option, values) of the issue's five runs
    and (`more`) the checks on other vessels (module text)."""
    out = []
    if "issue" in which:
        out.append(("Mariner", zigzags("mariner", folder, speed=[7.7]), "mariner", "speeds",
                    [7.7]))
        if hsva := measured("kvlcc2_simman2008_hsva", HSVA, ".dat"):
            out.append(("KVLCC2 (HSVA)", hsva, "kvlcc2", "rpm", [600, 711]))
        out.append(("thesis", zigzags("thesis", folder, rpm=[300, 400]), "thesis", "rpm",
                    [300, 400]))
    if "more" in which:
        if esso := measured("esso_osaka_frt/zigzag", ESSO, ".csv"):
            out.append(("Esso Osaka (12 rps)", esso, "esso_osaka", "rpm", [600, 720]))
        for name in PRESETS:
            speed = float(js.get_vessel(name).nominal_speed)
            out.append((name, zigzags(name, folder, speed=[speed]), name, "speeds", [speed]))
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", nargs="+", default=["nomoto1", "nomoto1-norrbin"])
    parser.add_argument("--tune", action="store_true",
                        help="tune as `jaxship autopilot --tune` does (the second table)")
    parser.add_argument("--vessels", nargs="+", choices=("issue", "more"), default=["issue"],
                        help="the issue's vessels, and/or more (module text)")
    args = parser.parse_args(argv)
    jax.config.update("jax_enable_x64", True)  # as the command
    js.enable_compilation_cache()
    print("| vessel | model | run | pid+ff sum [deg] | pid sum [deg] | ratio | "
          "pid+ff overshoot [deg] | pid overshoot [deg] | peak r_d [deg/s] | "
          "model's steady rudder there [deg] | vessel's [deg] | fit |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    tuned_rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        for name, train, plant, option, values in cases(folder, args.vessels):
            for model in args.models:
                result = js.identify(model, train)
                determined = result.fit.success and result.fit.code != js.RESULTS.undetermined
                fitted = "converged" if determined else "NOT converged"
                if model == "auto":  # identify("auto", ...): the model it chose
                    fitted += f"; auto chose {result.model_name}"
                try:
                    evaluation = js.evaluate_autopilot(result, js.get_vessel(plant),
                                                       **{option: values}, tune=args.tune)
                except ValueError as error:  # a design the command refuses (exit 2)
                    print(f"| {name} | {model} | autopilot refused: "
                          f"{str(error).splitlines()[-1][:80]} | | | | | | | | | {fitted} |")
                    continue
                written = evaluation.to_dict()
                rows, at = written["runs"], written["feedforward_at_step"]
                if "candidates" in at:  # from auto: the two designed on, say which does what
                    fitted += (f"; poles on {written['gains']['pid']['feedback']}, "
                               f"feed-forward inverts {at['model']}")
                by = {(r["controller"], r["rpm"], r["speed"]): r for r in rows}
                for (controller, rpm, speed), ff in by.items():
                    if controller != "pid+ff":
                        continue
                    fb = by[("pid", rpm, speed)]
                    run = f"{speed:.3g} m/s" if option == "speeds" else f"{rpm:.0f} rpm"
                    a, b = ff["sum_abs_error_deg"], fb["sum_abs_error_deg"]
                    ratio = "-" if None in (a, b) else f"{a / b:.2f}"
                    print(f"| {name} | {model} | {run} | {_cell(a, '.1f')} | {_cell(b, '.1f')} | "
                          f"{ratio} | {_cell(ff['max_overshoot_deg'], '.2f')} | "
                          f"{_cell(fb['max_overshoot_deg'], '.2f')} | "
                          f"{at['peak_rate_deg_s']:.3g} | {at['model_rudder_deg']:.3g} | "
                          f"{_cell(at['vessel_rudder_deg'])} | {fitted} |", flush=True)
                    if "tuned" in written["gains"]:
                        tuned_rows.append(_tuned_row(name, model, run, written, rpm, speed))
    if tuned_rows:
        print("\n| vessel | model | run | pid+ff vs ordered [deg] | tuned vs ordered [deg] | "
              "ratio | pid+ff vs its reference [deg] | tuned vs its reference [deg] | "
              "omega before -> after [rad/s] | bound at tuned g_a [rad/s] | g_a after | "
              "tuned overshoot [deg] |")
        print("|---|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|")
        print("\n".join(tuned_rows))
    return 0


def _cell(x, spec: str = ".3g") -> str:
    """A number in format `spec`; "-" where none was measured (a trial that failed, a run
    that blew up)."""
    return "-" if x is None else format(x, spec)


def _tuned_row(name, model, run, written, rpm, speed) -> str:
    """One row of the `--tune` table (module text)."""
    by = {(r["controller"], r["rpm"], r["speed"]): r for r in written["runs"]}
    ff, tuned = by[("pid+ff", rpm, speed)], by[("tuned", rpm, speed)]
    g = written["gains"]["tuned"]
    a, b = ff["sum_abs_error_ordered_deg"], tuned["sum_abs_error_ordered_deg"]
    ratio = "-" if None in (a, b) else f"{b / a:.2f}"
    return (f"| {name} | {model} | {run} | {a:.1f} | {b:.1f} | {ratio} | "
            f"{ff['sum_abs_error_deg']:.1f} | {tuned['sum_abs_error_deg']:.1f} | "
            f"{g['reference_frequency_before']:.4g} -> {g['reference_frequency_after']:.4g} | "
            f"{g['reference_frequency_bound']:.4g} | {g['ff_gain_after_reference']:.3g} | "
            f"{tuned['max_overshoot_deg']:.2f} |")


if __name__ == "__main__":
    sys.exit(main())
