"""Trial CSV format, Experiment/Dataset containers and the measured-data readers."""

import jax
import numpy as np
import pytest
from helpers import linear_test_vessel

import jaxship as js
from jaxship import (
    Dataset,
    Experiment,
    read_measured,
    read_trial_csv,
    shared_data_dir,
    write_trial_csv,
)
from jaxship._simulation._data import CHANNELS
from jaxship._simulation._measured import read_esso_osaka, read_hsva_kvlcc2, read_marin_kvlcc2
from jaxship.identification import read_experiments


def synthetic_experiment(num=201, dt=0.1, t0=5.0):
    """Smooth trajectory-like signals in every channel (SI)."""
    t = t0 + dt * np.arange(num)
    s = t - t0
    rng = np.random.default_rng(0)
    return Experiment(
        t, np.deg2rad(20) * np.sin(0.2 * s), psi=0.3 * np.sin(0.05 * s) + 0.01 * s,
        r=0.015 * np.cos(0.05 * s) + 0.01, u=7.5 + 0.1 * np.cos(0.03 * s),
        v=-0.2 * np.sin(0.1 * s), x=7.5 * s + rng.normal(0, 1e-3, num), y=0.3 * s**1.5,
        n=1.5 + 0.01 * np.sin(s), delta_c=np.deg2rad(20) * np.sign(np.sin(0.2 * s) + 1e-9),
        wind_speed=5.0 + 0.1 * np.sin(s), wind_dir=np.deg2rad(135.0) + 0.01 * s,
        name="synthetic",
    )


def assert_channels_equal(a: Experiment, b: Experiment, rtol=1e-12):
    assert a.channels == b.channels
    for key in CHANNELS:
        x, y = getattr(a, key), getattr(b, key)
        scale = np.max(np.abs(x)) + 1e-300
        np.testing.assert_allclose(y, x, rtol=0, atol=rtol * scale, err_msg=key)


# --- trial CSV round trip ------------------------------------------------------------------


@pytest.mark.parametrize("units", [js.strategies.DisplayUnits(), js.strategies.SIUnits()],
                         ids=["display", "si"])
def test_round_trip_all_channels(tmp_path, units):
    exp = synthetic_experiment()
    path = tmp_path / "trial.csv"
    write_trial_csv(path, exp, units=units)
    header = path.read_text().splitlines()[0]
    if units == js.strategies.DisplayUnits():
        assert "psi [deg]" in header and "r [deg/s]" in header and "n [rpm]" in header
    else:
        assert "psi [rad]" in header and "r [rad/s]" in header and "n [rps]" in header
    back = read_trial_csv(path, require_uniform=True)
    assert back.name == "trial"
    assert back.derived == ()
    assert_channels_equal(exp, back)
    # writing the read-back again gives the same file (SI) or values (display)
    again = tmp_path / "again.csv"
    write_trial_csv(again, back, units=units)
    assert_channels_equal(exp, read_trial_csv(again))


def test_round_trip_keeps_derived_channels_derived(tmp_path):
    t = np.arange(50) * 0.2
    exp = Experiment(t, 0.1 * np.ones(50), r=0.02 + 0.001 * t, name="rate only")
    assert exp.channels == ("delta", "r")
    assert exp.derived == ("psi",)
    # cumulative trapezoid of a linear r is exact
    np.testing.assert_allclose(exp.psi, 0.02 * t + 0.0005 * t**2, rtol=0, atol=1e-14)
    path = tmp_path / "rate.csv"
    write_trial_csv(path, exp)
    assert path.read_text().splitlines()[0] == "t [s],delta [deg],r [deg/s]"
    back = read_trial_csv(path)
    assert back.derived == ("psi",)
    assert_channels_equal(exp, back)


def test_r_from_psi_by_differencing():
    t = np.arange(0.0, 100.0, 0.1)
    exp = Experiment(t, np.zeros_like(t), psi=np.sin(0.1 * t))
    assert exp.derived == ("r",) and not exp.has("r")
    # central differences: error 0.1^3 * dt^2 / 6 inside, first order at the two ends
    np.testing.assert_allclose(exp.r[1:-1], 0.1 * np.cos(0.1 * t[1:-1]), atol=2e-6)
    np.testing.assert_allclose(exp.r[[0, -1]], 0.1 * np.cos(0.1 * t[[0, -1]]), atol=1e-3)
    assert not exp.has("u") and np.all(exp.u == 0.0)


@pytest.fixture(scope="module")
def turn():
    """A starboard turn of the linear test vessel, started at t0 = 100 s."""
    vessel = linear_test_vessel()
    x0 = js.straight_run(vessel)
    manoeuvre = js.Turn(np.deg2rad(20.0), duration=60.0, dt=0.5, execute=2.0, start=100.0)
    trajectory = js.simulate(vessel, manoeuvre, x0)
    assert bool(trajectory.success)
    return vessel, trajectory


def test_write_trajectory_round_trip(turn, tmp_path):
    _, trajectory = turn
    path = tmp_path / "sim.csv"
    write_trial_csv(path, trajectory)
    assert path.read_text().splitlines()[0] == (
        "t [s],delta [deg],delta_c [deg],psi [deg],r [deg/s],u [m/s],v [m/s],x [m],y [m],n [rpm]"
    )
    back = read_trial_csv(path, require_uniform=True)
    np.testing.assert_allclose(back.t, trajectory.t, rtol=1e-15)
    np.testing.assert_allclose(back.delta_c, trajectory.command.delta, rtol=1e-12)
    for key in ("delta", "psi", "r", "u", "v", "x", "y", "n"):
        np.testing.assert_allclose(getattr(back, key), getattr(trajectory.state, key),
                                   rtol=1e-12, atol=1e-300, err_msg=key)
    assert back.psi[-1] > np.deg2rad(30.0)  # it did turn to starboard


def test_batched_trajectory_is_rejected(turn, tmp_path):
    _, trajectory = turn
    batched = jax.tree.map(lambda a: np.stack([a, a]), trajectory)
    with pytest.raises(ValueError, match="batched"):
        write_trial_csv(tmp_path / "x.csv", batched)


def test_replay_reproduces_the_simulation(turn):
    """Open-loop replay of the recorded commands from the recorded initial state gives
    back the same trajectory (the t0/start offset included)."""
    vessel, trajectory = turn
    exp = Experiment.from_trajectory(trajectory)
    replay = exp.replay(rudder="delta_c")
    assert replay.num_samples == exp.num_samples and replay.start == 100.0
    assert replay.dt == pytest.approx(0.5, rel=1e-14)
    again = js.simulate(vessel, replay, exp.initial_state())
    for key in ("psi", "r", "u", "v", "x", "y", "delta"):
        np.testing.assert_allclose(getattr(again.state, key), getattr(trajectory.state, key),
                                   rtol=1e-10, atol=1e-10, err_msg=key)


def test_initial_state_defaults():
    t = np.arange(10) * 0.5
    exp = Experiment(t, np.full(10, 0.1), psi=0.02 * t + 1.0, name="no speed")
    with pytest.raises(ValueError, match="'no speed'.*default_u"):
        exp.initial_state()
    x0 = exp.initial_state(default_u=3.0, default_n=2.0)
    assert float(x0.u) == 3.0 and float(x0.n) == 2.0 and float(x0.v) == 0.0
    assert float(x0.psi) == 1.0 and float(x0.delta) == pytest.approx(0.1)
    assert float(x0.r) == pytest.approx(0.02, rel=1e-12)  # from d(psi)/dt
    with pytest.raises(ValueError, match="no measured 'delta_c'"):
        exp.replay(rudder="delta_c")
    assert np.all(np.asarray(exp.replay(n=1.25).n_record) == 1.25)
    uneven = Experiment(np.array([0.0, 0.1, 0.3]), np.zeros(3), psi=np.zeros(3))
    with pytest.raises(ValueError, match="not uniformly sampled"):
        uneven.replay()


def test_experiment_validation():
    with pytest.raises(ValueError, match="heading `psi` or a yaw rate `r`"):
        Experiment(np.arange(3.0), np.zeros(3))
    with pytest.raises(ValueError, match="channel 'r' has 2 samples"):
        Experiment(np.arange(3.0), np.zeros(3), r=np.zeros(2))
    with pytest.raises(ValueError, match="channel 'delta' sample 1 is nan"):
        Experiment(np.arange(3.0), np.array([0.0, np.nan, 0.0]), r=np.zeros(3))
    with pytest.raises(ValueError, match=r"t\[2\] = 1.0 s follows t\[1\] = 1.0 s"):
        Experiment(np.array([0.0, 1.0, 1.0]), np.zeros(3), r=np.zeros(3))


# --- errors name the file, the column and the row --------------------------------------

GOOD = "t [s],delta [deg],psi [deg]\n0.0,0.0,0.0\n0.1,1.0,0.1\n0.2,2.0,0.3\n"

ERROR_CASES = {
    "missing delta": (
        "t [s],psi [deg]\n0,0\n0.1,0\n",
        r"bad\.csv: header row \(line 1\): missing required column 'delta'",
    ),
    "missing psi and r": (
        "t [s],delta [deg]\n0,0\n0.1,0\n",
        r"bad\.csv: header row \(line 1\): missing required column 'psi' or 'r'",
    ),
    "unknown unit": (
        "t [s],delta [grad],psi [deg]\n0,0,0\n0.1,0,0\n",
        r"bad\.csv: column 'delta \[grad\]' \(header row, line 1\): unknown unit 'grad'",
    ),
    "unknown column": (
        "t [s],delta [deg],psi [deg],foo [m]\n0,0,0,1\n0.1,0,0,2\n",
        r"bad\.csv: column 'foo \[m\]' \(header row, line 1\): unknown column name 'foo'",
    ),
    "duplicate column": (
        "t [s],delta [deg],psi [deg],psi [rad]\n0,0,0,0\n0.1,0,0,0\n",
        r"bad\.csv: column 'psi \[rad\]' \(header row, line 1\): column 'psi' appears twice",
    ),
    "unclosed quote": (  # the message was the rest of the file, newlines and all
        't [s],"delta [deg],psi [deg]\n0,1,2\n1,2,3\n',
        r"bad\.csv: header row \(line 1\): the quote opened in column 'delta \[deg\],psi "
        r"\[deg\]' is never closed, so the header runs on over 3 lines\.$",
    ),
    "header without unit": (
        "t,delta [deg],psi [deg]\n0,0,0\n0.1,0,0\n",
        r"bad\.csv: column 't' \(header row, line 1\): a header must read 'name \[unit\]'",
    ),
    "nan": (
        "t [s],delta [deg],psi [deg]\n0.0,0,0\n0.1,nan,0\n0.2,0,0\n",
        r"bad\.csv: column 'delta \[deg\]', row 2 \(line 3\): value 'nan' is not finite",
    ),
    "infinite": (
        "t [s],delta [deg],psi [deg]\n0.0,0,0\n0.1,0,0\n0.2,0,-inf\n",
        r"bad\.csv: column 'psi \[deg\]', row 3 \(line 4\): value '-inf' is not finite",
    ),
    "empty cell": (
        "t [s],delta [deg],psi [deg]\n0.0,0,0\n0.1,,0\n0.2,0,0\n",
        r"bad\.csv: column 'delta \[deg\]', row 2 \(line 3\): empty value",
    ),
    "text": (
        "t [s],delta [deg],psi [deg]\n0.0,0,0\n0.1,abc,0\n",
        r"bad\.csv: column 'delta \[deg\]', row 2 \(line 3\): cannot read 'abc' as a number",
    ),
    "field count": (
        "t [s],delta [deg],psi [deg]\n0.0,0,0\n0.1,0\n",
        r"bad\.csv: row 2 \(line 3\) has 2 fields but the header has 3 columns",
    ),
    # the trust audit: degrees labelled rad gave K 57 times too small, with exit 0
    "rudder in degrees labelled rad": (
        "t [s],delta [rad],psi [rad]\n0.0,0,0\n0.5,20,0.01\n",
        r"bad\.csv: column 'delta \[rad\]', row 2 \(line 3\): 1146 deg is beyond the rudder "
        r"angle of any ship \(at most 90 deg\); is the column in deg rather than rad\?",
    ),
    "yaw rate in degrees labelled rad/s": (
        "t [s],delta [deg],r [rad/s]\n0.0,0,0\n0.5,20,1.5\n",
        r"column 'r \[rad/s\]', row 2 \(line 3\): 85\.94 deg/s is beyond the yaw rate.*"
        r"in deg/s rather than rad/s",
    ),
    "propeller rate in rpm labelled rps": (
        "t [s],delta [deg],psi [deg],n [rps]\n0.0,0,0,120\n0.5,20,1,120\n",
        r"column 'n \[rps\]', row 1 \(line 2\): 7200 rpm is beyond the propeller rate.*rpm "
        r"rather than rps",
    ),
    "speed in knots or km/h": (
        "t [s],delta [deg],psi [deg],u [m/s]\n0.0,0,0,72\n0.5,20,1,72\n",
        r"column 'u \[m/s\]', row 1 \(line 2\): 72 m/s is beyond the speed.*check the "
        r"column's unit",
    ),
    "time not increasing": (
        "t [s],delta [deg],psi [deg]\n0.0,0,0\n0.1,0,0\n0.1,0,0\n0.2,0,0\n",
        r"bad\.csv: column 't \[s\]', row 3 \(line 4\): time 0\.1 is not greater",
    ),
}


@pytest.mark.parametrize("case", sorted(ERROR_CASES))
def test_errors_name_file_column_and_row(tmp_path, case):
    text, message = ERROR_CASES[case]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        read_trial_csv(path)


def test_non_uniform_sampling(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("t [s],delta [deg],psi [deg]\n0,0,0\n0.1,0,0\n0.2,0,0\n0.4,0,0\n0.5,0,0\n")
    assert read_trial_csv(path).num_samples == 5  # fine unless uniformity is required
    with pytest.raises(ValueError, match=r"bad\.csv: column 't \[s\]', row 4 \(line 5\): "
                                         r"sampling interval 0\.2.*require_uniform=True"):
        read_trial_csv(path, require_uniform=True)


def test_unknown_columns_allowed_and_trailing_empty_rows(tmp_path):
    path = tmp_path / "extra.csv"
    path.write_text("t [s],delta [deg],psi [deg],depth [m]\n0,1,0,20\n0.1,2,0,21\n\n,,,\n,,,\n")
    exp = read_trial_csv(path, allow_unknown=True)
    assert exp.num_samples == 2 and exp.channels == ("delta", "psi")
    np.testing.assert_array_equal(exp.extra["depth"], [20.0, 21.0])
    np.testing.assert_allclose(exp.delta, np.deg2rad([1.0, 2.0]), rtol=1e-15)


def test_units_are_converted(tmp_path):
    path = tmp_path / "units.csv"
    path.write_text("n [rpm],t [s],r [rad/s],delta [rad],wind_dir [deg]\n"
                    "90,0,0.01,0.1,180\n120,1,0.02,0.2,90\n")
    exp = read_trial_csv(path)
    np.testing.assert_allclose(exp.n, [1.5, 2.0], rtol=1e-15)
    np.testing.assert_allclose(exp.wind_dir, [np.pi, np.pi / 2], rtol=1e-15)
    np.testing.assert_allclose(exp.psi, [0.0, 0.015], rtol=1e-15)  # trapezoid of r


# --- Dataset -------------------------------------------------------------------------------


def test_dataset_padding_and_mask():
    long, short = synthetic_experiment(num=120), synthetic_experiment(num=80, dt=0.2, t0=0.0)
    data = Dataset.from_experiments([long, short])
    assert data.num_experiments == 2 and data.num_samples == 120
    arrays, mask = data.stack()
    assert set(arrays) == set(CHANNELS)
    assert all(a.shape == (2, 120) for a in arrays.values()) and mask.shape == (2, 120)
    np.testing.assert_array_equal(mask.sum(axis=1), [120, 80])
    assert np.all(np.isfinite(np.stack(list(arrays.values()))))
    np.testing.assert_allclose(np.diff(data.t[1]), 0.2, rtol=1e-9)  # time continues
    np.testing.assert_allclose(data.dt, [0.1, 0.2], rtol=1e-12)
    assert np.all(data.delta[1, 80:] == short.delta[-1])
    assert data.channels == long.channels
    for i, exp in enumerate([long, short]):
        assert_channels_equal(exp, data.experiment(i), rtol=0.0)
    with pytest.raises(ValueError, match="shorter than the longest"):
        Dataset.from_experiments([long, short], num_samples=100)


def test_dataset_vmap_replay_matches_original(turn):
    """Replaying two segments of a simulation in one vmapped batch gives back the
    original trajectory on the unmasked samples."""
    vessel, trajectory = turn
    full = Experiment.from_trajectory(trajectory)
    first, later = full.segment(stop=120.0), full.segment(start=110.0)
    data = Dataset.from_experiments([first, later])
    assert data.lengths == (41, 101)
    batch = js.simulate_batch(vessel, data.replays(rudder="delta_c"), data.initial_states())
    np.testing.assert_array_equal(np.asarray(batch.valid), data.mask)
    np.testing.assert_allclose(np.asarray(batch.t), data.t, rtol=1e-14)
    for key in ("psi", "r", "u", "v", "x", "y"):
        got = np.asarray(getattr(batch.state, key))[data.mask]
        want = np.concatenate([getattr(first, key), getattr(later, key)])
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10, err_msg=key)


# --- measured data sets ------------------------------------------------------------------

DATA = shared_data_dir()
needs_data = pytest.mark.skipif(DATA is None, reason="shared/data not found (set JAXSHIP_DATA)")


def data_file(*parts):
    path = DATA.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"{path} not found")
    return path


def test_shared_data_dir_env(tmp_path, monkeypatch):
    monkeypatch.setenv("JAXSHIP_DATA", str(tmp_path))
    assert shared_data_dir() == tmp_path
    monkeypatch.setenv("JAXSHIP_DATA", str(tmp_path / "missing"))
    assert shared_data_dir() is None


@needs_data
def test_esso_trailing_empty_rows():
    """README: zigzag_31-Jul-2020_13_50_28.csv has 1701 rows (0-170.0 s) and then 327
    empty rows."""
    exp = read_esso_osaka(data_file("esso_osaka_frt", "zigzag", "zigzag_31-Jul-2020_13_50_28.csv"))
    assert exp.num_samples == 1701
    assert exp.t[0] == 0.0 and exp.t[-1] == pytest.approx(170.0)
    assert exp.is_uniform() and exp.dt == pytest.approx(0.1, rel=1e-9)
    assert exp.derived == () and set(exp.channels) == {
        "delta", "psi", "r", "u", "v", "x", "y", "n", "wind_speed", "wind_dir"}
    assert all(np.all(np.isfinite(getattr(exp, k))) for k in CHANNELS)
    assert set(exp.extra) == {"wind_speed_relative", "wind_dir_relative"}
    # README summary: n 0-12 rps, delta -30.3..29.6 deg, u up to 0.33 m/s
    assert np.max(exp.n) == pytest.approx(12.0)
    assert np.rad2deg(exp.delta.min()) == pytest.approx(-30.3, abs=0.05)
    assert np.rad2deg(exp.delta.max()) == pytest.approx(29.6, abs=0.05)


@needs_data
def test_esso_late_start_and_sign():
    path = data_file("esso_osaka_frt", "random", "random_06-Aug-2020_16_24_25_3.csv")
    exp = read_esso_osaka(path)
    assert exp.num_samples == 7179 and exp.t[0] == pytest.approx(1176.1)
    assert exp.replay().start == pytest.approx(1176.1)


@needs_data
def test_esso_turns_unwrapped_and_signed():
    """The files' psi_hat is wrapped to [-180, 180] deg; after unwrapping, every turning
    run turns to the side of its rudder and psi is the integral of r (README: r = dpsi/dt,
    +35 deg turns reach psi ~ +640 deg)."""
    paths = sorted((DATA / "esso_osaka_frt" / "turning").glob("*.csv"))
    if not paths:
        pytest.skip("Esso Osaka turning runs not found")
    for path in paths:
        exp = read_esso_osaka(path)
        turned = exp.psi[-1] - exp.psi[0]
        # no 2 pi jumps left (the heading estimate has glitches of up to ~10 deg per step)
        assert np.max(np.abs(np.diff(exp.psi))) < np.deg2rad(20.0), path.name
        assert np.sign(turned) == np.sign(np.median(exp.delta)), path.name
        assert abs(turned) > np.deg2rad(250.0), path.name
        steps = 0.5 * (exp.r[1:] + exp.r[:-1]) * np.diff(exp.t)
        heading = np.concatenate([[0.0], np.cumsum(steps)])  # integral of r
        assert turned == pytest.approx(heading[-1], rel=0.05), path.name
        # over 2 s windows (the heading estimate is noisy): d(psi)/dt = 1.00-1.03 x mean r
        w = 20
        rate, mean_r = (exp.psi[w:] - exp.psi[:-w]) / 2.0, (heading[w:] - heading[:-w]) / 2.0
        assert np.corrcoef(rate, mean_r)[0, 1] > 0.93, path.name
        assert np.polyfit(mean_r, rate, 1)[0] == pytest.approx(1.015, abs=0.025), path.name


HSVA_RUNS = [
    "Z_05_01", "Z_10_01", "Z_10_05", "Z_10_10_S", "Z_10_10_P", "Z_15_01", "Z_15_05", "Z_20_05",
    "Z_20_10_S", "Z_20_10_P", "Z_25_05", "Z_30_05", "Z_35_05",
]


@needs_data
@pytest.mark.parametrize("run", HSVA_RUNS)
def test_hsva_kvlcc2(run):
    exp = read_hsva_kvlcc2(data_file("kvlcc2_simman2008_hsva", f"HSVA_CPMC_KVLCC2_{run}.dat"))
    assert exp.is_uniform() and exp.dt == pytest.approx(0.05, rel=1e-6)
    # column 7 is the yaw rate
    assert np.corrcoef(np.gradient(exp.psi, exp.t), exp.r)[0, 1] > 0.99
    # body-fixed velocities at the start: straight ahead at about 1.178 m/s
    assert exp.u[0] == pytest.approx(1.178, abs=0.01) and abs(exp.v[0]) < 0.01
    assert exp.n[0] == pytest.approx(10.2295)
    # the first rudder goes to the starting side (starboard unless "_P") and the heading follows
    side = -1.0 if run.endswith("_P") else 1.0
    first = np.argmax(np.abs(exp.delta) > np.deg2rad(1.0))
    assert np.sign(exp.delta[first]) == side
    reverse = first + np.argmax(np.sign(exp.delta[first:]) == -side)
    assert side * (exp.psi[reverse] - exp.psi[0]) > np.deg2rad(0.5)


@pytest.fixture(scope="module")
def marin():
    if DATA is None:
        pytest.skip("shared/data not found (set JAXSHIP_DATA)")
    folder = DATA / "kvlcc2_simman2008_marin"
    runs = {}
    for key in ("tc_-35", "zz_10"):
        path = folder / f"MARIN_FREE_KVLCC2_{key}_m.dat"
        if not path.exists():
            pytest.skip(f"{path} not found")
        runs[key] = read_marin_kvlcc2(path)
    runs["tc_-35 model"] = read_marin_kvlcc2(folder / "MARIN_FREE_KVLCC2_tc_-35_m.dat",
                                             model_scale=True)
    return runs


def test_marin_time_and_speed(marin):
    turn = marin["tc_-35"]
    assert turn.num_samples == 15753  # README rows
    np.testing.assert_allclose(np.diff(turn.t), 0.13526, rtol=0, atol=1e-11)
    assert turn.t[-1] == pytest.approx(2131, abs=1.0)
    for exp in (turn, marin["zz_10"]):
        assert exp.u[0] == pytest.approx(8.0, abs=0.15)  # body surge at approach
        assert abs(exp.v[0]) < 0.1
        assert exp.n[0] == pytest.approx(91.4 / 60, abs=0.01)


def test_marin_starboard_turn(marin):
    """`tc_-35` is the 35 deg turn to starboard: positive rudder and yaw rate in our
    convention, heading up to about +764 deg."""
    turn = marin["tc_-35"]
    steady = (turn.t > 300.0) & (turn.t < 1200.0)
    assert np.rad2deg(np.median(turn.delta[steady])) == pytest.approx(35.0, abs=1.0)
    assert np.all(turn.r[steady] > 0.0)
    assert np.rad2deg(turn.psi.max()) > 700.0
    assert np.median(turn.v[steady]) < 0.0  # drift outwards: sway to port at midship


def test_marin_zigzag_port_first(marin):
    """`zz_10` starts with +10 deg in MARIN's convention = rudder to port: ours is -10 deg
    and the heading first decreases."""
    exp = marin["zz_10"]
    first = np.argmax(np.abs(exp.delta) > np.deg2rad(3.0))
    assert np.rad2deg(exp.delta[first + 20]) == pytest.approx(-10.0, abs=1.5)
    reverse = first + np.argmax(exp.delta[first:] > 0.0)
    assert exp.psi[reverse] - exp.psi[0] < -np.deg2rad(5.0)


def test_marin_model_scale(marin):
    full, model = marin["tc_-35"], marin["tc_-35 model"]
    root = np.sqrt(45.714)
    assert model.dt == pytest.approx(0.02, rel=1e-3)
    assert model.u[0] == pytest.approx(1.179, abs=0.03)  # HSVA's model approach speed
    assert model.n[0] * 60 == pytest.approx(614, rel=0.02)  # HSVA: 614 rpm model
    np.testing.assert_allclose(model.x, full.x / 45.714, rtol=1e-14)
    np.testing.assert_allclose(model.r, full.r * root, rtol=1e-14)
    np.testing.assert_allclose(model.psi, full.psi, rtol=0)
    assert model.meta["lpp"] == pytest.approx(7.0, rel=1e-4)


@needs_data
def test_read_measured_dispatch(tmp_path):
    cases = {
        data_file("esso_osaka_frt", "zigzag", "zigzag_31-Jul-2020_13_04_24.csv"): "esso_osaka",
        data_file("kvlcc2_simman2008_hsva", "HSVA_CPMC_KVLCC2_Z_10_10_P.dat"): "hsva_kvlcc2",
        data_file("kvlcc2_simman2008_marin", "MARIN_FREE_KVLCC2_zz_-20_m.dat"): "marin_kvlcc2",
    }
    trial = tmp_path / "trial.csv"
    trial.write_text(GOOD)
    cases[trial] = "trial csv"
    for path, kind in cases.items():
        record = read_measured(path)
        assert record.meta["format"] == kind
        # the measured data sets log u, v over ground (GNSS track, carriage); a trial
        # CSV (jaxship's simulation) through the water
        assert record.over_ground == (kind != "trial csv"), path
        assert js.Dataset.from_experiments([record]).over_ground.tolist() == [
            record.over_ground]
    with pytest.raises(ValueError, match="zz_-20_m.dat: no such file"):
        read_measured(tmp_path / "zz_-20_m.dat")


def test_read_measured_unknown_format(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("hello, world\n1,2\n")
    with pytest.raises(ValueError, match=r"notes\.txt: unknown measurement format"):
        read_measured(path)
    trial = tmp_path / "trial.csv"
    trial.write_text(GOOD)
    assert read_measured(trial).num_samples == 3


# --- robustness of every reader (issue 13): one line naming the file and what to do -------

ESSO_HEADER = ("t [s],x_position_mid [m],u_velo [m/s],y_position_mid [m],vm_velo [m/s],"
               "psi_hat [rad],r_angvelo [rad/s],n_prop [rps],delta_rudder [rad]")


def esso_text(rows=5, header=ESSO_HEADER, edit=None, sep=","):
    lines = [header.replace(",", sep)]
    for k in range(rows):
        cells = [f"{0.1 * k:.1f}", "1.0", "0.5", "2.0", "0.0", f"{0.01 * k}", "0.01", "10.0",
                 "0.1"]
        if edit:
            cells = edit(k, cells)
        lines.append(sep.join(cells))
    return "\n".join(lines) + "\n"


def hsva_text(rows=5, edit=None, sep=" "):
    lines = [" HSVA, experimental data CPMC", " KVLCC2", " Z10/10", " Time series of motions"]
    for k in range(rows):
        cells = [f"{0.05 * k:.6f}", "2.9", "-0.001", "-0.04", "1.17", "-0.002", "-0.03",
                 "-0.003", "0.0", "10.2", "40.5", "1.01"]
        if edit:
            cells = edit(k, cells)
        lines.append(sep.join(cells))
    return "\n".join(lines) + "\n"


def marin_text(rows=5, edit=None, sep="\t"):
    lines = ["MARIN(Maritime Research Institute Netherlands)", "Turning test for KVLCC2"]
    for k in range(rows):
        cells = [f"{k * 0.13526:.2E}",
                 "0.00E+00", "-1.00E-02", "-2.39E-01", "1.54E-01", "8.01E+00", "6.65E-02",
                 "-1.95E-02", "1.99E-02", "-8.52E-01", "9.14E+01"]
        if edit:
            cells = edit(k, cells)
        lines.append(sep.join(cells))
    return "\n".join(lines) + "\n"


def cell(row, col, value):
    return lambda k, cells: cells[:col] + [value] + cells[col + 1:] if k == row else cells


def repeat(row):  # row `row` repeats the one before
    state = {}

    def edit(k, cells):
        if k == row - 1:
            state["cells"] = cells
        return state["cells"] if k == row else cells
    return edit


READER_CASES = {
    # trial CSV through read_measured (the commands' reader)
    "trial: empty": ("x.csv", b"", read_measured, r"x\.csv: the file is empty"),
    "trial: blank lines": ("x.csv", b"\n \n\n", read_measured, r"x\.csv: the file is empty"),
    "trial: semicolons": ("x.csv", b"t [s];delta [deg];psi [deg]\n0;0;0\n", read_measured,
                          r"x\.csv: header row \(line 1\): the columns are separated by "
                          r"semicolons, not commas; save the file as comma-separated CSV"),
    "trial: tabs": ("x.csv", b"t [s]\tdelta [deg]\tpsi [deg]\n0\t0\t0\n", read_trial_csv,
                    r"separated by tabs, not commas"),
    "trial: latin-1": ("x.csv", "t [s],delta [deg],psi [deg]\n0,0,0\n0.1,0,1é\n".encode(
        "latin-1"), read_measured, r"x\.csv: line 3 is not UTF-8 text \(byte 0xe9\)"),
    "trial: header only": ("x.csv", b"t [s],delta [deg],psi [deg]\n", read_measured,
                           r"x\.csv: needs at least two data rows, got 0"),
    "trial: decimal commas": ("x.csv", b"t [s],delta [deg],psi [deg]\n0,0,0\n0,1,0,2,0\n",
                              read_measured, r"row 2 \(line 3\) has 5 fields but the header "
                                             r"has 3 columns"),
    # Esso Osaka
    "esso: header only": ("e.csv", (ESSO_HEADER + "\n").encode(), read_measured,
                          r"e\.csv: needs at least two data rows"),
    "esso: semicolons": ("e.csv", esso_text(sep=";").encode(), read_measured,
                         r"e\.csv: header row \(line 1\): the columns are separated by semi"),
    "esso: missing column": ("e.csv", esso_text(header=ESSO_HEADER.replace(
        "r_angvelo", "r_angvel")).encode(), read_esso_osaka,
        r"e\.csv: column 'r_angvel \[rad/s\]' \(header row, line 1\): unknown Esso Osaka"),
    "esso: unit": ("e.csv", esso_text(header=ESSO_HEADER.replace("psi_hat [rad]",
                                                                  "psi_hat [deg]")).encode(),
                   read_measured, r"column 'psi_hat \[deg\]'.*unit 'deg', expected 'rad'"),
    "esso: nan": ("e.csv", esso_text(edit=cell(2, 5, "nan")).encode(), read_measured,
                  r"e\.csv: column 'psi_hat \[rad\]', row 3 \(line 4\): value 'nan' is not "
                  r"finite"),
    "esso: text": ("e.csv", esso_text(edit=cell(3, 6, "n/a")).encode(), read_measured,
                   r"column 'r_angvelo \[rad/s\]', row 4 \(line 5\): cannot read 'n/a'"),
    "esso: repeated time": ("e.csv", esso_text(edit=repeat(3)).encode(), read_measured,
                            r"row 4 \(line 5\): time 0\.2 is not greater than the previous"),
    # HSVA
    "hsva: empty": ("h.dat", b"", read_hsva_kvlcc2, r"h\.dat: the file is empty; expected an "
                                                    r"HSVA file"),
    "hsva: not hsva": ("h.dat", b"hello\n1 2 3\n", read_hsva_kvlcc2,
                       r"h\.dat: not an HSVA file \(line 1 names HSVA\) \(line 1 is 'hello'\)"),
    "hsva: header only": ("h.dat", hsva_text(rows=0).encode(), read_measured,
                          r"h\.dat: needs at least two data rows, got 0"),
    "hsva: commas": ("h.dat", hsva_text(sep=",").encode(), read_measured,
                     r"h\.dat: row 1 \(line 5\) has 1 fields but an HSVA record has 12 "
                     r"numbers separated by spaces"),
    "hsva: missing column": ("h.dat", hsva_text(edit=lambda k, c: c[:11]).encode(),
                             read_measured, r"has 11 fields but an HSVA record has 12"),
    "hsva: nan": ("h.dat", hsva_text(edit=cell(1, 3, "NaN")).encode(), read_measured,
                  r"h\.dat: column 'column 4', row 2 \(line 6\): value 'NaN' is not finite"),
    "hsva: text": ("h.dat", hsva_text(edit=cell(1, 3, "x")).encode(), read_measured,
                   r"column 'column 4', row 2 \(line 6\): cannot read 'x' as a number"),
    "hsva: decreasing time": ("h.dat", hsva_text(edit=cell(3, 0, "0.01")).encode(),
                              read_measured, r"row 4 \(line 8\): time 0\.01 is not greater"),
    "hsva: undecodable": ("h.dat", hsva_text().encode() + b"\x81\n", read_hsva_kvlcc2,
                          r"h\.dat: line 10 is not CP1252 text \(byte 0x81\)"),
    # MARIN
    "marin: empty": ("m.dat", b"", read_marin_kvlcc2, r"m\.dat: the file is empty; expected a "
                                                      r"MARIN file"),
    "marin: header only": ("m.dat", marin_text(rows=0).encode(), read_measured,
                           r"m\.dat: needs at least two data rows, got 0"),
    "marin: spaces": ("m.dat", marin_text(sep=" ").encode(), read_measured,
                      r"m\.dat: row 1 \(line 3\) has 1 fields but a MARIN record has 11 numbers "
                      r"separated by tabs"),
    "marin: missing column": ("m.dat", marin_text(edit=lambda k, c: c[:10]).encode(),
                              read_measured, r"has 10 fields but a MARIN record has 11"),
    "marin: nan": ("m.dat", marin_text(edit=cell(2, 4, "nan")).encode(), read_measured,
                   r"m\.dat: column 'column 5', row 3 \(line 5\): value 'nan' is not finite"),
    "marin: text": ("m.dat", marin_text(edit=cell(2, 4, "--")).encode(), read_measured,
                    r"column 'column 5', row 3 \(line 5\): cannot read '--' as a number"),
    "marin: repeated row": ("m.dat", marin_text(edit=repeat(3)).encode(), read_measured,
                            r"m\.dat: column 1 \(time\), row 4 \(line 6\): printed time .* "
                            r"\(a row repeated, missing or out of order"),
}


@pytest.mark.parametrize("case", sorted(READER_CASES))
def test_every_reader_gives_one_line_errors(tmp_path, case):
    name, content, reader, message = READER_CASES[case]
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(ValueError, match=message) as error:
        reader(path)
    text = str(error.value)
    assert "\n" not in text and str(path) in text


@pytest.mark.parametrize("reader", [read_measured, read_trial_csv, read_esso_osaka,
                                    read_hsva_kvlcc2, read_marin_kvlcc2])
def test_readers_refuse_folders_and_missing_files(tmp_path, reader):
    with pytest.raises(ValueError, match=r"is a folder; pass one measurement file"):
        reader(tmp_path)
    with pytest.raises(ValueError, match=r"nope\.csv: (no such file|cannot read the file)"):
        reader(tmp_path / "nope.csv")


def test_marin_rejects_a_nonsense_sample_interval(tmp_path):
    path = tmp_path / "m.dat"
    path.write_text(marin_text())
    assert read_marin_kvlcc2(path).num_samples == 5
    with pytest.raises(ValueError, match=r"`dt` must be a positive number of seconds"):
        read_marin_kvlcc2(path, dt=-0.1)


def test_rows_are_read_in_chunks_with_the_right_row_numbers(tmp_path, monkeypatch):
    """A file longer than a chunk reads the same as in one piece; a bad cell in a later
    chunk is reported at its own row and line; empty rows inside the data are errors and
    trailing ones are dropped, across chunk boundaries too."""
    rows = [f"{0.1 * k!r},{float(np.sin(k))!r},{float(np.cos(k))!r}" for k in range(23)]
    path = tmp_path / "long.csv"
    path.write_text("t [s],delta [rad],psi [rad]\n" + "\n".join(rows) + "\n,,\n,,\n")
    whole = read_trial_csv(path)
    monkeypatch.setattr("jaxship._simulation._readers._CHUNK", 4)
    assert_channels_equal(read_trial_csv(path), whole, rtol=0)
    assert whole.num_samples == 23
    bad = rows[:17] + [rows[17].replace(",", ",oops", 1)] + rows[18:]
    path.write_text("t [s],delta [rad],psi [rad]\n" + "\n".join(bad) + "\n")
    with pytest.raises(ValueError, match=r"column 'delta \[rad\]', row 18 \(line 19\): "
                                         r"cannot read 'oops"):
        read_trial_csv(path)
    gap = rows[:9] + [",,"] + rows[9:]
    path.write_text("t [s],delta [rad],psi [rad]\n" + "\n".join(gap) + "\n")
    with pytest.raises(ValueError, match=r"column 't \[s\]', row 10 \(line 11\): empty value"):
        read_trial_csv(path)


def test_a_folder_with_a_record_in_the_wrong_dialect_says_so(tmp_path):
    """A semicolon-separated record in a folder is read (and refused with the reason),
    not skipped in silence; other tables are still skipped."""
    (tmp_path / "a.csv").write_text(GOOD)
    (tmp_path / "open_water.csv").write_text("J,Kt\n0,0.3\n")
    assert [e.name for e in read_experiments([tmp_path])] == ["a"]
    (tmp_path / "b.csv").write_text(GOOD.replace(",", ";"))
    with pytest.raises(ValueError, match=r"b\.csv: header row \(line 1\): the columns are "
                                         r"separated by semicolons"):
        read_experiments([tmp_path])


def test_a_folder_reads_quoted_headers_and_refuses_utf16(tmp_path):
    """The trust audit: a folder scan skipped a quoted CSV and a UTF-16 one in silence, so
    a fit used fewer records than given. Quoted fields are valid CSV and are read; a
    UTF-16 record is refused, naming its encoding."""
    (tmp_path / "a.csv").write_text(GOOD)
    quoted = GOOD.splitlines()
    quoted[0] = ",".join(f'"{h}"' for h in quoted[0].split(","))
    (tmp_path / "quoted.csv").write_text("\n".join(quoted) + "\n")
    assert [e.name for e in read_experiments([tmp_path])] == ["a", "quoted"]
    for encoding in ("utf-16", "utf-16-le", "utf-16-be"):  # with a byte-order mark, without
        (tmp_path / "wide.csv").write_bytes(GOOD.encode(encoding))
        with pytest.raises(ValueError, match=r"wide\.csv: the file is UTF-16 text; save it "
                                             r"as UTF-8"):
            read_experiments([tmp_path])


def test_a_held_out_record_named_as_a_training_one_is_told_apart(tmp_path):
    """The trust audit: `discover` showed a training and a held-out `trial.csv` as the same
    "trial". A name another role's records already use gets the record's folder."""
    for folder in ("train", "test"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "trial.csv").write_text(GOOD)
    train = read_experiments([tmp_path / "train" / "trial.csv"])
    held = read_experiments([tmp_path / "test" / "trial.csv"], role="held-out",
                            taken=[e.name for e in train])
    assert [e.name for e in train] == ["trial"] and [e.name for e in held] == ["test/trial"]


def test_decimate_keeps_measured_channels_and_extra_signals():
    t = np.arange(10) * 0.1
    e = js.Experiment(t, np.sin(t), psi=t, u=np.ones(10), name="x",
                      extra={"gust": 2 * t, "setting": np.array([1.0, 2.0])})
    d = e.decimate(3)
    np.testing.assert_allclose(d.t, t[::3])
    assert d.channels == e.channels and d.name == "x" and d.derived == ("r",)
    np.testing.assert_allclose(d.extra["gust"], 2 * t[::3])
    np.testing.assert_allclose(d.extra["setting"], [1.0, 2.0])
    with pytest.raises(ValueError, match="positive integer"):
        e.decimate(0)


def test_a_record_renamed_restated_and_checked(tmp_path):
    """`Experiment.renamed`, `with_velocities` (either way) and `check_uniform`, and
    `measurement_files` of a folder: the doors the command line reads records through."""
    t = np.arange(5) * 0.5
    e = js.Experiment(t, np.zeros(5), psi=np.zeros(5), u=np.ones(5), name="a",
                      metadata={"file": "a.csv"})
    assert e.renamed("b").name == "b" and e.renamed("b").meta["file"] == "a.csv"
    ground = e.with_velocities(over_ground=True)
    assert ground.over_ground and not e.over_ground
    assert not ground.with_velocities(over_ground=False).over_ground
    np.testing.assert_array_equal(ground.u, e.u)
    e.check_uniform()
    uneven = js.Experiment(np.array([0.0, 0.5, 1.0, 2.0]), np.zeros(4), psi=np.zeros(4),
                           name="uneven")
    with pytest.raises(ValueError, match=r"^where: .*interpolate first"):
        uneven.check_uniform("interpolate first", where="where")
    with pytest.raises(ValueError, match=r"^Experiment 'uneven'"):
        uneven.check_uniform()
    write_trial_csv(tmp_path / "run.csv", e)
    (tmp_path / "open_water.csv").write_text("J,KT,KQ\n0.1,0.3,0.04\n")
    (tmp_path / "README.md").write_text("not a record")
    (tmp_path / "semicolons.csv").write_text("t [s];delta [deg]\n0;0\n")
    records, skipped = js.measurement_files(tmp_path)
    assert [p.name for p in records] == ["run.csv", "semicolons.csv"]
    assert [p.name for p in skipped] == ["open_water.csv"]


@pytest.mark.parametrize("units", [js.strategies.DisplayUnits(), js.strategies.SIUnits()])
def test_writing_refuses_what_reading_would_and_leaves_the_file(tmp_path, units):
    """Issue 72 ("saving refuses what loading would refuse", the audit of 2026-12-07): a
    rudder of 2 rad (115 deg) was written, and `read_trial_csv` then refused the file.
    `write_trial_csv` refuses it in one line naming the channel; a file already at the
    path is left as it was."""
    t = np.arange(0.0, 10.0, 0.5)
    path = tmp_path / "trial.csv"
    path.write_text("the old one")
    with pytest.raises(ValueError, match=r"channel 'delta' sample 0 is 114\.6 deg, beyond the "
                       r"rudder angle of any ship \(at most 90 deg\)"):
        js.write_trial_csv(path, js.Experiment(t, np.full_like(t, 2.0), psi=0.01 * t),
                           units=units)
    assert path.read_text() == "the old one"
