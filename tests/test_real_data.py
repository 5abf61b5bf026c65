"""Identification on the measured data sets (skipped when `shared/data` is absent)."""

import numpy as np
import pytest

import jaxship as js
from jaxship.studies.real_data import (
    ESSO_TEST,
    esso_osaka_split,
    hsva_split,
    identify_kvlcc2_hsva,
)


DATA = js.shared_data_dir()
needs_esso = pytest.mark.skipif(DATA is None or not (DATA / "esso_osaka_frt").is_dir(),
                                reason="Esso Osaka data (shared/data/esso_osaka_frt) absent")
needs_hsva = pytest.mark.skipif(DATA is None or not (DATA / "kvlcc2_simman2008_hsva").is_dir(),
                                reason="HSVA KVLCC2 data (shared/data) absent")


def test_missing_data_folder_raises(tmp_path):
    with pytest.raises(FileNotFoundError, match="esso_osaka_frt"):
        esso_osaka_split(tmp_path)


@needs_esso
def test_esso_osaka_split():
    train, test = esso_osaka_split(factor=5)
    assert tuple(e.name for e in test) == ESSO_TEST
    assert len(train) == 8 and not {e.name for e in train} & set(ESSO_TEST)
    for e in train + test:
        assert e.is_uniform() and abs(e.dt - 0.5) < 1e-9
        assert {"u", "v", "n", "wind_speed", "wind_dir"} <= set(e.channels)


@needs_hsva
def test_hsva_nomoto_generalises_to_held_out_zigzags():
    """Nomoto 1 and 2 by output error on three HSVA zig-zags predict four others by
    simulation better than the mean (fit > 0) in yaw rate, and Nomoto 2 fits the
    training data at least as well as Nomoto 1 (it contains it). Nomoto 2's pole and zero
    T2 and T3 (about 1.5 and 1.7 s) nearly cancel: their robust (HAC) standard errors are
    about ten times their values, so that fit is poorly determined in them alone (issue 72)."""
    train, test = hsva_split()
    assert len(train) == 3 and len(test) == 4
    report = identify_kvlcc2_hsva()
    n1, n2 = report.models
    assert n1.result.success
    assert n2.result.result == js.RESULTS.poorly_determined
    assert [f.split(" ")[0] for f in n2.result.parameters.undetermined] == ["T2", "T3"]
    assert n2.result.cost <= n1.result.cost * (1 + 1e-6)
    for m in report.models:
        assert m.validation["simulation"].metrics["r"].fit_percent > 50.0
    assert "| Nomoto2 | simulation | all |" in report.table()


# Asserted by the notebooks that run them for their readers (`test_notebooks`), one run
# each, not two: the 3-DOF Esso Osaka fit against the preset on the held-out runs
# (`identify_esso_osaka`, notebooks/esso_osaka_identification.ipynb), and the three
# low-speed Esso Osaka studies on the zig-zag split (the terms fitted by hand, the
# low-speed sway-yaw model, and discover's joint search from the speed-scaled Nomoto 1;
# notebooks/discovery.ipynb).


@needs_hsva
def test_the_kvlcc2_drift_is_recovered_from_the_track_without_a_logged_v():
    """The six held-out KVLCC2 10/10 and 20/20 zig-zags (HSVA, MARIN) with their logged v
    removed: the MMG preset's EKF + RTS smoothed drift from psi, r, u and the track
    matches the logged v within 10 % of its spread (RMS difference 0.0004-0.0005 m/s
    on HSVA, whose v is derived from the track; 0.004 m/s on MARIN, v spreading
    0.08-0.13 m/s)."""
    from jaxship._analysis._discover._forces import smoothed_vessel_states
    from jaxship.studies.real_data import kvlcc2_discovery_split

    _, holdout = kvlcc2_discovery_split(DATA)
    records = [js.Experiment(e.t, e.delta, psi=e.psi, r=e.r, u=e.u, x=e.x, y=e.y, n=e.n,
                             name=e.name) for e in holdout]
    smoothed = smoothed_vessel_states(js.get_vessel("kvlcc2"), records)
    for s, e in zip(smoothed, holdout):
        assert np.sqrt(np.mean((s.state("v") - e.v) ** 2)) < 0.1 * np.std(e.v), e.name


@needs_esso
def test_discover_judges_measured_zigzags_of_one_ship():
    """Issue 72's `cannot_judge` on records jaxship did not simulate: the base Nomoto 1
    fitted, as `discover` fits it, to two measured Esso Osaka zig-zags describes both
    (psi and r fits over its 60 s windows 59-86 %, measured 2026-12-07), so
    `not_described` stays silent and the records are judged, not refused."""
    from jaxship._analysis._discover._workflow import FIT_SOLVER, not_described, too_short

    files = sorted((DATA / "esso_osaka_frt" / "zigzag").glob("*.csv"))[:2]
    records = [js.read_measured(p).decimate(5) for p in files]
    records = [js.Experiment(e.t, e.delta, psi=e.psi, r=e.r, name=e.name) for e in records]
    estimator = js.PredictionError(horizon=60.0, initial=js.EstimatedStarts(),
                                   solver=FIT_SOLVER)
    base = js.fit(js.identify("nomoto1", records).model, records, estimator=estimator)
    fits = [float(f) for c in ("psi", "r") for f in base.metrics[c].fit_per_experiment]
    assert min(fits) > 40.0, fits
    assert not_described(base, [e.name for e in records]) == ""
    assert too_short(js.Dataset.from_experiments(records), 60.0) == ""
