"""Vessel files (`save_vessel`, `load_vessel`, `jaxship vessels --show`) and `--vessel`
taking a preset, a vessel file or an identify result (issue 62)."""

import json
import math
import re

import equinox as eqx
import jax
import numpy as np
import pytest

import jaxship as js
from jaxship._foundation._validate import _to_plain
from jaxship._models._vessel.file import vessel_text, vessel_to_dict
from jaxship.cli import main
from jaxship.identification import model_from_report, read_result


@pytest.mark.parametrize("name", list(js.VESSELS))
def test_every_preset_round_trips_bit_for_bit(name, tmp_path):
    """Written and read back, each preset has the same class and leaves, bit for bit,
    and simulates to the same trajectory."""
    vessel = js.get_vessel(name)
    back = js.load_vessel(js.save_vessel(vessel, tmp_path / f"{name}.toml"))
    assert type(back) is type(vessel)
    leaves, tree = jax.tree.flatten(vessel)
    again, tree_back = jax.tree.flatten(back)
    assert tree == tree_back
    assert all(np.float64(a).tobytes() == np.float64(b).tobytes()
               for a, b in zip(leaves, again))
    manoeuvre = js.ZigZag(math.radians(10), math.radians(10), duration=20.0, dt=0.5)
    x0 = js.straight_state(float(vessel.nominal_speed), float(vessel.nominal_n))
    first, second = js.simulate(vessel, manoeuvre, x0), js.simulate(back, manoeuvre, x0)
    for a, b in zip(jax.tree.leaves(first), jax.tree.leaves(second)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


def test_vessels_show_writes_a_file_that_simulate_reads(tmp_path, capsys):
    assert main(["vessels", "--show", "kvlcc2"]) == 0
    text = capsys.readouterr().out
    assert 'model = "MMGVessel"' in text and 'length = { value = 7.0, unit = "m" }' in text
    path = tmp_path / "ship.toml"
    path.write_text(text)
    assert main(["simulate", "--vessel", str(path), "--manoeuvre", "zigzag:10/10",
                 "--out", str(tmp_path / "own")]) == 0
    assert main(["simulate", "--vessel", "kvlcc2", "--manoeuvre", "zigzag:10/10",
                 "--out", str(tmp_path / "preset")]) == 0
    capsys.readouterr()
    own, preset = (json.loads((tmp_path / d / "indices.json").read_text())
                   for d in ("own", "preset"))
    assert own == preset


BAD = [
    ('length = { value = 3.0, unit = "m" }', 'lenght = { value = 3.0, unit = "m" }',
     "unknown field 'lenght'"),
    ('x_0f = -0.02139  # X_0F\', resistance coefficient ahead\n', "", "missing field 'x_0f'"),
    ('length = { value = 3.0, unit = "m" }', 'length = { value = 3.0, unit = "ft" }',
     "field 'length': unit 'ft' is wrong"),
    ('length = { value = 3.0, unit = "m" }', 'length = { value = -3.0, unit = "m" }',
     "field 'length' = -3.0 m is out of its physical range"),
    ('max_angle = { value = 0.6108652381980153, unit = "rad" }',
     'max_angle = { value = 135, unit = "deg" }',
     "field 'rudder.max_angle' = 2.356194490192345 rad is out of its physical range"),
    ('model = "LowSpeedMMGVessel"', 'model = "Tugboat"', "unknown vessel class 'Tugboat'"),
    ('length = { value = 3.0, unit = "m" }', "length = 3.0", "field 'length': give its unit"),
    ('model = "LowSpeedMMGVessel"', 'model = "LowSpeedMMGVessel', "is not a vessel file (TOML)"),
]


@pytest.mark.parametrize("old, new, message", BAD, ids=[b[2] for b in BAD])
def test_a_bad_vessel_file_is_one_line_and_exit_2(old, new, message, tmp_path, capsys):
    text = vessel_text(js.get_vessel("esso_osaka"))
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1))
    out = tmp_path / "out"
    code = main(["simulate", "--vessel", str(path), "--manoeuvre", "turn:35", "--out",
                 str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert message in err and str(path) in err, err
    assert not out.exists()


# issue 72: values no ship has, each refused naming the field and the likely slip
IMPLAUSIBLE = [
    ('nominal_n = { value = 8.333333333333334, unit = "rev/s" }',
     'nominal_n = { value = 500, unit = "rev/s" }', "is beyond any propeller's rate"),
    ("n_propellers = 2.0", "n_propellers = -2.0", "a ship has at least one propeller"),
    ('xg = { value = -0.018, unit = "m" }', 'xg = { value = -18, unit = "m" }',
     "the centre of gravity lies outside the hull"),
    ('stall_angle = { value = 0.8726646259971648, unit = "rad" }',
     'stall_angle = { value = 50, unit = "rad" }', "between 0 and 90 deg (in rad: is it in deg?)"),
    ('n_rdot = { value = -196.48104824758687, unit = "kg m^2" }',
     'n_rdot = { value = 196.48104824758687, unit = "kg m^2" }', "an added mass"),
]


@pytest.mark.parametrize("old, new, message", IMPLAUSIBLE, ids=[b[2] for b in IMPLAUSIBLE])
def test_a_vessel_no_ship_can_be_is_refused_naming_the_field(old, new, message, tmp_path):
    text = vessel_text(js.get_vessel("thesis"))
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ValueError, match=re.escape(message)) as error:
        js.load_vessel(path)
    assert str(path) in str(error.value) and "\n" not in str(error.value)


def test_degrees_and_rpm_are_read_in_a_file(tmp_path):
    text = vessel_text(js.get_vessel("esso_osaka"))
    text = text.replace('max_angle = { value = 0.6108652381980153, unit = "rad" }',
                        'max_angle = { value = 35, unit = "deg" }')
    text = text.replace('nominal_n = { value = 10.0, unit = "rev/s" }',
                        'nominal_n = { value = 600, unit = "rpm" }')
    path = tmp_path / "deg.toml"
    path.write_text(text)
    vessel = js.load_vessel(path)
    assert vessel.rudder.max_angle == pytest.approx(math.radians(35), abs=1e-15)
    assert vessel.nominal_n == 10.0


def test_identify_then_simulate_reproduces_the_fitted_model(tmp_path, capsys):
    """A Nomoto 1 fitted to a thesis-vessel zig-zag: `simulate --vessel result.json`
    runs the fitted model (the same trajectory as the fit's model in Python), and the
    rebuilt model replays its training record to the fit % of the result."""
    trial = tmp_path / "trial"
    assert main(["simulate", "--vessel", "thesis", "--manoeuvre", "zigzag:20/20",
                 "--out", str(trial)]) == 0
    fit = tmp_path / "fit"
    assert main(["identify", str(trial / "trial.csv"), "--model", "nomoto1", "--quiet",
                 "--no-figures", "--out", str(fit)]) == 0
    assert main(["simulate", "--vessel", str(fit / "result.json"), "--manoeuvre",
                 "zigzag:20/20", "--out", str(tmp_path / "sim")]) == 0
    capsys.readouterr()
    report = json.loads((fit / "result.json").read_text())
    fitted = js.Nomoto1(**{k: e["value"] for k, e in report["parameters"].items()},
                        **report["frozen"])
    record = js.read_trial_csv(trial / "trial.csv")
    dt = float(record.t[1] - record.t[0])
    ours = js.simulate(fitted, js.ZigZag(math.radians(20), math.radians(20),
                                         duration=float(record.t[-1]), dt=dt),
                       simulator=js.Simulator(substeps=2))
    simulated = js.read_trial_csv(tmp_path / "sim" / "trial.csv")
    assert simulated.t.size == ours.t.size
    np.testing.assert_allclose(simulated.psi, np.asarray(ours.state.psi), atol=1e-9)
    model, _ = read_result(fit / "result.json")
    assert model == fitted
    predicted = js.predict(model, record, estimator=js.PredictionError(horizon=None))
    assert predicted.metrics["psi"].fit_percent == pytest.approx(
        report["train_simulation"]["channels"]["psi"]["fit_percent"], abs=0.5)


def test_imo_check_of_a_preset_and_a_steering_model_refused(tmp_path, capsys):
    out = tmp_path / "imo"
    assert main(["simulate", "--vessel", "kvlcc2", "--manoeuvre", "imo", "--out",
                 str(out)]) == 0
    printed = capsys.readouterr().out
    indices = json.loads((out / "indices.json").read_text())
    rows = {r["criterion"]: r for r in indices["imo_criteria"]}
    assert len(rows) == 6 and "stopping: track reach, full astern" in rows
    for row in rows.values():
        assert row["margin"] == pytest.approx(row["limit"] - row["value"])
        assert row["passed"] == (row["margin"] >= 0) and row["band"] is None
    assert indices["uncertainty"]["from"].startswith("none")
    assert {"criteria.md", "imo_criteria.png", "turn35.png", "stop.png"} <= {
        p.name for p in out.iterdir()}
    assert "| criterion | value | limit | margin" in printed
    assert "notes" not in indices and "Note:" not in (out / "criteria.md").read_text()


def test_imo_check_below_the_resolutions_test_speed_says_so(tmp_path, capsys):
    """Issue 72, point 5: MSC.137(76) tests at no less than 90 % of the service speed; an
    approach at 1.2 m/s of the thesis vessel's 1.54 m/s is said on stderr, in criteria.md
    and in indices.json."""
    out = tmp_path / "imo"
    assert main(["simulate", "--vessel", "thesis", "--manoeuvre", "imo", "--speed", "1.2",
                 "--out", str(out)]) == 0
    said = "the approach speed 1.2 m/s is 78 % of the service speed 1.54 m/s"
    assert said in capsys.readouterr().err
    assert said in (out / "criteria.md").read_text()
    assert said in json.loads((out / "indices.json").read_text())["notes"][0]


def test_imo_band_from_the_standard_errors_of_a_result(tmp_path, capsys):
    """Independent normal draws from std where the result stores no correlation."""
    vessel = js.get_vessel("kvlcc2")
    result = tmp_path / "result.json"
    result.write_text(json.dumps({"model": "kvlcc2", "parameters": {
        "n_r": {"value": float(vessel.n_r), "std": 0.002 * abs(float(vessel.n_r))}}}))
    out = tmp_path / "imo"
    assert main(["simulate", "--vessel", str(result), "--manoeuvre", "imo", "--out",
                 str(out)]) == 0
    capsys.readouterr()
    indices = json.loads((out / "indices.json").read_text())
    assert indices["uncertainty"]["from"].startswith("independent normal draws from std")
    assert indices["uncertainty"]["used"] == indices["uncertainty"]["draws"] > 0
    for row in indices["imo_criteria"]:
        low, high = row["band"]  # n_r moves the turn; the stop hardly
        assert low <= row["value"] * 1.01 and high >= row["value"] * 0.99
        assert low < high or row["criterion"].startswith("stopping")


def test_a_result_of_ones_own_vessel_rebuilds_it_with_effects():
    """`result.json` keeps the vessel (`vessel`) and its effects (`effects`): a vessel of
    a file comes back with its fitted values, effect parameters included."""
    vessel = js.get_vessel("kvlcc2")
    report = {"model": "vessel", "parameters": {
        "n_r": {"value": 0.01, "std": 0.001}, "rudder_offset.delta0": {"value": 0.02}},
        "vessel": _to_plain(vessel_to_dict(vessel)), "effects": ["RudderOffset"]}
    model = model_from_report(report)
    assert isinstance(model, js.effects.AugmentedVessel)
    assert model.base.n_r == 0.01 and model.effects[0].delta0 == 0.02
    assert model.base.shaft.max_rate == math.inf


def test_identify_and_discover_start_from_a_result_and_autopilot_needs_a_vessel(tmp_path, capsys):
    model = js.Nomoto1(K=0.05, T=10.0)
    zigzag = js.simulate(model, js.ZigZag(math.radians(10), math.radians(10),
                                          duration=200.0, dt=1.0))
    record = tmp_path / "zigzag.csv"
    js.write_trial_csv(record, js.Experiment.from_trajectory(zigzag))
    fit = ["identify", str(record), "--no-figures", "--quiet"]
    assert main([*fit, "--model", "nomoto1", "--out", str(tmp_path / "a")]) == 0
    assert main([*fit, "--vessel", str(tmp_path / "a" / "result.json"),
                 "--out", str(tmp_path / "b")]) == 0
    again = json.loads((tmp_path / "b" / "result.json").read_text())
    assert again["model"] == "nomoto1" and "--vessel" in again["start"]["method"]
    assert again["parameters"]["K"]["value"] == pytest.approx(0.05, rel=2e-2)
    capsys.readouterr()
    assert main([*fit, "--model", "nomoto1", "--vessel", "thesis", "--out",
                 str(tmp_path / "c")]) == 2
    assert "one of them" in capsys.readouterr().err
    assert main(["autopilot", "--model", str(tmp_path / "a" / "result.json"), "--vessel",
                 str(tmp_path / "a" / "result.json"), "--rpm", "300", "--out",
                 str(tmp_path / "d")]) == 2
    assert "this needs a vessel" in capsys.readouterr().err
    # discover starts from the fitted model too: nothing is missing from these records
    assert main(["discover", str(record), "--vessel", str(tmp_path / "a" / "result.json"),
                 "--out", str(tmp_path / "e"), "--quiet"]) == 0
    report = json.loads((tmp_path / "e" / "discovery.json").read_text())
    assert report["verdict"] == "nothing_missing", report["effects"]


def test_simulate_reads_the_fit_code_of_its_result(tmp_path, capsys):
    """Issue 57's "every command reads the code of what it consumes": a result whose fit
    did not converge simulates, says so first on stderr and exits 3 (the README's exit
    status for a fit that did not converge); the files are written."""
    vessel = js.get_vessel("kvlcc2")
    result = tmp_path / "result.json"
    result.write_text(json.dumps({"model": "kvlcc2", "fit": {"code": "max_steps_reached"},
                                  "parameters": {"n_r": {"value": float(vessel.n_r)}}}))
    out = tmp_path / "tc"
    assert main(["simulate", "--vessel", str(result), "--manoeuvre", "turn:35", "--duration",
                 "100", "--out", str(out)]) == 3
    err = capsys.readouterr().err
    assert f"not a converged estimate (code max_steps_reached in {result})" in err, err
    assert (out / "trial.csv").is_file()


def test_a_wind_model_round_trips_in_its_table(tmp_path):
    """The Esso Osaka preset with Fujiwara's wind loads (issue 58): written with a
    `[wind_model]` table, read back bit for bit; the default writes no table, and a
    table without a known model or with a field missing is one line naming it."""
    lab = eqx.tree_at(lambda v: v.wind_model, js.get_vessel("esso_osaka"),
                      js.wind_loads.FujiwaraWindLoads.esso_osaka())
    text = vessel_text(lab)
    assert '[wind_model]\nmodel = "FujiwaraWindLoads"' in text
    assert "\n[wind_model]\n" not in vessel_text(js.get_vessel("esso_osaka"))
    back = js.load_vessel(js.save_vessel(lab, tmp_path / "lab.toml"))
    assert back.wind_model == lab.wind_model
    assert jax.tree.structure(back) == jax.tree.structure(lab)
    for old, new, message in [
            ('model = "FujiwaraWindLoads"', 'model = "Isherwood"', "table [wind_model] must name"),
            ('bridge_height = { value = 0.294, unit = "m" }\n', "",
             "missing field 'wind_model.bridge_height'"),
            ('breadth = { value = 0.48925, unit = "m" }', 'breadth = { value = -0.5, unit = "m" }',
             "field 'wind_model.breadth' = -0.5 m is out of its physical range")]:
        path = tmp_path / "bad.toml"
        path.write_text(text.replace(old, new, 1))
        with pytest.raises(ValueError, match=re.escape(message)):
            js.load_vessel(path)


def test_the_vessel_file_as_text_and_as_a_dict_reads_back_bit_for_bit():
    """The public doors of the vessel file (issue 59: the command line goes through
    them): `save_vessel(vessel)` with no path gives the file's text, `load_vessel` reads
    its parsed content (a dict) as it reads the file."""
    import tomllib

    vessel = js.get_vessel("kvlcc2")
    text = js.save_vessel(vessel, source="a test")
    assert text.splitlines()[3] == "# a test" and 'model = "MMGVessel"' in text
    back = js.load_vessel(tomllib.loads(text))
    assert all(np.float64(a).tobytes() == np.float64(b).tobytes()
               for a, b in zip(jax.tree.leaves(vessel), jax.tree.leaves(back)))
    with pytest.raises(ValueError, match="field 'model': unknown vessel class 'Tug'"):
        js.load_vessel(tomllib.loads(text.replace('model = "MMGVessel"', 'model = "Tug"')))


def test_save_vessel_text_loads_back_and_saving_refuses_what_loading_would():
    """Issue 72: `load_vessel(save_vessel(v))` is a round trip (it answered "File name too
    long"), and `save_vessel` refuses a mass of nan or -5 before writing, naming the field."""
    vessel = js.get_vessel("mariner")
    back = js.load_vessel(js.save_vessel(vessel))
    assert all(np.float64(a).tobytes() == np.float64(b).tobytes()
               for a, b in zip(jax.tree.leaves(vessel), jax.tree.leaves(back)))
    with pytest.raises(ValueError, match="the text given is not a vessel file"):
        js.load_vessel("model = \nMariner\n")
    for bad, message in ((math.nan, "field 'm' is nan"), (-5.0, "field 'm' = -5.0 is out")):
        with pytest.raises(ValueError, match=f"cannot save Mariner: {message}"):
            js.save_vessel(eqx.tree_at(lambda v: v.m, vessel, bad))


def test_parameters_by_name_on_every_model():
    """`parameter_names`, `get_parameter` and `with_parameters` address a vessel's, a
    steering model's and an effect's parameters alike (`"<effect id>.<field>"`)."""
    model = js.augment(js.Nomoto1(K=0.1, T=20.0), js.effects.RudderOffset(delta0=0.01))
    assert model.parameter_names() == ("K", "T", "delta0", "rudder_offset.delta0")
    changed = model.with_parameters({"T": 25.0, "rudder_offset.delta0": -0.02})
    assert changed.get_parameter("T") == 25.0 and model.get_parameter("T") == 20.0
    assert changed.get_parameter("rudder_offset.delta0") == -0.02
    assert model.with_parameters({}) is model
    vessel = js.get_vessel("mariner")
    assert "length" in vessel.parameter_names()
    assert float(vessel.with_parameters({"length": 200.0}).get_parameter("length")) == 200.0


def _damaged_results():
    """A result.json of the KVLCC2 preset with two estimated coefficients, their
    standard errors and correlation, and the damages a hand edit makes (issue 72): each
    with the field the refusal names."""
    vessel = js.get_vessel("kvlcc2")
    good = {"model": "kvlcc2", "data": {"train": [{"dt_s": 0.5, "duration_s": 100.0}]},
            "parameters": {"n_r": {"value": float(vessel.n_r), "std": 1e-4},
                           "n_v": {"value": float(vessel.n_v), "std": 1e-4}},
            "correlation": {"names": ["n_r", "n_v"], "matrix": [[1.0, 0.3], [0.3, 1.0]]}}
    damages = {
        "data as a list": (("data",), [], "field 'data' is a list, not an object"),
        "correlation as a list": (("correlation",), [[1.0, 0.3], [0.3, 1.0]],
                                  "field 'correlation' is a list, not an object"),
        "a 1 x 1 matrix for 2 names": (("correlation", "matrix"), [[1.0]],
                                       "field 'correlation.matrix' is 1 x 1, not 2 x 2"),
        "a matrix of strings": (("correlation", "matrix"), [["a", "b"], ["c", "d"]],
                                "field 'correlation.matrix' row 1, column 1 is \"a\""),
        "a boolean value": (("parameters", "n_r", "value"), True,
                            "parameter n_r is true, a boolean, not a number"),
        "a boolean std": (("parameters", "n_r", "std"), True,
                          "field 'parameters.n_r.std' is true, not a number"),
        # found by the audit of 2026-12-07: a traceback from `simulate`'s steering path
        "a record's dt as text": (("data", "train", 0, "dt_s"), "a",
                                  "field 'data.train[0].dt_s' is \"a\", not a number"),
        "a record's dt as a boolean": (("data", "train", 0, "dt_s"), True,
                                       "field 'data.train[0].dt_s' is true, a boolean"),
        "a negative duration": (("data", "train", 0, "duration_s"), -5.0,
                                "field 'data.train[0].duration_s' = -5.0 s is out of its "
                                "physical range"),
    }
    return good, damages


@pytest.mark.parametrize("record", [{"dt_s": 1e-9, "duration_s": 120.0},
                                    {"dt_s": 1.0, "duration_s": 1e12}])
def test_a_steering_results_trial_too_long_to_hold_is_refused(record, tmp_path, capsys):
    """`simulate --vessel result.json` of a steering model takes its trial's step and
    length from the result's first training record: a hand-edited one that asks for more
    than `MAX_SAMPLES` samples is refused in one line (the audit of 2026-12-07: an
    out-of-memory traceback), naming where the values came from."""
    traj = js.simulate(js.Nomoto1(K=0.05, T=10.0),
                       js.ZigZag(math.radians(10), math.radians(10), duration=120.0, dt=1.0))
    report = js.identify("nomoto1", [js.Experiment.from_trajectory(traj)],
                         max_steps=20).to_dict()
    report["data"]["train"][0].update(record)
    result = tmp_path / "result.json"
    result.write_text(json.dumps(report))
    out = tmp_path / "zz"
    assert main(["simulate", "--vessel", str(result), "--manoeuvre", "zigzag:20/20",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "more than 5e+06" in err and "the result's first training record" in err, err
    assert "\n" not in err and not out.exists()


@pytest.mark.parametrize("case", list(_damaged_results()[1]))
def test_a_damaged_result_is_refused_naming_the_file_and_field_before_any_work(
        case, tmp_path, capsys):
    """A hand-edited result.json (issue 72, "Broken 2"): `load_model` and
    `read_result` refuse it in one line naming the file and the field, and
    `simulate --manoeuvre imo` exits 2 with that line before any trial (no output
    folder); the undamaged file reads."""
    good, damages = _damaged_results()
    keys, value, message = damages[case]
    result = tmp_path / "result.json"
    result.write_text(json.dumps(good))
    assert isinstance(js.load_model(result), js.MMGVessel)
    report = json.loads(json.dumps(good))
    place = report
    for key in keys[:-1]:
        place = place[key]
    place[keys[-1]] = value
    result.write_text(json.dumps(report))
    for read in (js.load_model, read_result):
        with pytest.raises(ValueError) as error:
            read(result)
        assert "\n" not in str(error.value) and str(error.value).startswith(f"{result}: ")
        assert message in str(error.value), str(error.value)
    out = tmp_path / "imo"
    assert main(["simulate", "--vessel", str(result), "--manoeuvre", "imo", "--out",
                 str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and str(result) in err and "\n" not in err, err
    assert not out.exists()
    with pytest.raises(ValueError, match=re.escape(message.split(" is ")[0])):
        js.indices.check_imo(js.get_vessel("kvlcc2"), identification=report)
