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
    python benchmarks/discovery.py --generator mariner-scipy --seeds 20 --jobs 2  # issue 71
    python benchmarks/discovery.py --generator kvlcc2-shipmmg --seeds 20 --jobs 2

`--generator NAME` runs instead issue 71's scenarios (the null; a 1.5 deg rudder offset, a
(0.3, -0.4) m/s current, a 0.05 deg/s gyro bias or, but on shipmmg, a 1.5 s rudder delay;
offset + current; current + a 20 % yaw added-inertia error; all three; u, v over ground) on
the records of `jaxship`
(`vessel_records`), `mariner-scipy` (`jaxship/studies/generators.py`: the published
equations in NumPy, `solve_ivp`, its own servo and autopilot hold) or `kvlcc2-shipmmg`
(`jaxship/studies/kvlcc2_shipmmg.py`: shipmmg's MMG code, Froude-scaled sizes).
"""

import argparse
import dataclasses
import inspect
import json
import multiprocessing
import pathlib
import subprocess
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import jax
import numpy as np

import jaxship as js
from jaxship import effects
from jaxship.strategies import Prior
from jaxship.studies.discovery import (
    covered,
    outcome,
    run_case,
    run_vessel_case,
    vessel_records,
    wind_records,
)
from jaxship.studies.generators import generator_from_effects, mariner_scipy_records
from jaxship.studies.kvlcc2_shipmmg import KVLCC2Shipmmg, kvlcc2_shipmmg_records


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


# issue 71: issue 60's single, double and triple effects and the null on records of a
# generator (`--generator`): jaxship's own Mariner (`vessel_records`, over ground), the
# independent Mariner (`jaxship/studies/generators.py`: the MSS equations in NumPy, solve_ivp,
# its own servo and autopilot hold; 400 s records) or shipmmg's KVLCC2 L7 model
# (`jaxship/studies/kvlcc2_shipmmg.py`; 150 s records), whose current and gyro bias are the
# Mariner's Froude-scaled (speeds / sqrt(320 / 7), rates * sqrt(320 / 7))
GENERATORS = {"jaxship": ("mariner", 1.0), "mariner-scipy": ("mariner", 1.0),
              "kvlcc2-shipmmg": ("kvlcc2", (320.0 / 7.0) ** 0.5)}


def generator_scenarios(froude=1.0, delay=True) -> dict:
    """`{name: (hidden effects, truth)}` of issue 71 at the Froude scale factor `froude`;
    with `delay` a 1.5 s rudder delay too (the generators that can hide one)."""
    north, east, bias = 0.3 / froude, -0.4 / froude, 0.05 * DEG * froude
    offset, current = effects.RudderOffset(delta0=1.5 * DEG), effects.UniformCurrent(
        north=north, east=east)
    gyro, added = effects.YawRateSensorBias(bias=bias), effects.AddedMassError(s_r=0.2)
    truth = {"rudder_offset.delta0": 1.5 * DEG, "current.north": north, "current.east": east,
             "yaw_rate_sensor_bias.bias": bias, "added_mass_error.s_r": 0.2,
             "rudder_delay.delay": 1.5}
    return {name: (hidden, {k: v for k, v in truth.items()
                            if k.split(".")[0] in {e.id for e in hidden}})
            for name, hidden in (
                ("null", ()),
                ("offset 1.5 deg", (offset,)),
                ("current", (current,)),
                ("gyro bias", (gyro,)),
                *((("rudder delay 1.5 s", (effects.RudderDelay(delay=1.5),)),) if delay else ()),
                ("offset + current", (offset, current)),
                ("current + added mass s_r 0.2", (current, added)),
                ("offset + current + added mass s_r 0.2", (offset, current, added)),
            )}


def generator_case(generator, prior=None):
    """`run(effects, seed) -> (report, seconds)`: discovery from the preset on the records
    of `generator` (a key of `GENERATORS`) with `effects` hidden; with `prior` (a relative
    scale) every fit has a Gaussian prior centred on the preset (`Prior(scale=prior)`)."""
    default = inspect.signature(js.discover).parameters["estimator"].default
    estimator = None if prior is None else dataclasses.replace(default, prior=Prior(scale=prior))

    def run(hidden, seed):
        options = {} if estimator is None else {"estimator": estimator}
        if generator == "jaxship":
            return run_vessel_case(hidden, 1000 + seed, **options)
        if generator == "mariner-scipy":
            train, holdout = mariner_scipy_records(generator_from_effects(hidden), 1000 + seed)
        else:
            train, holdout = kvlcc2_shipmmg_records(
                generator_from_effects(hidden, KVLCC2Shipmmg), 1000 + seed)
        began = time.perf_counter()
        report = js.discover(js.get_vessel(GENERATORS[generator][0]), train, holdout,
                             **options)
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
    parser.add_argument("--jobs", type=int, default=1,
                        help="cases run at once, each in its own process")
    parser.add_argument("--prior", type=float, default=None,
                        help="with --generator: a Gaussian prior on the base coefficients, "
                             "centred on the preset, of this relative scale (issue 69)")
    parser.add_argument("--mariner", action="store_true",
                        help="instead: time one discovery on Mariner records (4 + 3 records of "
                             "800 s at 2 Hz, 8 channels) with a hidden 0.5 deg rudder offset, "
                             "by the library and by the `jaxship discover` command")
    parser.add_argument("--generator", choices=tuple(GENERATORS), default=None,
                        help="instead: the scenarios of issue 71 (null, single, double and "
                             "triple effects; u, v over ground) on records of this generator: "
                             "jaxship's own Mariner, the independent Mariner of "
                             "jaxship/studies/generators.py or shipmmg's KVLCC2 "
                             "(pip install --no-deps shipmmg)")
    args = parser.parse_args()
    jax.config.update("jax_enable_x64", True)
    if args.mariner:
        time_mariner()
        return
    names = [n for n in build_cases(args.generator) if not args.only or n in args.only]
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    jobs = [(args.generator, name, seed, args.prior) for name in names for seed in seeds]
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs, mp_context=multiprocessing.get_context("spawn")) \
                as pool:
            done = list(pool.map(run_one, *zip(*jobs)))
    else:
        done = [run_one(*job) for job in jobs]
    rows = [summary(name, [d for (_, n, _, _), d in zip(jobs, done) if n == name])
            for name in names]
    print(f"\n{f'generator {args.generator}: ' if args.generator else ''}"
          f"{f'prior {args.prior}: ' if args.prior else ''}"
          "| scenario | detected (null: silent) % | wrong name % | missed % | base fit blew "
          "up % | hidden named (with anything else) % | median rel. error % | truth within "
          "3 SE % | s per run | named beside the hidden |\n"
          "|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]:.0f} | {r[2]:.0f} | {r[3]:.0f} | {r[4]:.0f} | "
              f"{r[8]:.0f} | {r[5]:.2f} | "
              f"{r[6]:.0f} | {r[7]:.1f} | {r[9]} |")
    print(f"\n{args.seeds} seeds per scenario (from {1000 + args.first_seed}); "
          f"{time.strftime('%Y-%m-%d')}.")


def build_cases(generator, prior=None) -> dict:
    """`{name: (effects, truth, run)}`: the generator's scenarios or the ordinary ones."""
    if generator:
        return {name: (hidden, truth, generator_case(generator, prior)) for name, (hidden, truth)
                in generator_scenarios(GENERATORS[generator][1],
                                       delay=generator != "kvlcc2-shipmmg").items()}
    return ordinary_cases()


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


def run_one(generator, name, seed, prior=None) -> dict:
    """One case (a scenario of `generator`, or an ordinary one, at `seed`): its outcome
    ("blew up" where the fitted base model's prediction of the held-out records is not
    finite, `FitError`), seconds, the relative errors of the named parameters in the truth
    and whether they hold it within 3 standard errors. Runs in a worker process with
    `--jobs`."""
    jax.config.update("jax_enable_x64", True)
    hidden, truth, run = build_cases(generator, prior)[name]
    began = time.perf_counter()
    try:
        report, seconds = run(hidden, seed)
    except js.FitError as error:
        print(f"  {name} seed {seed}: blew up: {error}", flush=True)
        return dict(result="blew up", null=not hidden, seconds=time.perf_counter() - began,
                    errors=[], inside=None, found=False, extra=[])
    result = outcome(report, tuple(e.id for e in hidden))
    classes = report.names_or_classes()
    found = all(any(e.id in c for c in classes) for e in hidden)  # whatever else is named
    errors = [abs(p.value - truth[n]) / abs(truth[n]) for e in report.effects
              for n, p in e.parameters.items() if n in truth] if result == "correct" else []
    inside = covered(report, truth) if result == "correct" else None
    print(f"  {name} seed {seed}: {result}, named {report.named}, not judged "
          f"{report.not_judged}, truth within 3 SE {covered(report, truth)}, {seconds:.0f} s",
          flush=True)
    return dict(result=result, null=not hidden, seconds=seconds, errors=errors, inside=inside,
                found=found, extra=sorted(set().union(*classes) - {e.id for e in hidden}))


def summary(name, done):
    """One scenario's row from its cases (`run_one`'s records): `(name, detected or silent
    %, wrong %, missed %, blew up %, median relative error % of the named parameters in the
    truth, % of correct cases whose every estimate in the truth holds it within 3 standard
    errors, median s per run, % with every hidden effect named whatever else is, the other
    effects named in any case)`. Detection: every hidden effect named (or its class),
    nothing else."""
    share = lambda key: 100.0 * sum(d["result"] == key for d in done) / len(done)
    null = done[0]["null"]
    errors = [x for d in done for x in d["errors"]]
    inside = [d["inside"] for d in done if d["inside"] is not None]
    found = np.nan if null else 100.0 * np.mean([d["found"] for d in done])
    extra = sorted({x for d in done for x in d["extra"]})
    row = (name, share("nothing") if null else share("correct"), share("wrong"),
           share("missed"), share("blew up"), np.median(errors) * 100 if errors else np.nan,
           100.0 * np.mean(inside) if inside else np.nan,
           np.median([d["seconds"] for d in done]), found, ", ".join(extra) or "-")
    print(f"{name:34s} {'silent' if null else 'detected':>8s} {row[1]:5.1f} %  "
          f"wrong {row[2]:5.1f} %  missed {row[3]:5.1f} %  blew up {row[4]:5.1f} %  "
          f"recovery err {row[5]:6.2f} %  within 3 SE {row[6]:5.1f} %  "
          f"{row[7]:5.1f} s/run", flush=True)
    return row


if __name__ == "__main__":
    main()
