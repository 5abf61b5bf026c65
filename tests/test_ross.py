"""The thesis vessel (Ross-type 3-DOF model of the 4 m DTMB 5415 model).

Reference ranges are from Odegard (2009), sec. 4.1: about 3.5 kn (1.8 m/s) top speed,
fig. 4.3 (40 deg turn at 500 rpm: speed 1.2-1.6 m/s, yaw rate axis 0-6, fig. 4.8: 0-8
deg/s), the vessel turns "as much as 10 [deg/s] using the maximum rudder deflection of 45
degrees" (figs. 4.7, 4.16: -10..10 deg/s, speed axis from 0.8 m/s), and the rudder limits
of Table 4.1. The coefficient derivation is in docs/thesis_vessel.md; the rudder stalls in
the propeller race only near the hard-over angle (sec. 16).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxship as js
from jaxship._models._vessel.ross import RossVessel, clarke83, thesis_vessel


DEG = np.pi / 180
RPM = 1 / 60
SIM = js.Simulator(substeps=2)


@pytest.fixture(scope="module")
def vessel():
    return thesis_vessel()


def steady_turn(vessel, angle, rpm=500.0, duration=80.0):
    x0 = js.straight_run(vessel, n=rpm * RPM)
    return x0, js.simulate(vessel, js.Turn(angle, duration=duration, dt=0.2), x0, simulator=SIM)


def test_preset_fields(vessel):
    assert isinstance(vessel, RossVessel)
    assert vessel.length == 4.002
    assert vessel.rudder.max_angle == pytest.approx(45 * DEG)
    assert vessel.rudder.max_rate == pytest.approx(15 * DEG)
    assert vessel.nominal_n == pytest.approx(500 * RPM)
    # the mass matrix is symmetric positive definite (thesis eq. 2.15)
    M = np.asarray(vessel.mass_matrix())
    np.testing.assert_allclose(M, M.T, rtol=0, atol=0)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    # Table 4.1: m = rho * 0.188 m^3, I_z = m (0.295 Lpp)^2 about the CG
    assert vessel.mass == pytest.approx(188.0)
    assert vessel.iz - vessel.mass * vessel.xg**2 == pytest.approx(188.0 * (0.295 * 4.002) ** 2)


def test_straight_run_speeds(vessel):
    """500 rpm: 1.2-1.8 m/s and equal to nominal_speed; 200 rpm slower; 600 rpm ~ 3.5 kn."""
    u500 = float(js.straight_run(vessel, n=500 * RPM).u)
    u200 = float(js.straight_run(vessel, n=200 * RPM).u)
    u600 = float(js.straight_run(vessel, n=600 * RPM).u)
    assert 1.2 < u500 < 1.8
    assert u500 == pytest.approx(vessel.nominal_speed, rel=1e-9)
    assert 0.3 < u200 < 0.6 * u500
    assert 1.7 < u600 < 1.95  # thesis: "approximately maximum speed of 3.5 knots (1.8 m/s)"
    assert float(js.straight_run(vessel, n=0.0).u) == pytest.approx(0.0, abs=1e-9)


def test_linear_derivatives_are_clarke(vessel):
    """Hull-only linear derivatives (rudder and propeller off) equal Clarke et al. (1983)
    plus the rigid-body centripetal terms: the explicit C_A split loses nothing."""
    hull = eqx.tree_at(lambda v: v.rudder_area, vessel, 0.0)
    L, u, rho = vessel.length, 1.3, vessel.rho
    c = clarke83(L, 0.538, 0.172, 0.188 / (L * 0.538 * 0.172))
    jac = jax.jacfwd(lambda vr: hull.forces(u, vr[0], vr[1], 0.0, 0.0))(jnp.zeros(2))
    m, mxg = vessel.mass, vessel.mass * vessel.xg
    np.testing.assert_allclose(jac[1, 0], c["y_v"] * 0.5 * rho * L**2 * u, rtol=1e-12)
    np.testing.assert_allclose(jac[1, 1], c["y_r"] * 0.5 * rho * L**3 * u - m * u, rtol=1e-12)
    np.testing.assert_allclose(jac[2, 0], c["n_v"] * 0.5 * rho * L**3 * u, rtol=1e-12)
    np.testing.assert_allclose(jac[2, 1], c["n_r"] * 0.5 * rho * L**4 * u - mxg * u, rtol=1e-12)


@pytest.mark.parametrize("rpm", [200.0, 500.0])
def test_course_stable(vessel, rpm):
    """Linearised sway-yaw dynamics about the straight run are stable (both poles < 0)."""
    x0 = js.straight_run(vessel, n=rpm * RPM)
    jac = jax.jacfwd(lambda vr: vessel.forces(x0.u, vr[0], vr[1], 0.0, x0.n)[1:])(jnp.zeros(2))
    poles = np.linalg.eigvals(np.linalg.solve(np.asarray(vessel.mass_matrix())[1:, 1:], jac))
    assert np.all(poles.real < -0.01)


def test_turn_40_deg_at_500_rpm(vessel):
    """Steady 40 deg turn: yaw rate 3-10 deg/s (thesis figs. 4.3, 4.8: below 8) with speed
    loss."""
    x0, tr = steady_turn(vessel, 40 * DEG)
    r_end, U_end = float(tr.state.r[-1]), float(tr.speed[-1])
    assert bool(tr.success)
    assert abs(float(tr.state.r[-1] - tr.state.r[-26])) < 1e-3 * DEG  # steady (last 5 s)
    assert 3 * DEG < r_end < 10 * DEG
    # fig. 4.3: 1.2-1.6 m/s. Was 1.1 < U_end (1.28 m/s with the rudder stalled at 40 deg);
    # with the stall in the propeller race (docs sec. 16) the harder turn slows the ship to
    # 1.10 m/s; fig. 4.7 (45 deg in the suggested manoeuvre) has its speed axis from 0.8
    assert 1.0 < U_end < float(x0.u) - 0.1


def test_turn_45_deg_and_200_rpm(vessel):
    """Max rudder keeps the yaw rate below ~12 deg/s; at 200 rpm everything is slower."""
    _, tr45 = steady_turn(vessel, 45 * DEG)
    _, tr200 = steady_turn(vessel, 40 * DEG, rpm=200.0)
    r45 = float(jnp.max(jnp.abs(tr45.state.r)))
    assert 3 * DEG < r45 < 12 * DEG
    assert float(jnp.max(tr200.state.r)) < 0.6 * float(tr45.state.r[-1])
    assert float(tr200.speed[-1]) < 0.7


@pytest.mark.parametrize("rpm", [200.0, 500.0])
def test_rudder_effectiveness_grows_to_hard_over(vessel, rpm):
    """Issue 12: in the propeller race the rudder does not stall within its travel, so a
    larger rudder angle turns the ship faster and on a smaller circle up to 45 deg (the
    thesis' vessel turns fastest at 45 deg, sec. 4.1); before the in-race stall a 40 deg
    rudder turned no faster than a 20 deg one."""
    angles = (10, 20, 35, 40, 45)
    r_end, diameter = [], []
    for a in angles:
        _, tr = steady_turn(vessel, a * DEG, rpm=rpm, duration=120.0)
        assert bool(tr.success)
        r_end.append(float(tr.state.r[-1]))
        diameter.append(float(2 * tr.speed[-1] / tr.state.r[-1]))
    assert np.all(np.diff(r_end) > 0.01 * DEG), np.rad2deg(r_end)
    assert np.all(np.diff(diameter) < 0), diameter
    # and the growth flattens: the speed loss in the hard turn and sin(alpha) saturate it
    assert r_end[-1] - r_end[-2] < r_end[2] - r_end[1]


def test_mirror_symmetry(vessel):
    """+35 and -35 deg turns mirror each other: (x, -y, -psi, -v, -r, -delta)."""
    x0 = js.straight_run(vessel, n=500 * RPM)
    run = lambda a: js.simulate(vessel, js.Turn(a, duration=60.0, dt=0.2), x0, simulator=SIM)
    p, s = run(35 * DEG), run(-35 * DEG)
    for name, sign in dict(u=1, x=1, n=1, v=-1, r=-1, y=-1, psi=-1, delta=-1).items():
        np.testing.assert_allclose(getattr(p.state, name), sign * getattr(s.state, name),
                                   rtol=0, atol=1e-10, err_msg=name)
    assert float(jnp.max(p.state.r)) > 3 * DEG  # it did turn


def test_zero_rudder_keeps_course_exactly(vessel):
    x0 = js.straight_run(vessel, n=500 * RPM)
    tr = js.simulate(vessel, js.Turn(0.0, duration=60.0, dt=0.2, n=600 * RPM), x0,
                     simulator=SIM)
    for name in ("v", "r", "y", "psi", "delta"):
        assert np.all(np.asarray(getattr(tr.state, name)) == 0.0), name
    assert float(tr.state.u[-1]) > float(x0.u) + 0.2  # it accelerated towards 600 rpm


def test_rudder_force_saturates_and_grows_with_rpm(vessel):
    """In the propeller race |F_N| grows up to the hard-over angle and stalls beyond it
    (docs sec. 16); at fixed alpha F_N grows with rpm."""
    u = vessel.nominal_speed
    angles = jnp.deg2rad(jnp.linspace(0.0, 70.0, 701))
    fn = jax.vmap(lambda d: vessel.rudder_normal_force(u, 0.0, 0.0, d, 500 * RPM))(angles)
    fn = np.asarray(fn)
    peak = int(np.argmax(fn))
    # was 20-35 deg (open-water stall); the in-race stall is at the hard-over angle, 45 deg
    assert 42 * DEG < float(angles[peak]) < 48 * DEG
    assert np.all(np.diff(fn[: peak + 1]) > 0)  # monotone below stall
    hard_over = int(np.argmin(np.abs(np.asarray(angles) - 45 * DEG)))
    assert fn[hard_over] > 0.99 * fn[peak]  # the full rudder travel is effective
    assert fn[-1] < 0.8 * fn[peak]  # and beyond it the rudder does stall
    # the race adds to the inflow once the propeller is loaded (thrust > 0)
    rpms = jnp.array([0.0, 200.0, 400.0, 500.0, 600.0]) * RPM
    for speed in (u, 0.6):
        f10 = jax.vmap(lambda n: vessel.rudder_normal_force(speed, 0.0, 0.0, 10 * DEG, n))(rpms)
        f10 = np.asarray(f10)
        assert np.all(np.diff(f10) >= 0) and f10[-1] > f10[-2] > f10[0]
    assert f10[1] > f10[0]  # at 0.6 m/s, 200 rpm already loads the propeller
    # and the ship turns faster with a faster propeller at the same speed through water
    n_eff = lambda n: vessel.forces(u, 0.0, 0.0, 10 * DEG, n)[2]
    assert float(n_eff(600 * RPM)) > float(n_eff(500 * RPM)) > 0.0


def test_stopped_propeller_gives_no_thrust(vessel):
    us = jnp.linspace(-1.0, 2.0, 31)
    thrust = jax.vmap(lambda u: vessel.thrust(u, 0.0))(us)
    assert np.all(np.asarray(thrust * us) <= 0.0)  # drag only


def test_power_is_dissipative_without_thrust(vessel):
    """nu^T tau <= 0 for any (u, v, r) with n = 0 and delta = 0 (Coriolis does no work)."""
    nu = jax.random.uniform(jax.random.key(0), (4000, 3), minval=-1.0, maxval=1.0)
    nu = nu * jnp.array([2.0, 0.6, 0.4])
    tau = jax.vmap(lambda q: vessel.forces(q[0], q[1], q[2], 0.0, 0.0))(nu)
    power = np.asarray(jnp.sum(nu * tau, axis=1))
    assert np.all(power <= 1e-12)
    assert np.min(power) < -1.0  # and it does dissipate


@pytest.mark.parametrize("u0, v0, r0", [(1.5, 0.3, 0.15), (0.8, -0.4, 0.25), (-0.5, 0.2, -0.2)])
def test_coast_down_energy_decays(vessel, u0, v0, r0):
    """Kinetic energy 1/2 nu^T M nu never increases in a coast-down (n = 0, rudder 0)."""
    x0 = js.ShipState(u=u0, v=v0, r=r0, x=0.0, y=0.0, psi=0.0, delta=0.0, n=0.0)
    tr = js.simulate(vessel, js.Turn(0.0, duration=60.0, dt=0.2, n=0.0), x0, simulator=SIM)
    nu = jnp.stack([tr.state.u, tr.state.v, tr.state.r], axis=1)
    energy = np.asarray(0.5 * jnp.einsum("ti,ij,tj->t", nu, vessel.mass_matrix(), nu))
    assert np.all(np.diff(energy) <= 1e-12 * energy[0])
    assert energy[-1] < 0.2 * energy[0]
