"""Issue 72's fuzz goal: generated mutations of valid vessel files and `result.json`s
(types, nesting, booleans, shapes, implausible values, units swapped). The reader
either gives a model whose parameters are all finite, and flagged where they are
beyond what ships can do, or refuses in one line (`ValueError`); never another
exception, never a silent non-finite model. Derandomized: every run draws the same
examples; a case found once is kept as an `@example`."""

import copy
import json
import math
import tomllib

import numpy as np
import pytest
from hypothesis import example, given, settings, strategies as st

import jaxship as js
from jaxship._models._vessel.file import MAX_MAGNITUDE
from jaxship.cli import main
from jaxship.identification import implausible, nomoto_indices, read_result


def SETTINGS(count):
    """Derandomized, no database, no deadline: `count` examples."""
    return settings(max_examples=count, deadline=None, database=None, derandomize=True)

PRESETS = ("thesis", "mariner", "kvlcc2", "esso_osaka", "sea_scout")
KVLCC2 = js.MainParticulars(
    length=7.0, breadth=1.2688, draft=0.455, block_coefficient=0.810, speed=1.179,
    propeller_diameter=0.216, rudder_area=0.0539, rudder_span=0.345,
    rudder_rate=math.radians(15.8), k_t=(0.2931, -0.2753, -0.1385), x_g=0.25)
VESSEL_TEXTS = [js.save_vessel(js.get_vessel(n)) for n in PRESETS] + [js.save_vessel(KVLCC2)]
# a value no ship has, and each kind a hand edit can put in a value's place
IMPLAUSIBLE = [1e300, -1e300, 1e-300, 0, -5.0, 1e16, 5e15]
REPLACEMENTS = ["nan", "inf", "a", "", True, False, None, [], {}, [1.0], {"value": 1.0},
                [[1.0]], 2**1100, float("nan"), float("inf")] + IMPLAUSIBLE
UNITS = ["m", "kg", "rad", "deg", "rev/s", "rpm", "s", "deg/s", "-", "kg m^2", 3, None]


def _paths(node, at=()):
    """Every place in a parsed document: (path of keys or indices)."""
    yield at
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*at, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*at, i))


def _get(doc, path):
    for key in path:
        doc = doc[key]
    return doc


@st.composite
def mutated(draw, documents):
    """A deep copy of one of `documents` with one to three mutations."""
    doc = copy.deepcopy(draw(st.sampled_from(documents)))
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent, key = _get(doc, path[:-1]), path[-1]
        old = parent[key]
        how = draw(st.sampled_from(["replace", "scale", "nest", "delete", "add", "unit",
                                    "shape"]))
        if how == "replace":
            parent[key] = copy.deepcopy(draw(st.sampled_from(REPLACEMENTS)))
        elif how == "scale" and isinstance(old, float):
            parent[key] = old * draw(st.sampled_from([-1, 1e6, 1e-6, 57.29577951308232,
                                                      0.017453292519943295, 1e300, 60.0]))
        elif how == "nest":
            parent[key] = copy.deepcopy(draw(st.sampled_from(
                [[old], {"value": old}, {"x": old}, {"value": old, "unit": "m", "extra": 1}])))
        elif how == "delete":
            del parent[key]
        elif how == "add" and isinstance(old, dict):
            old[draw(st.sampled_from(["bogus", "value", "unit", "model", "std"]))] = \
                copy.deepcopy(draw(st.sampled_from(REPLACEMENTS)))
        elif how == "unit" and isinstance(old, dict) and "unit" in old:
            old["unit"] = draw(st.sampled_from(UNITS))
        elif how == "shape" and isinstance(old, list):
            parent[key] = copy.deepcopy(draw(st.sampled_from(
                [old[:-1], old + old[-1:], [old], old[:1]])))
        else:
            parent[key] = copy.deepcopy(draw(st.sampled_from(REPLACEMENTS)))
    return doc


def _one_line_or(read, source):
    """`read(source)`'s model, or None where it refuses in one line."""
    try:
        return read(source)
    except ValueError as error:
        assert "\n" not in str(error).strip() and str(error).strip(), repr(error)
        return None


def _values(model) -> dict:
    return {n: float(np.asarray(model.get_parameter(n))) for n in model.parameter_names()}


def _judged(model) -> None:
    """All parameters finite; beyond what ships do (a vessel coefficient beyond
    `MAX_MAGNITUDE`, a steering model's parameter beyond 1e6 or a Nomoto index below
    1e-12) only with a plausibility flag (`implausible`)."""
    values = _values(model)
    assert all(math.isfinite(v) for v in values.values()), values
    if isinstance(getattr(model, "base", model), js.AbstractVessel):
        assert all(abs(v) <= MAX_MAGNITUDE for v in values.values()), values
    elif any(abs(v) > 1e6 for v in values.values()) or any(
            abs(v) < 1e-12 for v in nomoto_indices(model) or ()):
        assert implausible(model), values


@SETTINGS(1000)
@given(mutated([tomllib.loads(t) for t in VESSEL_TEXTS]))
@example({"model": "MMGVessel", "particulars": {**tomllib.loads(VESSEL_TEXTS[-1])[
    "particulars"], "length": {"value": 1e14, "unit": "m"}}})
@example({"model": ["MMGVessel"]})  # found: a TypeError (unhashable list)
@example({**tomllib.loads(VESSEL_TEXTS[0]), "length": {"value": 2**1100, "unit": "m"}})  # found:
# an OverflowError (an integer beyond any float)
def test_a_mutated_vessel_file_reads_or_is_refused_in_one_line(data):
    model = _one_line_or(js.load_vessel, data)
    if model is not None:
        _judged(model)


TEXT_EDITS = [('unit = "m"', 'unit = "mm"'), ('unit = "rad"', 'unit = "deg"'),
              ('unit = "rev/s"', 'unit = "rpm"'), ('unit = "rad/s"', 'unit = "deg/s"'),
              ("= { value = ", "= { value = -"), ("= { value = ", "= { value = 1e300 * "),
              ('model = "', 'model = "x'), ("]\n", "]\n]\n"), ("[rudder]", "[rudder.x]"),
              ("= { value = ", "= { value = nan, x = "), ("= 0.", "= true #"),
              ("= { value = ", '= { value = "1" } #'), ("= -", "= inf #")]


@SETTINGS(500)
@given(st.sampled_from(VESSEL_TEXTS), st.lists(st.tuples(st.sampled_from(TEXT_EDITS),
                                                         st.integers(0, 40)), max_size=3))
def test_a_mutated_vessel_text_reads_or_is_refused_in_one_line(text, edits):
    """Edits of the TOML text itself: the n-th occurrence of a unit, a sign, a number."""
    for (old, new), n in edits:
        at = -1
        for _ in range(n % max(1, text.count(old)) + 1):
            at = text.find(old, at + 1)
        if at >= 0:
            text = text[:at] + new + text[at + len(old):]
    model = _one_line_or(js.load_vessel, text)
    if model is not None:
        _judged(model)


@pytest.fixture(scope="module")
def identification():
    """A real Nomoto 1 identification of a short simulated zig-zag."""
    traj = js.simulate(js.Nomoto1(K=0.05, T=10.0),
                       js.ZigZag(math.radians(10), math.radians(10), duration=120.0, dt=1.0))
    return js.identify("nomoto1", [js.Experiment.from_trajectory(traj)], max_steps=20)


@pytest.fixture(scope="module")
def results(identification) -> list[dict]:
    """The identification's result.json dict, and a hand-made KVLCC2 result with two
    estimates, their std and correlation."""
    ident = identification
    vessel = js.get_vessel("kvlcc2")
    kvlcc2 = {"model": "kvlcc2", "data": {"train": [{"dt_s": 0.5, "duration_s": 100.0}]},
              "parameters": {"n_r": {"value": float(vessel.n_r), "std": 1e-4},
                             "n_v": {"value": float(vessel.n_v), "std": 1e-4}},
              "correlation": {"names": ["n_r", "n_v"], "matrix": [[1.0, 0.3], [0.3, 1.0]]}}
    return [json.loads(ident.to_json()), kvlcc2]


def test_results_fuzz(results, tmp_path):
    """`load_model` of the dict and `read_result` of the file it is saved as agree:
    a model judged as above, or the same one-line refusal naming the file."""
    path = tmp_path / "result.json"

    @SETTINGS(1000)
    @given(mutated(results))
    @example({**results[1], "model": ["kvlcc2"]})
    @example({**results[1], "parameters": {"length": {"value": -5.0}}})
    @example({**results[0], "parameters": {"K": {"value": 2**1100}, "T": 3.0}})
    def check(report):
        model = _one_line_or(js.load_model, report)
        text = json.dumps(report)
        path.write_text(text)
        read = _one_line_or(lambda p: read_result(p)[0], path)
        assert (model is None) == (read is None), (model, read)
        if model is not None:
            _judged(model)

    check()


def test_a_mutated_steering_result_through_simulate(identification, tmp_path, capsys):
    """The command, not only the reader (the audit of 2026-12-07 found a traceback in
    `simulate`'s use of the result's records, which the reader fuzz never reached):
    mutations of a Nomoto 1 result.json through `jaxship simulate --vessel result.json
    --manoeuvre zigzag:10/10` (the trial's step and length from the result's first
    record) end in exit 0, 2 (a refusal in one line, after the line that says a result
    did not converge, where it did not) or 3, never a traceback; exit 0 with a finite
    trial, and a model beyond what ships do only with its warning."""
    base = json.loads(identification.to_json())
    path = tmp_path / "result.json"

    @SETTINGS(100)
    @given(mutated([base]))
    @example({**base, "data": {"train": [{"dt_s": "a", "duration_s": 100.0}]}})
    @example({**base, "data": {"train": [{"dt_s": 1e-9, "duration_s": 100.0}]}})
    def check(report):
        path.write_text(json.dumps(report))
        out = tmp_path / "zz"
        code = main(["simulate", "--vessel", str(path), "--manoeuvre", "zigzag:10/10",
                     "--out", str(out)])
        err = capsys.readouterr().err.strip()
        assert code in (0, 2, 3), (code, err)
        assert all(line.startswith("jaxship: ") for line in err.splitlines()), err
        if code == 2:
            lines = err.splitlines()
            assert lines[-1].startswith("jaxship: error: "), err
            assert len(lines) == 1 or len(lines) == 2 and "converge" in lines[0], err
        if code == 0:
            indices = json.loads((out / "indices.json").read_text())
            assert all(math.isfinite(v) for v in indices.values()
                       if isinstance(v, float)), indices
            model = js.load_model(path)
            assert not implausible(model) or "warning" in err, err
        if out.exists():
            import shutil
            shutil.rmtree(out)

    check()


def test_saving_refuses_what_loading_would_and_leaves_the_file(identification, tmp_path,
                                                               monkeypatch):
    """`Identification.save` checks its dict by the reader's schema before writing: a
    boolean value or a 1 x 1 correlation for two names is refused, the old file stays."""
    path = tmp_path / "result.json"
    assert js.load_model(identification.save(path)) == identification.model
    good = identification.to_dict()
    path.write_text("the old one")
    for damage, message in ((("parameters", "K", "value"), True),
                            (("correlation", "matrix"), [[1.0]])):
        bad = copy.deepcopy(good)
        _get(bad, damage[:-1])[damage[-1]] = message
        monkeypatch.setattr(type(identification), "to_dict", lambda self, bad=bad: bad)
        with pytest.raises(ValueError, match="cannot save the nomoto1 result: "):
            identification.save(path)
        assert path.read_text() == "the old one"
