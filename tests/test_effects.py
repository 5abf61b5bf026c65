"""Effects with their own states (rudder lag, delay, rate limit) and effects in the yaw
equation of a steering model: their physics against closed-form responses, and their
parameters recovered by `fit` like any other."""

import jax.numpy as jnp
import numpy as np
import pytest

import jaxship as js


DEG = np.pi / 180
K, T = 0.06, 25.0


def step(num=600, angle=10 * DEG):
    delta = np.full(num, angle)
    delta[0] = 0.0
    return delta


def test_rudder_lag_gives_the_two_time_constant_step_response():
    """Nomoto 1 behind a lag $T_l$: $r = K\\delta[1 - (Te^{-t/T} - T_le^{-t/T_l})/(T - T_l)]$."""
    lag = 4.0
    model = js.augment(js.Nomoto1(K=K, T=T), js.RudderLag(time_constant=lag))
    assert model.state_names == ("r", "rudder_lag.delta_lagged")
    dt = 0.5
    delta = step()
    out = js.simulate_steering(model, delta, dt, hold="zoh", substeps=5)
    t = np.asarray(out.t) - dt  # the step acts from the second sample
    expected = K * 10 * DEG * (1 - (T * np.exp(-t / T) - lag * np.exp(-t / lag)) / (T - lag))
    # RK4 at 0.1 s control steps: error of order (h / T_l)^4 = 4e-7 of the final rate
    np.testing.assert_allclose(out.r[1:], expected[1:], rtol=0, atol=1e-6 * K * 10 * DEG)
    # the lagged rudder is a state: it follows delta (1 - exp(-t / T_l))
    np.testing.assert_allclose(out.state[1:, 1], 10 * DEG * (1 - np.exp(-t[1:] / lag)),
                               atol=1e-6 * 10 * DEG)


def test_rudder_delay_follows_the_delayed_response():
    """A 2 s delay (first-order Pade) shifts Nomoto 1's step response by 2 s: within
    0.5 % of the step's final yaw rate once the delay has passed."""
    delay, dt = 2.0, 0.25
    model = js.augment(js.Nomoto1(K=K, T=T), js.RudderDelay(delay=delay))
    out = js.simulate_steering(model, step(1200), dt, hold="zoh", substeps=5)
    t = np.asarray(out.t) - dt
    exact = K * 10 * DEG * (1 - np.exp(-np.clip(t - delay, 0, None) / T))
    late = t > 2 * delay
    assert np.max(np.abs(out.r[late] - exact[late])) < 5e-3 * K * 10 * DEG
    undelayed = K * 10 * DEG * (1 - np.exp(-np.clip(t, 0, None) / T))
    assert np.max(np.abs(out.r[late] - undelayed[late])) > 0.05 * K * 10 * DEG


def test_rudder_rate_limit_ramps_the_acting_rudder():
    """The limiter tracks with a 0.1 s time constant, so it needs control steps of
    about that length (here 5 per 0.5 s sample)."""
    rate = 2.3 * DEG
    model = js.augment(js.Nomoto1(K=K, T=T), js.RudderRateLimit(inverse_rate=1 / rate))
    out = js.simulate_steering(model, step(200, 20 * DEG), 0.5, hold="zoh", substeps=5)
    acting = np.asarray(out.state[:, 1])
    slope = np.diff(acting) / 0.5
    np.testing.assert_allclose(slope[2:15], rate, rtol=1e-9)  # ramping at the limit
    assert acting[-1] == pytest.approx(20 * DEG, abs=1e-9)  # then reaches the order


@pytest.mark.parametrize("effect", [js.RudderLag(), js.RudderDelay(), js.RudderRateLimit()])
def test_stateful_effects_at_zero_equal_the_base_on_a_vessel(effect):
    vessel = js.vessel("mariner")
    man, x0 = js.ZigZag(10 * DEG, 10 * DEG, duration=120.0, dt=1.0), js.straight_run(vessel)
    base = js.simulate(vessel, man, x0)
    same = js.simulate(js.augment(vessel, effect), man, x0)
    for key in ("u", "v", "r", "psi", "delta"):
        np.testing.assert_array_equal(getattr(same.state, key), getattr(base.state, key))


def test_rudder_lag_on_a_vessel_slows_the_zigzag_and_is_recovered_by_fit():
    """Mariner behind a 3 s rudder lag overshoots more; `fit` recovers the lag from the
    replayed rudder (prediction error, noise-free) within 1 %."""
    vessel = js.vessel("mariner")
    man, x0 = js.ZigZag(10 * DEG, 10 * DEG, duration=300.0, dt=0.5), js.straight_run(vessel)
    lagged = js.augment(vessel, js.RudderLag(time_constant=3.0))
    truth = js.simulate(lagged, man, x0)
    plain = js.simulate(vessel, man, x0)
    over = lambda traj: js.zigzag_indices(traj, 10 * DEG).overshoots[0]
    assert float(over(truth)) > float(over(plain)) + 0.2 * DEG
    data = js.Experiment.from_trajectory(truth)
    start = js.augment(vessel, js.RudderLag(time_constant=1.0))
    result = js.fit(start, data, estimator=js.PredictionError(horizon=60.0),
                    free=("rudder_lag.time_constant",))
    values = dict(zip(result.names, result.values))
    assert values["rudder_lag.time_constant"] == pytest.approx(3.0, rel=1e-2)


def test_fit_recovers_a_rudder_lag_on_a_steering_model():
    truth = js.augment(js.Nomoto1(K=K, T=T), js.RudderLag(time_constant=3.0))
    delta = 10 * DEG * np.sign(np.sin(2 * np.pi * np.arange(800) / 160.0) + 1e-9)
    delta[0] = 0.0  # from a straight run, as trials start
    out = js.simulate_steering(truth, delta, 0.5, substeps=20)  # a finer truth
    data = js.Experiment(np.asarray(out.t), delta, psi=np.asarray(out.psi), r=np.asarray(out.r))
    start = js.augment(js.Nomoto1(K=0.05, T=20.0), js.RudderLag(time_constant=1.0))
    result = js.fit(start, data, estimator=js.PredictionError(horizon=None, substeps=5),
                    free=("K", "T", "rudder_lag.time_constant"))
    values = dict(zip(result.names, result.values))
    for name, value in (("K", K), ("T", T), ("rudder_lag.time_constant", 3.0)):
        assert values[name] == pytest.approx(value, rel=1e-3), name


def test_nonlinear_nomoto2_is_nomoto2_with_cubic_damping():
    """Lu & Zhao (2008, eq. 4) in the states of `Nomoto2`: $\\dot r_{aux} = K(\\delta
    + \\delta_0) - r - \\beta_1 r^3$, $\\dot r$ as `Nomoto2`."""
    K2, T1, T2, T3, beta, d0 = 0.06, 25.0, 3.0, 5.0, 120.0, 0.01
    model = js.nonlinear_nomoto2(K2, T1, T2, T3, beta1=beta, delta0=d0)
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
        moment = js.simulate_steering(js.augment(base, js.YawMomentBias(n0=K * d0)), delta, 0.5)
        offset = js.simulate_steering(js.augment(base, js.RudderOffset(delta0=d0)), delta, 0.5)
        if isinstance(base, js.Nomoto1):
            np.testing.assert_allclose(moment.r, offset.r, rtol=1e-12, atol=1e-15)
        else:  # Nomoto 2: the offset also enters through K T3 (delta + delta0)
            assert np.max(np.abs(moment.r - offset.r)) < 1e-2 * np.max(np.abs(offset.r))
