"""`jaxship identify` and `jaxship.identify`: recovery of known steering
models from trial CSV files written from simulations (every registered kind: Nomoto,
Ross, sway-yaw, ARMAX and a vessel preset), the report's schema, figures, validation on
held-out records, progress reporting and clear errors on bad input."""

import json
import math
import re

import equinox as eqx
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship import (
    AuxInputs,
    Identification,
    LinearSwayYaw,
    Nomoto1,
    Nomoto2,
    NonlinearNomoto,
    NorrbinCrossFlow,
    Progress,
    RossAutopilot,
)
from jaxship.cli import main
from jaxship.identification import MODELS, linear_candidate, model_from_report, read_experiments


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples
ZOH = js.strategies.ZeroOrderHold()  # the replayed rudder held over each interval


DEG = np.pi / 180
DT = 0.5
NUM = 600
TRUTH = Nomoto1(K=0.06, T=25.0)  # K [1/s], T [s]
STEERING_MODELS = ("nomoto1", "nomoto2", "nomoto1-nonlinear", "nomoto1-norrbin",
                   "ross-autopilot", "linear-sway-yaw", "norrbin-crossflow",
                   "low-speed-sway-yaw", "armax")


def rudder_sequence(seed, amplitudes=(10.0,), hold=(16, 48)):
    """Rudder steps of random sign, amplitude [deg] and hold (zig-zag/PRBS mix) [rad]."""
    rng = np.random.default_rng(seed)
    out, sign = [], 1.0
    while len(out) < NUM:
        sign = -sign if rng.random() < 0.8 else sign
        out.extend([sign * rng.choice(amplitudes) * DEG] * int(rng.integers(*hold)))
    return np.array(out[:NUM])


def record(model, delta, *, name, noise=0.0, seed=0, command=None):
    """A record of `model` driven by `delta` from rest, heading 0.1 rad, with white
    measurement noise of `noise` deg on psi and `noise / 10` deg/s on r. `command`:
    an optional commanded rudder written as `delta_c`, which then drives the model held
    over each interval (as `identify --rudder delta_c` replays a command)."""
    tr = js.simulate(model, js.Replay(delta, dt=DT, delta_hold=FOH if command is None else ZOH),
                     js.straight_state(0.0, psi=0.1), simulator=per_sample())
    rng = np.random.default_rng(seed)
    psi = np.asarray(tr.state.psi) + noise * DEG * rng.standard_normal(NUM)
    r = np.asarray(tr.state.r) + 0.1 * noise * DEG * rng.standard_normal(NUM)
    extra = {} if command is None else {"delta_c": command}
    return js.Experiment(np.asarray(tr.t), delta, psi=psi, r=r, name=name, **extra)


def write(path, experiment):
    js.write_trial_csv(path, experiment)
    return str(path)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Training and held-out trial CSVs of the true Nomoto1 with measurement noise."""
    folder = tmp_path_factory.mktemp("trials")
    train = record(TRUTH, rudder_sequence(0), name="train", noise=0.05, seed=1)
    test = record(TRUTH, rudder_sequence(1, amplitudes=(5.0, 15.0)), name="test", noise=0.05,
                  seed=2)
    return {"train": write(folder / "train.csv", train), "test": write(folder / "test.csv", test),
            "folder": folder}


def run(args, capsys):
    code = main(["identify", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_recovers_nomoto1_validates_and_writes_report(files, tmp_path, capsys):
    """Output error on a noisy record recovers K and T within 4 standard errors and
    2 %; the report has the documented schema and the figures are written."""
    out = tmp_path / "id"
    code, stdout, _ = run([files["train"], "--model", "nomoto1", "--validate", files["test"],
                           "--out", str(out)], capsys)
    assert code == 0
    result = json.loads((out / "result.json").read_text())
    assert result["model"] == "nomoto1" and result["model_class"] == "Nomoto1"
    params = result["parameters"]
    assert set(params) == {"K", "T"}
    assert params["K"]["unit"] == "1/s" and params["T"]["unit"] == "s"
    for name, truth in (("K", TRUTH.K), ("T", TRUTH.T)):
        value, std = params[name]["value"], params[name]["std"]
        assert 0 < std < 0.02 * truth
        assert abs(value - truth) < 4 * std and abs(value - truth) < 0.02 * truth, name
    assert result["frozen"] == {"delta0": 0.0}
    assert result["fit"]["success"] and result["options"]["horizon_s"] is None
    assert result["options"]["initial"] == "estimate"
    assert result["train"]["start"] == "estimated" and result["validation"]["start"] == "measured"
    assert result["start"]["method"].startswith("linear least squares")
    # train, train_simulation and validation blocks with the same per-channel figures
    for block in ("train", "train_simulation", "validation"):
        assert result[block]["kind"] == "simulation"
        for channel in ("psi", "r"):
            m = result[block]["channels"][channel]
            for key in ("loss", "fpe", "aic", "bic", "fit_percent", "rms"):
                assert math.isfinite(m[key]), (block, channel, key)
            assert m["fpe"] > m["loss"] > 0
            # the fit also estimated the start r and psi (output error on noisy data)
            assert m["num_params"] == (4 if block == "train" else 2)
            assert m["whiteness"]["max_lag"] == 25
            assert isinstance(m["input_independence"]["passed"], bool)
    assert result["validation"]["experiments"] == ["test"]
    assert result["data"]["validation"][0]["file"] == files["test"]
    assert result["validation"]["channels"]["r"]["fit_percent"] > 95
    assert result["validation"]["channels"]["r"]["fit_percent_per_experiment"]["test"] > 95
    # output error with white measurement noise: white residuals on the training record
    assert result["train"]["channels"]["r"]["whiteness"]["passed"]
    corr = np.array(result["correlation"]["matrix"])
    assert result["correlation"]["names"] == ["K", "T"]
    np.testing.assert_allclose(np.diag(corr), 1.0)
    np.testing.assert_allclose(corr, corr.T)
    assert result["identifiability"]["identifiable"] and result["identifiability"]["flags"] == []
    figures = sorted(p.name for p in (out / "figures").iterdir())
    assert figures == ["correlation.png", "fit_train_00_train.png", "fit_validation_00_test.png",
                       "residuals_train.png", "residuals_validation.png"]
    assert all((out / "figures" / f).stat().st_size > 10_000 for f in figures)
    assert "K" in stdout and "validation (simulation)" in stdout


def test_no_excitation_is_not_a_success_exit_3(files, tmp_path, capsys):
    """A straight run (rudder held at 0): exit 3 (`poorly_determined`, not converged), a
    warning on stderr, infinite standard errors and plain-language flags in the report,
    which is written for inspection."""
    straight = js.Experiment(DT * np.arange(NUM), np.zeros(NUM), psi=np.full(NUM, 0.1),
                             r=np.zeros(NUM), name="straight")
    path = write(tmp_path / "straight.csv", straight)
    out = tmp_path / "id"
    code, _, err = run([path, "--model", "nomoto1", "--out", str(out), "--no-figures"], capsys)
    assert code == 3
    assert "warning" in err and "no excitation" in err and "poorly_determined" in err
    result = json.loads((out / "result.json").read_text())
    assert result["fit"]["success"] is False and result["fit"]["code"] == "poorly_determined"
    assert not result["identifiability"]["identifiable"]
    assert any("constant in every experiment" in f for f in result["identifiability"]["flags"])
    assert result["parameters"]["K"]["std"] == "inf"
    assert any("neutral start" in n for n in result["notes"])
    assert not (out / "figures").exists()


def test_folder_delta_c_horizon_and_channels(tmp_path, capsys):
    """A folder of records (other files skipped, the data-like ones named in a note),
    the commanded rudder, a finite horizon and one fitted channel: the nonlinear Nomoto
    model is recovered."""
    truth = NonlinearNomoto(K=0.06, T=25.0, n3=300.0)
    folder = tmp_path / "records"
    folder.mkdir()
    for seed in (3, 4):
        command = rudder_sequence(seed, amplitudes=(5.0, 15.0, 30.0))
        servo = 0.9 * command  # the measured angle differs from the command
        e = record(truth, command, name=f"zz{seed}", command=command)
        e = js.Experiment(e.t, servo, psi=e.psi, r=e.r, delta_c=command, name=e.name)
        write(folder / f"zz{seed}.csv", e)
    (folder / "README.md").write_text("not a record\n")
    (folder / "open_water.csv").write_text("J,Kt\n0,0.3\n")
    out = tmp_path / "id"
    code, _, err = run([str(folder), "--model", "nomoto1-nonlinear", "--rudder", "delta_c",
                        "--horizon", "10", "--channels", "r", "--out", str(out),
                        "--no-figures"], capsys)
    assert code == 0, err
    assert "skipped 1 file(s) whose format is not a measurement record: open_water.csv" in err
    result = json.loads((out / "result.json").read_text())
    values = {k: v["value"] for k, v in result["parameters"].items()}
    np.testing.assert_allclose([values["K"], values["T"], values["n3"]], [0.06, 25.0, 300.0],
                               rtol=1e-5)
    assert result["options"] == {"horizon_s": 10.0, "rudder": "delta_c", "channels": ["r"],
                                 "initial": "measured", "max_steps": 256, "substeps": 1,
                                 "free": None}
    assert result["train"]["kind"] == "prediction" and set(result["train"]["channels"]) == {"r"}
    assert set(result["train_simulation"]["channels"]) == {"psi", "r"}
    assert result["fit"]["window_samples"] == [20, 20]
    assert [d["name"] for d in result["data"]["train"]] == ["zz3", "zz4"]
    assert result["validation"] is None and result["frozen"]["n1"] == 1.0


@pytest.mark.parametrize("name, truth", [
    ("nomoto1", Nomoto1(K=0.06, T=25.0)),
    ("nomoto2", Nomoto2(K=0.06, T1=25.0, T2=3.0, T3=5.0)),
    pytest.param("nomoto1-nonlinear", NonlinearNomoto(K=0.06, T=25.0, n3=300.0, n1=-1.0),
                 marks=pytest.mark.slow),  # the fast tier has it in the folder test
])
def test_every_registered_model_recovers_quietly(name, truth, capsys):
    """Each Nomoto entry recovers its own noise-free truth from its start values
    (the course-unstable nonlinear model included); the library prints nothing and
    reports progress through the callable, with increasing optimiser steps."""
    assert set(MODELS) == set(STEERING_MODELS) | set(js.VESSELS)
    train = record(truth, rudder_sequence(5, amplitudes=(5.0, 15.0, 30.0)), name="a")
    test = record(truth, rudder_sequence(6, amplitudes=(5.0, 15.0, 30.0)), name="b")
    events = []
    res = js.identify(name, train, validate=[test], progress=events.append)
    assert isinstance(res, Identification) and res.fit.success
    expected = {n: float(getattr(truth, n)) for n in res.fit.names}
    np.testing.assert_allclose(res.fit.values, list(expected.values()), rtol=1e-5)
    assert res.validation.metrics["psi"].fit_percent > 99.9
    assert capsys.readouterr().out == ""
    fits = {}
    for e in events:
        if e.stage == "fit":
            fits.setdefault(e.message, []).append(e.step)
    assert len(fits) == (2 if name == "nomoto2" else 1)  # nomoto2 starts from a Nomoto1 fit
    for steps in fits.values():
        assert steps == sorted(steps) and steps[-1] >= 1
    assert all(isinstance(e, Progress) for e in events) and events[-1].done
    assert json.loads(res.to_json())["model"] == name


@pytest.mark.slow
def test_norrbin_of_either_stability_recovers_a_course_unstable_truth():
    """Issue 61: `nomoto1-norrbin` holds T at the linear start (the equation's scale) and
    estimates K, n1 of either sign and n3: on a course-unstable truth (n1 = -1) it
    recovers the truth scaled by T_start / T_truth, n1 < 0 included."""
    truth = NonlinearNomoto(K=0.06, T=25.0, n3=300.0, n1=-1.0)
    train = record(truth, rudder_sequence(5, amplitudes=(5.0, 15.0, 30.0)), name="a")
    res = js.identify("nomoto1-norrbin", train)
    assert res.fit.success and res.fit.names == ("K", "n3", "n1")
    scale = float(res.model.T) / truth.T
    np.testing.assert_allclose(res.fit.values, [scale * truth.K, scale * truth.n3,
                                                scale * truth.n1], rtol=1e-5)
    assert res.fit.values[2] < 0


def _csv_with(tmp_path, name, edit):
    lines = (tmp_path / "base.csv").read_text().splitlines()
    path = tmp_path / name
    path.write_text("\n".join(edit(lines)) + "\n")
    return str(path)


@pytest.fixture
def bad_files(tmp_path):
    t = DT * np.arange(40)
    write(tmp_path / "base.csv", js.Experiment(t, 0.1 * np.sin(t), psi=np.cos(t), r=-np.sin(t)))

    def nan_row(lines):
        cells = lines[5].split(",")
        cells[2] = "nan"  # columns t, delta, psi, r
        lines[5] = ",".join(cells)
        return lines

    def jump(lines):
        cells = lines[10].split(",")
        cells[0] = str(float(cells[0]) + 0.2)
        lines[10] = ",".join(cells)
        return lines

    return {
        "nan": _csv_with(tmp_path, "nan.csv", nan_row),
        "jump": _csv_with(tmp_path, "jump.csv", jump),
        "base": str(tmp_path / "base.csv"),
        "missing": str(tmp_path / "nope.csv"),
        "empty_folder": str(tmp_path),
    }


@pytest.mark.parametrize("args, message", [
    (["{missing}", "--model", "nomoto1"], "nope.csv: no such training file"),
    (["{base}", "--model", "nomoto3"], "unknown model 'nomoto3'; choose from nomoto1"),
    (["{nan}", "--model", "nomoto1"], "nan.csv: column 'psi [deg]', row 5"),
    (["{jump}", "--model", "nomoto1"], "jump.csv (training record 'jump'): column 't'"),
    (["{base}", "--model", "nomoto1", "--rudder", "delta_c"], "base.csv (training record "
     "'base'): no column 'delta_c'"),
    (["{base}", "--model", "nomoto1", "--channels", "psi,v"], "unknown output channel 'v'"),
    (["{base}", "--model", "nomoto1", "--horizon", "-3"], "horizon must be a non-negative"),
    (["{base}", "--model", "nomoto1", "--horizon", "soon"], "--horizon 'soon'"),
    (["{base}", "--model", "nomoto1", "--validate", "{missing}"],
     "nope.csv: no such validation file"),
])
def test_bad_input_is_a_clear_error(bad_files, tmp_path, capsys, args, message):
    args = [a.format(**bad_files) for a in args]
    code, _, err = run([*args, "--out", str(tmp_path / "out")], capsys)
    assert code == 2
    assert message in err
    assert not (tmp_path / "out").exists()


def test_folder_without_records_is_an_error(tmp_path):
    (tmp_path / "notes.txt").write_text("nothing here\n")
    with pytest.raises(ValueError, match="holds no measurement file"):
        read_experiments([tmp_path])


@pytest.mark.slow
def test_measured_esso_osaka_zigzags(tmp_path, capsys):
    """Real data (skipped without ../shared/data): Nomoto1 with a 10 s horizon on three
    Esso Osaka zig-zags, validated on two others: a course-keeping model that
    predicts the held-out yaw rate better than its mean, with every figure written."""
    data = js.shared_data_dir()
    if data is None:
        pytest.skip("measured data not available")
    files = sorted((data / "esso_osaka_frt" / "zigzag").glob("*.csv"))
    out = tmp_path / "esso"
    code, _, err = run([*map(str, files[:3]), "--model", "nomoto1", "--horizon", "10",
                        "--validate", *map(str, files[3:5]), "--out", str(out)], capsys)
    assert code == 0, err
    result = json.loads((out / "result.json").read_text())
    assert result["fit"]["success"]
    assert result["parameters"]["K"]["value"] > 0 and result["parameters"]["T"]["value"] > 0
    assert result["validation"]["channels"]["r"]["fit_percent"] > 0
    assert len(list((out / "figures").glob("fit_validation_*.png"))) == 2


# -- the other registered models: fit-then-recover on their own noise-free records ---------


def steps(num, seed, hold=(10, 40), lead=0):
    """Rudder steps of random sign and size 5-30 deg [rad], after `lead` samples at 0."""
    rng = np.random.default_rng(seed)
    out, sign = [0.0] * lead, 1.0
    while len(out) < num:
        sign = -sign if rng.random() < 0.8 else sign
        out.extend([sign * rng.choice([5.0, 15.0, 30.0]) * DEG] * int(rng.integers(*hold)))
    return np.array(out[:num])


def steering_csvs(folder, truth, dt, num, aux_of_t, seed=0):
    """Two noise-free trial CSVs (train, test) of the steering model `truth` driven by
    rudder steps and the measured u, v, n of `aux_of_t(t)` (v: the model's state
    where it has one)."""
    paths = []
    for k in range(2):
        t = dt * np.arange(num)
        delta, aux = steps(num, seed + k), aux_of_t(t)
        tr = js.simulate(truth, js.Replay(delta, dt=dt, delta_hold=FOH),
                         js.straight_state(0.0, psi=0.2), aux=aux, simulator=per_sample())
        v = np.asarray(tr.internal[:, 1]) if "v" in truth.state_names else aux.v
        e = js.Experiment(t, delta, psi=np.asarray(tr.state.psi), r=np.asarray(tr.state.r),
                          u=aux.u, v=v, n=aux.n, name=("train", "test")[k])
        paths.append(write(folder / f"{e.name}.csv", e))
    return paths


ROSS_TRUTH = RossAutopilot(  # a course-stable Ross model (tests/test_ross_autopilot.py)
    length=4.0, speed=1.5, rate=8.0, n_uv=-1.2, n_uuv=0.4, n_vvv=-3.0, n_rrv=-0.8,
    n_absv_v=0.3, n_absr_v=-0.5, n_ur=-4.0, n_uur=0.8, n_rrr=-0.6, n_vvr=-1.5, n_absv_r=-1.0,
    n_absr_r=-0.7, n_delta=2.5)


def ross_aux(t):
    """Measured u, v, n that vary independently of the rudder (every term excited)."""
    return AuxInputs(u=1.5 * (1 - 0.15 * np.sin(2 * np.pi * t / 37) ** 2),
                     v=0.12 * (np.sin(2 * np.pi * t / 23) + 0.6 * np.sin(2 * np.pi * t / 9.1 + 1)),
                     n=np.full(t.shape, 8.0))


def quiet_identify(train, *, model, **kwargs):
    return js.identify(model, train, **kwargs)


def test_ross_autopilot_recovers_from_trial_csvs(tmp_path):
    """Ross' 13 coefficients from one 60 s record: the start is the least-squares
    estimate, the reference scales come from the data (so the scaled coefficients
    differ from the truth's), and Ross' dimensional ratios are recovered to 1e-6."""
    train, test = steering_csvs(tmp_path, ROSS_TRUTH, 0.2, 300, ross_aux)
    res = quiet_identify([train], model="ross-autopilot", validate=[test])
    assert res.fit.success and isinstance(res.model, RossAutopilot)
    assert res.start_method.startswith("equation-error linear least squares")
    got, truth = res.model.dimensional(), ROSS_TRUTH.dimensional()
    np.testing.assert_allclose([got[n] for n in res.fit.names],
                               [truth[n] for n in res.fit.names], rtol=1e-6)
    assert len(res.fit.names) == 13
    assert res.validation.metrics["r"].fit_percent > 99.999
    assert any("reference scales" in n for n in res.notes)


@pytest.mark.parametrize("name, cls, preset", [
    ("linear-sway-yaw", LinearSwayYaw, "sea_stratus_linear"),
    pytest.param("norrbin-crossflow", NorrbinCrossFlow, "sea_stratus_nonlinear",
                 marks=pytest.mark.slow),  # the same code path with one more parameter
])
def test_sway_yaw_models_recover_from_trial_csvs(tmp_path, name, cls, preset):
    """The sway-yaw models start from the Sea Stratus derivatives and recover a
    truth 15 % away (cross-flow C 0.8 instead of 0.63) from psi, r and the
    measured v, with the measured (varying) surge speed as V, to 1e-6."""
    truth = cls.from_vessel(js.get_vessel(preset))
    changed = ("y_v", "n_r", "n_delta")
    truth = eqx.tree_at(lambda m: tuple(getattr(m, k) for k in changed), truth,
                        tuple(1.15 * float(getattr(truth, k)) for k in changed))
    if cls is NorrbinCrossFlow:
        truth = eqx.tree_at(lambda m: m.cross_flow, truth, 0.8)
    aux = lambda t: AuxInputs(u=8 + 0.8 * np.sin(2 * np.pi * t / 300), v=0.0 * t,
                              n=0.0 * t)
    train, test = steering_csvs(tmp_path, truth, 2.0, 200, aux)
    res = quiet_identify([train], model=name, validate=[test], channels="psi,r,v")
    assert res.fit.success and isinstance(res.model, cls)
    expected = [float(getattr(truth, n)) for n in res.fit.names]
    np.testing.assert_allclose(res.fit.values, expected, rtol=1e-6)
    assert set(res.validation.metrics) == {"psi", "r", "v"}
    assert res.validation.metrics["v"].fit_percent > 99.999


def test_armax_recovers_its_polynomials(tmp_path, capsys):
    """ARMAX(2,2,2) on a noise-free record of its own difference equation: A and B to
    1e-6 (C is not determined without noise), the one-step criterion as the train
    block, the simulation of r and psi on a held-out record, result.json via the CLI."""
    a, b = np.array([1.0, -1.6, 0.63]), np.array([0.004, 0.0035])
    paths = []
    for k in range(2):
        delta = steps(300, k, lead=5)
        r = np.zeros(300)
        for i in range(2, 300):  # r(t) - 1.6 r(t-1) + 0.63 r(t-2) = b0 d(t-1) + b1 d(t-2)
            r[i] = -a[1] * r[i - 1] - a[2] * r[i - 2] + b[0] * delta[i - 1] + b[1] * delta[i - 2]
        psi = 0.1 + np.concatenate([[0.0], np.cumsum(0.5 * DT * (r[1:] + r[:-1]))])
        e = js.Experiment(DT * np.arange(300), delta, psi=psi, r=r, name=f"arx{k}")
        paths.append(write(tmp_path / f"arx{k}.csv", e))
    out = tmp_path / "id"
    code, _, err = run([paths[0], "--model", "armax", "--validate", paths[1], "--out", str(out),
                        "--no-figures"], capsys)
    assert code == 0, err
    result = json.loads((out / "result.json").read_text())
    assert result["model"] == "armax" and result["model_class"] == "ARMAXModel"
    values = {k: v["value"] for k, v in result["parameters"].items()}
    assert list(values) == ["a1", "a2", "b0", "b1", "c1", "c2"]
    np.testing.assert_allclose([values[k] for k in ("a1", "a2", "b0", "b1")],
                               [a[1], a[2], b[0], b[1]], rtol=1e-6)
    assert result["parameters"]["b0"]["unit"] == "1/s"
    assert result["frozen"] == {"nk": 1.0, "dt": DT}
    assert result["options"]["channels"] == ["r"]
    assert result["train"]["kind"] == "prediction" and result["train"]["horizon_s"] == DT
    for block in ("train_simulation", "validation"):
        for channel in ("psi", "r"):
            m = result[block]["channels"][channel]
            assert m["fit_percent"] > 99.999 and math.isfinite(m["fpe"])
    assert result["correlation"]["names"] == list(values)
    assert isinstance(result["identifiability"]["flags"], list)
    # --prior reaches the ARMAX estimator: centred on the start, reported per coefficient
    code, _, err = run([paths[0], "--model", "armax", "--prior", "0.5", "--out",
                        str(tmp_path / "prior"), "--no-figures"], capsys)
    assert code == 0, err
    result = json.loads((tmp_path / "prior" / "result.json").read_text())
    assert result["fit"]["prior"]["scale"] == 0.5 and 0 < result["fit"]["effective_params"] <= 6
    assert all("data_share" in row for row in result["parameters"].values())
    # one training record only
    code, _, err = run([*paths, "--model", "armax", "--out", str(tmp_path / "two")], capsys)
    assert code == 2 and "armax is fitted to one record" in err


@pytest.mark.slow
def test_vessel_preset_recovers_its_default_free_coefficients(tmp_path, capsys):
    """`--model mariner`: the seven default free coefficients of the preset, started
    from the preset's values, recovered to 1e-6 from a zig-zag of a Mariner whose
    first three differ by 10 % (the command replayed through the servo), fitted to
    psi, r, u and v and validated by simulation."""
    ship = js.get_vessel("mariner")
    names = js.default_free(ship)
    truth = ship
    for n in names[:3]:
        truth = eqx.tree_at(lambda m: getattr(m, n), truth, 1.1 * getattr(truth, n))
    # the zig-zag logic at the 1 s samples, reversing at a step (not inside one), so that
    # the logged command is all it ordered
    trial = js.simulate(truth, js.ZigZag(20 * DEG, 20 * DEG, duration=200.0, dt=1.0,
                                         switch_at=js.strategies.SwitchAtNearestStep()),
                        js.straight_run(truth), simulator=js.Simulator(max_step=1.0))
    path = write(tmp_path / "zz.csv", js.Experiment.from_trajectory(trial, name="zz"))
    out = tmp_path / "id"
    code, _, err = run([path, "--model", "mariner", "--rudder", "delta_c", "--validate", path,
                        "--out", str(out), "--no-figures"], capsys)
    assert code == 0, err
    result = json.loads((out / "result.json").read_text())
    assert result["model"] == "mariner" and result["model_class"] == "Mariner"
    assert list(result["parameters"]) == list(names)
    np.testing.assert_allclose([result["parameters"][n]["value"] for n in names],
                               [float(getattr(truth, n)) for n in names], rtol=1e-6)
    assert result["options"]["channels"] == ["psi", "r", "u", "v"]
    assert result["options"]["initial"] == "measured"
    assert result["validation"]["channels"]["v"]["fit_percent"] > 99.999
    assert "x_u" not in result["frozen"] and "m" in result["frozen"]


@pytest.mark.parametrize("model", ["ross-autopilot", "mariner", "esso-osaka",
                                   "linear-sway-yaw"])
def test_models_driven_by_measured_speeds_need_them(files, tmp_path, capsys, model):
    """Records without u (and v): a clear error naming the file, before any fit."""
    code, _, err = run([files["train"], "--model", model, "--out", str(tmp_path / "o")], capsys)
    assert code == 2
    assert f"{files['train']} (training record 'train'): model " in err
    assert "no column 'u'" in err and not (tmp_path / "o").exists()


def test_help_lists_every_model(capsys):
    with pytest.raises(SystemExit):
        main(["identify", "--help"])
    out = capsys.readouterr().out
    listed = [line.split()[0] for line in out.split("models (--model):")[1].splitlines()
              if line.strip()]
    assert listed == [*STEERING_MODELS, *js.VESSELS, "auto"]


def test_a_speed_beyond_froude_1_for_the_preset_is_refused(tmp_path, capsys):
    """Trust audit, case 4: a record whose u is beyond Froude number 1 for the model's
    length (the Mariner's 7.7 m/s against the 3 m Esso Osaka model, Fn 1 at 5.42 m/s:
    another ship's record, or a speed in knots) is refused before any fit, with the file,
    column and likely cause, exit 2 and nothing written: `identify`'s records and
    `discover`'s held-out ones."""
    def trial(preset, path):
        vessel = js.get_vessel(preset)
        run_ = js.simulate(vessel, js.ZigZag(10 * DEG, 10 * DEG, duration=40.0, dt=1.0),
                           js.straight_run(vessel))
        js.write_trial_csv(path, js.Experiment.from_trajectory(run_))
        return str(path)

    fast = trial("mariner", tmp_path / "mariner.csv")
    slow = trial("esso_osaka", tmp_path / "esso.csv")
    expected = re.compile(r"mariner\.csv \((training|held-out) record 'mariner'\): column 'u' "
                          r"reaches 7\.\d+ m/s at t = 0 s, Froude number 1\.\d+ for the 3 m "
                          r"esso_osaka: no displacement ship runs beyond Fn 1 \(5\.42 m/s\)\. "
                          r"Is the column in knots or km/h")
    for command in (["identify", fast, "--model", "esso_osaka"],
                    ["discover", slow, "--holdout", fast, "--model", "esso_osaka"]):
        out = tmp_path / command[0]
        code = main([*command, "--out", str(out)])
        err = capsys.readouterr().err
        assert code == 2 and expected.search(err), err
        assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_auto_chooses_the_nonlinear_model_only_where_the_steady_turn_is_nonlinear():
    """Issue 61 point 1 (`identify --model auto`): Nomoto 1 and Norrbin's nonlinear Nomoto 1
    fitted to the same training records, the one with the least BIC on them chosen. On a
    vessel with cubic yaw damping (H(r) = r + 300 r^3, steps of 5-30 deg: the steady turn
    bends) it is the Norrbin model; on a linear Nomoto 1 truth (the same rudder and
    noise) the extra n3 buys less than BIC's log N and Nomoto 1 is chosen (6 of 6 noise
    draws, seed 1 the closest: 3.2 apart; Akaike's FPE took n3 there). The held-out
    record never enters the choice: the choice and its figures are the same without it;
    the result carries each candidate's BIC and FPE (result.json, the printed note)."""
    steps = rudder_sequence(5, amplitudes=(5.0, 15.0, 30.0))
    cubic = NonlinearNomoto(K=0.06, T=25.0, n3=300.0)
    train = record(cubic, steps, name="a", noise=0.05, seed=1)
    held_out = record(TRUTH, rudder_sequence(2), name="held-out", noise=0.05, seed=3)
    chosen = js.identify("auto", train, validate=held_out)
    assert chosen.model_name == "nomoto1-norrbin" and isinstance(chosen.model, NonlinearNomoto)
    figures = chosen.selection["candidates"]
    assert chosen.selection["chosen"] == "nomoto1-norrbin"
    assert figures["nomoto1-norrbin"]["bic"] < figures["nomoto1"]["bic"]
    assert (figures["nomoto1"]["num_params"], figures["nomoto1-norrbin"]["num_params"]) == (2, 3)
    assert js.identify("auto", train).selection == chosen.selection
    report = json.loads(chosen.to_json())
    assert report["selection"]["chosen"] == report["model"] == "nomoto1-norrbin"
    assert any(n.startswith("model chosen: nomoto1-norrbin") for n in report["notes"])
    # `autopilot --model result.json` inverts the chosen model, as any other result's
    rebuilt = model_from_report(report)
    assert isinstance(rebuilt, NonlinearNomoto) and float(rebuilt.n3) == float(chosen.model.n3)
    # ... and places the PID's poles on the linear candidate, kept in the selection: the
    # same fit as `identify --model nomoto1`
    feedback = model_from_report(linear_candidate(report["selection"]))
    alone = js.identify("nomoto1", train, validate=held_out).model
    assert isinstance(feedback, Nomoto1)
    assert (float(feedback.K), float(feedback.T)) == pytest.approx(
        (float(alone.K), float(alone.T)), rel=1e-12)
    for code in ("poorly_determined", "nonlinear_max_steps_reached"):  # T, K may be anything
        unusable = json.loads(json.dumps(report["selection"]))
        unusable["candidates"]["nomoto1"]["fit_code"] = code
        assert linear_candidate(unusable) is None
    linear = js.identify("auto", record(TRUTH, steps, name="b", noise=0.05, seed=1))
    assert linear.model_name == "nomoto1" and isinstance(linear.model, Nomoto1)
    figures = linear.selection["candidates"]
    assert figures["nomoto1"]["bic"] < figures["nomoto1-norrbin"]["bic"]
    assert linear_candidate(linear.selection) is None  # the poles on the chosen model
    with pytest.raises(ValueError, match="--free does not go with --model auto"):
        js.identify("auto", train, free=("K",))


def test_cli_auto_writes_the_choice_and_refuses_a_vessel(files, tmp_path, capsys):
    """`jaxship identify --model auto` on the noisy linear Nomoto 1 records: Nomoto 1
    chosen (parsimony), the note on stdout names each candidate's BIC and FPE, result.json
    has `selection` and the chosen model's own report; `--model auto` with `--vessel` is a
    one-line error (exit 2, nothing written)."""
    out = tmp_path / "auto"
    code, stdout, _ = run([files["train"], "--model", "auto", "--validate", files["test"],
                           "--out", str(out), "--no-figures", "--quiet"], capsys)
    assert code == 0
    report = json.loads((out / "result.json").read_text())
    assert report["model"] == report["selection"]["chosen"] == "nomoto1"
    assert set(report["selection"]["candidates"]) == {"nomoto1", "nomoto1-norrbin"}
    note = next(line for line in stdout.splitlines() if line.startswith("note: model chosen"))
    assert "nomoto1-norrbin: BIC" in note and "FPE" in note
    code, _, err = run([files["train"], "--model", "auto", "--vessel", "thesis", "--out",
                        str(tmp_path / "no")], capsys)
    assert code == 2 and "give --model" in err and not (tmp_path / "no").exists()


def test_free_plus_adds_to_a_steering_models_default_set(files, tmp_path, capsys):
    """`--free +delta0` on a model that is no preset (issue 72, "Broken 3") frees delta0
    beside the default K, T and the result's `options.free` records the set; an unknown
    name is refused in one line naming the model's parameters (exit 2)."""
    out = tmp_path / "plus"
    code, _, err = run([files["train"], "--model", "nomoto1", "--free", "+delta0",
                        "--out", str(out), "--no-figures", "--quiet"], capsys)
    assert code == 0, err
    result = json.loads((out / "result.json").read_text())
    assert result["options"]["free"] == ["K", "T", "delta0"]
    assert set(result["parameters"]) == {"K", "T", "delta0"} and "delta0" not in result["frozen"]
    code, _, err = run([files["train"], "--model", "nomoto1", "--free", "+bogus",
                        "--out", str(tmp_path / "bogus"), "--no-figures", "--quiet"], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "'bogus'" in err and "K, T, delta0" in err, err


@pytest.mark.parametrize("name", ["nomoto1", "nomoto2", "nomoto1-nonlinear", "nomoto1-norrbin"])
def test_free_plus_an_unknown_name_is_refused_for_every_model(name, files):
    """`free="+bogus"` is refused for every catalogue model, naming its parameters, as
    a list of names is (issue 72)."""
    with pytest.raises(ValueError, match=r"'bogus', which is not a parameter of \w+; its "
                                         r"parameters are K, T"):
        js.identify(name, files["train"], free="+bogus")
