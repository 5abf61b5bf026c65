"""`js.indices.check_imo` beyond the golden numbers (issue 72): no band from draws that
mostly blew up, and a criterion the trial cannot measure listed with its reason. Unlike
tests/test_simulate_golden.py these hold on every jaxlib."""

import dataclasses
import json
import math
import pathlib
import sys

import jaxship as js


sys.path.insert(0, str(pathlib.Path(__file__).parent / "golden"))
import simulate_cases as cases  # noqa: E402


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


def test_a_value_on_a_band_of_zero_width_is_within_it_to_rounding():
    """A criterion the drawn parameters do not move (the stop's track reach under drawn
    yaw derivatives) has a band of zero width; the fitted value may differ from it in its
    last digit (another compiled program) and is still within it; a real miss is not."""
    import numpy as np

    from jaxship._workflow._imo import _within

    band = 1.1799228658693657
    assert _within(np.nextafter(band, 2.0), band, band)
    assert _within(band, band, band)
    assert not _within(band * (1 + 1e-6), band, band)
    assert not _within(3.50, 0.23, 0.29)  # issue 72's advance outside its band
