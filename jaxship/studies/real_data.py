"""Identification on the measured data sets in `shared/data`.

- **Esso Osaka** (FRT-DS-ESSO, Osaka University 2020; Wakita et al. 2022, J. Mar.
  Sci. Technol. 27:772-785): the 3-DOF low-speed MMG model (`esso_osaka` preset) with
  a chosen set of free coefficients, and the Nomoto 1 and 2 response models, are
  identified on the "random" runs (operator-chosen rudder and propeller sequences,
  designed for identification) and validated on the held-out runs of Wakita et al.'s
  test set that are manoeuvres: `random_06-Aug-2020_16_24_25_3`,
  `turn_14-Oct-2020_15_06_53` and `zigzag_31-Jul-2020_13_42_53` (the berthing test
  runs are left out: thruster use is not logged). Training set: every other random
  run (the consecutive segments of the 06-Aug run included, segment 3 excluded).
  A second split for steering models at low speed (`esso_osaka_low_speed_steering`)
  trains on eight zig-zags and holds out zig-zag 13_42_53 and turn 15_06_53; the
  low-speed sway-yaw model (`esso_osaka_low_speed_sway_yaw`) trains on those zig-zags
  and the 13 other turns.
- **KVLCC2, HSVA** (SIMMAN 2008 free-running zig-zags, model scale): Nomoto 1 and 2
  identified by output error on some zig-zags and validated on the others.

Validation is reported as fit % per channel on the held-out runs, for two predictors:
`horizon` (the training horizon: restart from the measured state every T_p seconds)
and free simulation (`horizon=None`, output error: one simulation of each whole run
from its first sample). The records are decimated (`Experiment.decimate`) to
keep the fits fast; the raw data are 10 Hz (Esso Osaka) and 20 Hz (HSVA).
"""

import dataclasses
import math
from pathlib import Path

import optimistix as optx

import jaxship as js

from .published_splits import WAKITA_2022


# Wakita et al.'s test runs that are manoeuvres (their berthing runs used thrusters)
ESSO_TEST = tuple(r for r in WAKITA_2022["Test"] if not r.startswith("berthing"))
# the 3-DOF coefficients estimated on the Esso Osaka data (default set of the preset)
ESSO_FREE = ("x_0f", "y_v", "y_r", "n_v", "n_r", "c_d", "c_ry", "c_rn", "epsilon", "gamma_n",
             "gamma_p")
HSVA_TRAIN = ("HSVA_CPMC_KVLCC2_Z_10_10_P", "HSVA_CPMC_KVLCC2_Z_20_10_P",
              "HSVA_CPMC_KVLCC2_Z_15_05")
HSVA_TEST = ("HSVA_CPMC_KVLCC2_Z_10_10_S", "HSVA_CPMC_KVLCC2_Z_20_10_S",
             "HSVA_CPMC_KVLCC2_Z_10_05", "HSVA_CPMC_KVLCC2_Z_20_05")


def _root(root, folder):
    base = js.shared_data_dir() if root is None else Path(root)
    if base is None or not (base / folder).is_dir():
        raise FileNotFoundError(f"measured data folder {folder!r} not found (looked in "
                                f"{base}); set $JAXSHIP_DATA or pass `root`.")
    return base / folder


def esso_osaka_split(root=None, *, factor: int = 5) -> tuple[list, list]:
    """`(train, test)` experiments of the Esso Osaka split (module docstring),
    decimated by `factor` (10 Hz / 5 = 2 Hz by default)."""
    folder = _root(root, "esso_osaka_frt")
    train = [js.read_measured(p).decimate(factor) for p in sorted(folder.glob("random/*.csv"))
             if p.stem not in ESSO_TEST]
    test = []
    for name in ESSO_TEST:
        found = sorted(folder.glob(f"*/{name}.csv"))
        if not found:
            raise FileNotFoundError(f"held-out run {name}.csv not found under {folder}.")
        test.append(js.read_measured(found[0]).decimate(factor))
    return train, test


def hsva_split(root=None, *, factor: int = 4, train=HSVA_TRAIN, test=HSVA_TEST):
    """`(train, test)` HSVA KVLCC2 zig-zags, decimated by `factor` (20 Hz / 4 = 5 Hz)."""
    folder = _root(root, "kvlcc2_simman2008_hsva")
    read = lambda names: [js.read_measured(folder / f"{n}.dat").decimate(factor)
                          for n in names]
    return read(train), read(test)


def kvlcc2_discovery_split(root=None, *, marin: bool = True) -> tuple[list, list]:
    """`(train, holdout)` of the KVLCC2 discovery check: the 11 HSVA zig-zags other than
    the two 10/10 runs to train, and both HSVA 10/10 runs and (with `marin`) the four
    MARIN zig-zags (Froude-scaled to the 7 m HSVA model) held out, all at 5 Hz."""
    folder = _root(root, "kvlcc2_simman2008_hsva")
    files = sorted(p for p in folder.glob("*.dat") if "_Z_" in p.name)
    read = lambda paths: [js.read_measured(p).decimate(4) for p in paths]  # 20 Hz
    held = [p for p in files if "_Z_10_10_" in p.name]
    return read([p for p in files if p not in held]), read(held) + [
        js.read_measured(p, model_scale=True).decimate(10)  # 50 Hz
        for p in (sorted(_root(root, "kvlcc2_simman2008_marin").glob("*zz*.dat"))
                  if marin else ())]


@dataclasses.dataclass(frozen=True)
class Identified:
    """One identified model: the `FitResult` on the training data and its validation
    predictions (`jaxship.predict`) on the test runs, keyed by predictor (`"T_p = 20 s"`,
    `"simulation"`)."""

    label: str
    result: js.FitResult
    validation: dict


@dataclasses.dataclass(frozen=True)
class RealDataReport:
    """Identified models on one data set, with `table()` of the held-out fit %."""

    dataset: str
    models: tuple[Identified, ...]
    train: tuple[str, ...]
    test: tuple[str, ...]
    baseline: dict = dataclasses.field(default_factory=dict)

    def rows(self) -> list[dict]:
        """One row per (model, predictor, test run or 'all'): fit % per channel."""
        out = []
        entries = [(m.label, m.validation) for m in self.models]
        if self.baseline:
            entries.insert(0, ("preset (not fitted)", self.baseline))
        for label, validation in entries:
            for predictor, pred in validation.items():
                out.append({"model": label, "predictor": predictor, "run": "all",
                            **pred.fit_percent()})
                for run, fits in pred.fit_per_experiment().items():
                    out.append({"model": label, "predictor": predictor, "run": run, **fits})
        return out

    def table(self) -> str:
        """Markdown table of the held-out fit % (100 perfect, 0 no better than the mean)."""
        rows = self.rows()
        channels = [c for c in ("psi", "r", "u", "v") if any(c in r for r in rows)]
        head = ("| model | predictor | held-out run | "
                + " | ".join(f"{c} fit %" for c in channels) + " |")
        lines = [head, "|" + "---|" * (3 + len(channels))]
        for r in rows:
            cells = [f"{r[c]:.1f}" if c in r else "" for c in channels]
            lines.append(f"| {r['model']} | {r['predictor']} | {r['run']} | "
                         + " | ".join(cells) + " |")
        return "\n".join(lines)


def _validate(model, test, estimator, horizons):
    out = {}
    for h in horizons:
        key = "simulation" if h is None else f"T_p = {h:g} s"
        out[key] = js.predict(model, test, estimator=dataclasses.replace(estimator, horizon=h))
    return out


def _nomoto_models(train, test, estimator, horizons):
    """Nomoto1 from the ARX start, then Nomoto2 from the fitted Nomoto1."""
    est = dataclasses.replace(estimator, channels=("psi", "r"), wind=False)
    # the ARX least-squares start, then prediction error from it
    fit1 = js.fit(js.Nomoto1(K=0.1, T=10.0), train,
                  estimator=dataclasses.replace(est, start=js.LinearStart()))
    K, T = float(fit1.model.K), float(fit1.model.T)
    start2 = js.Nomoto2.from_first_order(K, T)  # the start `jaxship.identify` uses
    fit2 = js.fit(start2, train, estimator=est)
    return (Identified("Nomoto1", fit1, _validate(fit1.model, test, est, horizons)),
            Identified("Nomoto2", fit2, _validate(fit2.model, test, est, horizons)))


def identify_esso_osaka(root=None, *, factor: int = 5, horizon: float = 20.0,
                        free=ESSO_FREE, wind: bool = True, substeps: int = 2,
                        max_steps: int = 100, tol: float = 1e-6, nomoto: bool = True
                        ) -> RealDataReport:
    """Identify the Esso Osaka 3-DOF model (and Nomoto 1, 2) on the random runs and
    validate on the held-out runs (module docstring).

    **Arguments:** `root` (the data folder; default `shared_data_dir()`), `factor`
    (decimation), `horizon` T_p [s] of the prediction-error fit, `free` (coefficients
    of the `esso_osaka` preset), `wind` (replay the measured true wind as loads),
    `substeps` (RK4 steps per sample), `max_steps` (LM steps), `tol` (LM `rtol` and
    `atol`), `nomoto` (also fit the response models). Validation predictors:
    T_p = `horizon` and free simulation.

    **Raises:** `FileNotFoundError` when the data are absent.
    """
    train, test = esso_osaka_split(root, factor=factor)
    vessel = js.get_vessel("esso_osaka")
    # tolerances of 1e-6: relative cost changes below that are far inside the noise
    solver = optx.LevenbergMarquardt(rtol=tol, atol=tol)
    est = js.PredictionError(horizon=horizon, wind=wind, max_steps=max_steps, solver=solver,
                             simulator=js.Simulator(max_step=math.inf, substeps=substeps))
    horizons = (horizon, None)
    baseline = _validate(vessel, test, est, horizons)
    res = js.fit(vessel, train, estimator=est, free=free)
    models = [Identified("3-DOF esso_osaka", res, _validate(res.model, test, est, horizons))]
    if nomoto:
        models.extend(_nomoto_models(train, test, est, horizons))
    return RealDataReport("Esso Osaka FRT", tuple(models), tuple(e.name for e in train),
                          tuple(e.name for e in test), baseline)


def identify_kvlcc2_hsva(root=None, *, factor: int = 4, train=HSVA_TRAIN, test=HSVA_TEST
                         ) -> RealDataReport:
    """Nomoto 1 and 2 from HSVA KVLCC2 zig-zags by output error (`horizon=None`),
    validated by simulation of the held-out zig-zags."""
    train_runs, test_runs = hsva_split(root, factor=factor, train=train, test=test)
    est = js.PredictionError(horizon=None)
    models = _nomoto_models(train_runs, test_runs, est, (None,))
    return RealDataReport("KVLCC2 HSVA", models, tuple(train), tuple(test))


ESSO_ZIGZAG_TEST = ("zigzag_31-Jul-2020_13_42_53", "turn_14-Oct-2020_15_06_53")


def esso_osaka_zigzag_split(root=None, *, factor: int = 5, trim: float = 20.0,
                            turns: bool = False):
    """`(train, test)` of the Esso Osaka zig-zag split: the eight zig-zags other than
    `zigzag_31-Jul-2020_13_42_53` to train; that zig-zag and `turn_14-Oct-2020_15_06_53`
    (both of Wakita et al.'s test set) held out; the first `trim` seconds of each run
    cut (the propeller spinning up from rest), decimated by `factor` (2 Hz). With
    `turns`, the training set also has the 13 other turning runs (of a run with a cut
    copy, `turn_cut_...`, only the cut one, as the papers use it)."""
    folder = _root(root, "esso_osaka_frt")
    def read(path):
        run = js.read_measured(path)
        return run.segment(start=run.t[0] + trim).decimate(factor)

    paths = sorted(folder.glob("zigzag/*.csv"))
    if turns:
        cut = {p.stem.replace("turn_cut_", "turn_") for p in folder.glob("turning/turn_cut_*")}
        paths += sorted(p for p in folder.glob("turning/*.csv") if p.stem not in cut)
    train = [read(p) for p in paths if p.stem not in ESSO_ZIGZAG_TEST]
    return train, [read(next(folder.glob(f"*/{name}.csv"))) for name in ESSO_ZIGZAG_TEST]


def esso_osaka_low_speed_steering(root=None, *, factor: int = 5) -> RealDataReport:
    """Steering models of the Esso Osaka model at low speed, fitted by output error on
    r over the zig-zag split (`esso_osaka_zigzag_split`) and validated by simulating
    the held-out zig-zag and turn (psi, r):

    - `speed-scaled Nomoto 1 + offset`: $T\\dot r + s r = K s^2(\\delta + \\delta_0)$,
      $s = u/U_0$ with the measured u (Nomoto 1957), $U_0$ the mean training u;
    - `+ race, wind, r|r|`: the same with the three low-speed terms it lacks, fitted
      together: the propeller race on the rudder (`PropellerRace`, $b n^2\\delta$),
      the logged apparent wind (`ApparentWind`) and quadratic yaw damping
      (`YawQuadraticDamping`). At 0.1-0.5 m/s in 1-4 m/s of wind, the race and the
      wind carry rudder and yaw moments of the size the hull's speed gives;
    - `+ speed exponents free`: the same with the two speed exponents $\\kappa$ of
      `SpeedDependentRudder` and `SpeedDependentDamping` fitted too (1 and 1 above,
      Nomoto's scaling).
    """
    train, test = esso_osaka_zigzag_split(root, factor=factor)
    return RealDataReport("Esso Osaka FRT, zig-zag split", _low_speed_nomoto(train, test),
                          tuple(e.name for e in train), tuple(e.name for e in test))


def esso_osaka_low_speed_sway_yaw(root=None, *, factor: int = 5) -> RealDataReport:
    """The low-speed steering models on the zig-zag split with the turns trained on
    (`esso_osaka_zigzag_split(turns=True)`: 8 zig-zags and 13 turns): the last,
    richest Nomoto model of `esso_osaka_low_speed_steering` (fitted on r) and
    `LowSpeedSwayYaw` with a rudder offset (fitted on r and v; the drift of the turns
    reaches v = 0.12 m/s at u = 0.13 m/s, which a model without sway cannot follow),
    validated by simulating the held-out zig-zag and turn."""
    train, test = esso_osaka_zigzag_split(root, factor=factor, turns=True)
    nomoto = dataclasses.replace(_low_speed_nomoto(train, test)[-1],
                                 label="speed-scaled Nomoto 1 + all terms, exponents free")
    est = js.PredictionError(horizon=None, channels=("r", "v"), wind=True, max_steps=400)
    fit = js.fit(js.augment(js.LowSpeedSwayYaw(), js.effects.RudderOffset()), train, estimator=est)
    sway_yaw = Identified("low-speed sway-yaw + offset", fit, _validate(
        fit.model, test, dataclasses.replace(est, channels=("psi", "r", "v")), (None,)))
    return RealDataReport("Esso Osaka FRT, zig-zag split with turns", (nomoto, sway_yaw),
                          tuple(e.name for e in train), tuple(e.name for e in test))


def _low_speed_nomoto(train, test) -> tuple[Identified, ...]:
    """The three fits of `esso_osaka_low_speed_steering`, each from the last."""
    base, free = _speed_scaled_nomoto(train)
    est = js.PredictionError(horizon=None, channels=("r",), max_steps=400)
    fit0 = js.fit(base, train, estimator=est, free=free)
    full = js.augment(fit0.model.base, *fit0.model.effects, js.effects.PropellerRace(),
                      js.effects.ApparentWind(), js.effects.YawQuadraticDamping())
    windy = dataclasses.replace(est, wind=True)
    terms = ("propeller_race.gain", "wind.c1", "wind.c2", "yaw_quadratic_damping.beta")
    fit1 = js.fit(full, train, estimator=windy, free=free + terms)
    fit2 = js.fit(fit1.model, train, estimator=windy, free=free + terms + (
        "speed_dependent_rudder.kappa", "speed_dependent_damping.kappa"))
    shown = lambda e: dataclasses.replace(e, channels=("psi", "r"))
    return (Identified("speed-scaled Nomoto 1 + offset", fit0,
                       _validate(fit0.model, test, shown(est), (None,))),
            Identified("+ race, wind, r|r|", fit1,
                       _validate(fit1.model, test, shown(windy), (None,))),
            Identified("+ speed exponents free", fit2,
                       _validate(fit2.model, test, shown(windy), (None,))))


def _speed_scaled_nomoto(train):
    """(the speed-scaled Nomoto 1 with a rudder offset, its free parameters) for the
    training runs' mean speed (`esso_osaka_low_speed_steering`)."""
    nominal = float(sum(e.u.sum() for e in train) / sum(e.u.size for e in train))
    base = js.augment(js.Nomoto1(K=0.3, T=10.0),
                      js.effects.SpeedDependentRudder(kappa=1.0, nominal_speed=nominal),
                      js.effects.SpeedDependentDamping(kappa=1.0, nominal_speed=nominal),
                      js.effects.RudderOffset())
    return base, ("K", "T", "rudder_offset.delta0")


def esso_osaka_low_speed_discovery(root=None, *, factor: int = 5, progress=None):
    """`jaxship.discover` from the speed-scaled Nomoto 1 with offset on the zig-zag
    split (`esso_osaka_zigzag_split`; zig-zag and turn held out): does it find the
    low-speed terms of `esso_osaka_low_speed_steering` by itself? Returns the
    `DiscoveryReport`."""
    train, test = esso_osaka_zigzag_split(root, factor=factor)
    base, free = _speed_scaled_nomoto(train)
    return js.discover(base, train, test, free=free, progress=progress)
