"""Issue 72, point 2: identified values checked against what ships can do. Each unit slip
or sign of the issue's list gives a warning naming it, on the measured Esso Osaka
zig-zags (records jaxship did not simulate) and on the published Nomoto sets, which give
none."""

import equinox as eqx
import numpy as np
import pytest

import jaxship as js
from jaxship.identification import (
    implausible,
    propeller_rate_slip,
    rudder_in_rad,
    wind_too_strong,
)


DATA = js.shared_data_dir()
needs_esso = pytest.mark.skipif(DATA is None or not (DATA / "esso_osaka_frt").is_dir(),
                                reason="Esso Osaka data (shared/data/esso_osaka_frt) absent")


@pytest.mark.parametrize("model, length, speed", [
    (js.Nomoto2(K=0.185, T1=118.0, T2=7.8, T3=18.5), 161.0, 7.7),  # MSS cargo ship
    (js.Nomoto1(K=-0.019, T=-153.7), 350.0, 8.1),  # MSS tanker: course-unstable
    (js.Nomoto1(K=0.185, T=3.02), 4.0, 0.93),  # the thesis vessel
    (js.Nomoto1(K=0.171, T=7.63), None, None),  # Esso Osaka, no length given
    (js.NonlinearNomoto(K=0.19, T=3.2, n3=17.0, n1=0.98), 4.0, 0.93),
])
def test_published_ships_are_plausible(model, length, speed):
    assert implausible(model, length=length, speed=speed) == ()


@pytest.mark.parametrize("model, length, speed, said", [
    (js.Nomoto1(K=-0.185, T=3.02), None, None, "turns against its rudder"),
    (js.Nomoto1(K=0.185 / 57.3, T=3.02), None, None, "r in rad/s labelled deg/s"),
    (js.Nomoto1(K=0.185 * 57.3, T=3.02), 4.0, 0.93, "the rudder in rad labelled deg"),
    (js.Nomoto1(K=0.171e-3, T=7630.0), None, None, "is t in ms labelled s"),
    (js.Nomoto1(K=0.185e-3, T=3020.0), 4.0, 0.93, "|T'| = 702"),
    (js.NonlinearNomoto(K=-0.19, T=3.2, n3=17.0, n1=0.98), None, None, "against its rudder"),
])
def test_slips_and_signs_are_named(model, length, speed, said):
    assert any(said in line for line in implausible(model, length=length, speed=speed))


def test_a_fit_that_found_no_rudder_response_names_no_unit():
    """The audit of 2026-12-07: Nomoto 1 fitted to a course-unstable ship's zig-zags
    (`sea_swift`) ran T to 1.2e12 s with K T far below the ships' range, and the warnings
    asked "is t in ms labelled s?" and "is it the rudder in rad labelled deg?". No single
    slip moves T and K T both: one sentence says so, and names no unit."""
    said = implausible(js.Nomoto1(K=1e-14, T=1.2e12), length=90.0, speed=8.0)
    assert len(said) == 1 and "no single unit slip" in said[0], said
    assert "labelled" not in said[0] and "course-unstable" in said[0]


def test_a_propeller_rate_in_rev_s_labelled_rpm_is_said():
    """The audit of 2026-12-07: a record whose n column in rev/s was labelled rpm (8.33
    "rpm" against the thesis vessel's 500) fitted with no word. Under a tenth of the
    service rate it is said; the service rate itself, no n, or a vessel without a
    propeller rate say nothing."""
    thesis = js.get_vessel("thesis")
    t = np.arange(0.0, 10.0, 0.5)
    record = lambda n: js.Experiment(t, np.zeros_like(t), name="run", psi=np.zeros_like(t),
                                     n=np.full_like(t, n))
    said = propeller_rate_slip(record(float(thesis.nominal_n) / 60.0), thesis)
    assert said is not None and "rev/s labelled rpm" in said and "8.33 rpm" in said, said
    assert propeller_rate_slip(record(float(thesis.nominal_n)), thesis) is None
    assert propeller_rate_slip(js.Experiment(t, np.zeros_like(t), psi=np.zeros_like(t)),
                               thesis) is None
    assert propeller_rate_slip(record(0.1), js.get_vessel("mariner")) is None


def test_other_models_are_not_judged():
    assert implausible(js.get_vessel("mariner")) == ()


@needs_esso
def test_a_mislabelled_or_flipped_rudder_on_measured_zigzags_is_said():
    """The first three Esso Osaka zig-zags: as logged, no warning of plausibility; the
    rudder negated (a public data set's convention, positive to port) or in rad labelled
    deg, `identify` warns, naming the cause."""
    files = sorted((DATA / "esso_osaka_frt" / "zigzag").glob("*.csv"))[:3]
    records = js.identification.read_experiments(files)
    as_logged = js.identify("nomoto1", records, horizon=10.0)
    assert not [w for w in as_logged.warnings if "rudder" in w or "range of ships" in w]
    flipped = js.identify("nomoto1", [eqx.tree_at(lambda e: e.delta, e, -e.delta)
                                      for e in records], horizon=10.0)
    assert flipped.model.K < 0
    assert any("turns against its rudder" in w for w in flipped.warnings)
    rad = [eqx.tree_at(lambda e: e.delta, e, np.radians(e.delta)) for e in records]
    assert all(rudder_in_rad(e) for e in rad) and not any(map(rudder_in_rad, records))
    assert sum("is the rudder in rad labelled deg?" in w
               for w in js.identify("nomoto1", rad, horizon=10.0).warnings) == 3


def test_a_wind_beyond_hurricane_force_is_said():
    """Issue 72: a logged wind of 250 m/s was not flagged; the Esso Osaka model's own
    logged wind (a few m/s) is not."""
    t = np.arange(0.0, 10.0, 0.5)
    calm = js.Experiment(t, 0.1 * np.ones_like(t), psi=0.01 * t, wind_speed=np.full_like(t, 8.0),
                         wind_dir=np.zeros_like(t), name="calm")
    storm = eqx.tree_at(lambda e: e.wind_speed, calm, np.full_like(t, 250.0))
    assert wind_too_strong(calm) is None
    assert "reaches 250 m/s, beyond hurricane force" in wind_too_strong(storm)
    assert "knots or km/h" in wind_too_strong(storm)


def _zigzag_rows() -> dict:
    """A 20/20 zig-zag of the thesis vessel's Nomoto 1 (K 0.185 1/s, T 3.02 s) in SI."""
    traj = js.simulate(js.Nomoto1(K=0.185, T=3.02),
                       js.ZigZag(np.radians(20), np.radians(20), duration=60.0, dt=0.5))
    e = js.Experiment.from_trajectory(traj)
    return {"t": np.asarray(e.t), "delta": np.asarray(e.delta), "psi": np.asarray(e.psi),
            "r": np.asarray(e.r)}


# issue 72, "Broken 4": one motion channel, so no cross-channel check sees the slip;
# each column is written as the slip writes it, under the label that hides it. Every
# slip of one column (t in ms, an angle or rate in rad, the rudder signed the other way)
# with either motion channel, psi or r (the audit of 2026-12-07: the three cases
# first, then the rest of the grid)
DEG = 57.29577951308232
MISLABELS = {
    "r in rad/s labelled deg/s, no psi": {"t [s]": ("t", 1.0), "delta [deg]": ("delta", DEG),
                                          "r [deg/s]": ("r", 1.0)},
    "t in ms labelled s, psi only": {"t [s]": ("t", 1000.0), "delta [deg]": ("delta", DEG),
                                     "psi [deg]": ("psi", DEG)},
    "the rudder in rad labelled deg": {"t [s]": ("t", 1.0), "delta [deg]": ("delta", 1.0),
                                       "psi [deg]": ("psi", DEG)},
    "psi in rad labelled deg, no r": {"t [s]": ("t", 1.0), "delta [deg]": ("delta", DEG),
                                      "psi [deg]": ("psi", 1.0)},
    "t in ms labelled s, r only": {"t [s]": ("t", 1000.0), "delta [deg]": ("delta", DEG),
                                   "r [deg/s]": ("r", DEG)},
    "the rudder in rad labelled deg, r only": {"t [s]": ("t", 1.0), "delta [deg]": ("delta", 1.0),
                                               "r [deg/s]": ("r", DEG)},
    "the rudder signed the other way, psi only": {
        "t [s]": ("t", 1.0), "delta [deg]": ("delta", -DEG), "psi [deg]": ("psi", DEG)},
    "the rudder signed the other way, r only": {
        "t [s]": ("t", 1.0), "delta [deg]": ("delta", -DEG), "r [deg/s]": ("r", DEG)},
}


@pytest.mark.parametrize("case", list(MISLABELS))
def test_a_single_channel_unit_slip_is_flagged_or_refused(case, tmp_path):
    """Each slip ends refused or with a plausibility warning (`implausible`,
    `rudder_in_rad`), never a silent success."""
    rows = _zigzag_rows()
    columns = MISLABELS[case]
    path = tmp_path / "zz.csv"
    np.savetxt(path, np.column_stack([rows[k] * f for k, f in columns.values()]),
               delimiter=",", header=",".join(columns), comments="")
    try:
        ident = js.identify("nomoto1", path)
    except ValueError as error:
        assert "\n" not in str(error)
        return
    said = [w for w in ident.warnings if "range of ships" in w or "labelled" in w
            or "against its rudder" in w]
    assert said and (implausible(ident.model) or "rudder in rad" in " ".join(said)), \
        (ident.model, ident.warnings)
