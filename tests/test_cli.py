"""The `jaxship` command: listing, simulating to a folder, errors."""

import json

import numpy as np
import pytest

import jaxship as js
from jaxship.cli import main


def test_vessels_lists_every_preset_with_source(capsys):
    assert main(["vessels"]) == 0
    out = capsys.readouterr().out
    for name in js.VESSELS:
        assert name in out
    assert "Chislett" in out and "Yasukawa" in out


@pytest.mark.parametrize(
    "spec, keys",
    [
        ("zigzag:20/20", ["overshoot_1_deg", "overshoot_2_deg", "initial_turning_time_s"]),
        ("turn:-35", ["advance_m", "transfer_m", "tactical_diameter_m", "time_to_90_s"]),
    ],
)
def test_simulate_writes_csv_indices_and_figure(tmp_path, capsys, spec, keys):
    out = tmp_path / "run"
    code = main(["simulate", "--vessel", "mariner", "--manoeuvre", spec, "--out", str(out)])
    assert code == 0
    indices = json.loads((out / "indices.json").read_text())
    for key in keys:
        assert np.isfinite(indices[key])
    assert (out / "trial.png").stat().st_size > 10_000
    trial = js.read_trial_csv(out / "trial.csv")
    assert trial.t[0] == 0.0 and len(trial.t) > 100
    # the CSV is in display units and in the project's sign convention
    if spec.startswith("turn"):
        assert np.sign(trial.delta[-1]) == -1 and np.sign(trial.r[-1]) == -1  # port
        assert np.rad2deg(abs(trial.psi[-1] - trial.psi[0])) >= 540
        assert indices["tactical_diameter_m"] > 0


def test_mariner_zigzag_overshoots_match_reference(tmp_path):
    """MSS `mariner.m` 20/20 (vessel-models.md sec. 6, independent RK4): 7.78, 6.32 deg."""
    out = tmp_path / "zz"
    args = ["simulate", "--vessel", "mariner", "--manoeuvre", "zigzag:20/20", "--dt", "0.05"]
    assert main([*args, "--out", str(out)]) == 0
    indices = json.loads((out / "indices.json").read_text())
    np.testing.assert_allclose(indices["overshoot_1_deg"], 7.78, atol=0.02)
    np.testing.assert_allclose(indices["overshoot_2_deg"], 6.32, atol=0.02)


@pytest.mark.parametrize(
    "args, message",
    [
        (["--vessel", "nope", "--manoeuvre", "turn:35"], "Unknown vessel"),
        (["--vessel", "mariner", "--manoeuvre", "circle:35"], "Unknown manoeuvre"),
        (["--vessel", "mariner", "--manoeuvre", "zigzag:20"], "takes 2 value"),
        (["--vessel", "mariner", "--manoeuvre", "zigzag:20/-5"], "must be positive"),
        (["--vessel", "mariner", "--manoeuvre", "stop"], "no propeller"),
    ],
)
def test_bad_input_is_a_clear_error(tmp_path, capsys, args, message):
    assert main(["simulate", *args, "--out", str(tmp_path / "x")]) == 2
    assert message in capsys.readouterr().err


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"jaxship {js.__version__}"
