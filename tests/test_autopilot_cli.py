"""`jaxship autopilot` (thesis ch. 5 on one identified model): the command end to end on a
Nomoto model identified from a simulated zig-zag of the thesis vessel, its bad-input
errors, the loader of `identify` results, the autopilot figure, and (slow) the
chapter-5 study and the `--tune` option."""

import json
import math
import os
import pathlib
import re

import jax
import jax.numpy as jnp
import matplotlib
import numpy as np
import pytest

import jaxship as js
from jaxship._workflow import _autopilot as study, _autopilot_text as study_text
from jaxship._workflow._autopilot_reference import (
    RudderDemand,
    ordered_error_deg,
    tune_reference,
)
from jaxship._workflow._identify import model_from_report, read_result
from jaxship.cli import main
from jaxship.plotting import plot_autopilot


matplotlib.use("Agg")

RUN_KEYS = ("controller", "rpm", "speed", "sum_abs_error_deg", "rms_error_deg",
            "max_overshoot_deg", "settling_time_s", "mean_abs_rudder_deg",
            "rudder_travel_deg", "time_rate_limited_s")


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """`jaxship identify` of a Nomoto 1 model on a 20/20 zig-zag of the thesis vessel at
    400 rpm: the result.json path."""
    root = tmp_path_factory.mktemp("identified")
    assert main(["simulate", "--vessel", "thesis", "--manoeuvre", "zigzag:20/20", "--rpm",
                 "400", "--out", str(root / "trial")]) == 0
    assert main(["identify", str(root / "trial" / "trial.csv"), "--model", "nomoto1",
                 "--out", str(root / "fit"), "--no-figures", "--quiet"]) == 0
    return root / "fit" / "result.json"


@pytest.fixture(scope="module")
def written(identified, tmp_path_factory):
    """`jaxship autopilot` at 300 and 500 rpm (neither used for the fit)."""
    out = tmp_path_factory.mktemp("autopilot") / "run"
    code = main(["autopilot", "--model", str(identified), "--vessel", "thesis", "--rpm", "300",
                 "500", "--out", str(out), "--quiet"])
    assert code == 0
    return out


def test_autopilot_writes_gains_runs_report_and_figures(written):
    result = json.loads((written / "autopilot.json").read_text())
    assert result["model"]["class"] == "Nomoto1" and result["vessel"] == "thesis"
    assert set(result["gains"]) == {"pid+ff", "pid"}
    for gains in result["gains"].values():
        assert all(math.isfinite(gains[k]) and gains[k] > 0 for k in ("kp", "ki", "kd"))
    assert result["gains"]["pid+ff"]["feedforward"] == "Nomoto1"
    assert result["gains"]["pid"]["feedforward"] is None
    # issue 61: the feed-forward's gains, and in the report the model it inverts and its
    # steady-turn gain where the step steers against the linear one (equal for Nomoto1);
    # by default (--steady-turn trial) its steady-turn part is scaled to the rudder the
    # vessel needs at the step's peak yaw rate, measured first, its acceleration part not
    ff, at_step = result["gains"]["pid+ff"], result["feedforward_at_step"]
    assert ff["ff_gain"] == 1.0 and at_step["model"] == "Nomoto1"
    assert at_step["vessel_rudder_deg"] > 0 and at_step["model_rudder_deg"] > 0
    assert ff["ff_steady_gain"] == pytest.approx(
        at_step["vessel_rudder_deg"] / at_step["model_rudder_deg"], rel=1e-12)
    peak = np.degrees(np.radians(45.0) * result["design"]["reference_frequency"] * 2
                      * np.exp(-2.0))
    assert at_step["peak_rate_deg_s"] == pytest.approx(peak, rel=1e-12)
    assert at_step["model_rudder_deg"] == pytest.approx(
        np.degrees(np.radians(peak) / result["model"]["parameters"]["K"]), rel=1e-6)
    report = (written / "report.md").read_text()
    said = re.search(r"inverts the Nomoto1 model\. .* a gain r/delta = (\S+) 1/s where the "
                     r"autopilot steers, against the identified model's linear gain 1/d = "
                     r"(\S+) 1/s", report)
    assert said, report[:2000]
    assert float(said[1]) == pytest.approx(float(said[2]), rel=1e-3)
    assert float(said[2]) == pytest.approx(result["model"]["parameters"]["K"], rel=1e-3)
    assert (f"The vessel steered needs {at_step['vessel_rudder_deg']:.3g} deg there" in report
            and f"scaled by g_s = {ff['ff_steady_gain']:.3g}" in report)
    assert result["model"]["fit_code"] == "successful"
    runs = result["runs"]
    assert [(r["controller"], r["rpm"]) for r in runs] == [
        ("pid+ff", 300.0), ("pid+ff", 500.0), ("pid", 300.0), ("pid", 500.0)]
    for run in runs:
        assert set(RUN_KEYS) <= set(run) and run["success"]
        assert all(math.isfinite(run[k]) for k in RUN_KEYS[1:])
    assert runs[0]["speed"] < runs[1]["speed"]  # 300 rpm is slower than 500 rpm
    # feed-forward from the identified model beats feedback only at rpm not fitted on
    by = {(r["controller"], r["rpm"]): r["sum_abs_error_deg"] for r in runs}
    for rpm in (300.0, 500.0):
        assert by["pid+ff", rpm] < by["pid", rpm]
    # the thesis' rudder limits, and the design's numbers
    assert result["design"]["max_rudder_deg"] == 45.0
    assert result["design"]["max_rudder_rate_deg_s"] == 15.0
    assert result["design"]["window_s"] == [100.0, 200.0]
    assert result["design"]["sample_interval"] == 1.0
    # report and figures; no temporary files left behind
    report = (written / "report.md").read_text()
    assert "| pid+ff | 300 |" in report and "K_p" in report
    # the trust audit (case 3): the report says how the design was chosen from the model
    assert "Chosen: omega_n = " in report and "from the model's yaw time constant T = " in report
    for figure in result["figures"]:
        assert f"]({figure})" in report
        assert (written / figure).stat().st_size > 20_000
    assert sorted(p.name for p in (written / "figures").iterdir()) == [
        "heading_300rpm.png", "heading_500rpm.png"]
    assert not [p for p in written.rglob("*") if p.name.endswith(".tmp")]


def test_autopilot_by_speed_with_a_port_step(identified, tmp_path):
    out = tmp_path / "speed"
    assert main(["autopilot", "--model", str(identified), "--vessel", "thesis", "--speed",
                 "1.1", "--step", "-30", "--out", str(out), "--quiet"]) == 0
    result = json.loads((out / "autopilot.json").read_text())
    assert result["design"]["step"] == -30.0
    assert [r["speed"] for r in result["runs"]] == [1.1, 1.1]
    assert all(300 < r["rpm"] < 400 for r in result["runs"])
    assert all(r["sum_abs_error_deg"] < 200 for r in result["runs"])
    assert (out / "figures" / "heading_1.1mps.png").exists()


def test_from_auto_the_poles_sit_on_the_linear_candidate(identified, written, tmp_path,
                                                         capsys):
    """Issue 61: `identify --model auto` on the same 20/20 zig-zag chooses Norrbin's model
    (its cubic fits the zig-zag better). `autopilot` from that result places the PID's
    poles on the linear Nomoto 1 fitted to the same records (kept in the selection): the
    gains are exactly those from `identify --model nomoto1`'s result. Its feed-forward
    inverts whichever candidate turns steadily nearer the vessel at the step's peak yaw
    rate (the trial), autopilot.json and the report say which model does what, and the
    feed-forward helps at 300 and 500 rpm (not fitted on) by issue 61's goal. A selection
    whose linear candidate cannot be rebuilt is a one-line error, nothing written."""
    fit = tmp_path / "auto"
    assert main(["identify", str(identified.parent.parent / "trial" / "trial.csv"), "--model",
                 "auto", "--out", str(fit), "--no-figures", "--quiet"]) == 0
    report = json.loads((fit / "result.json").read_text())
    assert report["selection"]["chosen"] == report["model"] == "nomoto1-norrbin"
    values = lambda parameters: {k: e["value"] for k, e in parameters.items()}
    kept = report["selection"]["candidates"]["nomoto1"]["fitted"]["parameters"]
    own = json.loads(identified.read_text())["parameters"]
    assert values(kept) == pytest.approx(values(own), rel=1e-12)
    out = tmp_path / "run"
    assert main(["autopilot", "--model", str(fit / "result.json"), "--vessel", "thesis",
                 "--rpm", "300", "500", "--out", str(out), "--quiet"]) == 0
    result = json.loads((out / "autopilot.json").read_text())
    linear = json.loads((written / "autopilot.json").read_text())
    assert result["model"]["feedback"] == "nomoto1"
    for name in ("pid+ff", "pid"):
        gains, own = result["gains"][name], linear["gains"][name]
        assert gains["feedback"] == "Nomoto1"
        for k in ("kp", "ki", "kd", "reference_frequency"):
            assert gains[k] == pytest.approx(own[k], rel=1e-9), k
    at_step = result["feedforward_at_step"]
    vessel, candidates = at_step["vessel_rudder_deg"], at_step["candidates"]
    assert set(candidates) == {"NonlinearNomoto", "Nomoto1"} and vessel > 0
    nearest = min(candidates, key=lambda c: abs(math.log(candidates[c] / vessel)))
    assert result["gains"]["pid+ff"]["feedforward"] == at_step["model"] == nearest
    text = (out / "report.md").read_text()
    assert "The PID's poles are placed on its linear candidate nomoto1 (K = " in text
    assert f"the {nearest}'s is the nearest to the vessel's" in text
    by = {(r["controller"], r["rpm"]): r for r in result["runs"]}
    for rpm in (300.0, 500.0):
        assert by["pid+ff", rpm]["sum_abs_error_deg"] <= 0.7 * by["pid", rpm]["sum_abs_error_deg"]
        assert by["pid+ff", rpm]["max_overshoot_deg"] <= 2.0
    broken = json.loads((fit / "result.json").read_text())
    broken["selection"]["candidates"]["nomoto1"]["fitted"]["parameters"]["K"] = "fast"
    (tmp_path / "broken.json").write_text(json.dumps(broken))
    capsys.readouterr()
    code = main(["autopilot", "--model", str(tmp_path / "broken.json"), "--vessel", "thesis",
                 "--rpm", "300", "--out", str(tmp_path / "no"), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and not (tmp_path / "no").exists()
    assert len(err.splitlines()) == 1 and "the linear candidate of its selection" in err, err


def _bad_cases(tmp_path, identified):
    bad_json = tmp_path / "bad.json"
    bad_json.write_text("{not json")
    other_json = tmp_path / "other.json"
    other_json.write_text('{"model": "nomoto1"}')
    armax = tmp_path / "armax.json"
    armax.write_text(json.dumps({"model": "armax", "model_class": "ARMAXModel",
                                 "parameters": {"a1": {"value": -1.0}}}))
    a_file = tmp_path / "a_file"
    a_file.write_text("keep")
    latin1 = tmp_path / "latin1.json"
    latin1.write_bytes('{"model": "nomoto1", "note": "Kr\u00e5ke"}'.encode("latin-1"))
    report = json.loads(pathlib.Path(identified).read_text())

    def crafted(name, change):
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps(report | change))
        return path

    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    model = ["--model", str(identified)]
    out = ["--out", str(tmp_path / "out")]
    return [
        (model + ["--vessel", "nope", "--rpm", "300"] + out, "Unknown vessel"),
        (model + ["--vessel", "thesis", "--rpm", "-300"] + out, "positive"),
        (model + ["--vessel", "thesis", "--speed", "0"] + out, "positive"),
        (model + ["--vessel", "thesis", "--rpm", "fast"] + out, "not a number"),
        # the trust audit: these ran, blew up and exited 0 with a table of "-"
        (model + ["--vessel", "thesis", "--speed", "1e6"] + out, "10 times the service speed"),
        (model + ["--vessel", "thesis", "--speed", "0.05"] + out,
         "less than a tenth of the service speed"),
        (model + ["--vessel", "thesis", "--rpm", "1e9"] + out, "10 times the service propeller"),
        (model + ["--vessel", "thesis", "--rpm", "300", "--speed", "1.0"] + out, "one of them"),
        # a vessel without a propeller holds only its nominal speed: 5 m/s on the Mariner
        # ran back to 7.7 m/s before the step and was reported as 5 m/s
        (model + ["--vessel", "mariner", "--speed", "5"] + out,
         "Mariner has no straight run at u = 5 m/s"),
        (model + ["--vessel", "thesis"] + out, "one of them"),
        (model + ["--vessel", "thesis", "--rpm", "300", "--step", "0"] + out, "step"),
        (["--model", str(tmp_path / "missing.json"), "--vessel", "thesis", "--rpm", "300"] + out,
         "cannot read"),
        (["--model", str(bad_json), "--vessel", "thesis", "--rpm", "300"] + out,
         "not valid JSON"),
        (["--model", str(other_json), "--vessel", "thesis", "--rpm", "300"] + out,
         "not an identify result"),
        (["--model", str(latin1), "--vessel", "thesis", "--rpm", "300"] + out,
         "not a text file"),
        (["--model", str(armax), "--vessel", "thesis", "--rpm", "300"] + out, "armax"),
        # crafted result.json files ended in AttributeError / RecursionError tracebacks, a
        # FIFO blocked forever
        (["--model", str(crafted("frozen", {"frozen": [1, 2]})), "--vessel", "thesis", "--rpm",
          "300"] + out, "'frozen' in the identify result is a list, not a dict"),
        (["--model", str(crafted("constants", {"constants": "L"})), "--vessel", "thesis",
          "--rpm", "300"] + out, "'constants' in the identify result is a str, not a dict"),
        (["--model", str(deep), "--vessel", "thesis", "--rpm", "300"] + out,
         "nested too deeply"),
        (["--model", str(fifo), "--vessel", "thesis", "--rpm", "300"] + out,
         "not a regular file"),
        (model + ["--vessel", "mariner", "--rpm", "60"] + out, "no propeller"),
        # issue 61: a model with a yaw time constant of 1e12 s (a fit the data did not
        # determine) asked for a run of 1e14 s and ended in an out-of-memory traceback
        (["--model", str(crafted("slow", {"parameters": {"K": 0.2, "T": 1e12}})), "--vessel",
          "thesis", "--rpm", "300"] + out, "samples of 0.1 s (at most 1e+06): omega_n = 1.25e-12"),
        # issue 72: K < 0 first asked for --natural-frequency; K = 1e-9 (T = 1.8 s) blamed
        # "so long a yaw time constant": each now names its cause first
        (["--model", str(crafted("against", {"parameters": {"K": -0.05, "T": 1.8}})),
          "--vessel", "thesis", "--rpm", "300"] + out,
         "error: the Nomoto1 model turns the ship against its rudder"),
        (["--model", str(crafted("deaf", {"parameters": {"K": 1e-9, "T": 1.8}})),
          "--vessel", "thesis", "--rpm", "300"] + out,
         "error: the Nomoto1 model barely answers its rudder: its steady yaw rate per radian "
         "of rudder, 1/d = 1e-09 1/s"),
        (model + ["--vessel", "thesis", "--rpm", "300", "--out", str(a_file)], "is a file"),
        (model + ["--vessel", "thesis", "--rpm", "300", "--out", str(a_file / "sub")],
         "is a file"),
    ]


def test_bad_input_is_one_line_a_non_zero_exit_and_writes_nothing(identified, tmp_path,
                                                                  capsys):
    capsys.readouterr()
    for args, message in _bad_cases(tmp_path, identified):
        before = sorted(p.name for p in tmp_path.rglob("*"))
        assert main(["autopilot", *args, "--quiet"]) == 2, args
        captured = capsys.readouterr()
        err = captured.err.strip()
        assert err.startswith("jaxship: error:") and "\n" not in err, (args, err)
        assert message in err, (args, err)
        assert captured.out == ""
        assert sorted(p.name for p in tmp_path.rglob("*")) == before, args
    assert (tmp_path / "a_file").read_text() == "keep"


def test_a_closed_loop_that_blew_up_exits_3_and_says_so(identified, tmp_path, capsys,
                                                        monkeypatch):
    """A run whose simulation did not stay finite (`success` false: the trust audit's
    --speed 1e6, now refused before any work) is not a success: exit 3, and the report
    says so first, under its title."""
    evaluate = js.evaluate_autopilot

    def blown(*args, **kwargs):
        evaluation = evaluate(*args, **kwargs)
        evaluation.rows[0]["success"] = False
        return evaluation

    monkeypatch.setattr(js, "evaluate_autopilot", blown)
    out = tmp_path / "run"
    assert main(["autopilot", "--model", str(identified), "--vessel", "thesis", "--rpm", "300",
                 "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "The closed loop blew up (not finite) for pid+ff at 300 rpm" in err
    title, blank, first = (out / "report.md").read_text().splitlines()[:3]
    assert title.startswith("#") and blank == "" and first.startswith("**The closed loop blew")
    assert json.loads((out / "autopilot.json").read_text())["runs"]


def test_a_model_whose_fit_did_not_succeed_is_flagged_and_exits_3(identified, tmp_path, capsys):
    """Issue 57, case 3: a result whose code is `poorly_determined` (K and T at their start
    values) gave an autopilot, exit 0, and neither report nor JSON named the fit's code.
    Now the code is read: a fit that did not succeed is said first in
    the report and on stderr, is in autopilot.json, and the exit status is 3. (A model
    written by hand, with no fit, is taken as it is: `test_the_mariner_at_the_defaults`.)"""
    report = json.loads(pathlib.Path(identified).read_text())
    report["fit"] |= {"code": "poorly_determined", "success": False}
    model = tmp_path / "result.json"
    model.write_text(json.dumps(report))
    out = tmp_path / "run"
    assert main(["autopilot", "--model", str(model), "--vessel", "thesis", "--rpm", "300",
                 "--out", str(out), "--quiet"]) == 3
    code = "poorly_determined"
    assert f"not a converged estimate (code {code} in {model})" in capsys.readouterr().err
    title, blank, first = (out / "report.md").read_text().splitlines()[:3]
    assert first.startswith("**The model's fit is not a converged estimate")
    assert json.loads((out / "autopilot.json").read_text())["model"]["fit_code"] == code


@pytest.mark.skipif(not os.path.isdir("/proc") or os.name != "posix", reason="needs /proc")
def test_an_unwritable_output_folder_is_refused_before_the_runs(identified, capsys):
    code = main(["autopilot", "--model", str(identified), "--vessel", "thesis", "--rpm", "300",
                 "--out", "/proc/jaxship-autopilot-test", "--quiet"])
    assert code == 2
    assert "cannot write" in capsys.readouterr().err


# ------------------------------------------------------------------------------ the loader


def test_the_loader_rebuilds_the_fitted_model(identified):
    model, report = read_result(identified)
    assert isinstance(model, js.Nomoto1)
    assert float(model.K) == report["parameters"]["K"]["value"]
    assert float(model.T) == report["parameters"]["T"]["value"]
    assert read_result(identified.parent)[0] == model  # the folder works too


def test_the_loader_rebuilds_ross_with_its_reference_scales():
    values = dict(n_ur=-0.9, n_delta=-0.7, n_rrr=0.1)
    report = {"model": "ross-autopilot", "model_class": "RossAutopilot",
              "parameters": {k: {"value": v} for k, v in values.items()},
              "frozen": {"n_delta_nn": 0.0}, "constants": {"length": 4.0, "speed": 1.5,
                                                           "rate": 8.0}}
    model = model_from_report(report)
    assert isinstance(model, js.RossAutopilot)
    assert (model.length, model.speed, model.rate, model.n_rrr) == (4.0, 1.5, 8.0, 0.1)
    # results written before "constants": the reference scales from the start's note
    del report["constants"]
    report["notes"] = ["RossAutopilot reference scales (frozen): L = 4 m, U0 = 1.5 m/s, n0 = 8 "
                       "rev/s; the estimates are ..."]
    assert model_from_report(report) == model
    report["notes"] = []
    with pytest.raises(ValueError, match="reference scales"):
        model_from_report(report)


def test_the_loader_rebuilds_a_vessel_preset_with_its_estimates():
    vessel = js.get_vessel("thesis")
    report = {"model": "thesis", "model_class": "RossVessel",
              "parameters": {"n_ur": {"value": 2 * float(vessel.n_ur)}}, "frozen": {}}
    model = model_from_report(report)
    assert isinstance(model, js.RossVessel) and float(model.n_ur) == 2 * float(vessel.n_ur)
    report["parameters"]["n_ur"]["value"] = None
    with pytest.raises(ValueError, match="not a number"):
        model_from_report(report)


# ------------------------------------------------------------------------------ the figure


def _record(steps=2, points=3):
    t = np.arange(0.0, 20.01, 0.5)
    ordered = np.where(t >= 5.0, 0.5, 0.0)
    shape = lambda x: jnp.broadcast_to(jnp.asarray(x), (steps, points, t.size))
    return js.ClosedLoop(t=jnp.asarray(t), psi=shape(0.9 * ordered), psi_d=shape(ordered),
                         psi_ref=shape(ordered), r=shape(0 * t), r_d=shape(0 * t),
                         delta=shape(0.1 * ordered), delta_c=shape(0.1 * ordered),
                         speed=jnp.ones(points), max_rate=jnp.ones(steps),
                         control_period=jnp.ones(steps), result=js.RESULTS.successful)


def test_plot_autopilot_draws_heading_error_rudder_with_limits_and_outside_legends():
    fig = plot_autopilot(_record(), index=1, others=[_record(1)], labels=["a", "b", "c"],
                         max_angle=np.deg2rad(45.0), window=(0.0, 20.0), title="t")
    heading, error, rudder = fig.axes[:3]
    assert len(heading.get_lines()) == 2 + 3  # ordered, desired, three actual headings
    assert np.isclose(np.max(error.get_lines()[0].get_ydata()), np.rad2deg(0.05))
    assert sorted({line.get_ydata()[0] for line in rudder.get_lines()
                   if line.get_linestyle() == "--"}) == [-45.0, 45.0]
    fig.canvas.draw()
    for ax in (heading, error, rudder):  # each legend lies right of its axes
        legend = ax.get_legend().get_window_extent()
        assert legend.x0 >= ax.get_window_extent().x1
    matplotlib.pyplot.close(fig)
    with pytest.raises(ValueError, match="labels"):
        plot_autopilot(_record(), labels=["only one"])


# ------------------------------------------------------------------------------ slow tier


@pytest.mark.slow
def test_tune_adds_a_tuned_controller_that_tracks_better(identified, tmp_path):
    out = tmp_path / "tuned"
    assert main(["autopilot", "--model", str(identified), "--vessel", "thesis", "--rpm", "300",
                 "500", "--out", str(out), "--tune", "--quiet"]) == 0
    result = json.loads((out / "autopilot.json").read_text())
    tuned = result["gains"]["tuned"]
    assert tuned["objective_after"] < tuned["objective_before"]
    by = {(r["controller"], r["rpm"]): r["rms_error_deg"] for r in result["runs"]}
    assert all(by["tuned", rpm] < by["pid+ff", rpm] for rpm in (300.0, 500.0))
    # issue 61 point 2: the reference bandwidth, tuned against the ordered heading within
    # the rudder's limits, and the error against the step not worse than the untuned's
    assert tuned["reference_frequency"] == tuned["reference_frequency_after"]
    assert tuned["reference_frequency_after"] <= tuned["reference_frequency_top"]
    assert tuned["ordered_objective_after"] <= tuned["ordered_objective_before"]
    ordered = {(r["controller"], r["rpm"]): r["sum_abs_error_ordered_deg"]
               for r in result["runs"]}
    assert all(ordered["tuned", rpm] <= ordered["pid+ff", rpm] for rpm in (300.0, 500.0))
    assert "reference model's bandwidth omega" in (out / "report.md").read_text()


def test_the_default_design_follows_the_models_time_constant():
    """The trust audit's Mariner case: omega_n = 0.5 rad/s (the 4 m thesis model's) put a
    160 m ship's rudder on its limits. `auto` takes omega_n = 1.25 / T from the model's
    yaw time constant, capped at half the servo bandwidth, and scales the reference and
    the timing with it; on the thesis vessel it gives the thesis' own numbers."""
    mariner, thesis = js.get_vessel("mariner"), js.get_vessel("thesis")
    omega, basis = study.natural_frequency_for(js.Nomoto1(K=0.033, T=21.0), mariner,
                                               speed=7.7, n=0.0)
    assert omega == pytest.approx(1.25 / 21.0) and "T = 21 s" in basis
    design = js.AutopilotDesign.scaled(omega, basis=basis)
    assert design.reference_frequency == pytest.approx(0.4 * omega)
    assert (design.step_time, design.duration) == (840.0, 1680.0)
    omega, basis = study.natural_frequency_for(js.Nomoto1(K=0.2, T=2.0), thesis,
                                               speed=1.5, n=6.0)
    assert omega == 0.5 and "half the servo bandwidth" in basis
    default = js.AutopilotDesign()
    scaled = js.AutopilotDesign.scaled(0.5)
    assert (scaled.reference_frequency, scaled.step_time, scaled.duration) == (
        default.reference_frequency, default.step_time, default.duration)


def test_the_default_design_keeps_the_feedforward_within_the_rudders_limits():
    """Trust audit, case 3: the bandwidth also follows the rudder's limits. On the KVLCC2
    (its own equations as the model, 35 deg and 15.8 deg/s) 1.25 / T would ask the
    feed-forward of a 45 deg step for more rudder than half the limits; the design takes
    the frequency at which the reference model (stepped by `ReferenceModel`, not the
    closed form) asks for exactly half of one limit and less of the other, and says so."""
    kvlcc2 = js.get_vessel("kvlcc2")
    u0, n0 = study.operating_point(kvlcc2, speed=float(kvlcc2.nominal_speed))
    omega, basis = study.natural_frequency_for(kvlcc2, kvlcc2, speed=u0, n=n0, step=45.0)
    m, d = (float(x) for x in js.yaw_inertia(kvlcc2, speed=u0, n=n0))
    assert omega < 1.25 * abs(d / m) and "within half the rudder's limits" in basis
    reference, h = js.ReferenceModel(natural_frequency=0.4 * omega), 0.01 / (0.4 * omega)
    step = lambda state, _: (reference.step(state, np.radians(45.0), h),) * 2
    _, r_d, a_d = np.asarray(jax.lax.scan(step, jnp.zeros(3), length=3000)[1]).T
    rudder = m * a_d + d * r_d
    shares = (np.max(np.abs(rudder)) / float(kvlcc2.rudder.max_angle),
              np.max(np.abs(np.diff(rudder) / h)) / float(kvlcc2.rudder.max_rate))
    assert max(shares) == pytest.approx(0.5, rel=1e-3) and min(shares) < 0.5


def test_a_rudder_on_its_limits_is_a_code_and_a_sentence(identified, tmp_path, capsys):
    """omega_n = 5 rad/s and a 180 deg step on the thesis vessel: the ship cannot turn
    that fast and the rudder sits at its limit for most of the window; the report says
    so first and stderr warns. The ship is still 140 deg off the ordered heading at the
    end of the 10 s window: since issue 72 such a run is not_settled, not only
    rudder_saturated, and the command exits 3 (it exited 0). The model file gives its
    parameters as bare numbers, which the loader accepts (the trust audit: the command
    then ended in a TypeError traceback)."""
    report = json.loads(identified.read_text())
    report["parameters"] = {k: e["value"] for k, e in report["parameters"].items()}
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(report))
    out = tmp_path / "fast"
    assert main(["autopilot", "--model", str(bare), "--vessel", "thesis", "--rpm",
                 "400", "--natural-frequency", "5", "--step", "180", "--out", str(out),
                 "--quiet"]) == 3
    written = json.loads((out / "autopilot.json").read_text())
    assert written["model"]["parameters"] == report["parameters"]
    runs = written["runs"]
    assert {r["code"] for r in runs} == {"not_settled"}
    assert all(r["end_error_deg"] > 0.05 * 180.0 for r in runs)
    assert all(r["time_saturated_s"] > 0.5 * 10.0 for r in runs)  # window 10-20 s
    head = (out / "report.md").read_text().split("##")[0]
    assert "The rudder sat at its limit" in head and "code not_settled" in head
    # issue 61: no steady turn at the 180 deg step's peak rate; the model's own, said so
    at_step = written["feedforward_at_step"]
    assert at_step["vessel_rudder_deg"] is None and at_step["steady_gain"] == 1.0
    assert written["gains"]["pid+ff"]["ff_steady_gain"] == 1.0
    assert ("did not settle on the reverse-spiral trial's yaw rates" in at_step["trial_failed"]
            and "steady-turn part stays the model's" in (out / "report.md").read_text())
    assert "warning: The rudder sat at its limit" in capsys.readouterr().err


@pytest.mark.slow  # 20 s: two fits on 12160 samples, two trials and four closed loops
def test_the_kvlcc2_from_auto_meets_issue_61s_goal(tmp_path):
    """Issue 61's goal on measured records: `identify --model auto` on HSVA's KVLCC2
    zig-zags 10/5, 20/5, 10/10 P and 20/10 P chooses Norrbin's model with n1 < 0 (an
    unstable spiral, its loop to about 1.3 deg/s). `autopilot` with its defaults on the
    `kvlcc2` preset (an MMG model not fitted to these records) at 600 and 711 rpm places
    the poles on the linear candidate. At the step's peak yaw rate the Norrbin model turns
    steadily with a rudder of the other sign than the preset's (-0.73 against +0.03 deg;
    nearer in value than the linear candidate's +1.31 deg), so the feed-forward inverts
    the linear candidate, and PID+FF's summed error is at most 0.7 times PID's (measured
    0.64 and 0.63) with at most 2 deg overshoot. Before: the poles and the feed-forward on
    the Norrbin model gave 0.87 and 0.89."""
    root = js.shared_data_dir()
    folder = None if root is None else root / "kvlcc2_simman2008_hsva"
    if folder is None or not folder.is_dir():
        pytest.skip("measured data (../shared/data) not available")
    runs = ("Z_10_05", "Z_20_05", "Z_10_10_P", "Z_20_10_P")
    fit, out = tmp_path / "fit", tmp_path / "run"
    assert main(["identify", *(str(folder / f"HSVA_CPMC_KVLCC2_{r}.dat") for r in runs),
                 "--model", "auto", "--out", str(fit), "--no-figures", "--quiet"]) == 0
    report = json.loads((fit / "result.json").read_text())
    assert report["model"] == "nomoto1-norrbin" and report["parameters"]["n1"]["value"] < 0
    assert main(["autopilot", "--model", str(fit / "result.json"), "--vessel", "kvlcc2",
                 "--rpm", "600", "711", "--out", str(out), "--quiet"]) == 0
    result = json.loads((out / "autopilot.json").read_text())
    at_step, gains = result["feedforward_at_step"], result["gains"]
    assert gains["pid"]["feedback"] == gains["pid+ff"]["feedforward"] == "Nomoto1"
    vessel, norrbin = at_step["vessel_rudder_deg"], at_step["candidates"]["NonlinearNomoto"]
    assert norrbin < 0 < vessel < at_step["model_rudder_deg"] == at_step["candidates"]["Nomoto1"]
    assert abs(norrbin - vessel) < at_step["model_rudder_deg"] - vessel  # nearer, other sign
    by = {(r["controller"], r["rpm"]): r for r in result["runs"]}
    for rpm in (600.0, 711.0):
        assert by["pid+ff", rpm]["sum_abs_error_deg"] <= 0.7 * by["pid", rpm]["sum_abs_error_deg"]
        assert by["pid+ff", rpm]["max_overshoot_deg"] <= 2.0


@pytest.mark.slow
def test_the_mariner_at_the_defaults(tmp_path):
    """Issue 31 point 3 on the Mariner (Nomoto 1 from a 20/20 zig-zag: K = 0.033 1/s,
    T = 21 s) at the defaults: omega_n = 1.25 / T, the reference model slower than the
    loop (0.4 omega_n), the step and the window in proportion (840 s, 840-1680 s), and the
    rudder far from its limit (it sat there at omega_n = 0.5 rad/s). The zig-zag's
    Nomoto gain is several times below the Mariner's at the 1-3 deg rudder of this
    heading change (issue 61: inside its spiral loop): the model's own feed-forward
    (--steady-turn model) makes the tracking worse than feedback alone, and the report
    says so with the numbers; the default scales its steady-turn part to the rudder the
    Mariner needs at the step's peak yaw rate, and then the feed-forward helps (issue
    61's goal: at most 0.7 times pid's summed error, overshoot at most 2 deg); with the
    Mariner's own equations as the model the same feed-forward beats feedback only."""
    report = tmp_path / "nomoto.json"
    report.write_text(json.dumps({"model": "nomoto1", "model_class": "Nomoto1",
                                  "parameters": {"K": {"value": 0.033}, "T": {"value": 21.0}},
                                  "frozen": {}}))
    results = {}
    for mode in ("model", "trial"):
        out = tmp_path / mode
        assert main(["autopilot", "--model", str(report), "--vessel", "mariner", "--speed",
                     "7.7", "--steady-turn", mode, "--out", str(out), "--quiet"]) == 0
        results[mode] = json.loads((out / "autopilot.json").read_text()), out
    result, out = results["model"]
    d = result["design"]
    assert d["natural_frequency"] == pytest.approx(1.25 / 21.0)
    assert d["reference_frequency"] == pytest.approx(0.4 * d["natural_frequency"])
    assert d["window_s"] == [840.0, 1680.0]
    runs = {r["controller"]: r for r in result["runs"]}
    for r in runs.values():
        assert r["code"] == "successful" and r["time_saturated_s"] == 0.0
        assert r["mean_abs_rudder_deg"] < 0.1 * d["max_rudder_deg"]
    ff, fb = runs["pid+ff"], runs["pid"]
    assert ff["sum_abs_error_deg"] > fb["sum_abs_error_deg"]  # not hidden: stated
    text = (out / "report.md").read_text()
    assert (f"pid+ff {ff['sum_abs_error_deg']:.1f} against pid {fb['sum_abs_error_deg']:.1f} "
            "deg") in text and "**The feed-forward makes the tracking worse**" in text
    # why: the model's steady-turn rudder at the step's peak rate against the Mariner's
    at_step = result["feedforward_at_step"]
    assert at_step["model_rudder_deg"] > 2 * at_step["vessel_rudder_deg"] > 0
    assert "steady_gain" not in at_step and "The vessel steered needs" in text
    # the default: the steady-turn part from the trial; the same feedback gains
    result, out = results["trial"]
    assert result["gains"]["pid"] == results["model"][0]["gains"]["pid"]
    assert result["feedforward_at_step"]["steady_gain"] == pytest.approx(
        at_step["vessel_rudder_deg"] / at_step["model_rudder_deg"], rel=1e-9)
    runs = {r["controller"]: r for r in result["runs"]}
    assert runs["pid+ff"]["sum_abs_error_deg"] <= 0.7 * runs["pid"]["sum_abs_error_deg"]
    assert runs["pid+ff"]["max_overshoot_deg"] <= 2.0
    # the Mariner's own equations as the model: the feed-forward works at the defaults
    mariner = js.get_vessel("mariner")
    u0, n0 = study.operating_point(mariner, speed=7.7)
    omega, basis = study.natural_frequency_for(mariner, mariner, speed=u0, n=n0)
    own = study.evaluate(mariner, mariner, speeds=[7.7], design=js.AutopilotDesign.scaled(omega))
    by = {r["controller"]: r for r in own.rows}
    assert by["pid+ff"]["code"] == "successful"
    assert by["pid+ff"]["sum_abs_error_deg"] < 0.2 * by["pid"]["sum_abs_error_deg"]


@pytest.mark.slow
def test_the_steady_turn_trial_on_a_plant_that_is_not_the_design_model():
    """Issue 61 point 3: the loop closed on a plant the design model does not describe,
    the thesis vessel with a hidden rudder offset of 2 deg (an effect of the discovery
    tests, `jaxship.effects.RudderOffset`), steered from a Nomoto 1 with the vessel's
    yaw inertia per rudder angle m = T/K but a third of its linear gain (a zig-zag's
    gain for a ship more responsive at small rudder). The model's own feed-forward
    orders three times the steady-turn rudder the step needs and tracks worse than
    feedback alone; scaled by the trial it helps (issue 61's goal, at 400 rpm)."""
    thesis = js.get_vessel("thesis")
    plant = js.augment(thesis, js.effects.RudderOffset(np.radians(2.0)))
    u0, n0 = study.operating_point(thesis, rpm=400.0)
    m, d = (float(x) for x in js.yaw_inertia(thesis, speed=u0, n=n0))
    model = js.Nomoto1(K=1 / (3 * d), T=m / d)
    ratio = {}
    for mode in ("model", "trial"):
        evaluation = study.evaluate(model, plant, rpm=[400.0], steady_turn=mode)
        by = {r["controller"]: r for r in evaluation.rows}
        assert all(r["code"] == "successful" for r in evaluation.rows)
        ratio[mode] = by["pid+ff"]["sum_abs_error_deg"] / by["pid"]["sum_abs_error_deg"]
        overshoot = by["pid+ff"]["max_overshoot_deg"]
    assert ratio["model"] > 1.0
    assert ratio["trial"] <= 0.7 and overshoot <= 2.0
    at_step = evaluation.feedforward_at_step
    assert 0 < at_step["steady_gain"] < 1.0


@pytest.mark.slow  # 16 s: two closed loops and two open ones on the thesis vessel
def test_the_steady_turn_trial_measures_the_vessels_steady_turn():
    """`vessel_steady_rudder` (issue 61) against the open loop: the thesis vessel (course-
    stable) held at the measured rudder, +- it, turns steadily at the step's peak desired
    yaw rate within 2 %; a trial too short to settle is refused with a sentence."""
    thesis, design = js.get_vessel("thesis"), js.AutopilotDesign()
    u0, n0 = study.operating_point(thesis, rpm=400.0)
    pid = study.design_controllers(js.Nomoto1(K=0.2, T=2.5), thesis, design, speed=u0,
                                   n=n0)["pid"]
    rudder = study.vessel_steady_rudder(thesis, pid, design, rpm=400.0)
    x0 = js.straight_run(thesis, n=400.0 / 60.0)
    rates = [float(js.simulate(thesis, js.Turn(s * rudder, duration=150.0, dt=0.5),
                               x0).state.r[-1]) for s in (1, -1)]
    assert (rates[0] - rates[1]) / 2 == pytest.approx(study.peak_reference_rate(design),
                                                      rel=0.02)
    short = js.AutopilotDesign(step_time=1.0, duration=4.0)
    with pytest.raises(ValueError, match="did not settle on the reverse-spiral trial"):
        study.vessel_steady_rudder(thesis, pid, short, rpm=400.0)


def test_the_tuned_reference_bandwidth_stays_within_the_rudder_and_tracks_the_step_better():
    """Issue 61 point 2 (`autopilot --tune`): the reference model's bandwidth tuned against
    the ordered heading on a plant that is not the design model (a Norrbin ship with a
    cubic yaw damping, steered from a Nomoto 1 with its linear gain and time constant),
    the rudder 35 deg and 5 deg/s. The tuned feed-forward of the 45 deg step, stepped
    through `ReferenceModel` and the Nomoto inverse m a_d + d r_d (not the tuner's own
    bisection), stays within half of both limits and touches one of them (the faster
    reference pays against the step until the rudder stops it); its summed error against
    the step is below the untuned design's, whose reference is slower."""
    plant = js.NonlinearNomoto(K=0.1, T=10.0, n3=400.0)  # H(r) = r + 400 r^3
    model = js.Nomoto1(K=0.1, T=10.0)
    limits = (np.radians(35.0), np.radians(5.0))
    step = js.HeadingSteps(times=(50.0,), headings=(np.radians(45.0),))
    start = js.design_autopilot(model, natural_frequency=0.125, speed=5.0,
                                reference=js.ReferenceModel(natural_frequency=0.05),
                                steps=step, max_angle=limits[0], max_rate=limits[1])
    state = js.ShipState(u=5.0, v=0.0, r=0.0, x=0.0, y=0.0, psi=0.0, delta=0.0, n=0.0)
    demand = RudderDemand(state, np.radians(45.0), *limits)
    tuned, summary = tune_reference(plant, start, demand, duration=400.0, dt=1.0,
                                    rudder_weight=0.1, run_kw={"speeds": [5.0]})
    w, g = float(tuned.reference.natural_frequency), float(tuned.feedforward.gain)
    assert w == summary["reference_frequency_after"] and w > 0.05
    reference, h = js.ReferenceModel(natural_frequency=w), 0.01 / w
    scan = lambda s, _: (reference.step(s, np.radians(45.0), h),) * 2
    _, r_d, a_d = np.vstack([np.zeros(3), jax.lax.scan(scan, jnp.zeros(3), length=3000)[1]]).T
    rudder = g * model.T / model.K * a_d + r_d / model.K  # g_s = 1
    shares = (np.max(np.abs(rudder)) / limits[0],
              np.max(np.abs(np.diff(rudder) / h)) / limits[1])
    assert max(shares) == pytest.approx(0.5, rel=1e-3)
    runs = js.closed_loop(plant, [start, tuned], speeds=[5.0], duration=400.0, dt=0.1)
    before, after = ordered_error_deg(runs, 1.0, (50.0, 400.0))[:, 0]
    assert after < before, summary


def test_a_loop_that_never_settles_is_not_settled_and_exits_3(tmp_path, capsys):
    """Issue 72, "Broken 5": from a model with K = 1e-9 1/s and --natural-frequency 0.3
    the gains are K_p = 1.6e8 and the heading never settles (it was exit 0, code
    successful, nothing on stderr): every run's code is not_settled, the heading error
    over the window's last tenth beyond 5 % of the 45 deg step, and the command exits 3
    with one line on stderr."""
    model = tmp_path / "tiny_k.json"
    model.write_text(json.dumps({"model": "nomoto1", "model_class": "Nomoto1", "frozen": {},
                                 "parameters": {"K": {"value": 1e-9}, "T": {"value": 1.8}}}))
    out = tmp_path / "run"
    assert main(["autopilot", "--model", str(model), "--vessel", "thesis", "--rpm", "350",
                 "--natural-frequency", "0.3", "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert "did not settle (code not_settled)" in err[-1], err
    # and first, that no ship has such a K (the audit of 2026-12-07)
    assert all(line.startswith("jaxship: warning: ") for line in err[:-1]), err
    assert any("|K T| = 1.8e-09" in line for line in err[:-1]), err
    runs = json.loads((out / "autopilot.json").read_text())["runs"]
    assert {r["code"] for r in runs} == {"not_settled"}
    assert all(r["end_error_deg"] > 0.05 * 45.0 for r in runs)


@pytest.mark.parametrize("k_scale, t_scale, said", [
    (1000.0, 1.0, "the rudder in rad labelled deg"), (1e-3, 1000.0, "is t in ms labelled s")])
def test_a_hand_edited_result_beyond_what_ships_do_is_said(identified, tmp_path, capsys,
                                                           k_scale, t_scale, said):
    """The audit of 2026-12-07: `identify` warns of an implausible K or T, but a
    result.json edited by hand afterwards went into `autopilot` and `simulate` with no
    word. Both now check it by `implausible`'s ranges, against the plant's length and
    service speed where they have one (`autopilot` after its runs, so that a refusal
    stays one line: with its own design, T of 2,270 s is refused as too slow a ship;
    `simulate` after its trial, or in its refusal's line where the trial is beyond any
    ship's: K times 1000 turns at 214 deg/s, which no trial file may hold).
    K times 57.3 alone, the audit's case, stays inside the ranges on the thesis vessel:
    K' = 37, the range ends at 40."""
    report = json.loads(pathlib.Path(identified).read_text())
    report["parameters"]["K"]["value"] *= k_scale
    report["parameters"]["T"]["value"] *= t_scale
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(report))
    main(["autopilot", "--model", str(edited), "--vessel", "thesis", "--rpm", "400",
          "--natural-frequency", "0.5", "--out", str(tmp_path / "ap"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert any(line.startswith(f"jaxship: warning: {edited}: ") and said in line
               for line in err), err
    main(["simulate", "--vessel", str(edited), "--manoeuvre", "zigzag:20/20", "--out",
          str(tmp_path / "zz")])
    err = capsys.readouterr().err  # a warning, or in the refusal (a trial beyond any ship)
    assert str(edited) in err and said in err, err


def test_a_ship_that_turns_away_is_not_settled():
    """A closed loop whose ship turns away from the ordered heading (issue 72: a ship that
    circled passed it by 4e8 deg with a saturation warning only): the thesis vessel
    steered by the PID of its Nomoto model with the sign of every gain reversed turns
    away with its rudder hard over and ends near the opposite heading (its wrapped error
    is then stable), 190 deg off in the unwrapped heading the band is judged on: its run
    is not_settled and the failure sentence says so."""
    vessel = js.get_vessel("thesis")
    design = js.AutopilotDesign.scaled(0.5)
    pid = js.design_autopilot(js.Nomoto1(K=0.3, T=2.6), plant=vessel, rpm=[350.0],
                              design=design, feedforward=False)
    reversed_pid = eqx_negate(pid)
    run = js.closed_loop(vessel, reversed_pid, duration=design.duration, dt=design.dt,
                         rpm=[350.0])
    rows = study.run_rows("pid", run, design, [350.0], [1.0], float(vessel.rudder.max_angle))
    assert rows[0]["success"] and rows[0]["code"] == "not_settled", rows[0]
    assert rows[0]["end_error_deg"] > 90.0  # turned away, not swinging about the order
    failure, _ = study_text.problems(rows)
    assert "did not settle (code not_settled) for pid at 350 rpm" in failure


def eqx_negate(pid):
    """`pid` with its gains K_p, K_i, K_d of the other sign."""
    import equinox as eqx

    return eqx.tree_at(lambda a: (a.kp, a.ki, a.kd), pid, (-pid.kp, -pid.ki, -pid.kd))
