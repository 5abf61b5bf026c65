"""A ship from its main particulars (issue 69, point 3): `js.MainParticulars`,
`MMGVessel.from_particulars`, the vessel file's table [particulars] and `jaxship vessels
--from-particulars`; checked against a second implementation (mmgdynamics), a published
value (Fujii's f_alpha of the KVLCC2) and the KVLCC2's measured manoeuvres."""

import dataclasses
import math
import tomllib

import pytest

import jaxship as js
from jaxship._models._vessel.file import particulars_from_dict, vessel_to_dict
from jaxship.cli import main
from jaxship.studies.kvlcc2_simman import compare_marin_turn, compare_marin_zigzag


# KVLCC2 L7 (SIMMAN 2008: L_pp 7.0 m, B 1.2688 m, T 0.455 m, C_b 0.810, x_G 0.25 m;
# D_P, A_R, H_R and K_T as the kvlcc2 preset, Yasukawa & Yoshimura 2015 Tables 1, 4)
KVLCC2 = js.MainParticulars(
    length=7.0, breadth=1.2688, draft=0.455, block_coefficient=0.810, speed=1.179,
    propeller_diameter=0.216, rudder_area=0.0539, rudder_span=0.345,
    rudder_rate=math.radians(15.8), k_t=(0.2931, -0.2753, -0.1385), x_g=0.25)

# mmgdynamics (nikpau/mmgdynamics, src/mmgdynamics/dynamics.py at commit 6d38838, the
# version that codes Yoshimura & Masumoto 2012), `calibrate` run on the particulars above
# (m = C_b L B d, rho = 1025): its printed values, by our field name
MMGDYNAMICS = {
    "m_x": 0.014681828571428572, "m_y": 0.224282765530045,
    "x_vv": -0.011158971428571418, "x_vr": 0.023859839815759273,
    "x_vvvv": 0.11925385142857148, "y_v": -0.4097491224833366, "y_r": 0.08809097142857142,
    "y_vvv": -0.5406494325346785, "y_vvr": -0.75, "y_vrr": -0.3825409836065573,
    "y_rrr": -0.051, "n_v": -0.13, "n_r": -0.053300000000000014,
    "n_vvv": -0.10110000000000008, "n_vvr": -0.5324316571428571,
    "n_vrr": -0.17661759142496847, "n_rrr": -0.019295428571428568,
    "w_p0": 0.35500000000000004, "a_h": 0.35487, "t_r": 0.39,
    "kappa": 0.43254537142857147, "l_r": -0.9, "gamma_r_plus": 0.4424456685714286,
}
# its J_z' (0.00022900457946852562) lacks the factor L^2 of Zhou's (k L)^2: times 49
MMGDYNAMICS_J_Z = 0.00022900457946852562 * 7.0**2


def test_the_formulas_give_the_second_implementations_numbers():
    """Every coefficient that both code by the same formula agrees to rounding; X_rr'
    (mmgdynamics: Lee et al. 1998) and epsilon (Lee & Shin 1998) are other formulas."""
    mine = KVLCC2.coefficients()
    for name, theirs in MMGDYNAMICS.items():
        assert mine[name] == pytest.approx(theirs, rel=1e-12, abs=1e-15), name
    assert mine["j_z"] == pytest.approx(MMGDYNAMICS_J_Z, rel=1e-12)
    assert mine["gamma_r_minus"] == mine["gamma_r_plus"]


def test_fujii_f_alpha_gives_the_published_kvlcc2_value():
    """f_alpha = 6.13 Lambda/(Lambda + 2.25): with the KVLCC2's Lambda = 1.827 the
    paper's f_alpha = 2.747 (Yasukawa & Yoshimura 2015 Tables 1, 4)."""
    area = 0.0539
    ship = dataclasses.replace(KVLCC2, rudder_span=math.sqrt(1.827 * area))
    assert ship.coefficients()["f_alpha"] == pytest.approx(2.747, abs=5e-4)


def test_the_vessel_is_the_formulas_and_self_propelled_at_its_speed():
    vessel = js.MMGVessel.from_particulars(KVLCC2)
    for name, value in KVLCC2.coefficients().items():
        assert float(getattr(vessel, name)) == value, name
    assert float(vessel.volume) == pytest.approx(0.81 * 7.0 * 1.2688 * 0.455)
    run = js.straight_run(vessel)
    assert float(run.u) == pytest.approx(1.179) and float(run.n) == float(vessel.nominal_n)
    assert 5.0 < float(vessel.nominal_n) < 20.0


def test_a_vessel_file_with_particulars_round_trips(tmp_path):
    path = js.save_vessel(KVLCC2, tmp_path / "kvlcc2.toml")
    text = path.read_text()
    assert "[particulars]" in text and "x_vv" not in text
    assert particulars_from_dict(tomllib.loads(text)) == KVLCC2
    vessel = js.load_vessel(path)
    assert vessel_to_dict(vessel) == vessel_to_dict(js.MMGVessel.from_particulars(KVLCC2))
    # the computed vessel's own file (every coefficient) reads back bit for bit
    again = js.load_vessel(js.save_vessel(vessel, tmp_path / "full.toml"))
    assert vessel_to_dict(again) == vessel_to_dict(vessel)
    # the fields with defaults may be left out; degrees are read
    data = tomllib.loads(text)
    for name in ("x_g", "gyration_ratio", "rudder_max_angle", "rho", "viscosity"):
        del data["particulars"][name]
    data["particulars"]["rudder_rate"] = {"value": 15.8, "unit": "deg/s"}
    short = particulars_from_dict(data)
    assert short == dataclasses.replace(KVLCC2, x_g=0.0)


@pytest.mark.parametrize("change, message", [
    (lambda d: d["particulars"].pop("breadth"), "missing field 'particulars.breadth'"),
    (lambda d: d["particulars"].update(beam=1.0), "unknown field 'particulars.beam'"),
    (lambda d: d.update(x_vv=-0.04), "no other field"),
    (lambda d: d["particulars"].update(k_t=[0.3, -0.3]), "list of 3 numbers"),
    (lambda d: d["particulars"].update(draft={"value": 0.0, "unit": "m"}), "positive"),
    (lambda d: d["particulars"].update(block_coefficient=1.2), "between 0.3 and 1"),
])
def test_a_bad_particulars_table_is_refused_in_one_line(change, message):
    data = tomllib.loads(js.save_vessel(KVLCC2))
    change(data)
    with pytest.raises(ValueError, match=message) as error:
        js.load_vessel(data)
    assert "\n" not in str(error.value)


def test_vessels_from_particulars_prints_the_computed_vessel_file(tmp_path, capsys):
    path = js.save_vessel(KVLCC2, tmp_path / "ship.toml")
    assert main(["vessels", "--from-particulars", str(path)]) == 0
    out = capsys.readouterr().out
    assert js.load_vessel(tomllib.loads(out)) == js.MMGVessel.from_particulars(KVLCC2)
    assert "computed from the main particulars" in out and "x_vv = " in out


def test_vessels_from_particulars_refuses_a_bad_file_in_one_line(tmp_path, capsys):
    full = js.save_vessel(js.get_vessel("kvlcc2"), tmp_path / "full.toml")  # no [particulars]
    assert main(["vessels", "--from-particulars", str(full)]) == 2
    err = capsys.readouterr().err
    assert "no table [particulars]" in err and err.count("\n") == 1


@pytest.mark.slow
def test_kvlcc2_from_particulars_against_the_measured_marin_runs():
    """The particulars' KVLCC2 (self-propulsion rate) against MARIN's measured runs
    (benchmarks/results/particulars.md has every number). Of the issue's goals, the
    tactical diameter within 10 % holds (measured 3.33 / 3.07 L, simulated 3.29 L: -1 %,
    +7 %); the advance does not (3.10 / 3.02 L measured, 3.58 / 3.57 L simulated: +16 %,
    +18 %), nor do most first overshoots within 3 deg: the formulas' ship checks its yaw
    too soon (10/10: 3.9 deg against 8.1 / 9.4 measured; 20/20: 9.7 deg against 12.6 /
    15.7, the starboard one within 3 deg)."""
    root = js.shared_data_dir()
    marin = None if root is None else root / "kvlcc2_simman2008_marin"
    if marin is None or not marin.is_dir():
        pytest.skip("measured data (../shared/data) not available")
    vessel = js.MMGVessel.from_particulars(KVLCC2)
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_tc_*.dat")):
        rows = {label: (meas, sim) for _, label, meas, _, sim in compare_marin_turn(path, vessel)}
        meas, sim = rows["tactical diameter [L]"]
        assert abs(sim - meas) <= 0.10 * meas
        meas, sim = rows["advance [L]"]
        assert 0.10 * meas < sim - meas < 0.25 * meas  # the goal (10 %) is not met
    for path in sorted(marin.glob("MARIN_FREE_KVLCC2_zz_*.dat")):
        _, _, meas, _, sim = compare_marin_zigzag(path, vessel)[0]
        assert sim < meas  # every first overshoot too small
