"""MMG vessels: KVLCC2 (Yasukawa & Yoshimura 2015) and the Esso Osaka 3 m low-speed MMG model.

Cross-check numbers: ../shared/reference/vessel-models.md sec. 6 (an independent NumPy
re-implementation of the MMG equations, RK4 h = 0.02 s, rudder executed at t = 0 from the
self-propulsion point, 15.8 deg/s). Measured data (skipped when ../shared/data is absent):
SIMMAN 2008 KVLCC2 free-running tests (HSVA, MARIN) and FRT-DS-ESSO (Osaka Univ.).
"""

import importlib.util
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import central_difference

import jaxship as js
from jaxship._analysis._indices import turning_indices, zigzag_indices
from jaxship._models._vessel.esso_osaka import LowSpeedMMGVessel, cross_flow_integrals, esso_osaka
from jaxship._models._vessel.mmg import MMGVessel, kvlcc2
from jaxship._simulation._measured import read_esso_osaka, shared_data_dir


DEG = np.pi / 180
L = 7.0


def symmetrised(vessel: MMGVessel) -> MMGVessel:
    """KVLCC2 with the port and starboard values of gamma_R and C_2 made equal."""
    gamma = 0.5 * (vessel.gamma_r_plus + vessel.gamma_r_minus)
    c2 = 0.5 * (vessel.c_2_plus + vessel.c_2_minus)
    return eqx.tree_at(
        lambda s: (s.gamma_r_plus, s.gamma_r_minus, s.c_2_plus, s.c_2_minus), vessel,
        (gamma, gamma, c2, c2),
    )


def mirror_states(rng, num=20):
    """Random ahead manoeuvring states (u, v, r, delta) of the KVLCC2 model."""
    return np.stack([
        rng.uniform(0.4, 1.3, num), rng.uniform(-0.3, 0.3, num), rng.uniform(-0.06, 0.06, num),
        rng.uniform(-35, 35, num) * DEG,
    ], axis=1)


# --- KVLCC2: straight run, symmetry --------------------------------------------------------


def test_kvlcc2_self_propulsion_point():
    """X = 0 at U_0 = 1.179 m/s needs 11.85 rps; 17.95 rps gives 1.786 m/s (notes sec. 6)."""
    vessel = kvlcc2()
    n = float(js.straight_run(vessel, speed=1.179).n)
    assert abs(n - 11.85) < 0.01
    assert abs(n - vessel.nominal_n) < 1e-4
    assert abs(float(js.straight_run(vessel, n=17.95).u) - 1.786) < 0.002
    # residual surge force at the nominal point below 1e-4 of the resistance
    resistance = 0.5 * vessel.rho * L * vessel.draft * 1.179**2 * vessel.r_0
    assert abs(float(vessel.forces(1.179, 0.0, 0.0, 0.0, vessel.nominal_n)[0])) < 1e-4 * resistance


@pytest.mark.parametrize("factory", [kvlcc2, esso_osaka])
def test_straight_run_stays_straight(factory):
    """Zero rudder from the nominal straight run: no sway or yaw, speed held."""
    vessel = factory()
    x0 = js.straight_run(vessel)
    tau = vessel.length / vessel.nominal_speed
    traj = js.simulate(vessel, js.Turn(0.0, duration=20 * tau, dt=0.5), x0,
                       simulator=js.Simulator(substeps=4))
    assert bool(traj.success)
    assert np.max(np.abs(traj.state.r)) <= 1e-12
    assert np.max(np.abs(traj.state.v)) <= 1e-12
    assert np.max(np.abs(traj.state.u - vessel.nominal_speed)) < 1e-5 * vessel.nominal_speed


def test_kvlcc2_mirror_symmetry_of_forces():
    """The MMG standard method is port/starboard symmetric except through gamma_R and C_2.

    With their port and starboard values equal, (u, -v, -r, -delta) gives (X, -Y, -N);
    with the paper's values it does so only in straight motion (v = r = 0), and the
    asymmetry is of the size of the gamma_R difference.
    """
    rng = np.random.default_rng(1)
    vessel, sym = kvlcc2(), symmetrised(kvlcc2())
    flip = jnp.array([1.0, -1.0, -1.0])
    n = vessel.nominal_n
    worst_sym, worst_paper = 0.0, 0.0
    for u, v, r, d in mirror_states(rng):
        f, g = sym.forces(u, v, r, d, n), sym.forces(u, -v, -r, -d, n)
        scale = np.max(np.abs(f)) + 1e-300
        worst_sym = max(worst_sym, float(np.max(np.abs(f - flip * g)) / scale))
        f, g = vessel.forces(u, v, r, d, n), vessel.forces(u, -v, -r, -d, n)
        worst_paper = max(worst_paper, float(np.max(np.abs(f - flip * g)) / np.max(np.abs(f))))
        f, g = vessel.forces(u, 0.0, 0.0, d, n), vessel.forces(u, 0.0, 0.0, -d, n)
        np.testing.assert_allclose(np.asarray(f), np.asarray(flip * g), rtol=1e-13, atol=1e-12)
    assert worst_sym < 1e-12
    assert worst_paper > 1e-3  # the paper's model is not symmetric in turns


def test_kvlcc2_turning_mirror():
    """35 deg turns: the symmetrised model mirrors exactly; the paper's model within 1 %."""
    vessel = kvlcc2()
    x0 = js.straight_run(vessel)
    turn = lambda v, a: js.simulate(v, js.Turn(a * DEG, duration=120.0, dt=0.1), x0,
                                    simulator=js.Simulator(substeps=2))
    sym = symmetrised(vessel)
    stb, port = turn(sym, 35.0), turn(sym, -35.0)
    for name, sign in (("u", 1), ("v", -1), ("r", -1), ("x", 1), ("y", -1), ("psi", -1)):
        a, b = getattr(stb.state, name), getattr(port.state, name)
        np.testing.assert_allclose(np.asarray(a), sign * np.asarray(b), rtol=1e-9, atol=1e-9)
    stb, port = turning_indices(turn(vessel, 35.0)), turning_indices(turn(vessel, -35.0))
    assert stb.side == 1 and port.side == -1
    for name in ("advance", "transfer", "tactical_diameter"):
        a, b = getattr(stb, name), getattr(port, name)
        assert abs(a - b) < 0.01 * a, name


# --- KVLCC2: cross-check numbers -------------------------------------------------------------


def test_kvlcc2_turning_indices():
    """35 deg turn at the self-propulsion point: advance 3.08 L, transfer 1.33 L, tactical
    diameter 3.12 L (notes sec. 6). Tolerance 0.02 L: the notes give 3 digits and used
    h = 0.02 s (here 0.05 s) and an unspecified servo (here T = 0.1 s)."""
    vessel = kvlcc2()
    traj = js.simulate(vessel, js.Turn(35 * DEG, duration=120.0, dt=0.05),
                       js.straight_run(vessel), simulator=js.Simulator(substeps=1))
    ti = turning_indices(traj)
    assert abs(ti.advance / L - 3.08) < 0.02
    assert abs(ti.transfer / L - 1.33) < 0.02
    assert abs(ti.tactical_diameter / L - 3.12) < 0.02


@pytest.mark.parametrize("angle, first, second", [(10.0, 4.98, 13.6), (20.0, 10.53, 15.71)])
def test_kvlcc2_zigzag_overshoots(angle, first, second):
    """10/10 and 20/20 zig-zags, starboard first (notes sec. 6: 4.98, 13.6 and 10.53, 15.71 deg).

    Tolerance 0.1 deg: switching at the 0.02 s samples changes the heading by at most
    r dt = 0.01 deg, the servo lag (T = 0.1 s against a pure rate limit) moves the
    overshoots by 0.03 deg, and the notes give three digits.
    """
    vessel = kvlcc2()
    traj = js.simulate(vessel, js.ZigZag(angle * DEG, angle * DEG, duration=140.0, dt=0.02),
                       js.straight_run(vessel), simulator=js.Simulator(substeps=1))
    z = zigzag_indices(traj, angle * DEG)
    assert abs(np.rad2deg(z.overshoots[0]) - first) < 0.1
    assert abs(np.rad2deg(z.overshoots[1]) - second) < 0.1


# --- robustness and derivatives ------------------------------------------------------------


EDGE_STATES = [
    (0.0, 0.0, 0.0, 0.0, 0.0),  # at rest
    (0.0, 0.0, 0.0, 0.3, 10.0),  # bollard pull
    (0.0, 0.0, 0.05, 0.3, 0.0),  # pure rotation
    (0.5, 0.0, 0.0, 0.2, 0.0),  # propeller stopped
    (-0.3, 0.05, 0.01, 0.2, 5.0),  # astern, propeller ahead
    (-0.3, -0.05, 0.01, -0.2, -8.0),  # astern, propeller astern
    (0.3, 0.02, -0.01, 0.5, -8.0),  # ahead, propeller astern (crash stop)
]


@pytest.mark.parametrize("factory", [kvlcc2, esso_osaka])
def test_forces_finite_with_finite_derivatives(factory):
    """Forces and their Jacobian in (u, v, r, delta, n) stay finite at rest, at n = 0 and
    in the astern quadrants (outside the validity range of the MMG standard method)."""
    vessel = factory()
    jac = jax.jacfwd(lambda s: vessel.forces(*s))
    for state in EDGE_STATES:
        s = jnp.array(state)
        assert np.all(np.isfinite(vessel.forces(*s))), state
        assert np.all(np.isfinite(jac(s))), state


@pytest.mark.parametrize("factory", [kvlcc2, esso_osaka])
def test_force_jacobian_matches_finite_differences(factory):
    """The smoothed switches keep forward-mode derivatives exact in a turning state."""
    vessel = factory()
    u0 = vessel.nominal_speed
    state = np.array([0.8 * u0, -0.12 * u0, 0.4 * u0 / vessel.length, 20 * DEG, vessel.nominal_n])
    jac = np.asarray(jax.jacfwd(lambda s: vessel.forces(*s))(jnp.asarray(state)))
    for j in range(5):
        e = np.zeros(5)
        e[j] = 1.0
        forces = lambda h: np.asarray(vessel.forces(*(state + h * e)))
        fd = central_difference(forces, 0.0, eps=1e-6)
        np.testing.assert_allclose(jac[:, j], fd, rtol=1e-5, atol=1e-7 * np.max(np.abs(jac)))


def test_cross_flow_integrals_against_quadrature():
    x = np.linspace(-0.5, 0.5, 20001)
    for a, b in [(0.3, 0.1), (0.1, 0.5), (-0.2, 0.3), (0.0, 0.4), (0.05, -1.0), (0.2, 0.4)]:
        w = a + b * x
        i_1, i_2 = cross_flow_integrals(jnp.asarray(a), jnp.asarray(b))
        assert abs(float(i_1) - np.trapezoid(np.abs(w) * w, x)) < 1e-8
        assert abs(float(i_2) - np.trapezoid(x * np.abs(w) * w, x)) < 1e-8


def test_mass_matrices():
    """KVLCC2 m = rho nabla = 3351.75 kg (notes sec. 2.1); Esso m = 244.6 kg (README)."""
    k, e = kvlcc2(), esso_osaka()
    assert abs(float(k.mass()) - 3351.75) < 1e-6
    assert abs(float(e.mass()) - 244.6) < 0.05
    for vessel in (k, e):
        m = np.asarray(vessel.mass_matrix())
        np.testing.assert_array_equal(m, m.T)
        assert np.all(np.linalg.eigvalsh(m) > 0)


# --- Esso Osaka -----------------------------------------------------------------------------


def test_esso_osaka_straight_run_speed():
    """n = 10 rps gives 0.398 m/s: inside the measured range of the n = 10 rps runs
    (u up to 0.33-0.46 m/s, FRT-DS-ESSO README table; no run reaches a steady speed)."""
    vessel = esso_osaka()
    assert isinstance(vessel, LowSpeedMMGVessel)
    u = float(js.straight_run(vessel, n=10.0).u)
    assert 0.30 < u < 0.46
    assert abs(u - vessel.nominal_speed) < 1e-4


def test_esso_osaka_turns_the_right_way():
    vessel = esso_osaka()
    x0 = js.straight_run(vessel)
    for angle in (35.0, -35.0):
        traj = js.simulate(vessel, js.Turn(angle * DEG, duration=120.0, dt=0.1), x0,
                           simulator=js.Simulator(substeps=2))
        s = np.sign(angle)
        assert bool(traj.success)
        assert s * float(traj.state.r[-1]) > 1.5 * DEG  # steady about 2.3-2.4 deg/s
        assert s * float(traj.state.psi[-1]) > np.pi  # more than half a circle in 120 s
        assert float(traj.state.u[-1]) < 0.6 * float(x0.u)  # speed loss in the turn


def test_esso_osaka_windage():
    """The projected areas make `Environment(wind=...)` act: a beam wind from starboard
    pushes the drifting model to port (Fossen's wind loads, areas from the particulars)."""
    vessel = esso_osaka()
    assert vessel.frontal_wind_area == 0.13544 and vessel.lateral_wind_area == 0.52038
    wind = js.Environment(wind=js.Wind(speed=5.0, direction=np.pi / 2))  # from the east
    x0 = js.straight_state(0.0, 0.0)
    traj = js.simulate(vessel, js.Turn(0.0, duration=20.0, dt=0.1), x0, environment=wind)
    assert float(traj.state.y[-1]) < -0.01  # drifted west, i.e. to port
    assert float(traj.state.v[-1]) < 0.0


def _data(*parts):
    root = shared_data_dir()
    path = None if root is None else root.joinpath(*parts)
    if path is None or not path.exists():
        pytest.skip("measured data (../shared/data) not available")
    return path


def test_esso_osaka_acceleration_from_rest_against_measurement():
    """Run turn_14-Sep-2020_13_39_32 starts at rest with n = 10 rps and keeps the rudder
    near midships for 66 s: the model's speed after 65 s is within 15 % of the measured
    0.265 m/s (outdoor pond, true wind 1.4 m/s on average, not modelled here)."""
    exp = read_esso_osaka(_data("esso_osaka_frt", "turning", "turn_14-Sep-2020_13_39_32.csv"))
    k = int(round(65.0 / exp.dt))
    vessel = esso_osaka()
    replay = js.Replay(np.zeros(k + 1), exp.n[:k + 1], dt=exp.dt)
    traj = js.simulate(vessel, replay, js.straight_state(float(exp.u[0]), float(exp.n[0])),
                       simulator=js.Simulator(substeps=2))
    measured, simulated = float(exp.u[k]), float(traj.state.u[-1])
    assert abs(simulated - measured) < 0.15 * measured


# --- SIMMAN 2008 comparison ------------------------------------------------------------------


def _benchmark():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "kvlcc2_simman.py"
    spec = importlib.util.spec_from_file_location("kvlcc2_simman", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_simman_hsva_10_10_first_overshoot():
    """HSVA 10/10 zig-zag, starboard first, simulated at the measured 1.178 m/s and 10.23 rps.

    Measured 9.7 deg (repeat spread 0.2-0.5 deg); the MMG standard method with the
    paper's parameters gives 5.2 deg: it under-predicts the KVLCC2 overshoots (by 20-60 %
    over the 13 HSVA runs, see benchmarks/kvlcc2_simman.py), rather than the 10-20 %
    agreement one might hope for. The test pins that documented finding: the simulated
    first overshoot is on the right side and between 40 % and 100 % of the measured one.
    """
    bench = _benchmark()
    path = _data("kvlcc2_simman2008_hsva", "HSVA_CPMC_KVLCC2_Z_10_10_S.dat")
    rows = bench.compare_hsva(path, kvlcc2(), self_propulsion=False)
    run, label, measured, simulated, _ = rows[0]
    assert run == "HSVA 10/10 stb" and label.startswith("1st")
    assert abs(measured - 9.69) < 0.05
    assert 0.4 * measured < simulated < measured


def test_simman_marin_turning_circle():
    """MARIN 35 deg starboard turn (Froude-scaled to the model): the simulated tactical
    diameter at the measured speed and propeller rate is within 10 % of the measured
    3.33 L (the MMG paper's turning predictions agree to about that; we get -3 %)."""
    bench = _benchmark()
    path = _data("kvlcc2_simman2008_marin", "MARIN_FREE_KVLCC2_tc_-35_m.dat")
    rows = bench.compare_marin_turn(path, kvlcc2(), self_propulsion=False)
    (_, _, meas_adv, sim_adv, _), _, (_, _, meas_td, sim_td, _) = rows
    assert abs(meas_td - 3.33) < 0.02
    assert abs(sim_td - meas_td) < 0.10 * meas_td
    assert abs(sim_adv - meas_adv) < 0.10 * meas_adv
