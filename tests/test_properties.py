"""Property-based tests (hypothesis) of the trial CSV format and its readers, the unit
and angle conversions and the smallest signed angle `ssa`: write-then-read gives the
same numbers for arbitrary finite arrays in either unit system, the conversions invert
each other to a few ulp, and time that is not strictly increasing is always rejected
at the first offending row."""

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings, strategies as st

import jaxship as js
from jaxship._foundation._kinematics import ssa
from jaxship._simulation._consistency import HEADING_SPAN
from jaxship._simulation._data import _cumulative_trapezoid
from jaxship._simulation._readers import _PLAUSIBLE, _UNITS, _from_si, _to_si


# derandomize: every run draws the same examples (issue 72: the README's test command
# gives every user the same answer); a failure found once becomes an `@example`
SETTINGS = settings(max_examples=60, deadline=None, database=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])
OPTIONAL = ("psi", "r", "u", "v", "x", "y", "n", "delta_c", "wind_speed", "wind_dir")
ANGLES = {"delta", "delta_c", "psi", "r", "wind_dir"}  # written in degrees in display units


def finite(limit=1e12):
    return st.floats(-limit, limit, allow_nan=False, allow_infinity=False)


@st.composite
def experiments(draw, limit=1e12, both=False):
    """An `Experiment` with strictly increasing time and arbitrary finite values in a
    random subset of the channels (psi or r among them; both with `both`, so that none is
    derived: a derivative of values near the float limit overflows); values up to `limit`,
    and up to what any ship logs in the channels the reader checks (`_PLAUSIBLE`). The
    channels agree with each other as the reader checks (`_consistency`): psi turns by
    at most 1 rad a sample, by the integral of r where r is logged, and x, y run the
    track of u, v (u ahead, |v| below u/5) turned by psi (or along a line)."""
    num = draw(st.integers(2, 25))
    t0 = draw(finite(1e6))
    steps = draw(st.lists(st.floats(1e-3, 1e3), min_size=num - 1, max_size=num - 1))
    t = t0 + np.concatenate([[0.0], np.cumsum(steps)])
    assume(np.all(np.diff(t) > 0))
    chosen = draw(st.sets(st.sampled_from(OPTIONAL)))
    chosen.update(("psi", "r") if both else (draw(st.sampled_from(("psi", "r"))),))
    column = lambda key: st.lists(finite(min(limit, _PLAUSIBLE.get(key, (limit,))[0])),
                                  min_size=num, max_size=num).map(np.array)
    values = {key: draw(column(key)) for key in ("delta", *sorted(chosen))}
    if "psi" in chosen:  # from its first value, by the integral of r or by turns of 1 rad
        if "r" in chosen:  # r scaled down where it would turn by more than 1 rad a sample
            most = np.max(np.abs(np.diff(_cumulative_trapezoid(values["r"], t))))
            values["r"] = values["r"] * min(1.0, 1.0 / most) if most > 0 else values["r"]
        turns = (_cumulative_trapezoid(values["r"], t) if "r" in chosen else
                 np.concatenate([[0.0], np.cumsum(draw(column("turn")) % 2.0 - 1.0)[:-1]]))
        values["psi"] = values["psi"][0] + turns
    if {"x", "y", "u"} <= chosen:  # the track of u, v turned by psi, from the first position
        values["u"] = np.abs(values["u"])
        if "v" in chosen:
            values["v"] = 0.2 * values["u"] * np.sin(values["v"])
        psi = values.get("psi", draw(st.floats(-math.pi, math.pi)))
        u, v = values["u"], values.get("v", 0.0)
        values["x"] = values["x"][0] + _cumulative_trapezoid(u * np.cos(psi) - v * np.sin(psi), t)
        values["y"] = values["y"][0] + _cumulative_trapezoid(u * np.sin(psi) + v * np.cos(psi), t)
    return js.Experiment(t, name="prop", **values)


def assert_close(read, written, key):
    """Equal, to a few ulp where a unit conversion was applied (subnormals: absolutely)."""
    np.testing.assert_allclose(read, written, rtol=4 * np.finfo(float).eps, atol=1e-300,
                               err_msg=key)


@SETTINGS
@given(experiments(), st.sampled_from([js.strategies.DisplayUnits(), js.strategies.SIUnits()]))
def test_write_then_read_gives_the_same_numbers(tmp_path_factory, experiment, units):
    path = tmp_path_factory.mktemp("roundtrip") / "trial.csv"
    js.write_trial_csv(path, experiment, units=units)
    back = js.read_trial_csv(path)
    assert back.channels == experiment.channels and back.derived == experiment.derived
    np.testing.assert_array_equal(back.t, experiment.t)  # seconds: written exactly
    for key in experiment.channels:
        written, read = getattr(experiment, key), getattr(back, key)
        if units == js.strategies.SIUnits() or (key not in ANGLES and key != "n"):
            np.testing.assert_array_equal(read, written, err_msg=key)  # no conversion: exact
        else:
            assert_close(read, written, key)
    # a derived channel is recomputed from the measured one read back: equal to the
    # ulps of that one, amplified by the differencing (r) or summed (psi)
    eps, scale = 8 * np.finfo(float).eps, {"r": "psi", "psi": "r"}
    for key in experiment.derived:
        source = np.max(np.abs(getattr(experiment, scale[key]))) + 1e-300
        span = (1.0 / np.min(np.diff(experiment.t)) if key == "r"
                else experiment.t[-1] - experiment.t[0])
        np.testing.assert_allclose(getattr(back, key), getattr(experiment, key), rtol=0,
                                   atol=eps * source * span * experiment.num_samples,
                                   err_msg=key)


@SETTINGS
@given(experiments(limit=1e308, both=True))
def test_huge_values_round_trip_or_are_refused_in_display_units(tmp_path_factory, experiment):
    path = tmp_path_factory.mktemp("huge") / "trial.csv"
    js.write_trial_csv(path, experiment, units=js.strategies.SIUnits())  # always writable in SI
    assert js.read_trial_csv(path).channels == experiment.channels
    try:
        js.write_trial_csv(path, experiment, units=js.strategies.DisplayUnits())
    except ValueError as error:
        assert "not finite in" in str(error) and "units=SIUnits()" in str(error)
    else:
        back = js.read_trial_csv(path)
        for key in experiment.channels:
            assert_close(getattr(back, key), getattr(experiment, key), key)


@SETTINGS
@given(experiments(), st.sampled_from(sorted(_PLAUSIBLE)), st.floats(1.0 + 1e-9, 1e6),
       st.sampled_from([js.strategies.DisplayUnits(), js.strategies.SIUnits()]))
def test_values_beyond_any_ship_are_refused_naming_the_column(tmp_path_factory, experiment,
                                                              key, factor, units):
    """A channel the reader checks, beyond what any ship logs (degrees in a column
    labelled rad, rpm labelled rps, ...) at one random sample: refused, naming the
    column and that row; and `write_trial_csv` refuses to write it, naming the channel
    and the sample (issue 72: saving refuses what loading would), writing nothing."""
    values = {k: np.array(getattr(experiment, k)) for k in experiment.channels}
    values.setdefault(key, np.zeros(experiment.num_samples))
    row = experiment.num_samples // 2
    beyond = _PLAUSIBLE[key][0] * factor
    values[key][row] = beyond
    path = tmp_path_factory.mktemp("beyond") / "trial.csv"
    with pytest.raises(ValueError, match=rf"channel '{key}' sample {row} is .* beyond"):
        js.write_trial_csv(path, js.Experiment(experiment.t, name="prop", **values), units=units)
    assert not path.exists()
    values[key][row] = 0.0  # written as a logger would: the value put in the file itself
    js.write_trial_csv(path, js.Experiment(experiment.t, name="prop", **values), units=units)
    header = next(h for h in path.read_text().splitlines()[0].split(",")
                  if h.split(" [")[0] == key)

    def put(columns):
        columns[header][row] = _from_si(np.array(beyond), header.split(" [")[1].rstrip("]"))

    rewritten(path, put)
    with pytest.raises(ValueError, match=rf"column '{re.escape(header)}', row {row + 1} "
                                         rf"\(line {row + 2}\): .* is beyond"):
        js.read_trial_csv(path)


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300))
@settings(max_examples=300, deadline=None, database=None, derandomize=True)
def test_unit_conversions_invert_each_other(value):
    x = np.array([value])
    for unit in ("deg", "deg/s", "rpm"):
        assert_close(_to_si(_from_si(x, unit), unit), x, unit)
        assert np.sign(_to_si(x, unit)[0]) * np.sign(value) >= 0  # a subnormal may become 0
    np.testing.assert_array_equal(_to_si(x, "deg"), np.deg2rad(x))
    np.testing.assert_array_equal(_from_si(_to_si(x, "deg"), "deg"), np.rad2deg(np.deg2rad(x)))
    for unit in ("s", "rad", "rad/s", "m/s", "m", "rps"):
        np.testing.assert_array_equal(_to_si(x, unit), x)
        np.testing.assert_array_equal(_from_si(x, unit), x)
    for key, factors in _UNITS.items():  # the table's factors are what `_to_si` applies
        for unit, factor in factors.items():
            assert_close(_to_si(x, unit), x * factor, f"{key} [{unit}]")


@given(st.floats(-1e6, 1e6, allow_nan=False))
@settings(max_examples=300, deadline=None, database=None, derandomize=True)
def test_ssa_wraps_to_the_equivalent_angle_in_minus_pi_pi(angle):
    wrapped = float(ssa(angle))
    # [-pi, pi): an angle a rounding step below -pi can come out as +pi (the same angle)
    assert -math.pi <= wrapped <= math.pi
    turns = (angle - wrapped) / (2 * math.pi)
    tol = 8 * np.finfo(float).eps * max(1.0, abs(angle))
    assert abs(turns - round(turns)) * 2 * math.pi <= tol
    assert abs(float(ssa(wrapped)) - wrapped) <= tol or abs(abs(wrapped) - math.pi) <= tol
    if abs(angle) < math.pi - 1e-9:
        assert abs(wrapped - angle) <= 4 * np.finfo(float).eps * math.pi
    if abs(wrapped) < math.pi - 1e-6:
        assert abs(float(ssa(-angle)) + wrapped) <= tol


@st.composite
def bad_times(draw):
    """Strictly increasing times made non-increasing by a shuffle or a repeated sample;
    the first row whose time is not greater than the one before."""
    num = draw(st.integers(3, 30))
    steps = draw(st.lists(st.floats(1e-3, 100.0), min_size=num - 1, max_size=num - 1))
    t = np.concatenate([[draw(finite(1e4))], np.cumsum(steps)])
    t = np.cumsum(t)
    assume(np.all(np.diff(t) > 0))
    if draw(st.booleans()):
        order = np.array(draw(st.permutations(range(num))))
        assume(np.any(order != np.arange(num)))
        t = t[order]
    else:
        i = draw(st.integers(1, num - 1))
        t[i] = t[i - 1]
    first = int(np.nonzero(np.diff(t) <= 0)[0][0]) + 1  # 0-based index of the bad row
    return t, first


@SETTINGS
@given(bad_times())
def test_reader_rejects_shuffled_or_repeated_time(tmp_path_factory, case):
    t, first = case
    path = tmp_path_factory.mktemp("time") / "trial.csv"
    rows = "".join(f"{value!r},0.0,{k!r}\n" for k, value in enumerate(t.tolist()))
    path.write_text("t [s],delta [deg],psi [deg]\n" + rows)
    with pytest.raises(ValueError, match=rf"column 't \[s\]', row {first + 1} \(line "
                                         rf"{first + 2}\): time .* time must be strictly "
                                         "increasing") as error:
        js.read_trial_csv(path)
    assert "\n" not in str(error.value)
    with pytest.raises(ValueError, match="strictly increasing"):
        js.read_measured(path)


VALID = ("t [s],delta [deg],psi [deg],r [deg/s],u [m/s]\n"
         + "".join(f"{0.5 * k},{10 if k % 8 < 4 else -10},{k * 0.3},{0.6},{5.0}\n"
                   for k in range(12))).encode()


def _heads(lines=12):
    """The first `lines` lines of one record of each measured format in ../shared/data
    (Esso Osaka CSV, HSVA and MARIN .dat), each a valid file of its format; none where
    the data are absent (under CI they are always there: conftest.py)."""
    root = js.shared_data_dir()
    if root is None:
        return []
    found = []
    for pattern in ("esso_osaka_frt/zigzag/*.csv", "kvlcc2_simman2008_hsva/*.dat",
                    "kvlcc2_simman2008_marin/*.dat"):
        path = sorted(root.glob(pattern))[0]
        head = b"".join(path.read_bytes().splitlines(keepends=True)[:lines])
        found.append((path.suffix, head))
    return found


# valid files to mutate: the trial CSV above and the head of each measured format
SEEDS = [(".csv", VALID), *_heads()]


@st.composite
def mutated(draw):
    """(suffix, bytes) of a valid file of one of the formats read (`SEEDS`) with random
    bytes overwritten, inserted or cut."""
    suffix, valid = draw(st.sampled_from(SEEDS))
    data = bytearray(valid)
    for _ in range(draw(st.integers(1, 6))):
        at = draw(st.integers(0, len(data)))
        piece = draw(st.binary(min_size=0, max_size=4))
        kind = draw(st.sampled_from(["overwrite", "insert", "cut"]))
        if kind == "insert":
            data[at:at] = piece
        elif kind == "cut":
            del data[at:at + len(piece) + 1]
        else:
            data[at:at + len(piece)] = piece
    return suffix, bytes(data)


@pytest.mark.parametrize("suffix, data", SEEDS, ids=lambda x: x if isinstance(x, str) else "")
def test_the_fuzz_seeds_are_valid_files(tmp_path, suffix, data):
    path = tmp_path / f"record{suffix}"
    path.write_bytes(data)
    assert js.read_measured(path).num_samples >= 1


@settings(max_examples=400, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(st.tuples(st.sampled_from([".csv", ".dat", ".txt"]), st.binary(max_size=300)),
                 mutated()))
def test_any_bytes_give_a_record_or_one_line_error(tmp_path_factory, case):
    """Fuzzing the readers: random bytes, and random mutations of a valid file of each
    format (trial CSV, Esso Osaka CSV, HSVA and MARIN .dat), are either read into an
    `Experiment` or refused with a one-line `ValueError` naming the file; never another
    exception."""
    suffix, data = case
    path = tmp_path_factory.mktemp("fuzz") / f"record{suffix}"
    path.write_bytes(data)
    try:
        experiment = js.read_measured(path)
    except ValueError as error:
        assert "\n" not in str(error) and str(path) in str(error), str(error)
    else:
        assert experiment.num_samples >= 1 and np.all(np.isfinite(experiment.t))


@st.composite
def ship_records(draw):
    """A trial a ship could log (issue 57): a heading turned by a yaw rate of a few
    sinusoids (spanning at least 10 deg), u, v of 0.5-10 m/s and the track they run;
    r, and x, y with u, v, each logged or not (at least one of them)."""
    num = draw(st.integers(30, 300))
    dt = draw(st.sampled_from([0.05, 0.1, 0.2, 0.5, 1.0]))
    t = draw(st.floats(0.0, 1e4)) + dt * np.arange(num)
    s = t - t[0]
    amplitude = math.radians(draw(st.floats(0.5, 5.0)))  # deg/s
    period = draw(st.floats(10.0, 200.0))
    r = amplitude * np.sin(2 * math.pi * s / period + draw(st.floats(0, 6)))
    r += math.radians(10.0) / s[-1] * draw(st.sampled_from([-1.0, 1.0]))  # a turn of 10 deg
    psi = draw(st.floats(-10.0, 10.0)) + _cumulative_trapezoid(r, t)
    u = draw(st.floats(0.5, 10.0)) * (1 + 0.1 * np.cos(2 * math.pi * s / period))
    v = -0.05 * u * np.sin(2 * math.pi * s / period)
    x = _cumulative_trapezoid(u * np.cos(psi) - v * np.sin(psi), t)
    y = _cumulative_trapezoid(u * np.sin(psi) + v * np.cos(psi), t)
    values = dict(psi=psi, u=u, v=v)
    logged = draw(st.sampled_from([("r",), ("x", "y"), ("r", "x", "y")]))
    values.update({k: {"r": r, "x": x, "y": y}[k] for k in logged})
    delta = np.deg2rad(10.0) * np.sign(np.sin(2 * math.pi * s / period))
    return js.Experiment(t, delta, name="ship", **values)


def rewritten(path, change):
    """The trial CSV at `path` with `change(columns)` applied to its {header: values}."""
    lines = path.read_text().splitlines()
    headers = lines[0].split(",")
    columns = dict(zip(headers, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2).T))
    change(columns)
    rows = zip(*columns.values())
    path.write_text(",".join(columns) + "\n"
                    + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in rows))


def relabel(columns, old, new, factor=1.0):
    columns[new] = columns.pop(old) * factor


# a column written in another unit than its label: (units written, the change, the label
# of the column named, the unit it likely holds); r in deg/s labelled rad/s is left to
# the yaw-rate bound (`_PLAUSIBLE`) when beyond it
SI, DISPLAY = js.strategies.SIUnits(), js.strategies.DisplayUnits()
CORRUPTIONS = {
    "psi in deg labelled rad": (SI, lambda c: relabel(c, "psi [rad]", "psi [rad]",
                                                      180 / math.pi), "psi [rad]", "deg"),
    "psi in rad labelled deg": (DISPLAY, lambda c: relabel(c, "psi [deg]", "psi [deg]",
                                                           math.pi / 180), "psi [deg]", "rad"),
    "r in rad/s labelled deg/s": (DISPLAY, lambda c: relabel(c, "r [deg/s]", "r [deg/s]",
                                                             math.pi / 180), "r [deg/s]",
                                  "rad/s"),
    "t in ms labelled s": (js.strategies.DisplayUnits(),
                           lambda c: relabel(c, "t [s]", "t [s]", 1000.0), "t [s]", "ms"),
}


def short_turn():
    """The record hypothesis found on a fresh machine (issue 72): 1.45 s, 30 samples at
    20 Hz, a 10 deg rudder step, the heading turning by 2 deg with r logged: too little
    for the heading and the integrated yaw rate to tell a unit error."""
    t = 0.05 * np.arange(30)
    r = np.deg2rad(2.0) / t[-1] * np.minimum(1.0, t / 0.3) * 1.12
    delta = np.where(t >= 0.25, np.deg2rad(10.0), 0.0)
    return js.Experiment(t, delta, name="ship", psi=_cumulative_trapezoid(r, t), r=r,
                         u=np.full(30, 5.0), v=np.zeros(30))


def heading_turn(path) -> float:
    """The largest turn [rad] of the heading in the trial CSV at `path`, as its labels
    say it is: of the psi column and of the integral of the r column."""
    headers = path.read_text().splitlines()[0].split(",")
    data = dict(zip(headers, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2).T))
    si = {h.split(" [")[0]: _to_si(v, h.split(" [")[1].rstrip("]")) for h, v in data.items()}
    turns = [np.ptp(si["psi"])] if "psi" in si else []
    turns += [np.ptp(_cumulative_trapezoid(si["r"], si["t"]))] if "r" in si else []
    return max(turns)


@SETTINGS
@given(ship_records(), st.sampled_from(sorted(CORRUPTIONS)))
@example(short_turn(), "psi in rad labelled deg")
def test_columns_that_disagree_by_a_unit_are_refused_naming_the_column(tmp_path_factory,
                                                                       experiment, case):
    """Cross-channel inconsistencies (issue 57): a record that agrees with itself reads;
    a heading, yaw rate or time column scaled by a unit error (57.3 or 1000) is refused,
    naming the column and the unit it likely holds. The limit of the check (issue 72):
    heading against yaw rate has power only where the heading, as the file labels it,
    turns by `HEADING_SPAN` (5 deg): there a psi or r unit error is refused; below it,
    and for a heading with no r (the track cannot tell a ship that barely turns from one
    that holds its course), the record is refused or reads with a note that says which
    columns cannot be checked."""
    units, change, header, likely = CORRUPTIONS[case]
    path = tmp_path_factory.mktemp("units") / "trial.csv"
    js.write_trial_csv(path, experiment, units=units)
    js.read_trial_csv(path)  # the record as logged agrees with itself
    if case.startswith("r ") and not experiment.has("r"):
        return  # no r column to corrupt
    rewritten(path, change)
    powered = case.startswith("t ") or (experiment.has("r")
                                        and heading_turn(path) >= HEADING_SPAN)
    try:
        back = js.read_trial_csv(path)
    except ValueError as error:
        message = str(error)
        assert "\n" not in message and f"'{header}'" in message, message
        assert f"in {likely} rather than" in message or "is beyond" in message, message
    else:
        assert not powered, f"{case} read where the check has power"
        note = back.meta.get("unchecked", "")
        assert f"'{header}'" in note and "cannot be checked" in note, note


@SETTINGS
@given(ship_records(), st.sampled_from(["+-180", "0-360"]))
def test_a_wrapped_heading_is_unwrapped_with_a_note(tmp_path_factory, experiment, wrap):
    """A heading logged wrapped (at +-180 deg or in 0-360 deg, from any start) reads as
    the unwrapped heading, to a whole number of turns, with a note naming the column."""
    path = tmp_path_factory.mktemp("wrap") / "trial.csv"
    js.write_trial_csv(path, experiment)
    low = -180.0 if wrap == "+-180" else 0.0

    def wrapped(columns):
        columns["psi [deg]"] = (columns["psi [deg]"] - low) % 360.0 + low

    rewritten(path, wrapped)
    back = js.read_trial_csv(path)
    turns = (back.psi - experiment.psi) / (2 * math.pi)
    np.testing.assert_allclose(turns, np.round(turns[0]), atol=1e-9)
    jumps = np.abs(np.diff(np.deg2rad(np.loadtxt(path, delimiter=",", skiprows=1)[:, 2])))
    assert ("note" in back.meta) == bool(np.any(jumps > math.pi))
    if "note" in back.meta:
        assert "'psi [deg]'" in back.meta["note"] and "unwrapped" in back.meta["note"]


def test_a_records_unchecked_columns_reach_result_json(tmp_path):
    """The audit of 2026-12-07: the reader's "cannot be checked" note (a heading that
    turns 1.5 deg) stayed in the record's metadata, and `identify`'s result.json did not
    say it. It is now each training record's `unchecked` there."""
    traj = js.simulate(js.Nomoto1(K=0.05, T=10.0), js.ZigZag(
        math.radians(2), math.radians(0.5), duration=120.0, dt=0.5))
    path = tmp_path / "small.csv"
    js.write_trial_csv(path, js.Experiment.from_trajectory(traj))
    record, = js.identify("nomoto1", [path]).to_dict()["data"]["train"]
    assert "'psi [deg]', 'r [deg/s]' cannot be checked" in record["unchecked"], record
    assert "heading turns by 1.5 deg" in record["unchecked"], record
