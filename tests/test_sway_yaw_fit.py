"""Linear sway-yaw and Norrbin cross-flow steering models (Astrom & Kallstrom 1979, eq. 3
and section 2): agreement with the 3-DOF `sea_stratus_nonlinear` vessel, fit-then-recover,
gradients, and the reproduction of the report's finding that prediction error with a
horizon beats output error under disturbances (Table 3 model, C = 0.63)."""


import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship import (
    AuxInputs,
    LinearSwayYaw,
    NorrbinCrossFlow,
    PredictionError,
    fit,
)
from jaxship._models._steering import WindowStart
from jaxship._models._vessel._base import state_derivative
from jaxship._models._vessel.sway_yaw import sea_stratus_linear, sea_stratus_nonlinear
from jaxship.studies.astrom import (
    FREE,
    TABLE3_START,
    NoiseLevels,
    simulate_disturbed,
    zigzag_trial,
)


DEG = np.pi / 180
VESSEL = sea_stratus_nonlinear()
TRUTH = NorrbinCrossFlow.from_vessel(VESSEL)
QUIET = NoiseLevels(yaw_noise=0.0, psi=0.0, r=0.0, v=0.0)


def with_values(model, values: dict):
    return eqx.tree_at(lambda m: tuple(getattr(m, k) for k in values), model,
                       tuple(float(v) for v in values.values()))


def table3_start(model=TRUTH):
    """Table 3's "Initial estim." column (N'_delta missing there: -0.00100)."""
    names = [k for k in FREE if hasattr(model, k)]  # no C in the linear model
    return with_values(model, {k: TABLE3_START[k] for k in names})


def rudder_steps(num, seed, amplitudes=(10.0, 20.0, 30.0), hold=(60, 240)):
    """Open-loop rudder steps of alternating sign and random amplitude and hold [rad]."""
    rng = np.random.default_rng(seed)
    out, sign = [], 1.0
    while len(out) < num:
        sign = -sign
        out.extend([sign * rng.choice(amplitudes) * DEG] * int(rng.integers(*hold)))
    return np.array(out[:num])


def own_record(model, delta, dt=1.0, seed=0):
    """A noise-free record of `model` itself, with a measured surge speed that varies
    (7.2-8.8 m/s): the model must use the measured u as V at every sample."""
    t = dt * np.arange(delta.shape[0])
    u = 8.0 + 0.8 * np.sin(2 * np.pi * t / 700.0 + seed)
    tr = js.simulate(model, js.Replay(delta, dt=dt, delta_hold=js.strategies.FirstOrderHold()),
                     js.straight_state(0.0, psi=0.2), aux=AuxInputs(u=u), simulator=per_sample())
    return js.Experiment(t, delta, psi=np.asarray(tr.state.psi), r=np.asarray(tr.state.r), u=u,
                         v=np.asarray(tr.internal[:, 1]))


# -- the steering model is the vessel's sway-yaw dynamics ----------------------------------


def test_rhs_equals_the_vessel_sway_and_yaw_accelerations():
    """At random (u, v, r, delta) the steering model's (r_dot, v_dot) are the sway and
    yaw rows of the 3-DOF vessel's M^-1 tau (same force function), to 1e-12."""
    rng = np.random.default_rng(0)
    for _ in range(20):
        u, v, r, d = 8 + rng.normal(), rng.normal(), 0.01 * rng.normal(), 0.3 * rng.normal()
        state = js.ShipState(u=u, v=v, r=r, x=0.0, y=0.0, psi=0.0, delta=d, n=0.0)
        ref = state_derivative(VESSEL, state, js.Command(d, 0.0), js.Environment())
        got = TRUTH.rhs(jnp.array([r, v]), d, AuxInputs(u=u))
        np.testing.assert_allclose(got, [ref.r, ref.v], rtol=1e-12, atol=1e-18)
        # no surge speed measured (u = 0 filled in): the model's nominal speed
        fallback = TRUTH.rhs(jnp.array([r, v]), d, AuxInputs(u=0.0))
        np.testing.assert_allclose(fallback, TRUTH.rhs(jnp.array([r, v]), d, AuxInputs(u=8.0)),
                                   rtol=1e-14)


def test_matches_the_3dof_simulation_of_sea_stratus():
    """What agrees: r, v and psi of a 20/20 zig-zag of the 3-DOF `sea_stratus_nonlinear`
    (rudder servo, RK4 at 0.1 s; u stays 8 m/s as X = 0) and of `NorrbinCrossFlow`
    replaying the vessel's rudder angle sampled at 0.1 s (linear between samples, the
    default hold) with the measured u, to 2e-6 of each signal's range; sampled at 1 s,
    where the servo's ramps start and end between samples, to 2e-4. `zigzag_trial`
    without noise is `simulate`."""
    man = js.ZigZag(angle=20 * DEG, heading=20 * DEG, duration=600.0, dt=0.1)
    tr = js.simulate(VESSEL, man, js.straight_run(VESSEL))
    d = np.asarray(tr.state.delta)
    for over, tol in ((1, 2e-6), (10, 2e-4)):
        st = js.simulate(TRUTH, js.Replay(d[::over], dt=0.1 * over,
                                          delta_hold=js.strategies.FirstOrderHold()),
                         aux=AuxInputs(u=np.asarray(tr.state.u)[::over]), simulator=per_sample())
        for name, got in (("r", st.state.r), ("v", st.internal[:, 1]), ("psi", st.state.psi)):
            ref = np.asarray(getattr(tr.state, name))[::over]
            assert np.max(np.abs(got - ref)) <= tol * np.ptp(ref), (name, over)
    np.testing.assert_allclose(np.asarray(tr.state.u), 8.0, rtol=1e-12)
    trial = zigzag_trial(VESSEL, 20 * DEG, duration=600.0, noise=QUIET)
    np.testing.assert_allclose(trial.r, np.asarray(tr.state.r)[::10], rtol=0, atol=1e-15)
    np.testing.assert_allclose(trial.psi, np.asarray(tr.state.psi)[::10], rtol=0, atol=1e-14)


def test_steady_turn_and_window_state():
    """`initial_state(r)` is an equilibrium at the steady-turn rudder; straight run is 0;
    windows start from the measured r and v."""
    for model in (TRUTH, LinearSwayYaw.from_vessel(sea_stratus_linear())):
        for r in (0.002, -0.004):
            v, delta = model.steady_turn(r)
            x = model.initial_state(r)
            np.testing.assert_allclose(x, [r, v])
            rhs = model.rhs(x, delta, AuxInputs(u=model.speed))
            assert np.max(np.abs(rhs)) < 1e-14
        np.testing.assert_array_equal(model.initial_state(0.0), [0.0, 0.0])
    start = WindowStart(r=0.01, psi=0.3, delta=0.1, r_first=0.0, psi_first=0.0,
                        delta_integral=0.0, elapsed=10.0, aux=AuxInputs(u=8.0, v=-0.4))
    np.testing.assert_array_equal(TRUTH.window_state(start), [0.01, -0.4])


def test_from_vessel_and_errors():
    linear = LinearSwayYaw.from_vessel(VESSEL)
    assert linear.cross_flow_coefficient() == 0.0 and linear.y_v == VESSEL.y_v
    assert NorrbinCrossFlow.from_vessel(sea_stratus_linear(), cross_flow=0.7).cross_flow == 0.7
    with pytest.raises(ValueError, match="SwayYawVessel"):
        NorrbinCrossFlow.from_vessel(js.get_vessel("mariner"))


# -- fit-then-recover and gradients ---------------------------------------------------------


@pytest.mark.parametrize("horizon", [pytest.param(None, marks=pytest.mark.slow), 60.0])
def test_norrbin_model_recovers_from_table3_start(horizon):
    """Noise-free data of the model itself (open-loop rudder steps up to 30 deg, varying
    measured speed): output error and T_p = 60 s recover the six derivatives and
    C = 0.63 to 1e-6 from the report's initial estimates."""
    data = own_record(TRUTH, rudder_steps(1000, 0))
    res = fit(table3_start(), data,
              estimator=PredictionError(horizon=horizon, channels=("psi", "r", "v")))
    assert res.success and res.names == FREE
    np.testing.assert_allclose(res.values, [getattr(TRUTH, k) for k in FREE], rtol=1e-6)
    assert res.model.m22 == TRUTH.m22  # mass terms frozen


@pytest.mark.slow
def test_linear_model_recovers_on_psi_and_r_only():
    """The linear model (Sea Stratus linear column) from psi and r alone, T_p = 60 s."""
    truth = LinearSwayYaw.from_vessel(sea_stratus_linear())
    data = own_record(truth, rudder_steps(1500, 1, amplitudes=(5.0, 10.0)))
    res = fit(table3_start(truth), data, estimator=PredictionError(horizon=60.0))
    names = FREE[:-1]
    np.testing.assert_allclose(res.values, [getattr(truth, k) for k in names], rtol=1e-6)


def test_gradients_match_finite_differences():
    """d(sum of squared yaw-rate and sway outputs)/d(coefficient) by reverse and forward
    mode equals central differences (relative step 1e-6) to 1e-6."""
    delta = rudder_steps(200, 2, hold=(30, 60))
    aux = AuxInputs(u=np.full(200, 8.0))

    @jax.jit
    def loss(values):
        model = eqx.tree_at(lambda m: tuple(getattr(m, k) for k in FREE), TRUTH,
                            tuple(values[i] for i in range(len(FREE))))
        tr = js.simulate(model, js.Replay(delta, dt=1.0,
                                          delta_hold=js.strategies.FirstOrderHold()), aux=aux,
                         simulator=per_sample())
        return jnp.sum(tr.state.r**2) * 1e4 + jnp.sum(tr.internal[:, 1] ** 2)

    p = jnp.array([getattr(TRUTH, k) for k in FREE])
    grad = jax.grad(loss)(p)
    fwd = jax.jacfwd(loss)(p)
    for i in range(len(FREE)):
        h = 1e-6 * abs(float(p[i]))
        e = jnp.zeros_like(p).at[i].set(h)
        fd = (loss(p + e) - loss(p - e)) / (2 * h)
        np.testing.assert_allclose(grad[i], fd, rtol=1e-6)
        np.testing.assert_allclose(fwd[i], grad[i], rtol=1e-10)


def test_disturbed_simulation_adds_the_yaw_moment():
    """A constant yaw moment equal to the rudder moment of 1 deg (N = rho/2 L^3 V^2
    N'_delta delta) has the yaw-moment effect of a 1 deg rudder without its sway force:
    the initial yaw acceleration matches, the rudder stays at 0."""
    man = js.Turn(angle=0.0, duration=2.0, dt=1.0)
    moment = 0.5 * VESSEL.rho * VESSEL.length**3 * 64.0 * VESSEL.n_delta * DEG
    x0 = js.straight_run(VESSEL)
    traj = simulate_disturbed(VESSEL, man, x0, jnp.full(3, moment))
    deriv = state_derivative(VESSEL, x0, js.Command(0.0, 0.0), js.Environment())
    assert float(deriv.r) == 0.0 and float(traj.state.r[-1]) > 0.0
    assert np.all(np.asarray(traj.command.delta) == 0.0)
    assert np.all(np.asarray(traj.state.delta) == 0.0)


# -- noise: coverage and prediction error against output error ------------------------------


def _noisy_fit(seed, horizon, angle=20.0):
    exp = zigzag_trial(VESSEL, angle * DEG, duration=1800.0, seed=seed)
    est = PredictionError(horizon=horizon, channels=("psi", "r", "v"))
    res = fit(table3_start(), exp, estimator=est, free=FREE)
    return res, res.parameters.std_robust


@pytest.mark.slow
def test_robust_intervals_cover_the_truth_under_noise():
    """20/20 zig-zags with the default random yaw moment and sensor noise, 12 seeds,
    T_p = 60 s: the 95 % intervals from the HAC (Newey-West) standard errors cover the
    truth for at least 85 % of the 84 (parameter, seed) pairs; the white-residual
    standard errors of `fit` are too small under process noise (coverage below 70 %)."""
    truth = np.array([getattr(TRUTH, k) for k in FREE])
    robust, plain = [], []
    for seed in range(12):
        res, rstd = _noisy_fit(100 + seed, 60.0)
        assert res.success
        robust.append(np.abs(res.values - truth) <= 1.96 * rstd)
        plain.append(np.abs(res.values - truth) <= 1.96 * res.std)
    assert np.mean(robust) >= 0.85, np.mean(robust)
    assert np.mean(plain) < 0.70, np.mean(plain)


@pytest.mark.slow
def test_prediction_error_beats_output_error_under_process_noise():
    """Same data (20/20 zig-zag, random yaw moment, 4 seeds): T_p = 60 s estimates are
    closer to the truth than output error's in every seed (relative RMS error over the
    seven coefficients, and |C - 0.63|), as Astrom & Kallstrom (1979, section 4)
    report; on noise-free data both are exact (see the recovery test)."""
    truth = np.array([getattr(TRUTH, k) for k in FREE])
    for seed in range(4):
        pe, _ = _noisy_fit(200 + seed, 60.0)
        oe, _ = _noisy_fit(200 + seed, None)
        rel = lambda r: np.sqrt(np.mean(((r.values - truth) / truth) ** 2))
        assert rel(pe) < rel(oe), (seed, rel(pe), rel(oe))
        assert abs(pe.values[-1] - 0.63) < abs(oe.values[-1] - 0.63)
