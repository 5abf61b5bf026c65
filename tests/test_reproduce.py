"""`jaxship reproduce --quick`: the thesis pipeline end to end on the built-in vessel."""

import json

import pytest

from jaxship.cli import main
from jaxship.studies.reproduce import reproduce


def test_quick_reproduce_writes_trials_and_matches_thesis_ranges(tmp_path):
    reproduce(tmp_path, quick=True, identification=False)
    summary = json.loads((tmp_path / "indices.json").read_text())
    assert set(summary) >= {"turn40_500rpm", "zigzag40-40_500rpm", "thesis_500rpm"}
    for name in summary:
        assert (tmp_path / "trials" / f"{name}.csv").stat().st_size > 0
    assert list((tmp_path / "figures").glob("*.png"))
    assert "| trial |" in (tmp_path / "summary.md").read_text()
    # thesis section 4.1 (figs. 4.3, 4.5, 4.7): 1.2-1.6 m/s at 500 rpm (fig. 4.7, with the
    # 45 deg step: from 0.8 m/s) and yaw rates of several deg/s, at most about 10 deg/s, at
    # 40-45 deg rudder. The lower speed bound was 1.1 m/s while the rudder stalled at 33 deg;
    # with the stall in the propeller race (docs/thesis_vessel.md sec. 16) the 40-45 deg
    # turns are harder and slow the ship to 1.05-1.10 m/s
    for name in ("turn40_500rpm", "zigzag40-40_500rpm", "thesis_500rpm"):
        traj = summary[name]
        assert 3.0 < traj["max_yaw_rate_deg_s"] < 10.5, (name, traj["max_yaw_rate_deg_s"])
        assert 0.9 < traj["min_speed_m_s"] and traj["max_speed_m_s"] < 1.7, name
    # the same rudder at 200 rpm turns on about the same circle, more slowly (the rudder
    # sits in the propeller race: both forces scale with speed squared)
    slow, fast = summary["turn40_200rpm"], summary["turn40_500rpm"]
    assert slow["max_yaw_rate_deg_s"] < 0.5 * fast["max_yaw_rate_deg_s"]
    assert abs(slow["tactical_diameter_m"] / fast["tactical_diameter_m"] - 1) < 0.2
    assert summary["zigzag40-40_500rpm"]["overshoot_1_deg"] > 0


@pytest.mark.slow
def test_quick_reproduce_command_identifies_the_steering_models(tmp_path, capsys):
    assert main(["reproduce", "--quick", "--out", str(tmp_path)]) == 0
    study = json.loads((tmp_path / "identification.json").read_text())
    rows = {(r["case"], r["model"], r["family"]): r for r in study["table"]}
    assert len(rows) == 18  # single / merged x three models x three families
    # the Ross model explains the single 40 deg / 500 rpm records better than Nomoto
    for family in ("turning", "zigzag", "thesis"):
        assert rows["single", "ross", family]["fit"] > rows["single", "nomoto", family]["fit"]
    assert "Steering models identified" in (tmp_path / "summary.md").read_text()
