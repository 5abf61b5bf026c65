"""The Esso Osaka data owners' published splits, and the score their readers know.

The data set's upstream README (`esso_osaka_frt/UPSTREAM_README.md`, "Correspondence
table with the paper") fixes the training and test runs of two papers by the lab that
recorded it (Osaka University):

- Miyauchi et al. 2022, J. Mar. Sci. Technol. 27:1065-1083 (low-speed MMG explored with
  CMA-ES): `MIYAUCHI_2022`;
- Wakita et al. 2022, J. Mar. Sci. Technol. 27:772-785 (recurrent neural network):
  `WAKITA_2022`.

Each is `{set name: run names}` (file stems), the test set under `"Test"`;
`tests/test_published_splits.py` checks them against the upstream table. The score
(`free_run_score`) is that of a free simulation of each test run from its first
measured state, replaying the logged rudder angle, propeller rate and true wind: RMSE
of u, v, r and psi, mean and final distance between the simulated and measured
positions, and fit % per channel. `lab_as_published` is the lab's simulator: the
`esso_osaka` preset (the lab's coefficients) with the lab's wind loads.
"""

import dataclasses
from pathlib import Path

import equinox as eqx
import numpy as np

import jaxship as js


MIYAUCHI_2022 = {
    "Train-R": ("random_06-Aug-2020_16_24_25_1", "random_06-Aug-2020_16_24_25_4",
                "random_06-Aug-2020_16_24_25_5", "random_06-Aug-2020_16_24_25_6"),
    "Train-TR": ("random_06-Aug-2020_16_24_25_4", "random_06-Aug-2020_16_24_25_5",
                 "random_06-Aug-2020_16_24_25_6", "turn_cut_14-Sep-2020_15_58_08",
                 "turn_cut_14-Sep-2020_16_09_02"),
    "Train-TRZ": ("random_06-Aug-2020_16_24_25_4", "random_06-Aug-2020_16_24_25_5",
                  "random_06-Aug-2020_16_24_25_6", "turn_cut_14-Sep-2020_16_09_02",
                  "zigzag_31-Jul-2020_13_22_52", "zigzag_31-Jul-2020_13_50_28"),
    "Test": ("random_06-Aug-2020_16_24_25_3", "turn_14-Sep-2020_14_50_41",
             "zigzag_31-Jul-2020_14_10_05", "berthing_12-Nov-2020_11_49_21",
             "berthing_12-Nov-2020_13_21_03"),
}

WAKITA_2022 = {
    "Train-TZB": ("turn_14-Sep-2020_13_39_32", "turn_14-Sep-2020_14_16_04",
                  "turn_14-Sep-2020_15_58_08", "turn_cut_14-Sep-2020_16_09_02",
                  "zigzag_31-Jul-2020_13_22_52", "zigzag_31-Jul-2020_13_29_19",
                  "zigzag_31-Jul-2020_13_50_28", "zigzag_31-Jul-2020_13_57_45",
                  "zigzag_31-Jul-2020_14_03_39", "berthing_12-Nov-2020_11_14_47",
                  "berthing_12-Nov-2020_13_37_05"),
    "Train-TZRB": ("random_06-Aug-2020_16_24_25_4", "random_06-Aug-2020_16_24_25_6",
                   "turn_cut_14-Sep-2020_15_58_08", "turn_cut_14-Sep-2020_16_09_02",
                   "zigzag_31-Jul-2020_13_22_52", "zigzag_31-Jul-2020_13_50_28",
                   "berthing_12-Nov-2020_11_14_47", "berthing_12-Nov-2020_13_37_05"),
    "Train-TZRB+": (
        "random_03-Aug-2020_11_04_37", "random_06-Aug-2020_16_24_25_1",
        "random_06-Aug-2020_16_24_25_4", "random_06-Aug-2020_16_24_25_5",
        "random_06-Aug-2020_16_24_25_6", "random_31-Jul-2020_12_29_58",
        "random_31-Jul-2020_12_48_39", "random_31-Jul-2020_14_52_18",
        "turn_14-Oct-2020_14_08_51", "turn_14-Oct-2020_14_17_39", "turn_14-Oct-2020_14_29_49",
        "turn_14-Oct-2020_14_39_54", "turn_14-Oct-2020_14_56_07", "turn_14-Oct-2020_15_21_57",
        "turn_14-Sep-2020_13_39_32", "turn_14-Sep-2020_13_51_45", "turn_14-Sep-2020_14_16_04",
        "turn_14-Sep-2020_14_50_41", "turn_14-Sep-2020_15_47_33", "turn_14-Sep-2020_15_58_08",
        "turn_cut_14-Sep-2020_15_58_08", "turn_cut_14-Sep-2020_16_09_02",
        "zigzag_31-Jul-2020_13_04_24", "zigzag_31-Jul-2020_13_14_21",
        "zigzag_31-Jul-2020_13_22_52", "zigzag_31-Jul-2020_13_29_19",
        "zigzag_31-Jul-2020_13_50_28", "zigzag_31-Jul-2020_13_57_45",
        "zigzag_31-Jul-2020_14_03_39", "zigzag_31-Jul-2020_14_10_05",
        "berthing_12-Nov-2020_11_07_23", "berthing_12-Nov-2020_11_14_47",
        "berthing_12-Nov-2020_11_21_46", "berthing_12-Nov-2020_13_09_11",
        "berthing_12-Nov-2020_13_37_05"),
    "Test": ("random_06-Aug-2020_16_24_25_3", "turn_14-Oct-2020_15_06_53",
             "zigzag_31-Jul-2020_13_42_53", "berthing_12-Nov-2020_11_38_50",
             "berthing_12-Nov-2020_11_49_21", "berthing_12-Nov-2020_13_21_03"),
}

SPLITS = {"Miyauchi 2022": MIYAUCHI_2022, "Wakita 2022": WAKITA_2022}
SCORED = ("u", "v", "r", "psi")


def lab_as_published() -> js.AbstractVessel:
    """The lab's simulator as published (GitHub NAOE-5thLab/mmg-1p1r-simulator): the
    `esso_osaka` preset, the lab's coefficients, with its wind loads, Fujiwara et al.'s
    (1998) regression for the lab's geometry (`jaxship.wind_loads.FujiwaraWindLoads.esso_osaka()`)
    instead of jaxship's generic `FossenWindLoads`."""
    return eqx.tree_at(lambda v: v.wind_model, js.get_vessel("esso_osaka"),
                       js.wind_loads.FujiwaraWindLoads.esso_osaka())


def read_runs(names, root=None) -> list[js.Experiment]:
    """The Esso Osaka runs `names` (file stems) at their logged 10 Hz, from `root`
    (default `jaxship.shared_data_dir()`)."""
    base = js.shared_data_dir() if root is None else Path(root)
    folder = None if base is None else base / "esso_osaka_frt"
    if folder is None or not folder.is_dir():
        raise FileNotFoundError(f"the Esso Osaka data (esso_osaka_frt) is not under {base}; "
                                "set $JAXSHIP_DATA or pass `root`.")
    runs = []
    for name in names:
        found = sorted(folder.glob(f"*/{name}.csv"))
        if not found:
            raise FileNotFoundError(f"run {name}.csv not found under {folder}.")
        runs.append(js.read_measured(found[0]))
    return runs


@dataclasses.dataclass(frozen=True)
class RunScore:
    """A free simulation of one run against the measurement: `rmse` `{channel: value}`
    (u, v [m/s], r [rad/s], psi [rad]), `position_mean` and `position_final` [m] (the
    distance between simulated and measured positions, averaged over the run and at its
    last sample) and `fit_percent` `{channel: %}`."""

    run: str
    rmse: dict
    position_mean: float
    position_final: float
    fit_percent: dict


def free_run(model, run, *, wind: bool = True) -> dict:
    """A free simulation of `run` from its first measured state (u, v, r, psi and
    position), replaying the logged rudder angle, propeller rate and (with `wind`, where
    the model feels it) true wind, at the run's own samples: `{channel: values}` for u,
    v, r, psi, x and y at the samples the simulation reaches (all but the first), `"t"`
    their times and `"hit"` the run's samples they are (a boolean mask)."""
    channels = SCORED + ("x", "y")
    estimator = js.PredictionError(horizon=None, channels=channels,
                                   wind=bool(wind and model.wind_loads))
    pred = js.predict(model, [run], estimator=estimator)
    hit = pred.predicted[0, :run.num_samples]
    out = {c: pred.predictions[c][0, :run.num_samples][hit] for c in channels}
    return {"hit": hit, "t": run.t[hit], **out}


def run_score(run, sim) -> RunScore:
    """The score of `sim` (a `free_run` of `run`): RMSE of u, v, r and psi, mean and
    final position error, and fit % per channel (`jaxship.fit_percent`)."""
    hit = sim["hit"]
    error = {c: sim[c] - getattr(run, c)[hit] for c in SCORED + ("x", "y")}
    distance = np.hypot(error["x"], error["y"])
    return RunScore(
        run=run.name, rmse={c: float(np.sqrt(np.mean(error[c] ** 2))) for c in SCORED},
        position_mean=float(np.mean(distance)), position_final=float(distance[-1]),
        fit_percent={c: js.fit_percent(getattr(run, c)[hit], sim[c]) for c in SCORED})


def free_run_score(model, runs, *, wind: bool = True) -> list[RunScore]:
    """Score `model` on each of `runs` by its `free_run` (`run_score`)."""
    return [run_score(run, free_run(model, run, wind=wind)) for run in runs]
