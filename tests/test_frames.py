"""pandas DataFrames of trajectories and fit results (`jaxship._foundation._frames`)."""

import builtins
import warnings

import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship._foundation._frames import Z95, fit_to_dataframe, trajectory_to_dataframe


pd = pytest.importorskip("pandas")


@pytest.fixture(scope="module")
def zigzag():
    vessel = js.get_vessel("mariner")
    x0 = js.straight_run(vessel)
    manoeuvre = js.ZigZag(np.deg2rad(10.0), np.deg2rad(10.0), duration=120.0, dt=1.0)
    return js.simulate(vessel, manoeuvre, x0)


def test_trajectory_frame_has_one_row_per_valid_sample(zigzag):
    frame = trajectory_to_dataframe(zigzag)
    assert tuple(frame.columns) == ("t", "u", "v", "r", "x", "y", "psi", "delta", "n",
                                    "delta_c", "n_c")
    valid = np.asarray(zigzag.valid, dtype=bool)
    assert len(frame) == int(valid.sum())
    np.testing.assert_array_equal(frame["t"], np.asarray(zigzag.t)[valid])
    np.testing.assert_array_equal(frame["r"], np.asarray(zigzag.state.r)[valid])
    np.testing.assert_array_equal(frame["delta_c"], np.asarray(zigzag.command.delta)[valid])
    # the zig-zag command reverses: both signs of the commanded rudder appear
    assert frame["delta_c"].max() > 0 > frame["delta_c"].min()


def test_trajectory_frame_drops_padding():
    vessel = js.get_vessel("mariner")
    x0 = js.straight_run(vessel)
    padded = js.Turn(np.deg2rad(10.0), duration=20.0, dt=1.0, num_samples=41)
    traj = js.simulate(vessel, padded, x0)
    frame = trajectory_to_dataframe(traj)
    assert np.asarray(traj.t).size == 41 and len(frame) == 21
    assert frame["t"].max() == pytest.approx(20.0)


def test_batched_trajectory_is_refused():
    vessel = js.get_vessel("mariner")
    x0 = js.straight_run(vessel)
    turns = [js.Turn(np.deg2rad(a), duration=10.0, dt=1.0) for a in (5.0, 10.0)]
    batch = js.simulate_batch(vessel, js.stack(turns), x0)
    with pytest.raises(ValueError, match="index one run first"):
        trajectory_to_dataframe(batch)


def test_fit_frame_has_one_row_per_free_parameter():
    model = js.Nomoto1(K=0.1, T=20.0)
    delta = np.deg2rad(10.0) * np.sign(np.sin(2 * np.pi * np.arange(400) / 120.0) + 1e-9)
    sim = js.simulate(model, js.Replay(delta, dt=0.5, delta_hold=js.strategies.FirstOrderHold()),
                      simulator=per_sample())  # a logged rudder angle
    rng = np.random.default_rng(0)
    data = js.Experiment(0.5 * np.arange(400), delta, psi=np.asarray(sim.state.psi),
                         r=np.asarray(sim.state.r) + 1e-4 * rng.standard_normal(400))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = js.fit(js.Nomoto1(K=0.05, T=10.0), data,
                        estimator=js.PredictionError(horizon=None, channels=("r",)))
    frame = fit_to_dataframe(result)
    assert list(frame["name"]) == list(result.names) == ["K", "T"]
    assert list(frame["unit"]) == ["1/s", "s"]
    np.testing.assert_allclose(frame["value"], result.values)
    np.testing.assert_allclose(frame["std"], result.std)
    np.testing.assert_allclose(frame["upper_95"] - frame["lower_95"], 2 * Z95 * result.std)
    assert np.all((frame["lower_95"] < frame["value"]) & (frame["value"] < frame["upper_95"]))
    # noisy yaw rate: the estimates within three of their standard errors of the truth
    assert np.all(np.abs(frame["value"].to_numpy() - [0.1, 20.0]) < 3 * frame["std"].to_numpy())


def test_missing_pandas_says_how_to_install(zigzag, monkeypatch):
    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas":
            raise ImportError("No module named 'pandas'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    with pytest.raises(ImportError, match="pip install pandas"):
        trajectory_to_dataframe(zigzag)
