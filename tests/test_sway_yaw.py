"""Linear/nonlinear sway-yaw vessels and the Nomoto vessel (Astrom & Kallstrom 1979; thesis).

Published constants are from the seed report: Astrom & Kallstrom (1979), Tables 1-4
(prime system, their rudder sign: K' < 0 for a ship whose positive rudder turns it to
port). jaxship's sign is the opposite, so K' and K'_v change sign and the T's do not.
"""

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxship as js
from jaxship._models._vessel.nomoto import NomotoVessel, sea_scout
from jaxship._models._vessel.sway_yaw import (
    SwayYawVessel,
    _cross_flow_integrals,
    _derive_mass_terms,
    compass_island_linear,
    compass_island_nonlinear,
    sea_stratus_linear,
    sea_stratus_nonlinear,
    sea_swift,
)


DEG = np.pi / 180
KEYS = ("K", "T1", "T2", "T3", "Kv", "T3v")

# factory: (Y'v, Y'r - m', N'v, N'r - m'xG, Y'delta, N'delta), (K', T1', T2', T3', K'v, T3v')
PUBLISHED = {
    sea_stratus_linear: ((-0.02121, -0.01010, -0.00258, -0.00144, 0.00203, None),
                         (-1.01, 9.36, 0.37, 0.61, 0.12, 0.15)),  # Table 3, linear
    sea_stratus_nonlinear: ((-0.02037, -0.01065, -0.00300, -0.00138, 0.00206, -0.00097),
                            (-1.03, -11.08, 0.36, 0.61, 0.13, 0.15)),  # Table 3, nonlinear
    compass_island_linear: ((-0.01313, -0.00844, -0.00009, -0.00106, 0.00218, -0.00105),
                            (-1.28, 1.15, 0.85, 1.18, 0.17, 0.19)),  # Table 4, E1 linear
    compass_island_nonlinear: ((-0.00892, -0.00817, -0.00075, -0.00100, 0.00240, -0.00115),
                               (-1.42, 7.09, 0.64, 1.50, 0.18, 0.19)),  # Table 4, E1 nonlin.
    sea_swift: ((-0.01988, -0.01507, -0.00079, -0.00029, 0.00147, -0.00069),
                (-0.41, -8.04, 1.04, 1.38, 0.05, 0.23)),  # Table 2, E2
}
CROSS_FLOW = {sea_stratus_nonlinear: 0.63, compass_island_nonlinear: 0.35}


@pytest.mark.parametrize("factory", list(PUBLISHED), ids=lambda f: f.__name__)
def test_reproduces_published_constants(factory):
    """K', T1', T2', T3', K'v, T3v' of the preset's own matrices equal the published values
    to within 0.0082 (Sea Swift K'; every other residual is at most 0.0032, i.e. within
    the rounding of the two-decimal tables), and the stored mass terms are what the
    least-squares derivation gives."""
    derivatives, constants = PUBLISHED[factory]
    vessel = factory()
    assert isinstance(vessel, SwayYawVessel)
    c = vessel.prime_transfer_constants()
    sign = dict(K=-1, Kv=-1)  # jaxship rudder sign
    residuals = np.array([sign.get(k, 1) * float(c[k]) - p for k, p in zip(KEYS, constants)])
    limit = 0.0082 if factory is sea_swift else 0.0032
    assert np.max(np.abs(residuals)) <= limit, residuals
    # the published derivatives are stored as given (rudder terms sign-flipped)
    y_v, y_r, n_v, n_r, y_d, n_d = derivatives
    np.testing.assert_allclose([vessel.y_v, vessel.y_r, vessel.n_v, vessel.n_r, vessel.y_delta],
                               [y_v, y_r, n_v, n_r, -y_d], rtol=1e-15)
    masses, n_delta, res = _derive_mass_terms(derivatives, constants)
    np.testing.assert_allclose(-vessel.n_delta, n_delta, rtol=1e-5)
    np.testing.assert_allclose([vessel.m22, vessel.m23, vessel.m32, vessel.m33], masses,
                               rtol=2e-5)
    np.testing.assert_allclose(residuals, res, atol=5e-5)  # 6-digit rounding of the masses
    assert vessel.cross_flow == CROSS_FLOW.get(factory, 0.0)
    # physically sensible: positive diagonal, small coupling
    assert vessel.m22 > 0 and vessel.m33 > 0 and abs(vessel.m23) < 0.05 * vessel.m22


def test_exact_derivation_is_exact():
    """Constants of a known model (Mariner-like mass terms) give its mass terms back."""
    M = np.array([[0.0155, 0.0002], [0.0001, 0.0008]])
    ship = SwayYawVessel(
        length=160.0, draught=8.0, rudder=js.RudderServo(0.6, 0.1), nominal_speed=7.0,
        m22=M[0, 0], m23=M[0, 1], m32=M[1, 0], m33=M[1, 1], y_v=-0.0116, y_r=-0.0065,
        n_v=-0.0026, n_r=-0.0017, y_delta=-0.0028, n_delta=0.0014,
    )
    c = {k: float(v) for k, v in ship.prime_transfer_constants().items()}
    masses, _, res = _derive_mass_terms(
        (ship.y_v, ship.y_r, ship.n_v, ship.n_r, -ship.y_delta, -ship.n_delta),
        (-c["K"], c["T1"], c["T2"], c["T3"], -c["Kv"], c["T3v"]),
    )
    np.testing.assert_allclose(masses, M.ravel(), rtol=1e-9)
    np.testing.assert_allclose(res, 0.0, atol=1e-12)


@pytest.mark.parametrize("factory", list(PUBLISHED), ids=lambda f: f.__name__)
def test_transfer_constants_match_linearisation(factory):
    """The SI transfer functions from `transfer_constants` equal e (sM - A)^-1 b of the
    autodiff linearisation of `forces` and `mass_matrix` at a few complex frequencies."""
    vessel = factory()
    V = vessel.nominal_speed
    jac = jax.jacfwd(lambda x: vessel.forces(V, x[0], x[1], x[2], 0.0))(jnp.zeros(3))
    A, b = np.asarray(jac[1:, :2]), np.asarray(jac[1:, 2])
    M = np.asarray(vessel.mass_matrix())[1:, 1:]
    c = {k: float(v) for k, v in vessel.transfer_constants().items()}
    for s in (0.001 + 0.01j, 0.05j, 0.2 + 0.1j):
        v_s, r_s = np.linalg.solve(s * M - A, b)
        den = (s + 1 / c["T1"]) * (s + 1 / c["T2"])
        np.testing.assert_allclose(r_s, c["K"] * (s + 1 / c["T3"]) / den, rtol=1e-9)
        np.testing.assert_allclose(v_s, c["Kv"] * (s + 1 / c["T3v"]) / den, rtol=1e-9)


def _step(K, T1, T2, T3, t):
    """Step response of K(s + 1/T3)/((s + 1/T1)(s + 1/T2)) to a unit step (partial fractions)."""
    a, p1, p2 = 1 / T3, 1 / T1, 1 / T2
    return K * (a / (p1 * p2) + (a - p1) / (-p1 * (p2 - p1)) * np.exp(-p1 * t)
                + (a - p2) / (-p2 * (p1 - p2)) * np.exp(-p2 * t))


@pytest.mark.parametrize(
    "factory, duration, delta0, rtol",
    [
        (compass_island_linear, 200.0, 10 * DEG, 1e-8),
        (sea_stratus_linear, 600.0, 10 * DEG, 1e-8),
        (sea_swift, 300.0, 10 * DEG, 1e-8),  # course-unstable: growing mode
        (compass_island_nonlinear, 200.0, 1e-4 * DEG, 1e-4),  # cross-flow negligible
    ],
    ids=["compass_island_linear", "sea_stratus_linear", "sea_swift", "compass_nonlinear_small"],
)
def test_step_response_matches_transfer_function(factory, duration, delta0, rtol):
    """With the rudder at delta0 from t = 0 (an exact step), the simulated r and v equal
    the analytic step responses of eq. 4-5; the nonlinear model does for a tiny rudder."""
    vessel = factory()
    x0 = dataclasses.replace(js.straight_run(vessel), delta=jnp.asarray(delta0))
    traj = js.simulate(vessel, js.Turn(delta0, duration=duration, dt=0.5),
                       x0, simulator=js.Simulator(substeps=5))
    assert traj.success
    c = {k: float(v) for k, v in vessel.transfer_constants().items()}
    t = np.asarray(traj.t)
    r = delta0 * _step(c["K"], c["T1"], c["T2"], c["T3"], t)
    v = delta0 * _step(c["Kv"], c["T1"], c["T2"], c["T3v"], t)
    scale_r, scale_v = np.max(np.abs(r)), np.max(np.abs(v))
    assert np.max(np.abs(traj.state.r - r)) < rtol * scale_r
    assert np.max(np.abs(traj.state.v - v)) < rtol * scale_v
    np.testing.assert_allclose(traj.state.u, vessel.nominal_speed, rtol=1e-14)
    assert r[-1] > 0  # positive rudder turns to starboard


def test_nonlinear_departs_from_linear_at_large_rudder():
    """At 20 deg the cross-flow drag matters: the nonlinear model turns measurably slower
    than its own linear part (C = 0) after 200 s."""
    vessel = compass_island_nonlinear()
    linear = dataclasses.replace(vessel, cross_flow=0.0)
    x0 = js.straight_run(vessel)
    turn = js.Turn(20 * DEG, duration=200.0, dt=0.5)
    r_nl = js.simulate(vessel, turn, x0).state.r[-1]
    r_lin = js.simulate(linear, turn, x0).state.r[-1]
    assert 0 < r_nl < 0.95 * r_lin


# --- cross-flow drag ---------------------------------------------------------------------

L_TEST = 160.0
CASES = [
    (1.0, 0.0), (1.0, 1e-12), (1.0, 1e-9), (-0.7, 1e-6), (0.3, -2e-3), (0.3, 0.01),
    (-0.3, 0.01), (0.0, 0.01), (0.0, -0.02), (1e-8, 1e-3), (0.8, 0.01), (0.8, -0.01),
    (-2.0, 0.05), (0.0, 0.0), (1e-9, 0.0),
]


def _quadrature(v, r, L=L_TEST):
    """Gauss-Legendre quadrature (10 nodes) on the pieces of [-L/2, L/2] split where the
    cross-flow w = v + r x changes sign (the integrands are polynomials on each piece)."""
    edges = [-L / 2, L / 2]
    if r != 0 and abs(v / r) < L / 2:
        edges.insert(1, -v / r)
    nodes, weights = np.polynomial.legendre.leggauss(10)
    i0 = i1 = 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        x = 0.5 * (b - a) * nodes + 0.5 * (a + b)
        w = v + r * x
        i0 += 0.5 * (b - a) * np.sum(weights * np.abs(w) * w)
        i1 += 0.5 * (b - a) * np.sum(weights * x * np.abs(w) * w)
    return i0, i1


@pytest.mark.parametrize("v, r", CASES)
def test_cross_flow_closed_form_matches_quadrature(v, r):
    """Closed form = numerical quadrature to 1e-8 relative (of the natural scale
    L |v|(|v| + |r|L) for I0 and L^2 of that for I1), including r -> 0 and v -> 0."""
    i0, i1 = _cross_flow_integrals(jnp.float64(v), jnp.float64(r), L_TEST)
    q0, q1 = _quadrature(v, r)
    scale = L_TEST * (abs(v) + abs(r) * L_TEST) ** 2 + 1e-300
    assert abs(float(i0) - q0) <= 1e-8 * scale
    assert abs(float(i1) - q1) <= 1e-8 * scale * L_TEST


@pytest.mark.parametrize("v, r", CASES)
def test_cross_flow_is_antisymmetric(v, r):
    """Y_cf(-v, -r) = -Y_cf(v, r) and N_cf likewise (exactly)."""
    a = np.array(_cross_flow_integrals(jnp.float64(v), jnp.float64(r), L_TEST))
    b = np.array(_cross_flow_integrals(jnp.float64(-v), jnp.float64(-r), L_TEST))
    np.testing.assert_array_equal(b, -a)


@pytest.mark.parametrize("v", [1.0, -0.5, 0.0])
def test_cross_flow_gradient_at_zero_yaw_rate(v):
    """Gradients with respect to v and r are finite at r = 0 and equal finite differences
    (at v = 0, r = 0 both vanish); they are continuous across the branch boundary
    |v| = |r| L/2."""
    f = lambda x: jnp.stack(_cross_flow_integrals(x[0], x[1], L_TEST))
    x = jnp.array([v, 0.0])
    jac = np.asarray(jax.jacfwd(f)(x))
    assert np.all(np.isfinite(jac))
    assert np.all(np.isfinite(np.asarray(jax.jacrev(f)(x))))
    eps = 1e-7
    fd = np.stack([(f(x + e) - f(x - e)) / (2 * eps) for e in np.eye(2) * eps], axis=1)
    np.testing.assert_allclose(jac, fd, rtol=1e-6, atol=1e-6 * L_TEST**3)
    if v != 0:
        # analytic: dI0/dv = 2 L |v|, dI1/dr = |v| L^3 / 6 at r = 0
        np.testing.assert_allclose(jac[0, 0], 2 * L_TEST * abs(v), rtol=1e-12)
        np.testing.assert_allclose(jac[1, 1], abs(v) * L_TEST**3 / 6, rtol=1e-12)
        edge = 2 * abs(v) / L_TEST  # |v| = |r| L/2
        inside = np.asarray(jax.jacfwd(f)(jnp.array([v, edge * (1 + 1e-9)])))
        outside = np.asarray(jax.jacfwd(f)(jnp.array([v, edge * (1 - 1e-9)])))
        np.testing.assert_allclose(inside, outside, rtol=1e-6, atol=1e-9 * L_TEST**3)
    else:
        np.testing.assert_allclose(jac, 0.0, atol=1e-12)


def test_vessel_cross_flow_forces_and_mirror_symmetry():
    """forces = linear part - rho T C / 2 (I0, I1), and forces are odd in (v, r, delta)."""
    vessel = sea_stratus_nonlinear()
    linear = dataclasses.replace(vessel, cross_flow=0.0)
    u, v, r, d = 8.0, 0.4, -0.002, 5 * DEG
    i0, i1 = _cross_flow_integrals(v, r, vessel.length)
    drag = 0.5 * 1025 * vessel.draught * 0.63
    np.testing.assert_allclose(
        vessel.forces(u, v, r, d, 0.0),
        linear.forces(u, v, r, d, 0.0) - np.array([0.0, drag * i0, drag * i1]), rtol=1e-13,
    )
    np.testing.assert_allclose(vessel.forces(u, -v, -r, -d, 0.0),
                               -vessel.forces(u, v, r, d, 0.0),
                               rtol=1e-13, atol=1e-12)


def test_gradient_with_respect_to_cross_flow_coefficient():
    """d(final yaw rate)/dC through `simulate` equals central differences."""
    vessel = compass_island_nonlinear()
    x0 = js.straight_run(vessel)
    turn = js.Turn(20 * DEG, duration=100.0, dt=0.5)
    f = lambda c: js.simulate(dataclasses.replace(vessel, cross_flow=c), turn, x0).state.r[-1]
    grad = jax.grad(f)(0.35)
    fd = (f(0.35 + 1e-6) - f(0.35 - 1e-6)) / 2e-6
    assert grad < 0  # more drag, slower turn
    np.testing.assert_allclose(grad, fd, rtol=1e-6)


# --- Nomoto ------------------------------------------------------------------------------

def test_sea_scout_constants():
    """Table 1, E1 continuous time: K' = -1.04, T' = 1.37 -> gain = 1.04*1.37 V/L, T = T' L/V
    (jaxship sign), for L = 320 m, V = 8 m/s."""
    ship = sea_scout()
    assert isinstance(ship, NomotoVessel)
    np.testing.assert_allclose(ship.gain, 1.04 * 1.37 * 8.0 / 320.0, rtol=1e-14)
    np.testing.assert_allclose(ship.time_constant, 1.37 * 320.0 / 8.0, rtol=1e-14)


@pytest.mark.parametrize("r0", [0.0, -0.002])
def test_nomoto_step_response(r0):
    """r(t) = exp(-t/T) r0 + (1 - exp(-t/T)) K delta0 (thesis eq. 3.17) to 1e-6 relative."""
    ship = sea_scout()
    delta0 = 10 * DEG
    x0 = dataclasses.replace(js.straight_run(ship), delta=jnp.asarray(delta0),
                             r=jnp.asarray(r0))
    traj = js.simulate(ship, js.Turn(delta0, duration=400.0, dt=1.0), x0,
                       simulator=js.Simulator(substeps=4))
    t = np.asarray(traj.t)
    K, T = ship.gain, ship.time_constant
    expected = np.exp(-t / T) * r0 + (1 - np.exp(-t / T)) * K * delta0
    assert np.max(np.abs(traj.state.r - expected)) < 1e-6 * np.max(np.abs(expected))
    np.testing.assert_allclose(traj.state.v, 0.0, atol=0.0)
    np.testing.assert_allclose(traj.state.u, ship.nominal_speed, rtol=1e-15)
    np.testing.assert_allclose(traj.state.psi, _heading(t, K * delta0, r0, T),
                               rtol=1e-6, atol=1e-9)


def _heading(t, k_delta, r0, T):
    """Heading of eq. 3.17: integral of r from 0 to t."""
    return k_delta * (t - T * (1 - np.exp(-t / T))) + r0 * T * (1 - np.exp(-t / T))


def test_norrbin_steady_state():
    """Nonlinear Nomoto (thesis eq. 3.4-3.5): the steady turning rate solves H(r) = K delta,
    for a course-unstable characteristic (n1 = -1) on the stable branch."""
    base = sea_scout()
    ship = dataclasses.replace(base, n1=-1.0, n3=4.0e5, n2=0.0, n0=0.0)
    delta0 = 10 * DEG
    x0 = dataclasses.replace(js.straight_run(ship), delta=jnp.asarray(delta0))
    traj = js.simulate(ship, js.Turn(delta0, duration=2000.0, dt=1.0), x0)
    r_end = float(traj.state.r[-1])
    np.testing.assert_allclose(ship.characteristic(r_end), ship.gain * delta0, rtol=1e-8)
    assert r_end > 0
    # the unstable characteristic keeps turning at zero rudder once started (hysteresis)
    x1 = dataclasses.replace(js.straight_run(ship), r=jnp.asarray(1e-3))
    drift = js.simulate(ship, js.Turn(0.0, duration=2000.0, dt=1.0), x1).state.r[-1]
    np.testing.assert_allclose(drift, np.sqrt(1 / 4.0e5), rtol=1e-8)


def test_a_steering_simulation_starts_from_the_sway_velocity_it_is_given():
    """`simulate` takes psi, r and, on a model with a sway state, v from `x0` (a record's
    first sample): the linear sway-yaw model with the rudder amidships starts at the
    given drift and decays from it."""
    model = js.LinearSwayYaw.from_vessel(js.get_vessel("sea_stratus_linear"))
    x0 = dataclasses.replace(js.straight_state(0.0, psi=0.2), r=0.001, v=0.1)
    tr = js.simulate(model, js.Replay(np.zeros(40), dt=0.5), x0,
                     aux=js.AuxInputs(u=8.0))
    v = np.asarray(tr.internal[:, model.state_names.index("v")])
    assert v[0] == 0.1 and float(tr.state.r[0]) == 0.001 and float(tr.state.psi[0]) == 0.2
    assert abs(v[-1]) < abs(v[0])
