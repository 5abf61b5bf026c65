"""The Esso Osaka data owners' published splits and the free-simulation score
(issue 32; the data are needed only for the split check)."""

import jax
import numpy as np
import pytest

import jaxship as js
from benchmarks.studies.published_splits import (
    MIYAUCHI_2022,
    WAKITA_2022,
    free_run_score,
)
from benchmarks.studies.real_data import ESSO_TEST


DATA = js.shared_data_dir()
UPSTREAM = None if DATA is None else DATA / "esso_osaka_frt" / "UPSTREAM_README.md"
needs_esso = pytest.mark.skipif(UPSTREAM is None or not UPSTREAM.is_file(),
                                reason="Esso Osaka data (shared/data/esso_osaka_frt) absent")


def upstream_tables(text: str) -> dict:
    """`{paper: {set: [run stems]}}` from the "Correspondence table with the paper"
    of the upstream README (a circle marks a run in a set)."""
    section = text.split("## Correspondence table with the paper", 1)[1]
    tables = {}
    for block in section.split("\n- [")[1:]:
        paper = block.split("]", 1)[0]
        lines = block.splitlines()
        head = next(line for line in lines if line.startswith("| File path"))
        sets = [c.strip() for c in head.strip("|").split("|")][1:]
        tables[paper] = {s: [] for s in sets}
        for line in lines:
            if line.startswith("| `"):
                cells = [c.strip() for c in line.strip("|").split("|")]
                stem = cells[0].strip("`").rsplit("/", 1)[1].removesuffix(".csv")
                for s, mark in zip(sets, cells[1:]):
                    if "\u2b55" in mark:
                        tables[paper][s].append(stem)
    return tables


@needs_esso
def test_the_split_lists_are_the_upstream_readmes():
    tables = upstream_tables(UPSTREAM.read_text(encoding="utf-8"))
    assert set(tables) == {"Wakita (2022)", "Miyauchi (2022)"}
    wakita = {("Test" if k == "Test (TZRB)" else k): v
              for k, v in tables["Wakita (2022)"].items()}
    assert {k: list(v) for k, v in MIYAUCHI_2022.items()} == tables["Miyauchi (2022)"]
    assert {k: list(v) for k, v in WAKITA_2022.items()} == wakita
    # and the older study's held-out manoeuvres are Wakita's test set without berthing
    assert ESSO_TEST == tuple(r for r in WAKITA_2022["Test"] if not r.startswith("berthing"))
    for runs in (*MIYAUCHI_2022.values(), *WAKITA_2022.values()):
        for run in runs:
            assert list((DATA / "esso_osaka_frt").glob(f"*/{run}.csv")), run


def test_the_free_run_score_is_the_hand_computed_one():
    """A record that is a simulation of the vessel with known offsets added after its
    first sample: the free simulation from that sample reproduces the simulation, so
    every error is minus the offset (RMSE = |offset|, position error = the offsets'
    distance) and the fit % is the textbook formula on those errors."""
    jax.config.update("jax_enable_x64", True)
    vessel = js.get_vessel("esso_osaka")
    x0 = js.straight_run(vessel)  # the nominal straight run
    traj = js.simulate(vessel, js.ZigZag(20 * np.pi / 180, 20 * np.pi / 180, duration=20.0,
                                         dt=0.1), x0, simulator=js.Simulator(substeps=4))
    clean = js.Experiment.from_trajectory(traj, name="short")
    offset = {"u": 0.01, "v": -0.004, "r": 0.002, "psi": 0.03, "x": 0.3, "y": -0.4}
    shifted = {c: getattr(clean, c) + np.r_[0.0, np.full(clean.num_samples - 1, d)]
               for c, d in offset.items()}
    record = js.Experiment(clean.t, clean.delta, n=clean.n, name="short", **shifted)
    score, = free_run_score(vessel, [record], wind=False)
    for c in ("u", "v", "r", "psi"):
        assert score.rmse[c] == pytest.approx(abs(offset[c]), rel=2e-3), c
        y = getattr(record, c)[1:]
        error = np.full(y.size, -offset[c])
        by_hand = 100 * (1 - np.linalg.norm(error) / np.linalg.norm(y - y.mean()))
        assert score.fit_percent[c] == pytest.approx(by_hand, abs=0.2), c
    assert score.position_mean == pytest.approx(0.5, rel=2e-3)
    assert score.position_final == pytest.approx(0.5, rel=2e-3)
