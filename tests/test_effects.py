"""Effects with their own states (rudder lag, delay, rate limit) and effects in the yaw
equation of a steering model: their physics against closed-form responses, and their
parameters recovered by `fit` like any other."""


import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_equal_to_rounding, per_sample
from scipy.integrate import quad

import jaxship as js


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples
ZOH = js.strategies.ZeroOrderHold()  # the replayed rudder held over each interval


DEG = np.pi / 180
K, T = 0.06, 25.0


def step(num=600, angle=10 * DEG):
    delta = np.full(num, angle)
    delta[0] = 0.0
    return delta


def test_rudder_lag_gives_the_two_time_constant_step_response():
    """Nomoto 1 behind a lag $T_l$: $r = K\\delta[1 - (Te^{-t/T} - T_le^{-t/T_l})/(T - T_l)]$."""
    lag = 4.0
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.RudderLag(time_constant=lag))
    assert model.state_names == ("r", "rudder_lag.delta_lagged")
    dt = 0.5
    delta = step()
    out = js.simulate(model, js.Replay(delta, dt=dt, delta_hold=ZOH), simulator=per_sample(5))
    t = np.asarray(out.t) - dt  # the step acts from the second sample
    expected = K * 10 * DEG * (1 - (T * np.exp(-t / T) - lag * np.exp(-t / lag)) / (T - lag))
    # RK4 at 0.1 s control steps: error of order (h / T_l)^4 = 4e-7 of the final rate
    np.testing.assert_allclose(out.state.r[1:], expected[1:], rtol=0, atol=1e-6 * K * 10 * DEG)
    # the lagged rudder is a state: it follows delta (1 - exp(-t / T_l))
    np.testing.assert_allclose(out.internal[1:, 1], 10 * DEG * (1 - np.exp(-t[1:] / lag)),
                               atol=1e-6 * 10 * DEG)


def test_rudder_delay_follows_the_delayed_response():
    """A 2 s delay (first-order Pade) shifts Nomoto 1's step response by 2 s: within
    0.5 % of the step's final yaw rate once the delay has passed."""
    delay, dt = 2.0, 0.25
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.RudderDelay(delay=delay))
    out = js.simulate(model, js.Replay(step(1200), dt=dt, delta_hold=ZOH),
                      simulator=per_sample(5))
    t = np.asarray(out.t) - dt
    exact = K * 10 * DEG * (1 - np.exp(-np.clip(t - delay, 0, None) / T))
    late = t > 2 * delay
    assert np.max(np.abs(out.state.r[late] - exact[late])) < 5e-3 * K * 10 * DEG
    undelayed = K * 10 * DEG * (1 - np.exp(-np.clip(t, 0, None) / T))
    assert np.max(np.abs(out.state.r[late] - undelayed[late])) > 0.05 * K * 10 * DEG


def test_rudder_rate_limit_ramps_the_acting_rudder():
    """The limiter tracks with a 0.1 s time constant, so it needs control steps of
    about that length (here 5 per 0.5 s sample)."""
    rate = 2.3 * DEG
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.RudderRateLimit(inverse_rate=1 / rate))
    out = js.simulate(model, js.Replay(step(200, 20 * DEG), dt=0.5, delta_hold=ZOH),
                      simulator=per_sample(5))
    acting = np.asarray(out.internal[:, 1])
    slope = np.diff(acting) / 0.5
    np.testing.assert_allclose(slope[2:15], rate, rtol=1e-9)  # ramping at the limit
    assert acting[-1] == pytest.approx(20 * DEG, abs=1e-9)  # then reaches the order


@pytest.mark.parametrize("effect", [js.effects.RudderLag(), js.effects.RudderDelay(),
                                    js.effects.RudderRateLimit()])
def test_stateful_effects_at_zero_equal_the_base_on_a_vessel(effect):
    vessel = js.get_vessel("mariner")
    man, x0 = js.ZigZag(10 * DEG, 10 * DEG, duration=120.0, dt=1.0), js.straight_run(vessel)
    base = js.simulate(vessel, man, x0)
    same = js.simulate(js.augment(vessel, effect), man, x0)
    for key in ("u", "v", "r", "psi", "delta"):
        assert_equal_to_rounding(getattr(same.state, key), getattr(base.state, key))


def test_rudder_lag_on_a_vessel_slows_the_zigzag_and_is_recovered_by_fit():
    """Mariner behind a 3 s rudder lag overshoots more; `fit` recovers the lag from the
    replayed rudder (prediction error, noise-free) within 1 %."""
    vessel = js.get_vessel("mariner")
    man, x0 = js.ZigZag(10 * DEG, 10 * DEG, duration=300.0, dt=0.5), js.straight_run(vessel)
    lagged = js.augment(vessel, js.effects.RudderLag(time_constant=3.0))
    truth = js.simulate(lagged, man, x0)
    plain = js.simulate(vessel, man, x0)
    over = lambda traj: js.indices.zigzag_indices(traj, 10 * DEG).overshoots[0]
    assert float(over(truth)) > float(over(plain)) + 0.2 * DEG
    data = js.Experiment.from_trajectory(truth)
    start = js.augment(vessel, js.effects.RudderLag(time_constant=1.0))
    result = js.fit(start, data, estimator=js.PredictionError(horizon=60.0),
                    free=("rudder_lag.time_constant",))
    values = dict(zip(result.names, result.values))
    assert values["rudder_lag.time_constant"] == pytest.approx(3.0, rel=1e-2)


def test_fit_recovers_a_rudder_lag_on_a_steering_model():
    truth = js.augment(js.Nomoto1(K=K, T=T), js.effects.RudderLag(time_constant=3.0))
    delta = 10 * DEG * np.sign(np.sin(2 * np.pi * np.arange(800) / 160.0) + 1e-9)
    delta[0] = 0.0  # from a straight run, as trials start
    out = js.simulate(truth, js.Replay(delta, dt=0.5, delta_hold=FOH),
                      simulator=per_sample(20))  # a finer truth
    data = js.Experiment(np.asarray(out.t), delta, psi=np.asarray(out.state.psi),
                         r=np.asarray(out.state.r))
    start = js.augment(js.Nomoto1(K=0.05, T=20.0), js.effects.RudderLag(time_constant=1.0))
    result = js.fit(start, data,
                    estimator=js.PredictionError(horizon=None, simulator=per_sample(5)),
                    free=("K", "T", "rudder_lag.time_constant"))
    values = dict(zip(result.names, result.values))
    for name, value in (("K", K), ("T", T), ("rudder_lag.time_constant", 3.0)):
        assert values[name] == pytest.approx(value, rel=1e-3), name



def test_a_model_augmented_with_no_effects_fits_as_its_base():
    """`augment(model)` with nothing added is the base, in `fit` too (the parameter
    lookup once failed on the empty effects tuple)."""
    delta = 10 * DEG * np.sign(np.sin(2 * np.pi * np.arange(400) / 160.0) + 1e-9)
    delta[0] = 0.0
    out = js.simulate(js.Nomoto1(K=K, T=T), js.Replay(delta, dt=0.5, delta_hold=FOH),
                      simulator=per_sample())
    data = js.Experiment(np.asarray(out.t), delta, psi=np.asarray(out.state.psi),
                         r=np.asarray(out.state.r))
    estimator = js.PredictionError(horizon=None)
    start = js.Nomoto1(K=0.05, T=20.0)
    plain = js.fit(start, data, estimator=estimator)
    augmented = js.fit(js.augment(start), data, estimator=estimator)
    np.testing.assert_allclose(augmented.values, plain.values, rtol=1e-10)
    assert augmented.values == pytest.approx([K, T], rel=1e-6)

def test_nonlinear_nomoto2_is_nomoto2_with_cubic_damping():
    """Lu & Zhao (2008, eq. 4) in the states of `Nomoto2`: $\\dot r_{aux} = K(\\delta
    + \\delta_0) - r - \\beta_1 r^3$, $\\dot r$ as `Nomoto2`."""
    K2, T1, T2, T3, beta, d0 = 0.06, 25.0, 3.0, 5.0, 120.0, 0.01
    model = js.effects.nonlinear_nomoto2(K2, T1, T2, T3, beta1=beta, delta0=d0)
    rng = np.random.default_rng(0)
    for _ in range(5):
        r, r_aux, delta = rng.normal(0, [0.02, 0.5, 0.2])
        rudder = delta + d0
        expected = [(r_aux - (T1 + T2) * r + K2 * T3 * rudder) / (T1 * T2),
                    K2 * rudder - r - beta * r**3]
        got = model.rhs(jnp.array([r, r_aux]), delta, js.AuxInputs())
        np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-16)


def test_a_yaw_moment_on_nomoto_equals_a_rudder_offset():
    """In $T\\dot r + r = K\\delta + N_0$ a constant moment is the offset $N_0/K$: on a
    Nomoto model the two cannot be told apart (Lu & Zhao 2008, eq. 1)."""
    d0 = 0.01
    delta = 10 * DEG * np.sign(np.sin(2 * np.pi * np.arange(400) / 160.0) + 1e-9)
    for base in (js.Nomoto1(K=K, T=T), js.Nomoto2(K=K, T1=T, T2=3.0, T3=5.0)):
        moment = js.simulate(js.augment(base, js.effects.YawMomentBias(n0=K * d0)),
                             js.Replay(delta, dt=0.5, delta_hold=FOH), simulator=per_sample())
        offset = js.simulate(js.augment(base, js.effects.RudderOffset(delta0=d0)),
                             js.Replay(delta, dt=0.5, delta_hold=FOH), simulator=per_sample())
        if isinstance(base, js.Nomoto1):
            np.testing.assert_allclose(moment.state.r, offset.state.r, rtol=1e-12, atol=1e-15)
        else:  # Nomoto 2: the offset also enters through K T3 (delta + delta0)
            assert (np.max(np.abs(moment.state.r - offset.state.r))
                    < 1e-2 * np.max(np.abs(offset.state.r)))


# -- hull, rudder, propeller and environment effects (`_hydro_effects.py`) --

MARINER = js.get_vessel("mariner")
U0 = MARINER.nominal_speed
# (u, v, r, delta, n): straight, a starboard turn (v < 0 at midship), a port turn astern
STATES = [(U0, 0.0, 0.0, 0.0, 1.5), (0.8 * U0, -0.4, 0.012, 0.3, 1.5),
          (0.6 * U0, 0.3, -0.02, -0.5, -1.2)]


def added_loads(effect, state):
    """The loads `effect` adds to the Mariner at `state`."""
    return np.asarray(js.augment(MARINER, effect).forces(*state) - MARINER.forces(*state))


@pytest.mark.parametrize("effect, expected", [
    (js.effects.YawCubicDamping(beta=2e12), lambda u, v, r, d, n: (0, 0, -2e12 * r**3)),
    (js.effects.YawQuadraticDamping(beta=4e10), lambda u, v, r, d, n: (0, 0, -4e10 * r * abs(r))),
    (js.effects.PropellerAsymmetry(moment=1.4e6), lambda u, v, r, d, n: (0, 0, 1.4e6 * n * abs(n))),
    (js.effects.SurgeTurnResistance(x_vr=0.004),
     lambda u, v, r, d, n: (0.004 * 0.5 * 1025.0 * MARINER.length**3 * v * r, 0, 0)),
])
def test_load_effects_add_their_closed_form_to_a_vessel(effect, expected):
    """The augmented Mariner's loads minus the Mariner's are the effect's term; positive
    damping opposes r, and added turn resistance slows a drifting, turning ship."""
    for state in STATES:
        np.testing.assert_allclose(added_loads(effect, state), expected(*state), rtol=1e-6,
                                   atol=1e-9 * float(np.max(np.abs(MARINER.forces(*state)))))
    turning = STATES[1]
    if isinstance(effect, (js.effects.YawCubicDamping, js.effects.YawQuadraticDamping)):
        assert added_loads(effect, turning)[2] < 0  # r > 0: a moment to port
    if isinstance(effect, js.effects.SurgeTurnResistance):
        assert added_loads(effect, turning)[0] < 0  # v r < 0: more resistance


def steady_r(model, angle, aux=None, num=800, dt=1.0):
    """The yaw rate after `num` samples of a rudder step to `angle` from rest."""
    out = js.simulate(model, js.Replay(step(num, angle), dt=dt, delta_hold=ZOH), aux=aux,
                      simulator=per_sample(2))
    return float(out.state.r[-1])


def test_quadratic_damping_shifts_the_steady_turn_of_nomoto1():
    """$r + \\beta r|r| = K\\delta$: $r = (\\sqrt{1 + 4\\beta K\\delta} - 1)/(2\\beta)$, odd in
    the rudder (to 1e-9, after 32 time constants)."""
    beta, angle = 10.0, 10 * DEG
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.YawQuadraticDamping(beta=beta))
    expected = (np.sqrt(1 + 4 * beta * K * angle) - 1) / (2 * beta)
    assert expected < 0.92 * K * angle  # a visible shift: 9 % below the linear turn
    assert steady_r(model, angle) == pytest.approx(expected, rel=1e-9)
    assert steady_r(model, -angle) == pytest.approx(-expected, rel=1e-9)


def test_crossflow_drag_integrates_the_strip_loads_exactly():
    """Pure sway: $Y = -\\frac12\\rho cL^2v|v|$, N = 0; pure yaw: Y = 0,
    $N = -\\frac12\\rho cL^5r|r|/32$; a turn (the flow reverses along the hull) against
    an adaptive quadrature of the strip integrals."""
    c, L, rho = 0.04, MARINER.length, 1025.0
    effect = js.effects.CrossflowDrag(coefficient=c)
    q = 0.5 * rho * c * L
    for v in (0.4, -0.7):
        np.testing.assert_allclose(added_loads(effect, (U0, v, 0.0, 0.0, 0.0)),
                                   (0, -q * L * v * abs(v), 0), rtol=1e-12, atol=1e-6)
    for r in (0.01, -0.02):
        np.testing.assert_allclose(added_loads(effect, (U0, 0.0, r, 0.0, 0.0)),
                                   (0, 0, -q * L**4 / 32 * r * abs(r)), rtol=1e-6, atol=1e-4)
    for v, r in ((-0.4, 0.012), (0.3, 0.002), (0.5, -0.03)):
        w = lambda x: abs(v + x * r) * (v + x * r)
        kink = [-v / r] if abs(r) * L / 2 > abs(v) else None
        sway = quad(w, -L / 2, L / 2, points=kink, epsabs=0, epsrel=1e-13)[0]
        yaw = quad(lambda x: x * w(x), -L / 2, L / 2, points=kink, epsabs=0, epsrel=1e-13)[0]
        np.testing.assert_allclose(added_loads(effect, (U0, v, r, 0.0, 0.0)),
                                   (0, -q * sway, -q * yaw), rtol=1e-6, atol=1e-3)


def test_speed_dependent_rudder_is_the_base_at_the_nominal_speed():
    """Vessel: at $u = U_0$ the loads are the Mariner's bit for bit; at $0.8U_0$ the
    rudder's share $\\tau(\\delta) - \\tau(0)$ is scaled by $1 + \\kappa(0.64 - 1)$.
    Nomoto 1: the steady turn is $K\\delta(1 + \\kappa(u^2/U_0^2 - 1))$."""
    kappa = 0.5
    vessel = js.augment(MARINER, js.effects.SpeedDependentRudder(kappa=kappa))
    for _, v, r, d, n in STATES:
        np.testing.assert_array_equal(vessel.forces(U0, v, r, d, n),
                                      MARINER.forces(U0, v, r, d, n))
        u = 0.8 * U0
        share = MARINER.forces(u, v, r, d, n) - MARINER.forces(u, v, r, 0.0, n)
        np.testing.assert_allclose(vessel.forces(u, v, r, d, n),
                                   MARINER.forces(u, v, r, d, n) + kappa * (0.64 - 1) * share,
                                   rtol=1e-12, atol=1e-3)
    effect = js.effects.SpeedDependentRudder(kappa=kappa, nominal_speed=U0)
    model = js.augment(js.Nomoto1(K=K, T=T), effect)
    base = js.Nomoto1(K=K, T=T)
    delta = step(100)
    at_nominal = js.AuxInputs(u=U0)
    np.testing.assert_array_equal(js.simulate(model, js.Replay(delta, dt=1.0, delta_hold=FOH),
                                              aux=at_nominal, simulator=per_sample()).state.r,
                                  js.simulate(base, js.Replay(delta, dt=1.0, delta_hold=FOH),
                                              aux=at_nominal, simulator=per_sample()).state.r)
    slow = js.AuxInputs(u=0.8 * U0)
    assert steady_r(model, 10 * DEG, slow) == pytest.approx(
        K * 10 * DEG * (1 + kappa * (0.64 - 1)), rel=1e-9)
    with pytest.raises(ValueError, match="nominal_speed"):
        js.simulate(js.augment(base, js.effects.SpeedDependentRudder(kappa=kappa)),
                    js.Replay(delta, dt=1.0, delta_hold=FOH), simulator=per_sample())


def test_speed_dependent_damping_and_rudder_make_nomoto_speed_scaled():
    """With both kappa = 1 at a constant speed $u = sU_0$, Nomoto 1 is Nomoto's
    dimensionless model at that speed: $K = K's$, $T = T'/s$ (Nomoto 1957)."""
    s = 0.7
    scaled = js.augment(js.Nomoto1(K=K, T=T), js.effects.SpeedDependentRudder(kappa=1.0,
                                                                              nominal_speed=U0),
                        js.effects.SpeedDependentDamping(kappa=1.0, nominal_speed=U0))
    delta = step(200)
    aux = js.AuxInputs(u=s * U0)
    np.testing.assert_allclose(js.simulate(scaled, js.Replay(delta, dt=1.0, delta_hold=FOH),
                                           aux=aux, simulator=per_sample()).state.r,
                               js.simulate(js.Nomoto1(K=K * s, T=T / s),
                                           js.Replay(delta, dt=1.0, delta_hold=FOH),
                                           simulator=per_sample()).state.r,
                               rtol=1e-9, atol=1e-12)
    base = js.Nomoto1(K=K, T=T)
    np.testing.assert_allclose(  # the base model at the nominal speed (to rounding)
        js.simulate(js.augment(base, js.effects.SpeedDependentDamping(kappa=1.0, nominal_speed=U0)),
                    js.Replay(delta, dt=1.0, delta_hold=FOH), aux=js.AuxInputs(u=U0),
                    simulator=per_sample()).state.r,
        js.simulate(base, js.Replay(delta, dt=1.0, delta_hold=FOH), aux=js.AuxInputs(u=U0),
                    simulator=per_sample()).state.r, rtol=1e-14, atol=0)
    with pytest.raises(ValueError, match="nominal_speed"):
        js.simulate(js.augment(base, js.effects.SpeedDependentDamping(kappa=1.0)),
                    js.Replay(delta, dt=1.0, delta_hold=FOH), simulator=per_sample())


def test_rudder_stall_saturates_only_large_rudder_angles():
    """$\\delta' = \\delta - c\\delta^3$: monotonic to 46 deg at the upper bound; Nomoto 1
    turns at $K\\delta'$; on the Mariner at 0.6 deg the yaw moment changes by
    $-c\\delta^2$ of the rudder's (third order) within 0.1 %."""
    upper = 0.5  # the plausible bound
    angles = np.deg2rad(np.linspace(0, 46, 47))
    effect = js.effects.RudderStall(c=upper)
    seen = np.array([effect.rudder(a, None) for a in angles])
    assert np.all(np.diff(seen) > 0)
    c = 0.3
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.RudderStall(c=c))
    angle = 30 * DEG
    assert steady_r(model, angle) == pytest.approx(K * (angle - c * angle**3), rel=1e-9)
    small = 0.01
    stalled = js.augment(MARINER, js.effects.RudderStall(c=c)).forces(U0, 0.0, 0.0, small, 0.0)
    rudder = MARINER.forces(U0, 0.0, 0.0, small, 0.0) - MARINER.forces(U0, 0.0, 0.0, 0.0, 0.0)
    change = stalled - MARINER.forces(U0, 0.0, 0.0, small, 0.0)
    assert float(change[2] / rudder[2]) == pytest.approx(-c * small**2, rel=1e-3)


def test_propeller_asymmetry_on_nomoto1_turns_with_the_propeller_rate():
    """$T\\dot r + r = K\\delta + a_pn|n|$: steady $r = K\\delta + a_pn|n|$ with the
    measured n, reversed when the propeller is."""
    a_p = 2.6e-4
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.PropellerAsymmetry(moment=a_p))
    for n in (2.0, -1.0):
        assert steady_r(model, 5 * DEG, js.AuxInputs(n=n)) == pytest.approx(
            K * 5 * DEG + a_p * n * abs(n), rel=1e-9)


def test_propeller_race_on_nomoto1_adds_rudder_gain_with_rpm_squared():
    """$T\\dot r + r = K\\delta + b n_+^2\\delta$: steady $r = (K + b n^2)\\delta$ ahead,
    $K\\delta$ with the propeller astern (its race off the rudder) or stopped."""
    b = 2e-4
    model = js.augment(js.Nomoto1(K=K, T=T), js.effects.PropellerRace(gain=b))
    delta = 5 * DEG
    assert steady_r(model, delta, js.AuxInputs(n=3.0)) == pytest.approx(
        (K + b * 9.0) * delta, rel=1e-9)
    for n in (0.0, -3.0):
        assert steady_r(model, delta, js.AuxInputs(n=n)) == pytest.approx(K * delta, rel=1e-9)


def test_added_mass_error_scales_the_mass_matrix():
    """$M_{22}(1 + s_v)$, $M_{33}(1 + s_r)$, the rest unchanged; the accelerations are
    $M^{-1}\\tau$ of that matrix."""
    s_v, s_r = 0.2, -0.1
    vessel = js.augment(MARINER, js.effects.AddedMassError(s_v=s_v, s_r=s_r))
    m = np.asarray(MARINER.mass_matrix())
    expected = m.copy()
    expected[1, 1] *= 1 + s_v
    expected[2, 2] *= 1 + s_r
    np.testing.assert_array_equal(vessel.mass_matrix(), expected)
    state = js.ShipState(u=0.8 * U0, v=-0.4, r=0.012, x=0.0, y=0.0, psi=0.3, delta=0.3, n=0.0)
    d = js.state_derivative(vessel, state, js.Command(0.3, 0.0), js.Environment())
    tau = np.asarray(MARINER.forces(0.8 * U0, -0.4, 0.012, 0.3, 0.0))
    np.testing.assert_allclose([d.u, d.v, d.r], np.linalg.solve(expected, tau), rtol=1e-10)


def test_current_drifts_the_track_and_leaves_the_water_velocities():
    """A current of (0.5, -0.3) m/s (north, east), added to the environment's (0.2 m/s
    to the east): u, v, r, psi bit for bit the Mariner's, the track moved by
    $V_c t$."""
    man, x0 = js.ZigZag(10 * DEG, 10 * DEG, duration=60.0, dt=1.0), js.straight_run(MARINER)
    environment = js.Environment(current=js.Current(0.2, np.pi / 2))
    base = js.simulate(MARINER, man, x0, environment=environment)
    drifted = js.simulate(js.augment(MARINER, js.effects.UniformCurrent(north=0.5, east=-0.3)), man,
                          x0, environment=environment)
    for key in ("u", "v", "r", "psi", "delta"):
        np.testing.assert_array_equal(getattr(drifted.state, key), getattr(base.state, key))
    t = np.asarray(base.t) - float(base.t[0])
    np.testing.assert_allclose(drifted.state.x - base.state.x, 0.5 * t, atol=1e-8)
    np.testing.assert_allclose(drifted.state.y - base.state.y, -0.3 * t, atol=1e-8)


def test_windage_is_the_vessel_with_those_areas_when_wind_is_logged():
    """Calm water: nothing changes. In a 15 m/s wind, simulated and predicted from
    logged wind (`PredictionError(wind=True)`), the Mariner with `Windage` equals the
    Mariner with those areas bit for bit; without the logged wind the effect is absent."""
    areas = {"frontal_wind_area": 350.0, "lateral_wind_area": 2000.0}
    windy = js.augment(MARINER, js.effects.Windage(frontal_area=350.0, lateral_area=2000.0))
    assert (windy.frontal_wind_area, windy.lateral_wind_area) == (350.0, 2000.0)
    with_areas = eqx.tree_at(lambda v: (v.frontal_wind_area, v.lateral_wind_area), MARINER,
                             tuple(areas.values()))
    man, x0 = js.ZigZag(10 * DEG, 10 * DEG, duration=80.0, dt=1.0), js.straight_run(MARINER)
    calm = js.simulate(windy, man, x0)
    np.testing.assert_array_equal(calm.state.psi, js.simulate(MARINER, man, x0).state.psi)
    wind = js.Wind(15.0, np.deg2rad(60.0))
    environment = js.Environment(wind=wind)
    truth = js.simulate(windy, man, x0, environment=environment)
    np.testing.assert_array_equal(
        truth.state.psi, js.simulate(with_areas, man, x0, environment=environment).state.psi)
    assert np.max(np.abs(truth.state.psi - calm.state.psi)) > 0.1 * DEG
    e = js.Experiment.from_trajectory(truth)
    data = js.Experiment(e.t, e.delta, psi=e.psi, r=e.r, u=e.u, v=e.v, n=e.n,
                         wind_speed=np.full(e.t.shape, 15.0),
                         wind_dir=np.full(e.t.shape, np.deg2rad(60.0)))
    logged = js.PredictionError(horizon=None, wind=True)
    got = js.predict(windy, data, estimator=logged).predictions["psi"]
    np.testing.assert_array_equal(got, js.predict(with_areas, data,
                                                  estimator=logged).predictions["psi"])
    calm_replay = js.predict(windy, data, estimator=js.PredictionError(horizon=None))
    assert np.max(np.abs(np.asarray(calm_replay.predictions["psi"]) - np.asarray(got))) > 0.1 * DEG


def test_apparent_wind_adds_its_yaw_term_to_a_steering_model():
    """At zero (or without logged wind) the augmented Nomoto 1 is the base bit for bit;
    with wind its yaw term is $V^2(c_2\\sin 2\\gamma + c_1\\sin\\gamma)$ through the
    model's forcing, and only a model with it replays the wind."""
    t = np.arange(400) * 0.5
    gamma = 0.3 + 0.02 * t  # the apparent wind turning round the ship
    aux = js.AuxInputs(u=np.full(t.size, 7.0), wind_u=20.0 * np.cos(gamma),
                       wind_v=20.0 * np.sin(gamma))
    delta = np.deg2rad(10) * np.sign(np.sin(2 * np.pi * t / 80.0) + 1e-9)
    model = js.Nomoto1(K=K, T=T)
    base = js.simulate(model, js.Replay(delta, dt=0.5, delta_hold=FOH), aux=aux,
                       simulator=per_sample())
    zero = js.augment(model, js.effects.ApparentWind())
    np.testing.assert_array_equal(js.simulate(zero, js.Replay(delta, dt=0.5, delta_hold=FOH),
                                              aux=aux,
                                              simulator=per_sample()).state.psi, base.state.psi)
    windy = js.augment(model, js.effects.ApparentWind(c2=3e-6, c1=-1e-6))
    np.testing.assert_array_equal(js.simulate(windy, js.Replay(delta, dt=0.5, delta_hold=FOH),
                                              simulator=per_sample()).state.psi,
                                  js.simulate(model, js.Replay(delta, dt=0.5, delta_hold=FOH),
                                              simulator=per_sample()).state.psi)  # calm
    assert np.max(np.abs(js.simulate(windy, js.Replay(delta, dt=0.5, delta_hold=FOH), aux=aux,
                                     simulator=per_sample()).state.psi
                         - base.state.psi)) > 1 * DEG
    one = js.AuxInputs(u=7.0, wind_u=20.0 * np.cos(0.7), wind_v=20.0 * np.sin(0.7))
    x = jnp.array([0.01])
    term = 400.0 * (3e-6 * np.sin(1.4) - 1e-6 * np.sin(0.7))
    np.testing.assert_allclose(windy.rhs(x, 0.1, one) - model.rhs(x, 0.1, one),
                               model.forcing(x) * term, rtol=1e-12)
    assert windy.wind_loads and not js.augment(model, js.effects.RudderOffset()).wind_loads


def test_apparent_wind_is_the_ship_velocity_through_the_air_in_body_axes():
    """Heading east at 5 m/s in a 10 m/s wind from the north: the air comes from port,
    (u, v) = (5, -10) m/s, gamma = atan2(-10, 5); heading north into it: (15, 0)."""
    from jaxship._estimate._windows import apparent_wind, as_dataset

    t = np.arange(3) * 1.0
    for psi, expected in ((np.pi / 2, (5.0, -10.0)), (0.0, (15.0, 0.0))):
        e = js.Experiment(t, np.zeros(3), psi=np.full(3, psi), u=np.full(3, 5.0),
                          v=np.zeros(3), wind_speed=np.full(3, 10.0), wind_dir=np.zeros(3))
        got = apparent_wind(as_dataset(e))
        np.testing.assert_allclose([got["wind_u"][0, 0], got["wind_v"][0, 0]], expected,
                                   atol=1e-12)


def test_fit_recovers_the_wind_a_steering_model_feels_from_logged_wind():
    """Nomoto 1 in a logged 15 m/s wind (records: `wind_records`, 10/10 zig-zags on
    four headings): the wind's c2 and c1 (truth 0) within 3 robust standard errors; K
    and T within 2 % (1.2 and 1.4 % low here, with or without the wind: the noise's
    doing, as noiseless records give them to 1e-8)."""
    from jaxship.studies.discovery import wind_records

    truth = js.augment(js.Nomoto1(K=K, T=T), js.effects.ApparentWind(c2=3e-6))
    train, _ = wind_records(truth, 0)
    start = js.augment(js.Nomoto1(K=0.05, T=20.0), js.effects.ApparentWind())
    res = js.fit(start, train, estimator=js.PredictionError(horizon=60.0, wind=True,
                                                            initial=js.EstimatedStarts()))
    got = dict(zip(res.names, zip(res.values, res.parameters.std_robust)))
    for name, value in (("wind.c2", 3e-6), ("wind.c1", 0.0)):
        assert abs(got[name][0] - value) < 3 * got[name][1], (name, got[name])
    np.testing.assert_allclose([got["K"][0], got["T"][0]], [K, T], rtol=0.02)


@pytest.mark.parametrize("effect", [js.effects.SwayForceBias(y0=1e4), js.effects.CrossflowDrag(),
                                    js.effects.SurgeTurnResistance(), js.effects.AddedMassError(),
                                    js.effects.UniformCurrent(), js.effects.Windage()],
                                        ids=lambda e: e.id)
def test_a_vessel_only_effect_on_a_steering_model_is_an_error(effect):
    """Effects that act on a vessel's loads, mass, environment or wind areas only would
    add a parameter with no effect to a steering model (a singular fit): refused,
    while the same effect on a vessel is accepted."""
    with pytest.raises(ValueError, match="augment a vessel instead"):
        js.augment(js.Nomoto1(K=K, T=T), effect)
    assert js.augment(js.get_vessel("mariner"), effect).effects == (effect,)


def test_a_yaw_term_on_a_vessel_is_an_error():
    """The steering models' apparent-wind term has no place on a vessel (whose wind acts
    through its loads: `Windage`)."""
    with pytest.raises(ValueError, match="ApparentWind acts on nothing a vessel has .*"
                       "augment a steering model instead"):
        js.augment(js.get_vessel("mariner"), js.effects.ApparentWind())


def test_a_family_unit_is_read_on_the_model_it_acts_on():
    """`YawMomentBias.n0` is N m on a vessel, rad/s on a Nomoto model (T r' + r = K delta
    + f) and rad/s^2 on a model written as r' = ... (the Ross model)."""
    from jaxship._models._effects import family_unit

    unit = js.effects.YawMomentBias.__dataclass_fields__["n0"].metadata
    n0 = "N m | rad/s | rad/s^2"
    assert n0 in str(unit)
    assert family_unit(n0, js.get_vessel("mariner")) == "N m"
    assert family_unit(n0, js.Nomoto1(K=0.1, T=10.0)) == "rad/s"
    assert family_unit(n0, js.Nomoto2(K=0.1, T1=10.0, T2=1.0, T3=2.0)) == "rad/s"
    assert family_unit(n0, js.RossAutopilot()) == "rad/s^2"
    assert family_unit("s | -", js.Nomoto1(K=0.1, T=10.0)) == "-"
    assert family_unit("rad", js.get_vessel("mariner")) == "rad"
