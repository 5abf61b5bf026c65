"""Identification on the measured data sets (skipped when `shared/data` is absent)."""

import numpy as np
import pytest

import jaxship as js
from benchmarks.studies.real_data import (
    ESSO_TEST,
    esso_osaka_low_speed_discovery,
    esso_osaka_low_speed_steering,
    esso_osaka_low_speed_sway_yaw,
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
    training data at least as well as Nomoto 1 (it contains it)."""
    train, test = hsva_split()
    assert len(train) == 3 and len(test) == 4
    report = identify_kvlcc2_hsva()
    n1, n2 = report.models
    assert n1.result.success and n2.result.success
    assert n2.result.cost <= n1.result.cost * (1 + 1e-6)
    for m in report.models:
        assert m.validation["simulation"].metrics["r"].fit_percent > 50.0
    assert "| Nomoto2 | simulation | all |" in report.table()


# The 3-DOF Esso Osaka fit against the preset on the held-out runs (`identify_esso_osaka`)
# is asserted by notebooks/esso_osaka_identification.ipynb, which runs that fit for its
# readers (`test_notebooks`): one run, not two.


@needs_esso
def test_esso_osaka_low_speed_terms_beat_the_speed_scaled_nomoto_on_held_out_runs():
    """On the zig-zag split (eight zig-zags to train, zig-zag 13_42_53 and turn 15_06_53
    held out), the propeller race, the logged wind and r|r| added together to the
    speed-scaled Nomoto 1 with offset raise the simulated held-out r on both runs, and
    on the zig-zag clear the 62.4 % of the issue's SciPy anchor (the same base model)
    by 10 points; with the speed exponents free too, the zig-zag's r passes the issue's
    85 % goal. Measured: zig-zag 58.4 -> 78.5 -> 87.3 %, turn 29.6 -> 63.5 -> 61.4 %.
    The two larger models are not converged estimates: their rudder offset ends on its
    -0.1 rad bound (the result code `at_bound`, which a fit once called a success)."""
    report = esso_osaka_low_speed_steering()
    base, full, kappas = (m.validation["simulation"].fit_per_experiment()
                          for m in report.models)
    assert report.models[0].result.success
    for model in report.models[1:]:
        assert model.result.code == js.RESULTS.at_bound
        assert model.result.parameters.bound_flags[0].startswith(
            "rudder_offset.delta0 = -0.1 rad ended on its lower bound")
    for run in ("zigzag_31-Jul-2020_13_42_53", "turn_14-Oct-2020_15_06_53"):
        assert full[run]["r"] > base[run]["r"] + 10.0, (run, base[run], full[run])
        assert kappas[run]["r"] > base[run]["r"] + 10.0, (run, base[run], kappas[run])
    assert full["zigzag_31-Jul-2020_13_42_53"]["r"] > 62.4 + 10.0
    assert kappas["zigzag_31-Jul-2020_13_42_53"]["r"] > 85.0


@needs_esso
def test_esso_osaka_low_speed_sway_yaw_follows_the_held_out_turn():
    """Trained on the eight zig-zags and 13 turns, the low-speed sway-yaw model with a
    rudder offset (fitted on r and v) predicts the held-out turn's r 10 points better
    than the richest speed-scaled Nomoto 1 on the same runs, keeps r above 75 % on
    both held-out runs and predicts their drift v above 60 %; every coefficient lies
    two robust standard errors from zero. Measured: zig-zag r 80.0 (Nomoto 84.7), turn
    r 76.7 (Nomoto 63.6), v 70.8 and 67.9 %."""
    report = esso_osaka_low_speed_sway_yaw()
    nomoto, sway_yaw = (m.validation["simulation"].fit_per_experiment()
                        for m in report.models)
    turn = "turn_14-Oct-2020_15_06_53"
    assert sway_yaw[turn]["r"] > nomoto[turn]["r"] + 10.0, (nomoto, sway_yaw)
    for run, fits in sway_yaw.items():
        assert fits["r"] > 75.0 and fits["v"] > 60.0, (run, fits)
    result = report.models[1].result
    assert result.success
    assert np.all(np.abs(result.values) > 2 * result.parameters.std_robust), result.names


@needs_esso
def test_discover_finds_the_esso_osaka_low_speed_terms_only_together():
    """From the speed-scaled Nomoto 1 with offset on the zig-zag split, no single
    candidate passes (wind scores 15.6 against 16.5), but the joint step's forward
    search picks exactly the propeller race, the wind and r|r|, whose refit cuts the
    held-out cost by three quarters (168.9 -> 40.6). Each one's robust interval
    includes zero (race 0.0045 +- 0.0059), and the refit pins the base's rudder offset
    at its -0.1 rad bound (T 7 -> 59 s), so the verdict stays "nothing missing": on
    these eight zig-zags the three cannot be told apart one by one."""
    report = esso_osaka_low_speed_discovery()
    joint = [r for r in report.rejected if "+" in r.id]
    assert [set(r.id.split("+")) for r in joint] == [
        {"propeller_race", "wind", "yaw_quadratic_damping"}]
    assert joint[0].holdout_cost < 0.5 * report.holdout_cost_before
    assert report.verdict == "nothing_missing"
    why = joint[0].why
    assert [w for w in why if "confidence interval" in w] == [
        f"the confidence interval of {k} includes zero"
        for k in ("propeller_race", "wind", "yaw_quadratic_damping")]
    assert "at or beyond the edge of the plausible range: rudder_offset.delta0" in why


@needs_hsva
def test_the_kvlcc2_drift_is_recovered_from_the_track_without_a_logged_v():
    """The six held-out KVLCC2 10/10 and 20/20 zig-zags (HSVA, MARIN) with their logged v
    removed: the MMG preset's EKF + RTS smoothed drift from psi, r, u and the track
    matches the logged v within 10 % of its spread (RMS difference 0.0004-0.0005 m/s
    on HSVA, whose v is derived from the track; 0.004 m/s on MARIN, v spreading
    0.08-0.13 m/s)."""
    from benchmarks.studies.real_data import kvlcc2_discovery_split
    from jaxship._analysis._discover._forces import smoothed_vessel_states

    _, holdout = kvlcc2_discovery_split(DATA)
    records = [js.Experiment(e.t, e.delta, psi=e.psi, r=e.r, u=e.u, x=e.x, y=e.y, n=e.n,
                             name=e.name) for e in holdout]
    smoothed = smoothed_vessel_states(js.vessel("kvlcc2"), records)
    for s, e in zip(smoothed, holdout):
        assert np.sqrt(np.mean((s.state("v") - e.v) ** 2)) < 0.1 * np.std(e.v), e.name
