"""The `jaxship` command: listing, simulating to a folder, errors; robustness (issue 13):
bad input on every command is one line and a non-zero exit before any long work, results
are written whole or not at all, fits that do not converge say so and exit with 3."""

import json
import math
import os
import pathlib

import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
import jaxship.cli as cli
from jaxship._foundation._params import parameter_fields, resolve_free
from jaxship.cli import main
from jaxship.cli._files import MANIFEST, staged_folder
from jaxship.identification import FitDivergedError


def test_vessels_lists_every_preset_with_source(capsys):
    assert main(["vessels"]) == 0
    out = capsys.readouterr().out
    for name in js.VESSELS:
        assert name in out
    assert "Chislett" in out and "Yasukawa" in out
    # length, service speed and propeller rate (none: no propeller model)
    rows = {line.split()[0]: line.split()[1:4] for line in out.splitlines()[1:]}
    assert rows["kvlcc2"] == ["7", "1.179", "711.1"] and rows["mariner"][2] == "-"


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


def test_each_command_chooses_its_compiler_setting(tmp_path, capsys, monkeypatch):
    """XLA's setting for many small programs is chosen where a command runs such programs
    (a steering model's identify, simulate), not for a vessel's identify, discover or
    `vessels` (`benchmarks/cli.py --flags`)."""
    chosen = []
    monkeypatch.setattr(cli, "compile_for_small_programs", lambda: chosen.append(True))
    missing = str(tmp_path / "none.csv")
    for argv, small in ((["vessels"], False),
                        (["identify", missing, "--model", "nomoto1", "--out", "o"], True),
                        (["identify", missing, "--model", "esso_osaka", "--out", "o"], False),
                        (["discover", missing, "--model", "kvlcc2", "--out", "o"], False),
                        (["simulate", "--vessel", "mariner", "--manoeuvre", "turn:400",
                          "--out", "o"], True)):
        chosen.clear()
        main(argv)
        assert chosen == ([True] if small else []), argv
    capsys.readouterr()


@pytest.mark.parametrize("args, named, near", [
    (["simulate", "--manouvre", "zigzag:20/20"], "--manouvre", "--manoeuvre"),
    (["identify", "x.csv", "--modle=nomoto1"], "--modle", "--model"),
    (["reproduce", "--quik"], "--quik", "--quick"),
])
def test_a_misspelt_option_is_named_before_any_missing_one(capsys, args, named, near):
    """Issue 72: argparse alone says only that the required `--manoeuvre` is missing."""
    with pytest.raises(SystemExit) as exit_:
        main(args)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert f"unrecognized option {named} (did you mean {near}?)" in err
    assert "required" not in err


def test_an_abbreviated_option_and_reproduce_quiet_are_accepted(capsys):
    """A unique prefix stays an option (argparse's abbreviations); reproduce has `--quiet`
    as the other long commands (issue 72)."""
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", "--manoeuv", "nonsense", "--help"])
    assert exit_.value.code == 0
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    assert "--quiet" in capsys.readouterr().out


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"jaxship {js.__version__}"


# -- robustness (issue 13): bad input is one line on stderr, a non-zero exit status, no
# traceback and nothing written; --out is checked before any long work; results are
# written through a temporary folder and renamed, never half


def _record(path, *, psi=True, seed=0, num=400, dt=0.5):
    """A trial CSV of Nomoto1(K=0.06, T=25) driven by random rudder steps."""
    rng = np.random.default_rng(seed)
    delta = np.repeat(np.where(rng.random(num // 20) < 0.5, -1.0, 1.0) * np.deg2rad(10), 20)
    replay = js.Replay(delta, dt=dt, delta_hold=js.strategies.FirstOrderHold())
    tr = js.simulate(js.Nomoto1(K=0.06, T=25.0), replay,
                     js.straight_state(0.0, psi=0.1), simulator=per_sample())
    channels = {"psi": np.asarray(tr.state.psi)} if psi else {}
    js.write_trial_csv(path, js.Experiment(np.asarray(tr.t), delta, r=np.asarray(tr.state.r),
                                           name=path.stem, **channels))
    return str(path)


def _error_line(capsys):
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("jaxship: error: "), captured.err
    assert "Traceback" not in captured.err
    return lines[0]


@pytest.mark.parametrize("args, message", [
    (["--manoeuvre", "turn:35", "--dt", "-1"], "--dt -1: must be a positive number"),
    (["--manoeuvre", "turn:35", "--dt", "0"], "--dt 0: must be a positive number"),
    (["--manoeuvre", "turn:35", "--dt", "nan"], "--dt nan: must be a positive number"),
    (["--manoeuvre", "turn:35", "--dt", "1000"], "longer than the time scale L/U = 20.9 s"),
    (["--manoeuvre", "turn:35", "--dt", "1e-9"], "samples"),
    (["--manoeuvre", "turn:35", "--duration", "-5"], "--duration -5: must be a positive"),
    (["--manoeuvre", "turn:35", "--duration", "inf"], "--duration inf: must be a positive"),
    (["--manoeuvre", "turn:35", "--dt", "2", "--duration", "3"], "shorter than two samples"),
    (["--manoeuvre", "turn:35", "--speed", "-1"], "--speed -1: must be a positive number"),
    (["--manoeuvre", "turn:35", "--speed", "0"], "--speed 0: must be a positive number"),
    (["--manoeuvre", "turn:35", "--speed", "1e6"], "more than 10 times the service speed"),
    # the audit of 2026-12-07: a speed too slow to steer was accepted where the rpm was not
    (["--manoeuvre", "turn:35", "--speed", "0.05"], "less than a tenth of the service speed"),
    (["--manoeuvre", "turn:35", "--rpm", "-1"], "--rpm -1: must be a positive number"),
    (["--manoeuvre", "turn:35", "--rpm", "100"], "mariner has no propeller model"),
    (["--manoeuvre", "turn:400"], "rudder angle 400 deg is beyond 90 deg"),
    (["--manoeuvre", "turn:45"], "beyond the rudder limit of mariner (40 deg)"),
    (["--manoeuvre", "turn:nan"], "values must be finite numbers in degrees"),
    (["--manoeuvre", "turn:-inf"], "values must be finite numbers in degrees"),
    (["--manoeuvre", "zigzag:0/10"], "the rudder angle must not be 0"),
    (["--manoeuvre", "zigzag:10/400"], "heading change must be positive and below 180"),
    (["--manoeuvre", "prbs:-5"], "the amplitude must be positive"),
    (["--manoeuvre", "heading-steps:-5"], "heading amplitude must be positive"),
    (["--manoeuvre", "pullout:20", "--duration", "5"], "a pullout needs more than"),
    # issue 57: 1e9 failed without naming the option; 1e-6 ran 45 s and wrote 600,000 rows
    # with r = 12,000 deg/s, which jaxship's own reader refused
    (["--manoeuvre", "turn:35", "--length", "1e9"], "--length 1e+09 m: give a ship or model "
     "length between 1 and 1000 m (mariner is 160.9 m)"),
    (["--manoeuvre", "turn:35", "--length", "1e-6"], "--length 1e-06 m: give a ship or model"),
])
def test_simulate_rejects_nonsense_before_simulating(tmp_path, capsys, args, message):
    out = tmp_path / "a" / "b"
    assert main(["simulate", "--vessel", "mariner", *args, "--out", str(out)]) == 2
    assert message in _error_line(capsys)
    assert not (tmp_path / "a").exists()


def test_a_propeller_rate_too_slow_to_steer_is_refused(tmp_path, capsys):
    """Issue 72: ten times the service rate was refused, 1 % of it ran with a saturation
    warning only (rpm given as rev/s)."""
    assert main(["simulate", "--vessel", "thesis", "--manoeuvre", "turn:35", "--rpm", "5",
                 "--out", str(tmp_path / "o")]) == 2
    assert ("rpm 5: less than a tenth of the service propeller rate of thesis (500 rpm)"
            in _error_line(capsys))
    assert not (tmp_path / "o").exists()


def test_simulate_failure_leaves_the_output_folder_untouched(tmp_path, capsys):
    """A run that fails after the simulation (too short for turning indices) writes
    nothing: a new folder is removed again, an old one keeps its files, no temporary
    files are left."""
    args = ["simulate", "--vessel", "mariner", "--manoeuvre", "turn:35", "--duration", "40"]
    assert main([*args, "--out", str(tmp_path / "new")]) == 2
    assert "simulate longer" in _error_line(capsys)
    assert not (tmp_path / "new").exists()
    old = tmp_path / "old"
    old.mkdir()
    (old / "trial.csv").write_text("earlier run\n")
    assert main([*args, "--out", str(old)]) == 2
    capsys.readouterr()
    assert sorted(p.name for p in old.iterdir()) == ["trial.csv"]
    assert (old / "trial.csv").read_text() == "earlier run\n"


def test_simulate_replaces_earlier_results_whole(tmp_path, capsys):
    out = tmp_path / "run"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    assert main(["simulate", "--vessel", "mariner", "--manoeuvre", "turn:20", "--out",
                 str(out)]) == 0  # an earlier run
    assert main(["simulate", "--vessel", "mariner", "--manoeuvre", "zigzag:10/10", "--out",
                 str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    names = {p.name for p in out.iterdir()}
    assert {"indices.json", "notes.txt", "trial.csv", "trial.png"} <= names
    assert (out / "notes.txt").read_text() == "mine\n"
    # no temporary files left; the manifest of jaxship's own files
    assert [name for name in names if name.startswith(".")] == [MANIFEST]
    trial = js.read_trial_csv(out / "trial.csv")
    assert trial.num_samples > 100
    assert "n" not in trial.channels  # the Mariner has no propeller model: no column of zeros
    again = tmp_path / "again"  # same inputs, same numbers
    assert main(["simulate", "--vessel", "mariner", "--manoeuvre", "zigzag:10/10", "--out",
                 str(again)]) == 0
    capsys.readouterr()
    for name in ("trial.csv", "indices.json"):
        assert (again / name).read_text() == (out / name).read_text()


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    return _record(tmp_path_factory.mktemp("records") / "zz.csv")


@pytest.fixture(scope="module")
def fitted(record, tmp_path_factory):
    """The result.json of `identify` on `record`."""
    out = tmp_path_factory.mktemp("fitted")
    assert main(["identify", record, "--model", "nomoto1", "--out", str(out), "--no-figures",
                 "--quiet"]) == 0
    return str(out / "result.json")


def _command(name, record, fitted, out):
    """Each command with valid arguments but --out."""
    return {
        "simulate": ["simulate", "--vessel", "mariner", "--manoeuvre", "turn:35"],
        "identify": ["identify", record, "--model", "nomoto1"],
        "discover": ["discover", record, "--model", "nomoto1"],
        "autopilot": ["autopilot", "--model", fitted, "--vessel", "mariner", "--speed", "5"],
        "reproduce": ["reproduce", "--quick"],
    }[name] + ["--out", str(out)]


COMMANDS = ("simulate", "identify", "discover", "autopilot", "reproduce")


@pytest.mark.parametrize("command", COMMANDS)
def test_out_that_is_a_file_is_refused_first(command, record, fitted, tmp_path, capsys,
                                             monkeypatch):
    """An --out that is a file, lies under a file or cannot be written is one line, exit
    2, before any record is read or anything simulated or fitted."""
    _no_work(monkeypatch)
    target = tmp_path / "taken"
    target.write_text("a file\n")
    assert main(_command(command, record, fitted, target)) == 2
    assert f"--out {target} is a file, not a folder" in _error_line(capsys)
    assert main(_command(command, record, fitted, target / "sub")) == 2
    assert f"{target} is a file, not a folder" in _error_line(capsys)
    assert target.read_text() == "a file\n"

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr("jaxship.cli._common.tempfile.TemporaryFile", refuse)
    assert main(_command(command, record, fitted, tmp_path / "new")) == 2
    line = _error_line(capsys)
    assert f"--out {tmp_path / 'new'}: cannot write in {tmp_path} (Permission denied)" in line
    assert not (tmp_path / "new").exists()


def _no_work(monkeypatch):
    """Any long work fails the test: it must not start before --out is checked."""
    def no_work(*args, **kwargs):
        raise AssertionError("long work started before --out was checked")

    for name in ("simulate.simulate_to_folder", "identify.identify",
                 "identify.read_experiments", "discover.run_discovery",
                 "reproduce.reproduce", "autopilot.js.evaluate_autopilot"):
        monkeypatch.setattr(f"jaxship.cli.{name}", no_work)


@pytest.mark.parametrize("command", COMMANDS)
def test_out_that_is_a_dangling_or_looping_symlink_is_refused_first(command, record, fitted,
                                                                    tmp_path, capsys,
                                                                    monkeypatch):
    """Issue 57, case 7: an --out that is a symbolic link to nothing, or a loop, ran the
    whole fit and then ended with exit 1, "File exists". Now it is one line, exit 2,
    before the work, naming the link; a link to a folder is written through."""
    _no_work(monkeypatch)
    dangling, loop = tmp_path / "dangling", tmp_path / "loop"
    dangling.symlink_to(tmp_path / "nowhere")
    loop.symlink_to(loop)
    for out, link in ((dangling, dangling), (loop, loop), (dangling / "sub", dangling),
                      (loop / "sub", loop)):
        assert main(_command(command, record, fitted, out)) == 2
        line = _error_line(capsys)
        assert f"--out {out}: {link} is a symbolic link to" in line, line
        assert "missing or loops" in line
    assert not (tmp_path / "nowhere").exists() and dangling.is_symlink() and loop.is_symlink()


def test_an_input_that_the_run_would_replace_is_refused_first(record, fitted, tmp_path,
                                                              capsys, monkeypatch):
    """Issue 57, case 5: `simulate --out o/same`, then `identify o/same/trial.csv --out
    o/same` read the record and then removed it with the rest of the earlier run (the
    folder ended with only result.json). An input that is, or holds, a file of
    jaxship's earlier run in --out is now refused before the work: exit 2, one line
    naming it and what to do, and the folder as it was."""
    _no_work(monkeypatch)
    same = tmp_path / "o" / "same"
    with staged_folder(same) as stage:  # as `jaxship simulate --out o/same` left it
        (stage / "trial.csv").write_text(pathlib.Path(record).read_text())
        (stage / "indices.json").write_text("{}\n")
    before = {p.name: p.read_bytes() for p in same.iterdir()}
    trial = same / "trial.csv"
    for args, given in (
            (["identify", str(trial), "--model", "nomoto1"], trial),
            (["identify", str(same.parent), "--model", "nomoto1"], same.parent),
            (["identify", record, "--validate", str(trial), "--model", "nomoto1"], trial),
            (["discover", record, "--holdout", str(trial), "--model", "nomoto1"], trial),
            (["autopilot", "--model", fitted, "--vessel", "thesis", "--rpm", "300"],
             pathlib.Path(fitted))):
        out = pathlib.Path(fitted).parent if args[0] == "autopilot" else same
        assert main([*args, "--out", str(out)]) == 2
        line = _error_line(capsys)
        assert (f"{given} is an input of this run and holds results of jaxship's earlier "
                f"run in --out {out}") in line and "choose another --out" in line, line
    assert {p.name: p.read_bytes() for p in same.iterdir()} == before


def test_identify_checks_out_before_reading_records(tmp_path, capsys):
    target = tmp_path / "taken"
    target.write_text("x")
    assert main(["identify", str(tmp_path / "missing.csv"), "--model", "nomoto1", "--out",
                 str(target)]) == 2
    assert "is a file, not a folder" in _error_line(capsys)


@pytest.mark.parametrize("args, message", [
    (["--max-steps", "0"], "--max-steps 0: give a positive number"),
    (["--max-steps", "-3"], "--max-steps -3: give a positive number"),
    (["--horizon", "nan"], "--horizon 'nan': the horizon must be a non-negative"),
    (["--horizon", "inf"], "--horizon 'inf': the horizon must be a non-negative"),
])
def test_identify_rejects_nonsense_numbers(record, tmp_path, capsys, args, message):
    assert main(["identify", record, "--model", "nomoto1", *args, "--out",
                 str(tmp_path / "out")]) == 2
    assert message in _error_line(capsys)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", ["identify", "discover"])
@pytest.mark.parametrize("value", ["0", "-0.5", "nan"])
def test_a_sample_interval_that_is_no_interval_is_one_line(command, value, record, tmp_path,
                                                           capsys):
    assert main([command, record, "--model", "nomoto1", "--sample-interval", value, "--out",
                 str(tmp_path / "out")]) == 2
    assert "the sample interval must be a positive number of seconds" in _error_line(capsys)
    assert not (tmp_path / "out").exists()


def test_discover_names_the_files_it_skips_even_when_quiet(record, tmp_path, capsys,
                                                            monkeypatch):
    """The trust audit: `discover --quiet` on a folder fitted fewer records than given and
    said nothing. What is done to the records is a note, not a progress message."""
    folder = tmp_path / "records"
    folder.mkdir()
    (folder / "zz.csv").write_text(pathlib.Path(record).read_text())
    (folder / "open_water.csv").write_text("J,Kt\n0,0.3\n")
    if hasattr(os, "mkfifo"):  # skipped in silence before (the trust audit), never opened
        os.mkfifo(folder / "pipe.csv")

    def stop(*args, **kwargs):
        raise ValueError("stopped after reading")

    monkeypatch.setattr("jaxship.cli._discovery.identify", stop)
    assert main(["discover", str(folder), "--model", "nomoto1", "--sample-interval", "1",
                 "--quiet", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert "skipped 1 file(s) whose format is not a measurement record: open_water.csv" in err
    if hasattr(os, "mkfifo"):
        assert "skipped 1 file(s) that are not regular files (a FIFO, a device, a broken " \
            "link): pipe.csv" in err
    assert "training records resampled to every k-th sample (0.5 s -> 1 s)" in err


def test_discover_says_a_held_out_record_is_a_training_one(record, tmp_path, capsys,
                                                           monkeypatch):
    """Issue 72: `discover --holdout` of a training file was accepted with no note, where
    `identify --validate` has one; the note is said before any fit, even when quiet."""
    copy = tmp_path / "copy.csv"
    copy.write_text(pathlib.Path(record).read_text())

    def stop(*args, **kwargs):
        raise ValueError("stopped after reading")

    monkeypatch.setattr("jaxship.cli._discovery.identify", stop)
    assert main(["discover", record, "--holdout", str(copy), "--model", "nomoto1", "--quiet",
                 "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert f"the held-out record {copy} holds the samples of the training record" in err
    assert "(--holdout records not used in the fit for one)" in err


def test_identify_resamples_the_records_it_is_told_to(record, tmp_path, capsys):
    """`--sample-interval 2` on a record at 0.5 s fits every 4th sample, and says so."""
    out = tmp_path / "out"
    assert main(["identify", record, "--model", "nomoto1", "--sample-interval", "2",
                 "--out", str(out), "--no-figures", "--quiet"]) == 0
    assert "training records resampled to every k-th sample (0.5 s -> 2 s)" in \
        capsys.readouterr().err
    (data,) = json.loads((out / "result.json").read_text())["data"]["train"]
    assert data["dt_s"] == 2.0 and data["samples"] == 100


def test_velocities_states_the_reference_of_the_trial_csvs_u_v(record, tmp_path, capsys):
    """The real-data issue (point 5): a trial CSV's u, v are through the water unless
    `--velocities over-ground` says they are a track's (then a fitted current is added
    to the predicted u, v, `test_over_ground_velocities_recover_a_current`); result.json
    states the reference of every record, and a measured data set's reader, which states
    its own (over ground), is not overruled."""
    for option, stated in [([], "through the water"),
                           (["--velocities", "over-ground"], "over ground")]:
        out = tmp_path / stated.replace(" ", "_")
        assert main(["identify", record, "--model", "nomoto1", *option, "--validate", record,
                     "--out", str(out), "--no-figures", "--quiet"]) == 0
        data = json.loads((out / "result.json").read_text())["data"]
        assert [d["velocities"] for d in data["train"] + data["validation"]] == [stated] * 2
    capsys.readouterr()
    esso = tmp_path / "esso.csv"
    esso.write_text("t [s],x_position_mid [m],u_velo [m/s],y_position_mid [m],vm_velo [m/s],"
                    "psi_hat [rad],r_angvelo [rad/s],n_prop [rps],delta_rudder [rad]\n"
                    + "".join(f"{0.1 * k:.1f},1,0.5,2,0,0,0.01,10,0.1\n" for k in range(50)))
    for command in ("identify", "discover"):
        assert main([command, str(esso), "--model", "nomoto1", "--velocities", "through-water",
                     "--out", str(tmp_path / command)]) == 2
        assert (f"{esso}: its reader states that u, v are over ground; --velocities applies "
                "to trial CSV files only") in _error_line(capsys)
        assert not (tmp_path / command).exists()


@pytest.mark.parametrize("name, content, message", [
    ("empty.csv", "", "the file is empty"),
    ("semicolons.csv", "t [s];delta [deg];psi [deg]\n0;0;0\n1;0;0\n",
     "separated by semicolons, not commas"),
    ("latin1.csv", "t [s],delta [deg],psi [deg]\n0,0,0\n1,0,0\xe9\n", "line 3 is not UTF-8"),
    ("nonnumber.csv", "t [s],delta [deg],psi [deg]\n0,0,0\n1,zero,0\n",
     "column 'delta [deg]', row 2 (line 3): cannot read 'zero' as a number"),
    ("dup.csv", "t [s],delta [deg],psi [deg]\n0,0,0\n0,0,0\n", "strictly increasing"),
    ("unit.csv", "t [s],delta [grad],psi [deg]\n0,0,0\n1,0,0\n", "unknown unit 'grad'"),
    ("utf16.csv", "\ufefft [s],delta [deg],psi [deg]\n0,0,0\n1,0,0\n",
     "the file is UTF-16 text; save it as UTF-8"),
    ("fifo.csv", None, "is not a regular file (a pipe or a device)"),
])
@pytest.mark.parametrize("command", ["identify", "discover"])
def test_bad_records_are_one_line(tmp_path, capsys, command, name, content, message):
    path = tmp_path / name
    if content is None:  # a FIFO that nothing writes to: reading it would block forever
        os.mkfifo(path)
    else:
        path.write_bytes(content.encode("utf-16" if "utf16" in name else "latin-1"))
    assert main([command, str(path), "--model", "nomoto1", "--out", str(tmp_path / "o")]) == 2
    line = _error_line(capsys)
    assert str(path) in line and message in line
    assert not (tmp_path / "o").exists()


def test_identify_not_converged_exit_3_plain_sentence(record, tmp_path, capsys):
    """The step limit: exit 3, a plain sentence (not the optimiser's root-find text), the
    results written for inspection with the sentence in result.json."""
    out = tmp_path / "fit"
    code = main(["identify", record, "--model", "nomoto1", "--max-steps", "1", "--out",
                 str(out), "--no-figures", "--quiet"])
    captured = capsys.readouterr()
    assert code == 3
    assert "the fit stopped at the step limit (1) before converging" in captured.err
    assert "NOT converged (nonlinear_max_steps_reached, after 1 steps)" in captured.out
    assert "root-find" not in captured.out + captured.err
    result = json.loads((out / "result.json").read_text())
    assert not result["fit"]["success"]
    assert any("step limit (1)" in w for w in result["warnings"])
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "result.json"]  # no temporary files


def _identify_nomoto1_on_noise(tmp_path, name, rudder, capsys):
    """`jaxship identify --model nomoto1` on 300 s at 1 s of heading and yaw-rate noise
    (seed 0) with the rudder `rudder` (an array, or `rudder(rng, size)` drawn first):
    the output folder, the exit code and the captured output."""
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 300.0, 1.0)
    delta = rudder(rng, t.size) if callable(rudder) else rudder
    rows = np.column_stack([t, delta, rng.normal(0.0, 3.0, t.size),
                            rng.normal(0.0, 0.6, t.size)])
    path = tmp_path / f"{name}.csv"
    np.savetxt(path, rows, delimiter=",", header="t [s],delta [deg],psi [deg],r [deg/s]",
               comments="")
    out = tmp_path / "fit"
    code = main(["identify", str(path), "--model", "nomoto1", "--out", str(out),
                 "--no-figures", "--quiet"])
    return out, code, capsys.readouterr()


def test_identify_of_pure_noise_is_not_converged(tmp_path, capsys):
    """The trust audit's case: Nomoto 1 on 300 s of pure noise at 1 s samples said
    "converged in 30 steps" with a cost of 9.2e122 (one RK4 step per sample under a
    start T of 0.31 s); now it is not converged (here the optimiser, chasing the noise,
    reaches its step limit; a start that blows up says so): exit 3, the reason on
    stderr."""
    t = np.arange(0.0, 300.0, 1.0)
    out, code, captured = _identify_nomoto1_on_noise(
        tmp_path, "noise", np.where((t // 30) % 2 == 0, 10.0, -10.0), capsys)
    assert code == 3, captured.out + captured.err
    assert "NOT converged" in captured.out and "not a converged estimate" in captured.err
    result = json.loads((out / "result.json").read_text())
    assert not result["fit"]["success"]


def test_identify_of_white_noise_is_undetermined_exit_3(fitted, tmp_path, capsys):
    """Issue 59: Nomoto 1 on 300 s of white noise (rudder, heading and yaw rate) converged
    (fit 0.83 % / 0.45 %, T's standard error 139 % of its value) and exited 0. Now the fit
    is `undetermined` (no channel's fit reaches 5 % and T's 95 % interval includes zero):
    exit 3, one sentence on stderr, the flag naming T. A record the model explains still
    exits 0 (the `fitted` fixture)."""
    out, code, captured = _identify_nomoto1_on_noise(
        tmp_path, "white", lambda rng, size: rng.normal(0.0, 10.0, size), capsys)
    assert code == 3, captured.out + captured.err
    assert ("the fit explains almost nothing and leaves parameters undetermined "
            "(undetermined:") in captured.err
    assert "UNDETERMINED" in captured.out and "converged" not in captured.out
    assert "its 95 % interval includes zero" in captured.err and "determine T." in captured.err
    result = json.loads((out / "result.json").read_text())
    assert result["fit"]["code"] == "undetermined" and not result["fit"]["success"]
    assert json.loads(pathlib.Path(fitted).read_text())["fit"]["code"] == "successful"


def test_identify_flags_one_per_line(tmp_path, capsys):
    """Without excitation every identifiability flag is its own warning line (and the
    fit is `poorly_determined`: exit 3)."""
    t = 0.5 * np.arange(200)
    path = tmp_path / "straight.csv"
    js.write_trial_csv(path, js.Experiment(t, np.zeros_like(t), psi=np.full_like(t, 0.1),
                                           r=np.zeros_like(t)))
    out = tmp_path / "fit"
    assert main(["identify", str(path), "--model", "nomoto1", "--out", str(out),
                 "--no-figures", "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "not a converged estimate (poorly_determined:" in err
    flags = json.loads((out / "result.json").read_text())["identifiability"]["flags"]
    assert len(flags) >= 2
    lines = err.strip().splitlines()
    for flag in flags:
        assert sum(flag in line for line in lines) == 1
    for line in lines:
        assert sum(flag in line for flag in flags) <= 1


def test_identify_says_when_psi_is_derived(tmp_path, capsys):
    """A record without psi: the note says psi is integrated from r and the default fit
    uses r alone."""
    path = _record(tmp_path / "yawrate.csv", psi=False)
    out = tmp_path / "fit"
    assert main(["identify", path, "--model", "nomoto1", "--out", str(out), "--no-figures",
                 "--quiet"]) == 0
    stdout = capsys.readouterr().out
    assert ("note: psi is not measured in the training record yawrate: it is integrated from "
            "the measured r") in stdout
    assert "psi is not fitted (channels r)" in stdout
    result = json.loads((out / "result.json").read_text())
    assert result["options"]["channels"] == ["r"]
    np.testing.assert_allclose([result["parameters"][k]["value"] for k in ("K", "T")],
                               [0.06, 25.0], rtol=1e-6)


def test_identify_is_repeatable(record, tmp_path, capsys):
    """Same inputs, same numbers: two runs write the same result.json, byte for byte."""
    texts = []
    for name in ("a", "b"):
        assert main(["identify", record, "--model", "nomoto1", "--out", str(tmp_path / name),
                     "--no-figures", "--quiet"]) == 0
        texts.append((tmp_path / name / "result.json").read_text())
    capsys.readouterr()
    assert texts[0] == texts[1]


def test_identify_replaces_figures_whole(record, tmp_path, capsys):
    """A figure of jaxship's earlier run (its manifest lists it) that this run does not
    draw is removed; a figure of the user's in the same folder stays."""
    out = tmp_path / "fit"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "stale.png").write_bytes(b"old")
    (out / "figures" / "mine.png").write_bytes(b"mine")
    (out / MANIFEST).write_text(json.dumps({"files": ["figures/stale.png"]}))
    assert main(["identify", record, "--model", "nomoto1", "--out", str(out), "--quiet"]) == 0
    capsys.readouterr()
    figures = sorted(p.name for p in (out / "figures").iterdir())
    assert "stale.png" not in figures and "correlation.png" in figures
    assert "mine.png" in figures
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "figures", "result.json"]


def test_exit_status_of_diverged_fits_file_system_errors_and_interrupts(
        record, tmp_path, capsys, monkeypatch):
    def diverge(*args, **kwargs):
        raise FitDivergedError("the fit of nomoto1 diverged: the model's outputs became "
                               "non-finite")

    monkeypatch.setattr("jaxship.cli.identify.identify", diverge)
    out = tmp_path / "fit"
    assert main(["identify", record, "--model", "nomoto1", "--out", str(out)]) == 3
    assert "diverged" in _error_line(capsys)
    assert not out.exists()

    def disk_full(*args, **kwargs):
        raise OSError(28, "No space left on device", str(tmp_path / "run" / "trial.png"))

    monkeypatch.setattr("jaxship.cli.simulate.simulate_to_folder", disk_full)
    args = ["simulate", "--vessel", "mariner", "--manoeuvre", "turn:35", "--out",
            str(tmp_path / "run")]
    assert main(args) == 1
    assert "No space left on device" in _error_line(capsys)
    assert not (tmp_path / "run").exists()

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr("jaxship.cli.simulate.simulate_to_folder", interrupt)
    assert main(args) == 130
    assert "interrupted" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("preset", ["kvlcc2", "esso_osaka"])
def test_mmg_coefficients_have_units(preset):
    """The unit column of `identify` for the MMG presets: primed coefficients are "-",
    dimensional ones carry their SI unit; and every preset's coefficients have a unit
    (their `param` metadata), which Froude scaling reads."""
    fields = parameter_fields(js.get_vessel(preset))
    assert all(info.unit for info in fields.values()), [k for k, i in fields.items()
                                                        if not i.unit]
    assert fields["y_v"].unit == "-" and fields["length"].unit == "m"
    assert fields["rho"].unit == "kg/m^3"
    assert {spec.unit for spec in resolve_free(js.get_vessel(preset))} == {"-"}
    for name in js.VESSELS:
        fields = parameter_fields(js.get_vessel(name))
        assert all(info.unit for info in fields.values()), (name, [k for k, i in fields.items()
                                                                   if not i.unit])


@pytest.mark.slow
def test_ctrl_c_ends_the_command_with_130_at_once_every_time(tmp_path):
    """The trust audit: Ctrl-C on `discover` segfaulted (exit 139) after printing
    "interrupted.", and an interrupt raised inside a garbage-collection callback was
    swallowed so the run went on to exit 0. Now a real SIGINT at any stage of the
    command's work (from its first progress line on; before it, Python is still
    importing the package) ends it with status 130 within `GRACE` seconds, with no
    traceback, and a file of the user's in --out is left as it was."""
    import signal
    import subprocess
    import sys
    import threading
    import time

    from jaxship.cli import GRACE
    from jaxship.studies.discovery import hidden_effect_records

    train, held = hidden_effect_records(js.Nomoto1(K=0.06, T=25.0), 0)
    paths = []
    for i, record in enumerate(train + held):
        paths.append(tmp_path / f"r{i}.csv")
        js.write_trial_csv(paths[-1], record)
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("the user's\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    command = [sys.executable, "-m", "jaxship.cli", "discover", *map(str, paths[:-1]),
               "--holdout", str(paths[-1]), "--model", "nomoto1", "--out", str(out)]
    # the interrupt lands in each stage's work, right after its progress line (not after
    # fixed delays: with the compiled programs cached the whole run takes a few seconds)
    for stage in ("start values", "fitting the base model", "scoring"):
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                   text=True, env=env)
        lines, reached = [], threading.Event()

        def read(stream=process.stderr, lines=lines, reached=reached, stage=stage):
            for line in stream:
                lines.append(line)
                if stage in line:
                    reached.set()

        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        assert reached.wait(120), f"no {stage!r} line"
        sent = time.monotonic()
        process.send_signal(signal.SIGINT)
        process.wait(timeout=60)
        took = time.monotonic() - sent
        reader.join(10)
        process.stderr.close()
        err = "".join(lines)
        assert process.returncode == 130, (stage, process.returncode, err[-2000:])
        assert took < GRACE + 3.0, (stage, took)
        assert "Traceback" not in err and err.rstrip().endswith("jaxship: interrupted."), err
        assert (out / "mine.txt").read_text() == "the user's\n"


def test_help_shows_defaults_and_which_options_are_required(capsys):
    """`--help` of each command: the options that must be given say "(required)", the
    others their default where they have one."""
    seen = {}
    for command in ("simulate", "identify", "autopilot", "discover"):
        with pytest.raises(SystemExit) as stop:
            main([command, "--help"])
        assert stop.value.code == 0
        seen[command] = " ".join(capsys.readouterr().out.split())
    assert "--vessel VESSEL a preset (see `jaxship vessels`), a vessel file (TOML; " \
        "`jaxship vessels --show NAME` writes one to start from) or the result.json of " \
        "`jaxship identify` (its fitted model) (required)" in seen["simulate"]
    assert "--out OUT output folder (required)" in seen["identify"]
    assert "--max-steps MAX_STEPS optimiser step limit (default: 256)" in seen["identify"]
    assert "most effects added (default: 3)" in seen["discover"]
    assert "the controller's zeta (default: 1.0)" in seen["autopilot"]
    assert "(default: None)" not in " ".join(seen.values())


SWALLOWED_INTERRUPT = """
import gc, os, signal, sys, time, weakref
from jaxship import cli
cli._handle_interrupts()

def ctrl_c_now():  # Ctrl-C arriving while a callback whose exceptions Python swallows runs
    if not cli._INTERRUPTED.is_set():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)  # the handler runs here, inside the callback

class Thing:
    pass

try:
    if sys.argv[1] == "gc":  # XLA's garbage-collection callback
        gc.callbacks.append(lambda phase, info: phase == "start" and ctrl_c_now())
        gc.collect()
    else:  # a weakref callback (WeakKeyDictionary's, as in CI's stop 74)
        thing = Thing()
        ref = weakref.ref(thing, lambda ref: ctrl_c_now())
        del thing
    time.sleep(2.0)
    print("went on")
except KeyboardInterrupt:
    print("interrupted", flush=True)
os._exit(0)  # before the watchdog
"""


@pytest.mark.parametrize("where", ["gc", "weakref"])
def test_ctrl_c_inside_a_callback_is_not_swallowed(where):
    """The trust audit (case 7): a SIGINT that landed in XLA's garbage-collection callback
    was swallowed ("Exception ignored in: <function _xla_gc_callback ...>
    KeyboardInterrupt", with a traceback) and the run went on; CI's stop 74 met the same in
    a weakref callback. `sys.unraisablehook` now raises it again once the main thread is
    out of the callback, and prints nothing."""
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    run = subprocess.run([sys.executable, "-c", SWALLOWED_INTERRUPT, where],
                         capture_output=True, text=True, env=env, timeout=120)
    assert run.stdout.strip() == "interrupted", (run.stdout, run.stderr)
    assert "Exception ignored" not in run.stderr and "Traceback" not in run.stderr, run.stderr


LONG_XLA_CALL = """
import jax
import jax.numpy as jnp
from jaxship import cli

def main(argv=None):  # one XLA computation of tens of seconds: Python's handler waits
    loop = jax.jit(lambda x: jax.lax.fori_loop(0, 2_000_000_000,
                                               lambda i, x: jnp.sin(x) + 1e-9, x))
    loop = loop.lower(jnp.float32(0.0)).compile()  # compiled before "started"
    print("started", flush=True)
    loop(jnp.float32(0.0)).block_until_ready()
    return 0

cli.main = main
cli.run()
"""


def test_ctrl_c_during_a_long_xla_computation_ends_the_command_within_grace():
    """The trust audit (case 7): on an Esso Osaka `discover`, SIGINT took up to 27 s to
    end the process: Python's signal handler, which started the watchdog, runs only
    once the main thread leaves the XLA computation it is in. The watchdog now starts
    from the signal's wakeup byte, so the command ends with 130 within `GRACE`."""
    import signal
    import subprocess
    import sys
    import time

    from jaxship.cli import GRACE

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    process = subprocess.Popen([sys.executable, "-c", LONG_XLA_CALL], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    assert process.stdout.readline().strip() == "started"
    time.sleep(1.0)  # running
    sent = time.monotonic()
    process.send_signal(signal.SIGINT)
    err = process.communicate(timeout=60)[1]
    took = time.monotonic() - sent
    assert process.returncode == 130, (process.returncode, err)
    assert took < GRACE + 2.0, took
    assert err.rstrip().endswith("jaxship: interrupted.") and "Traceback" not in err, err


def test_ctrl_c_after_the_results_ends_with_130_and_its_line():
    """The audit of the trust fixes: a Ctrl-C that lands after the command returned (it
    landed in the interpreter's teardown and killed the process by the signal without
    "jaxship: interrupted."; today there is no teardown, and the last step after the
    results is the stage report) ends with 130 and that line."""
    import signal
    import subprocess
    import sys
    import time

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    process = subprocess.Popen([sys.executable, "-c", AFTER_RESULTS], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    assert process.stdout.readline().strip() == "done"
    time.sleep(0.5)
    process.send_signal(signal.SIGINT)
    err = process.communicate(timeout=60)[1]
    assert process.returncode == 130, (process.returncode, err)
    assert err.rstrip().endswith("jaxship: interrupted.") and "Traceback" not in err, err


@pytest.mark.parametrize("profiled", [False, True])
def test_the_command_ends_without_the_interpreters_teardown(tmp_path, profiled):
    """Issue 70: after the results the command leaves at once with its status
    (`os._exit`), its output flushed: an exit hook (as JAX's own, which clears its
    backends and caches) does not run. Under a profiler (`python -m cProfile`), which
    writes its results at exit, the usual exit."""
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    marker = tmp_path / "teardown ran"
    done = subprocess.run([sys.executable, "-c", TEARDOWN, str(marker), str(profiled)],
                          capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 3 and done.stdout == "done\nunflushed", done
    assert "Traceback" not in done.stderr, done.stderr
    assert marker.exists() == profiled


AFTER_RESULTS = """
import time
from jaxship import cli

def main(argv=None):
    print("done", flush=True)
    return 0

cli.main = main
cli.CLOCK.report = lambda: time.sleep(5.0)  # slow, after the results
cli.run()
"""

TEARDOWN = """
import atexit, pathlib, sys
from jaxship import cli

marker, profiled = pathlib.Path(sys.argv[1]), sys.argv[2] == "True"
atexit.register(marker.write_text, "")  # the interpreter's teardown after the results
sys.argv[1:] = []
if profiled:
    sys.setprofile(lambda frame, event, arg: None)

def main(argv=None):
    print("done")
    sys.stdout.write("unflushed")
    return 3

cli.main = main
cli.run()
"""


SLOW_TO_START = """
import multiprocessing, time

if multiprocessing.parent_process() is not None:
    time.sleep(3.0)  # in the child, before it rebuilds the semaphores of its arguments

def job(queue):
    queue.put("started")
"""

CHILD_STARTING = """
import multiprocessing, sys, time
from jaxship import cli
import slow_to_start

def main(argv=None):
    context = multiprocessing.get_context("spawn")
    child = context.Process(target=slow_to_start.job, args=(context.Queue(),))
    child.start()
    try:  # the pid inside: a signal during print's return would land outside the try
        print(child.pid, flush=True)
        time.sleep(60)
    except KeyboardInterrupt:  # as the commands do
        print("jaxship: interrupted.", file=sys.stderr)
        return 130
    return 0

cli.main = main
cli.run()
"""

CHILD_STARTING_UNCAUGHT = """
import multiprocessing, time
from jaxship import cli
import slow_to_start

def main(argv=None):  # a Ctrl-C before the command's own handler (while parsing)
    context = multiprocessing.get_context("spawn")
    child = context.Process(target=slow_to_start.job, args=(context.Queue(),))
    child.start()
    print(child.pid, flush=True)
    time.sleep(60)
    return 0

cli.main = main
cli.run()
"""


@pytest.mark.parametrize("script", [CHILD_STARTING, CHILD_STARTING_UNCAUGHT],
                         ids=["caught by the command", "escaping main"])
def test_ctrl_c_while_a_worker_starts_leaves_no_worker_and_no_traceback(tmp_path, script):
    """`reproduce`'s Ctrl-C test on a loaded machine (CI of 2026-11-28): a spawned worker
    still importing when the command ended outlived it, found the semaphores of its
    arguments unlinked and printed a FileNotFoundError traceback after "jaxship:
    interrupted.". The command now kills its child processes as it ends. And a Ctrl-C
    that escapes `main` (CI of 2026-11-29: it came while `print` returned, before the
    `try`) ends alike, not with a KeyboardInterrupt traceback and status -2."""
    import signal
    import subprocess
    import sys
    import time

    (tmp_path / "slow_to_start.py").write_text(SLOW_TO_START)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), *sys.path]))
    process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    child = int(process.stdout.readline())
    process.send_signal(signal.SIGINT)
    err = process.communicate(timeout=60)[1]  # also waits for the child: it shares stderr
    assert process.returncode == 130, (process.returncode, err)
    assert err.rstrip().endswith("jaxship: interrupted.") and "Traceback" not in err, err
    time.sleep(0.5)
    stat = pathlib.Path(f"/proc/{child}/stat")
    assert not stat.exists() or stat.read_text().rsplit(")", 1)[1].split()[0] == "Z", child


@pytest.mark.parametrize("entry", ["_jaxship_cli", "jaxship.cli"])
@pytest.mark.parametrize("signum, status, line", [(2, 130, "jaxship: interrupted."),
                                                  (15, 143, "jaxship: terminated.")])
def test_a_signal_during_the_imports_ends_with_its_line_and_status(signum, status, line,
                                                                   entry):
    """Issue 57, case 8: Ctrl-C in the first second, while Python imports the package
    (jax's import takes seconds), printed a KeyboardInterrupt traceback, and SIGTERM had
    no handler at all (exit 143, no line). The console entry (`_jaxship_cli`, outside the
    package) handles both before those imports; so does `python -m jaxship.cli` (issue
    72: its handlers came after the imports, and Ctrl-C was swallowed inside JAX's
    import or ended in a traceback), which installs the same entry's handlers first."""
    import subprocess
    import sys
    import time

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    process = subprocess.Popen([sys.executable, "-m", entry, "vessels"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=env, cwd=pathlib.Path(cli.__file__).parents[2])
    time.sleep(0.3)  # the interpreter up, the package's imports under way
    process.send_signal(signum)
    out, err = process.communicate(timeout=60)
    assert process.returncode == status, (process.returncode, err)
    assert err.strip() == line and out == "", err


TERMINATED_COMMIT = """
import os, pathlib, sys, time
from jaxship import cli
from jaxship.cli import _files
from jaxship.cli import simulate

def slow(source, target):  # each rename of the commit takes a while
    print("rename", flush=True)
    time.sleep(0.2)
    os.rename(source, target)

def run(args):
    with _files.staged_folder(args.out) as stage:
        (stage / "trial.csv").write_text("new")
        (stage / "indices.json").write_text("new")
        _files.os.replace = slow
    return 0

simulate.run = run
sys.argv[1:] = ["simulate", "--vessel", "mariner", "--manoeuvre", "turn:35", "--out",
                sys.argv[1]]
cli.run()
"""


def test_sigterm_during_the_commit_ends_with_143_and_the_earlier_results_visible(tmp_path):
    """Issue 57, case 8: SIGTERM had no handler: the process died mid-commit with exit
    143 and no line, and the earlier results sat hidden in `.jaxship.PID.old.*` until
    the next run recovered them. SIGTERM now ends the command as Ctrl-C does: the commit
    undone, "jaxship: terminated.", exit 143, the earlier results where they were."""
    import signal
    import subprocess
    import sys

    earlier = {"trial.csv": "old", "indices.json": "old", "trial.png": "old"}
    with staged_folder(tmp_path) as stage:
        for name, text in earlier.items():
            (stage / name).write_text(text)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), JAXSHIP_CACHE_DIR="off")
    process = subprocess.Popen([sys.executable, "-c", TERMINATED_COMMIT, str(tmp_path)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=env)
    for _ in range(3):  # the journal written, two of the earlier files moved aside
        assert process.stdout.readline().strip() == "rename"
    process.send_signal(signal.SIGTERM)
    err = process.communicate(timeout=60)[1]
    assert process.returncode == 143, (process.returncode, err)
    assert err.rstrip().endswith("jaxship: terminated.") and "Traceback" not in err, err
    assert {p.name: p.read_text() for p in tmp_path.iterdir() if p.name != MANIFEST} == earlier


def test_numpy_warnings_reach_stderr_as_one_line(record, tmp_path, capsys, monkeypatch):
    """Issue 57: a `discover` mixing a Mariner held-out record with a thesis-vessel
    training record printed ten raw NumPy overflow warnings with source paths. Whatever
    the numerical libraries warn of during a command is now one line, without paths,
    saying what it likely means; the command's own outcome is unchanged."""
    import warnings

    def overflowing(*args, **kwargs):
        for _ in range(10):
            np.exp(np.full(3, 1000.0))  # "overflow encountered in exp", as the audit saw
        raise ValueError("the fit stopped")

    monkeypatch.setattr("jaxship.cli.identify.identify", overflowing)
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # Python's filters outside pytest: each warning once
        code = main(["identify", record, "--model", "nomoto1", "--out", str(tmp_path / "o")])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and err[1] == "jaxship: error: the fit stopped", err
    assert err[0].startswith("jaxship: warning: overflow encountered in exp (from the "), err
    assert "floating-point range" in err[0] and ".py" not in err[0]


# -- issue 57 (part A): records checked against themselves, float types, messages that say
# which option or column and what to do


def _rewritten(source, path, change, drop=()):
    """The trial CSV `source` written to `path` with `change({header: values})` applied
    and the columns `drop` left out."""
    headers = pathlib.Path(source).read_text().splitlines()[0].split(",")
    columns = dict(zip(headers, np.loadtxt(source, delimiter=",", skiprows=1).T))
    for header in drop:
        del columns[header]
    change(columns)
    rows = "".join(",".join(repr(float(v)) for v in row) + "\n" for row in zip(*columns.values()))
    pathlib.Path(path).write_text(",".join(columns) + "\n" + rows)
    return str(path)


def _scaled(header, factor):
    return lambda columns: columns.__setitem__(header, columns[header] * factor)


@pytest.mark.parametrize("header, factor, likely", [
    ("psi [deg]", math.pi / 180, "in rad rather than deg"),  # radians labelled deg
    ("r [deg/s]", math.pi / 180, "in rad/s rather than deg/s"),  # rad/s labelled deg/s
    ("t [s]", 1000.0, "in ms rather than s"),
])
def test_a_column_in_another_unit_is_refused_naming_it(record, tmp_path, capsys, header,
                                                       factor, likely):
    """A heading in radians labelled deg (before: psi fit 1.8 %, exit 0), time stamps in
    ms labelled s (before: T = 1820 s, exit 0): refused in one line naming the column and
    the unit it likely holds, nothing written."""
    bad = _rewritten(record, tmp_path / "bad.csv", _scaled(header, factor))
    assert main(["identify", bad, "--model", "nomoto1", "--out", str(tmp_path / "out")]) == 2
    line = _error_line(capsys)
    assert f"column '{header}'" in line and likely in line, line
    assert not (tmp_path / "out").exists()


def test_a_wrapped_heading_is_unwrapped_with_a_note(record, tmp_path, capsys):
    """A heading wrapped at +-180 deg without an r column: before, K came out many times
    too small (r differenced across the 360 deg jumps); now unwrapped, said in a note,
    and K as from the unwrapped record (Nomoto1 K = 0.06)."""
    def wrap(columns):
        columns["psi [deg]"] = (columns["psi [deg]"] + 170.0 + 180.0) % 360.0 - 180.0
    bad = _rewritten(record, tmp_path / "wrapped.csv", wrap, drop=("r [deg/s]",))
    assert np.any(np.abs(np.diff(np.loadtxt(bad, delimiter=",", skiprows=1)[:, 2])) > 300)
    out = tmp_path / "out"
    assert main(["identify", bad, "--model", "nomoto1", "--no-figures", "--quiet", "--out",
                 str(out)]) == 0
    err = capsys.readouterr().err
    assert "column 'psi [deg]' wraps around" in err and "unwrapped" in err, err
    K = json.loads((out / "result.json").read_text())["parameters"]["K"]["value"]
    assert K == pytest.approx(0.06, rel=0.05)


def test_a_record_too_short_to_determine_the_model_ends_with_its_code(record, tmp_path,
                                                                       capsys):
    """Three rows: before, exit 0 "successful" with correlation(K, T) = +1; now the code
    poorly_determined (exit 3) and a flag saying the record is too short."""
    short = tmp_path / "short.csv"
    short.write_text("".join(pathlib.Path(record).read_text().splitlines(True)[:4]))
    out = tmp_path / "out"
    assert main(["identify", str(short), "--model", "nomoto1", "--no-figures", "--quiet",
                 "--out", str(out)]) == 3
    err = capsys.readouterr().err
    assert "too few to determine the parameters" in err and "longer record" in err, err
    assert json.loads((out / "result.json").read_text())["fit"]["code"] == "poorly_determined"


def test_uniform_epoch_time_stamps_are_uniform(record, tmp_path, capsys):
    """10 Hz stamps of 1.7e9 s (Unix time): before, refused as "not uniform" (a relative
    tolerance below the float spacing); now fitted."""
    def at_10_hz(columns):  # the record five times faster, sampled every 0.1 s
        columns["t [s]"] = 1.7e9 + columns["t [s]"] / 5
        columns["r [deg/s]"] = columns["r [deg/s]"] * 5

    epoch = _rewritten(record, tmp_path / "epoch.csv", at_10_hz)
    assert main(["identify", epoch, "--model", "nomoto1", "--no-figures", "--quiet", "--out",
                 str(tmp_path / "out")]) == 0


def test_jittered_time_stamps_say_what_to_do(record, tmp_path, capsys):
    """Before: `np.float64(0.1039...)` and "resample the record first", which
    --sample-interval cannot do; now plain numbers and what to do instead."""
    jitter = np.random.default_rng(1).uniform(-0.05, 0.05, 400)
    bad = _rewritten(record, tmp_path / "jitter.csv", lambda c: c.__setitem__(
        "t [s]", c["t [s]"] + jitter))
    assert main(["identify", bad, "--model", "nomoto1", "--out", str(tmp_path / "out")]) == 2
    line = _error_line(capsys)
    assert "sampling is not uniform" in line and "np.float64" not in line, line
    assert "interpolate the record onto a uniform time grid" in line, line
    assert "--sample-interval keeps every k-th sample" in line, line


def test_armax_on_a_straight_run_names_the_rudder(record, tmp_path, capsys):
    """Before: "the input `u` is constant", `u` being the surge-speed column."""
    straight = _rewritten(record, tmp_path / "straight.csv", lambda c: [
        c.__setitem__(k, c[k] * 0) for k in ("delta [deg]", "psi [deg]", "r [deg/s]")])
    main(["identify", straight, "--model", "armax", "--no-figures", "--quiet", "--out",
          str(tmp_path / "out")])
    captured = capsys.readouterr()
    text = captured.out + captured.err
    assert "rudder input is constant" in text and "`u`" not in text, text


def test_a_sample_interval_beyond_the_record_names_the_option(record, tmp_path, capsys):
    """Before: an error that did not name --sample-interval."""
    assert main(["identify", record, "--model", "nomoto1", "--sample-interval", "1000",
                 "--out", str(tmp_path / "out")]) == 2
    line = _error_line(capsys)
    assert "--sample-interval 1000" in line and "choose an interval of at most" in line, line


def test_a_horizon_beyond_the_records_is_said(record, tmp_path, capsys):
    """Before: --horizon 10000 on a 200 s record accepted with no note."""
    assert main(["identify", record, "--model", "nomoto1", "--horizon", "10000", "--no-figures",
                 "--quiet", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "--horizon 10000 s) is not shorter than any training record" in out, out
    # issue 72: it said "(--horizon none)", whose fit estimates the first state
    assert "output error from each record's measured first state" in out
    options = json.loads((tmp_path / "out" / "result.json").read_text())["options"]
    assert options["initial"] == "measured"


def test_validating_on_the_training_record_is_said(record, tmp_path, capsys):
    """Before: reported as a held-out check, with nothing said."""
    copy = tmp_path / "copy.csv"
    copy.write_text(pathlib.Path(record).read_text())
    out = tmp_path / "out"
    assert main(["identify", record, "--model", "nomoto1", "--validate", str(copy),
                 "--no-figures", "--quiet", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert f"the validation record {copy} holds the samples of the training record" in said
    assert "no held-out check" in json.loads((out / "result.json").read_text())["notes"][0]


def test_the_operating_point_check_is_the_librarys_and_its_verbs_apply_it():
    """Issue 72 and the library-first rule: the command's check of speeds and propeller
    rates is `js.check_operating_point`, and `check_imo`, `StandardTrial.sized` and
    `evaluate_autopilot` apply it themselves."""
    thesis, mariner = js.get_vessel("thesis"), js.get_vessel("mariner")
    js.check_operating_point(thesis, rpms=[300.0, 500.0], speeds=[1.5])
    with pytest.raises(ValueError, match=r"^rpm 5: less than a tenth of the service "
                       r"propeller rate of RossVessel \(500 rpm\)"):
        js.check_operating_point(thesis, rpms=[5.0])
    with pytest.raises(ValueError, match="more than 10 times the service speed of mariner"):
        js.check_operating_point(mariner, speeds=[1e6], name="mariner")
    with pytest.raises(ValueError, match="no propeller model"):
        js.check_operating_point(mariner, rpms=[60.0])
    with pytest.raises(ValueError, match="rpm 5: less than a tenth"):
        js.indices.check_imo(thesis, rpm=5.0)
    with pytest.raises(ValueError, match="rpm 5: less than a tenth"):
        js.StandardTrial.parse("turn:35").sized(thesis, rpm=5.0)
    with pytest.raises(ValueError, match="rpm 5: less than a tenth"):
        js.evaluate_autopilot(js.Nomoto1(K=0.3, T=1.8), thesis, rpm=[5.0])
