"""`jaxship simulate` gives the numbers it gave before the trials and the IMO check moved
into the library (issue 68; `tests/golden/simulate.json`, written at commit 91cbe21 by
`tests/golden/simulate_cases.py`), and the library's doors give the command's numbers:
`js.indices.check_imo` the table of `criteria.md`, `js.simulate` of a
`js.StandardTrial` sized with no duration the command's `trial.csv`. One text changed
since, by hand in the file (issue 72's audit): a check with no parameter draws says "No
band: ..." where it said "Band: the central 90% of 0 of 0 parameter draws from none: ..."."""

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
