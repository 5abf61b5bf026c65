"""`jaxship simulate` gives the numbers it gave before the trials and the IMO check moved
into the library (issue 68; `tests/golden/simulate.json`, written at commit 91cbe21 by
`tests/golden/simulate_cases.py`), and the library's doors give the command's numbers:
`js.indices.check_imo` the table of `criteria.md`, `js.simulate` of a
`js.StandardTrial` sized with no duration the command's `trial.csv`."""

import dataclasses
import hashlib
import importlib.metadata
import json
import math
import pathlib
import sys

import pytest

import jaxship as js
from jaxship._foundation._compiler import compiles_for_cpu


sys.path.insert(0, str(pathlib.Path(__file__).parent / "golden"))
import simulate_cases as cases  # noqa: E402


GOLDEN = json.loads((pathlib.Path(__file__).parent / "golden" / "simulate.json").read_text())
# the numbers are identical where XLA compiles the same programs: the jaxlib of the golden
# file on the CPU (the command's compiler flags hold for that version, `_compiler`)
pytestmark = pytest.mark.skipif(
    importlib.metadata.version("jaxlib") != GOLDEN["jaxlib"] or not compiles_for_cpu(),
    reason=f"the golden numbers are jaxlib {GOLDEN['jaxlib']}'s on the CPU")


@pytest.mark.parametrize("name", list(cases.CASES))
def test_the_command_gives_the_numbers_of_before(name, tmp_path):
    """Every value of `indices.json`, the text of `criteria.md` and the bytes of
    `trial.csv` (its SHA-256) as at 91cbe21: identical, not close."""
    assert cases.run_case(cases.CASES[name], tmp_path) == GOLDEN["cases"][name]


@pytest.mark.parametrize("name", ["thesis imo band", "mariner imo"])
def test_check_imo_gives_the_numbers_of_criteria_md(name, tmp_path):
    """`js.indices.check_imo` of the vessel (with the identification's dict, or an
    object with `to_dict()`) is the command's `criteria.md` and `indices.json`; the
    command runs a fitted vessel at its nominal propeller rate (`--rpm`), as here."""
    golden = GOLDEN["cases"][name]
    if name == "mariner imo":
        check, label = js.indices.check_imo(js.get_vessel("mariner")), "mariner"
    else:
        report = json.loads(pathlib.Path(cases.thesis_result(tmp_path)).read_text())

        class Identification:  # what an identification result offers
            def to_dict(self):
                return report

        vessel = js.get_vessel("thesis")
        check = js.indices.check_imo(vessel, identification=Identification(),
                                     rpm=60.0 * float(vessel.nominal_n))
        label = "thesis fitted (TMP/result.json)"
    assert check.to_markdown(label) == golden["criteria_md"]
    assert str(check) in golden["criteria_md"] and str(check) == check.table()
    assert json.loads(json.dumps(check.to_dict())) == golden["indices"]
    rows = check.to_dict()["imo_criteria"]
    assert all(r["margin"] == r["limit"] - r["value"] and r["passed"] == (r["margin"] >= 0)
               for r in rows)
    if name == "mariner imo":
        assert all(r["band"] is None for r in rows)
    else:
        assert all(r["band"][0] <= r["band"][1] for r in rows)


@pytest.mark.parametrize("spec", ["turn:35", "zigzag:20/20", "spiral", "stop"])
def test_simulate_of_a_standard_trial_is_the_commands_trial(spec, tmp_path):
    """`js.simulate` of `StandardTrial.parse(spec).sized(vessel)` (no duration: a turn
    to 540 deg, a stop to its end) writes the command's `trial.csv`, byte for byte; its
    indices are the command's."""
    vessel, trial = js.get_vessel("thesis"), js.StandardTrial.parse(spec)
    manoeuvre, x0 = trial.sized(vessel)
    traj = js.simulate(vessel, manoeuvre, x0, simulator=trial.simulator)
    js.write_trial_csv(tmp_path / "trial.csv", js.Experiment.from_trajectory(traj))
    golden = GOLDEN["cases"][f"thesis {spec}"]
    digest = hashlib.sha256((tmp_path / "trial.csv").read_bytes()).hexdigest()
    assert digest == golden["trial_csv_sha256"]
    indices = {k: None if isinstance(v, float) and not math.isfinite(v) else v
               for k, v in trial.indices(manoeuvre, traj).items()}  # as indices.json
    assert indices == {k: v for k, v in golden["indices"].items() if k != "imo_criteria"}


def test_a_band_from_draws_that_mostly_blew_up_is_not_given(tmp_path):
    """Issue 72: a result.json with a std of 1e6 dropped 34 of 64 draws, and the band
    then excluded the fitted value (advance 3.50 L, band 0.23-0.29 L) with no warning.
    Under half the draws running: no band, and a note saying why; otherwise every draw
    left out and every value outside its own band is noted."""
    report = json.loads(pathlib.Path(cases.thesis_result(tmp_path)).read_text())
    vessel = js.get_vessel("thesis")
    rpm = 60.0 * float(vessel.nominal_n)
    wide = json.loads(json.dumps(report))
    for entry in wide["parameters"].values():
        entry["std"] = 1e6
    check = js.indices.check_imo(vessel, identification=wide, rpm=rpm)
    assert check.draws["used"] < 32 and check.bands == {}, check.to_dict()
    assert any(n.startswith("only ") and "no band is given" in n for n in check.notes)
    assert "no band is given" in check.to_markdown("wide")
    fine = js.indices.check_imo(vessel, identification=report, rpm=rpm)
    assert fine.bands and all(lo <= row.value <= hi for row in fine.rows
                              for lo, hi in [fine.bands[row.criterion]]), fine.notes
    assert not any("band" in n for n in fine.notes)


def test_a_criterion_the_trial_cannot_measure_is_listed_with_its_reason():
    """Issue 72: a fitted ship that turned on through 200 deg against the 10/10
    zig-zag's counter-rudder had both 10/10 criteria simply missing from its table. Each
    is now listed, not met, its value and margin "-" (null in JSON) and the reason said."""
    mariner = js.get_vessel("mariner")
    unstable = mariner.with_parameters({"n_r": -0.3 * float(mariner.n_r)})  # yaw undamped
    check = js.indices.check_imo(unstable)
    rows = {row.criterion: row for row in check.rows}
    assert len(rows) == 5, list(rows)  # the turn's two, the 10/10's two, the 20/20's one
    ten = [rows[c] for c in ("yaw checking: 1st overshoot, 10/10 zig-zag",
                             "course keeping: 2nd overshoot, 10/10 zig-zag")]
    assert all(math.isnan(r.value) and not r.passed and r.note.startswith("not measured: ")
               for r in ten), ten
    assert all(r.passed and r.note == "" for r in rows.values() if "turning" in r.criterion)
    table = check.table()
    assert "| yaw checking: 1st overshoot, 10/10 zig-zag | - | 15.43 deg | - | - | NO |" in table
    assert "course keeping: 2nd overshoot, 10/10 zig-zag: not measured: the zigzag:10/10 run" \
        in table
    written = json.loads(json.dumps(check.to_dict(), allow_nan=False))["imo_criteria"]
    assert [r["value"] is None and r["margin"] is None for r in written] == \
        [math.isnan(row.value) for row in check.rows]


def test_a_10_10_zigzag_with_one_overshoot_gives_the_first_and_says_why_not_the_second():
    mariner = js.get_vessel("mariner")
    trial = js.StandardTrial.parse("zigzag:10/10")
    manoeuvre, x0 = trial.sized(mariner)
    traj = js.simulate(mariner, manoeuvre, x0, simulator=js.StandardTrial.simulator)
    marks = trial.marks(manoeuvre, traj)
    both = trial.criteria(mariner, traj, marks)
    one = trial.criteria(mariner, traj, dataclasses.replace(marks,
                                                            overshoots=marks.overshoots[:1]))
    assert one[0] == both[0] and one[0].note == "" and math.isfinite(one[0].value)
    assert math.isnan(one[1].value) and not one[1].passed and one[1].limit == both[1].limit
    assert one[1].note == ("not measured: the ship never checked its swing against the 10 deg "
                           "counter-rudder (1 of the 2 overshoots measured)")
