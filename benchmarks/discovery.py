"""Monte-Carlo benchmark of `jaxship.discover` on hidden-effect data (not run in CI).

For every scenario (an effect at a size, two or three effects at once, the white null
and the coloured null with a slowly varying yaw moment; and Mariner records with two or
three effects, u and v logged over ground) it runs discovery on `--seeds` independent data
sets (`jaxship/studies/discovery.py`: Nomoto 1 truth integrated finely, rate-limited
rudder logged at 2 Hz, 4 training zig-zags, 2 held-out turning circles) and prints:

- detection: the hidden effect (or each of two) named or in a named class, nothing
  else named;
- false alarm: anything named on null data;
- wrong name: a named effect whose class holds no hidden one;
- parameter recovery: median |estimate - truth| / truth of the named parameters of
  correct cases, and how often every estimate's +-3 standard-error interval holds the
  truth (`EffectParameter.interval`);
- runtime per discovery.

Goals (issue 11): detection >= 90 % at moderate size, false alarms <= 5 % on both
nulls, wrong names <= 5 %, both of two effects >= 80 %. Issue 60: two effects both named
>= 90 %, spurious <= 5 %, truth within 3 SE >= 90 %; three effects all named >= 75 %.

    python benchmarks/discovery.py --seeds 20
    python benchmarks/discovery.py --generator mariner-scipy --seeds 20   # issue 71

`--generator NAME` runs instead the Mariner scenarios (null, a 1.5 deg offset, a (0.3,
-0.4) m/s current, both; u, v over ground, 400 s records) on the records of `jaxship`
(`vessel_records`) or `mariner-scipy` (`jaxship/studies/generators.py`: the published
equations in NumPy, `solve_ivp`, its own servo and autopilot hold).
"""

import argparse
import json
import pathlib
import subprocess
import tempfile
import time

import jax
import numpy as np

import jaxship as js
from jaxship import effects
from jaxship.studies.discovery import (
    covered,
    outcome,
    run_case,
    run_vessel_case,
    vessel_records,
    wind_records,
)
from jaxship.studies.generators import generator_from_effects, mariner_scipy_records


DEG = np.pi / 180
K = 0.06
SCENARIOS = {  # name: (hidden effects, coloured-disturbance std [rad], true values)
    "null (white)": ((), 0.0, {}),
    "null (coloured, 1 deg)": ((), 1.0 * DEG, {}),
    "rudder offset 0.3 deg": ((effects.RudderOffset(delta0=0.3 * DEG),), 0.0,
                              {"rudder_offset.delta0": 0.3 * DEG,
                               "yaw_moment_bias.n0": K * 0.3 * DEG}),
    "rudder offset 0.3 deg, coloured": ((effects.RudderOffset(delta0=0.3 * DEG),), 1.0 * DEG, {}),
    "rudder offset 1 deg, coloured": ((effects.RudderOffset(delta0=1.0 * DEG),), 1.0 * DEG, {}),
    "cubic yaw damping 300": ((effects.YawCubicDamping(beta=300.0),), 0.0,
                              {"yaw_cubic_damping.beta": 300.0}),
    "rudder lag 1.5 s": ((effects.RudderLag(time_constant=1.5),), 0.0,
                         {"rudder_lag.time_constant": 1.5}),
    "gyro bias 0.02 deg/s": ((effects.YawRateSensorBias(bias=0.02 * DEG),), 0.0,
                             {"yaw_rate_sensor_bias.bias": 0.02 * DEG}),
    "offset + cubic": ((effects.RudderOffset(delta0=0.3 * DEG),
                        effects.YawCubicDamping(beta=300.0)),
                       0.0, {}),
    # several effects at once (issue 60), Nomoto 1 truth
    "offset 1 deg + delay 1.5 s": ((effects.RudderOffset(delta0=1.0 * DEG),
                                    effects.RudderDelay(delay=1.5)),
                                   0.0, {"rudder_offset.delta0": 1.0 * DEG,
                                         "yaw_moment_bias.n0": K * 1.0 * DEG,
                                         "rudder_delay.delay": 1.5}),
    "gyro bias 0.05 deg/s + cubic 300": ((effects.YawRateSensorBias(bias=0.05 * DEG),
                                          effects.YawCubicDamping(beta=300.0)), 0.0,
                                         {"yaw_rate_sensor_bias.bias": 0.05 * DEG,
                                          "yaw_cubic_damping.beta": 300.0}),
    "offset 1 deg + delay 1.5 s + cubic 300": (
        (effects.RudderOffset(delta0=1.0 * DEG), effects.RudderDelay(delay=1.5),
         effects.YawCubicDamping(beta=300.0)), 0.0,
        {"rudder_offset.delta0": 1.0 * DEG, "yaw_moment_bias.n0": K * 1.0 * DEG,
         "rudder_delay.delay": 1.5, "yaw_cubic_damping.beta": 300.0}),
}
# Nomoto 1 truth that feels a logged 15 m/s wind from 60 deg at 7 m/s (`wind_records`: 10/10
# zig-zags on four headings to train, +-20 deg turns held out)
WIND_SCENARIOS = {
    "wind c2 3e-6 + offset 1 deg": ((effects.ApparentWind(c2=3e-6),
                                     effects.RudderOffset(delta0=1.0 * DEG)),
                                    {"wind.c2": 3e-6, "rudder_offset.delta0": 1.0 * DEG,
                                     "yaw_moment_bias.n0": K * 1.0 * DEG}),
    "wind c2 3e-6 + offset 1 deg + delay 1.5 s": (
        (effects.ApparentWind(c2=3e-6), effects.RudderOffset(delta0=1.0 * DEG),
         effects.RudderDelay(delay=1.5)),
        {"wind.c2": 3e-6, "rudder_offset.delta0": 1.0 * DEG,
         "yaw_moment_bias.n0": K * 1.0 * DEG, "rudder_delay.delay": 1.5}),
}
# Mariner truth, u and v logged over ground (GNSS), 400 s records (`run_vessel_case`)
VESSEL_SCENARIOS = {
    "mariner: offset 1.5 deg + current (0.3, -0.4) m/s": (
        (effects.RudderOffset(delta0=1.5 * DEG), effects.UniformCurrent(north=0.3, east=-0.4)),
        {"rudder_offset.delta0": 1.5 * DEG, "current.north": 0.3, "current.east": -0.4}),
    "mariner: current (0.3, -0.4) m/s + added mass s_r 0.2": (
        (effects.UniformCurrent(north=0.3, east=-0.4), effects.AddedMassError(s_r=0.2)),
        {"current.north": 0.3, "current.east": -0.4, "added_mass_error.s_r": 0.2}),
    "mariner: offset 1.5 deg + current + added mass s_r 0.2": (
        (effects.RudderOffset(delta0=1.5 * DEG), effects.UniformCurrent(north=0.3, east=-0.4),
         effects.AddedMassError(s_r=0.2)),
        {"rudder_offset.delta0": 1.5 * DEG, "current.north": 0.3, "current.east": -0.4,
         "added_mass_error.s_r": 0.2}),
}


# issue 71: the Mariner scenarios on records of a generator (`--generator`): jaxship's own
# (`vessel_records`, over ground) or the independent one (`jaxship/studies/generators.py`:
# the MSS equations in NumPy, solve_ivp, its own servo and autopilot hold), 400 s records
GENERATOR_SCENARIOS = {
    "null": ((), {}),
    "offset 1.5 deg": ((effects.RudderOffset(delta0=1.5 * DEG),),
                       {"rudder_offset.delta0": 1.5 * DEG}),
    "current (0.3, -0.4) m/s": ((effects.UniformCurrent(north=0.3, east=-0.4),),
                                {"current.north": 0.3, "current.east": -0.4}),
    "offset 1.5 deg + current (0.3, -0.4) m/s": (
        (effects.RudderOffset(delta0=1.5 * DEG), effects.UniformCurrent(north=0.3, east=-0.4)),
        {"rudder_offset.delta0": 1.5 * DEG, "current.north": 0.3, "current.east": -0.4}),
}


def generator_case(generator):
    """`run(effects, seed) -> (report, seconds)`: discovery from the Mariner preset on the
    records of `generator` ("jaxship" or "mariner-scipy") with `effects` hidden."""
    def run(hidden, seed):
        if generator == "jaxship":
            return run_vessel_case(hidden, 1000 + seed)
        train, holdout = mariner_scipy_records(generator_from_effects(hidden), 1000 + seed)
        began = time.perf_counter()
        report = js.discover(js.get_vessel("mariner"), train, holdout)
        return report, time.perf_counter() - began
    return run


def time_mariner():
    """One discovery on Mariner-size records (4 + 3 records of 800 s at 2 Hz, 8 channels,
    a hidden 0.5 deg rudder offset): `jaxship.discover` from the preset, then the
    `jaxship discover` command on the same records written as trial CSVs, in a new
    process (import, compilation, the preset's `identify` start, discovery, report
    and figures), as a user runs it."""
    truth = js.augment(js.get_vessel("mariner"), effects.RudderOffset(delta0=0.5 * DEG))
    train, holdout = vessel_records(truth, 0)
    began = time.perf_counter()
    report = js.discover(js.get_vessel("mariner"), train, holdout,
                         progress=lambda m: print(
                             f"{time.perf_counter() - began:6.1f} s {m.message}", flush=True))
    print(report.to_markdown())
    print(f"Mariner discovery (library): {time.perf_counter() - began:.1f} s; named "
          f"{report.names_or_classes()}")
    with tempfile.TemporaryDirectory() as folder:
        paths = {}
        for role, records in (("train", train), ("holdout", holdout)):
            paths[role] = [f"{folder}/{role}{i}.csv" for i in range(len(records))]
            for path, e in zip(paths[role], records):
                js.write_trial_csv(path, e)
        command = ["jaxship", "discover", *paths["train"], "--holdout", *paths["holdout"],
                   "--model", "mariner", "--out", f"{folder}/out", "--quiet"]
        began = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - began
        named = [e["id"] for e in json.loads(pathlib.Path(f"{folder}/out/discovery.json")
                                              .read_text())["effects"]]
    print(f"`jaxship discover --model mariner` on the same records (new process): "
          f"{seconds:.1f} s; named {named}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=0,
                        help="the first seed (offset from 1000): continue an earlier run")
    parser.add_argument("--only", nargs="*", default=None, help="scenario names to run")
    parser.add_argument("--mariner", action="store_true",
                        help="instead: time one discovery on Mariner records (4 + 3 records of "
                             "800 s at 2 Hz, 8 channels) with a hidden 0.5 deg rudder offset, "
                             "by the library and by the `jaxship discover` command")
    parser.add_argument("--generator", choices=("jaxship", "mariner-scipy"), default=None,
                        help="instead: the Mariner scenarios (null, offset, current, both; u, "
                             "v over ground) on records of this generator: jaxship's own or "
                             "the independent one of jaxship/studies/generators.py")
    args = parser.parse_args()
    jax.config.update("jax_enable_x64", True)
    if args.mariner:
        time_mariner()
        return
    if args.generator:
        cases = {name: (hidden, truth, generator_case(args.generator))
                 for name, (hidden, truth) in GENERATOR_SCENARIOS.items()}
    else:
        cases = ordinary_cases()
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    rows = [scenario(name, *cases[name], seeds) for name in cases
            if not args.only or name in args.only]
    print(f"\n{f'generator {args.generator}: ' if args.generator else ''}"
          "| scenario | detected (null: silent) % | wrong name % | missed % | median rel. "
          "error % | truth within 3 SE % | s per run |\n|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]:.0f} | {r[2]:.0f} | {r[3]:.0f} | {r[4]:.2f} | {r[5]:.0f} | "
              f"{r[6]:.1f} |")
    print(f"\n{args.seeds} seeds per scenario (from {1000 + args.first_seed}); "
          f"{time.strftime('%Y-%m-%d')}.")


def ordinary_cases() -> dict:
    """The scenarios of issues 11 and 60 (jaxship's records): `{name: (effects, truth, run)}`."""
    cases = {name: (effects, truth, lambda e, seed, c=colour: run_case(e, 1000 + seed,
                                                                        disturbance_std=c))
             for name, (effects, colour, truth) in SCENARIOS.items()}
    cases |= {name: (effects, truth, lambda e, seed: run_case(e, 1000 + seed,
                                                               records=wind_records))
              for name, (effects, truth) in WIND_SCENARIOS.items()}
    cases |= {name: (effects, truth, lambda e, seed: run_vessel_case(e, 1000 + seed))
              for name, (effects, truth) in VESSEL_SCENARIOS.items()}
    return cases


def scenario(name, effects, truth, run, seeds):
    """One scenario over the `seeds` (a range): `(name, detected or silent %, wrong %, missed %,
    median relative error % of the named parameters in `truth`, % of correct cases whose
    every estimate in `truth` holds the truth within 3 standard errors, median s per run)`.
    Detection: every hidden effect named (or its class), nothing else."""
    counts, errors, inside, times = {}, [], [], []
    hidden = tuple(e.id for e in effects)
    for seed in seeds:
        report, seconds = run(effects, seed)
        result = outcome(report, hidden)
        counts[result] = counts.get(result, 0) + 1
        times.append(seconds)
        if result == "correct":
            for e in report.effects:
                errors += [abs(p.value - truth[n]) / abs(truth[n])
                           for n, p in e.parameters.items() if n in truth]
            if covered(report, truth) is not None:
                inside.append(covered(report, truth))
        print(f"  {name} seed {seed}: {result}, named {report.named}, truth within 3 SE "
              f"{covered(report, truth)}, {seconds:.0f} s", flush=True)
    share = lambda key: 100.0 * counts.get(key, 0) / len(seeds)
    row = (name, share("correct") if hidden else share("nothing"), share("wrong"),
           share("missed"), np.median(errors) * 100 if errors else np.nan,
           100.0 * np.mean(inside) if inside else np.nan, np.median(times))
    print(f"{name:34s} {'detected' if hidden else 'silent':>8s} {row[1]:5.1f} %  "
          f"wrong {row[2]:5.1f} %  missed {row[3]:5.1f} %  "
          f"recovery err {row[4]:6.2f} %  within 3 SE {row[5]:5.1f} %  "
          f"{row[6]:5.1f} s/run", flush=True)
    return row


if __name__ == "__main__":
    main()
