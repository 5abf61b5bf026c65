"""Response models (Nomoto 1/2, nonlinear Nomoto) and their RK4 simulation."""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship import AuxInputs, Nomoto1, Nomoto2, NonlinearNomoto
from jaxship._models._steering import WindowStart


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples
ZOH = js.strategies.ZeroOrderHold()  # the replayed rudder held over each interval


DEG = np.pi / 180


def step_input(num=401, angle=10 * DEG):
    return np.full(num, angle)


def test_nomoto1_step_response_is_exact():
    """T r' + r = K (delta + delta0): r = K (delta + delta0)(1 - exp(-t/T)) and
    psi = K (delta + delta0)(t - T (1 - exp(-t/T))) (thesis eq. 3.17 with r(0) = 0)."""
    m = Nomoto1(K=0.06, T=25.0, delta0=0.5 * DEG)
    tr = js.simulate(m, js.Replay(step_input(), dt=0.5, delta_hold=FOH),
                     js.straight_state(0.0, psi=0.3), simulator=per_sample())
    t = np.asarray(tr.t)
    gain = 0.06 * 10.5 * DEG
    np.testing.assert_allclose(tr.state.r, gain * (1 - np.exp(-t / 25.0)), rtol=1e-8, atol=1e-14)
    np.testing.assert_allclose(tr.state.psi, 0.3 + gain * (t - 25.0 * (1 - np.exp(-t / 25.0))),
                               rtol=1e-8)
    assert tr.state.r[-1] > 0  # positive rudder turns to starboard


def nomoto2_step(K, T1, T2, T3, t):
    """Step response of K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)) per unit rudder."""
    return K * (1 - (T1 - T3) / (T1 - T2) * np.exp(-t / T1)
                + (T2 - T3) / (T1 - T2) * np.exp(-t / T2))


def test_nomoto2_step_response_and_rk4_order():
    """The (r, r_aux) realisation has the transfer function of thesis eq. 3.1; the
    RK4 error falls by 2^4 when the substeps double."""
    K, T1, T2, T3 = 0.06, 25.0, 3.0, 5.0
    m = Nomoto2(K=K, T1=T1, T2=T2, T3=T3)
    t = 0.5 * np.arange(401)
    exact = 10 * DEG * nomoto2_step(K, T1, T2, T3, t)
    errors = []
    for substeps in (1, 2, 4):
        tr = js.simulate(m, js.Replay(step_input(), dt=0.5, delta_hold=FOH),
                         simulator=per_sample(substeps))
        errors.append(np.max(np.abs(np.asarray(tr.state.r) - exact)))
    assert errors[-1] < 1e-9 * np.max(exact)
    assert 12 < errors[0] / errors[1] < 20 and 12 < errors[1] / errors[2] < 20
    # the hidden state of a steady turn is (T1 + T2 - T3) r
    np.testing.assert_allclose(m.initial_state(0.01), [0.01, (T1 + T2 - T3) * 0.01])


def test_nomoto2_with_cancelling_zero_is_nomoto1():
    """T3 = T2 cancels the fast pole: Nomoto2(K, T1, T2, T2) = Nomoto1(K, T1)."""
    rng = np.random.default_rng(0)
    delta = np.repeat(rng.choice([-1, 1], 20) * 15 * DEG, 30)
    a = js.simulate(Nomoto2(K=0.05, T1=20.0, T2=2.0, T3=2.0),
                    js.Replay(delta, dt=0.25, delta_hold=FOH), simulator=per_sample(2))
    b = js.simulate(Nomoto1(K=0.05, T=20.0), js.Replay(delta, dt=0.25, delta_hold=FOH),
                    simulator=per_sample(2))
    np.testing.assert_allclose(a.state.r, b.state.r, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(a.state.psi, b.state.psi, rtol=1e-8, atol=1e-10)


def test_nonlinear_nomoto_steady_turn_and_linear_limit():
    """In a steady turn H_N(r) = K delta; with n3 = n2 = n0 = 0, n1 = 1 it is Nomoto1."""
    m = NonlinearNomoto(K=0.06, T=20.0, n3=400.0, n2=5.0, n0=1e-4)
    tr = js.simulate(m, js.Replay(step_input(2001, 20 * DEG), dt=0.5, delta_hold=FOH),
                     simulator=per_sample())
    r_end = float(tr.state.r[-1])
    assert abs(float(m.characteristic(r_end)) - 0.06 * 20 * DEG) < 1e-12
    assert r_end < 0.06 * 20 * DEG  # the cubic term reduces the steady rate
    lin = js.simulate(NonlinearNomoto(K=0.06, T=20.0),
                      js.Replay(step_input(), dt=0.5, delta_hold=FOH), simulator=per_sample())
    ref = js.simulate(Nomoto1(K=0.06, T=20.0), js.Replay(step_input(), dt=0.5, delta_hold=FOH),
                      simulator=per_sample())
    np.testing.assert_allclose(lin.state.r, ref.state.r, rtol=1e-13, atol=1e-16)


def test_nomoto2_window_state_reconstructs_the_hidden_state():
    """r_aux at any sample follows from the heading and the integral of the held rudder
    (Nomoto2.window_state), exactly, for a record that starts in a steady turn."""
    m = Nomoto2(K=0.05, T1=18.0, T2=2.5, T3=4.0, delta0=0.3 * DEG)
    rng = np.random.default_rng(1)
    delta = np.repeat(rng.uniform(-20, 20, 25) * DEG, 16)
    dt, r_first = 0.5, 0.004
    tr = js.simulate(m, js.Replay(delta, dt=dt, delta_hold=ZOH),
                     dataclasses.replace(js.straight_state(0.0, psi=0.2), r=r_first),
                     simulator=per_sample())
    integral = np.concatenate([[0.0], np.cumsum(delta[:-1]) * dt])
    k = np.arange(delta.shape[0])
    start = WindowStart(r=tr.state.r, psi=tr.state.psi, delta=delta, r_first=r_first, psi_first=0.2,
                        delta_integral=integral, elapsed=k * dt, aux=AuxInputs())
    states = jax.vmap(m.window_state, in_axes=(WindowStart(0, 0, 0, None, None, 0, 0, None),))(
        start)
    np.testing.assert_allclose(states, tr.internal, rtol=1e-9, atol=1e-13)


def test_forward_mode_derivatives_match_finite_differences():
    """Forward-mode (jvp) sensitivities of the simulated heading to K and T."""
    delta = np.repeat(np.array([10, -10, 20, -5, 0]) * DEG, 40)

    def psi_end(params):
        K, T = params
        return js.simulate(Nomoto1(K=K, T=T), js.Replay(delta, dt=0.5, delta_hold=FOH),
                           simulator=per_sample()).state.psi[-1]

    p = jnp.array([0.06, 25.0])
    jac = jax.jacfwd(psi_end)(p)
    for i, h in enumerate([1e-7, 1e-4]):
        e = np.zeros(2)
        e[i] = h
        fd = (psi_end(p + e) - psi_end(p - e)) / (2 * h)
        np.testing.assert_allclose(jac[i], fd, rtol=1e-6)


def test_vmap_over_parameters_equals_loop_and_no_retrace():
    from jaxship._simulation._simulate_steering import _replay

    delta = np.repeat(np.array([10, -10, 20]) * DEG, 30)
    gains = jnp.array([0.03, 0.05, 0.08])
    batched = jax.vmap(lambda K: js.simulate(Nomoto1(K=K, T=15.0),
                                             js.Replay(delta, dt=0.5, delta_hold=FOH),
                                             simulator=per_sample()).state.r)(gains)
    js.simulate(Nomoto1(K=0.01, T=15.0), js.Replay(delta, dt=0.5, delta_hold=FOH),
                simulator=per_sample())
    size = _replay._cached._cache_size()
    for i, K in enumerate([0.03, 0.05, 0.08]):
        single = js.simulate(Nomoto1(K=K, T=15.0 + i), js.Replay(delta, dt=0.5, delta_hold=FOH),
                             simulator=per_sample())
        if i == 0:
            np.testing.assert_allclose(batched[0], single.state.r, rtol=1e-14)
    assert _replay._cached._cache_size() == size
    counted = eqx.debug.assert_max_traces(_replay.__wrapped__, max_traces=1)
    jitted = eqx.filter_jit(counted)
    for K in (0.02, 0.04):
        m = Nomoto1(K=jnp.asarray(K), T=jnp.asarray(10.0), delta0=jnp.asarray(0.0))
        replay = js.Replay(jnp.asarray(delta), dt=jnp.asarray(0.5), start=jnp.asarray(0.0),
                           duration=jnp.asarray(0.5 * (delta.shape[0] - 1)))
        x0 = js.straight_state(jnp.asarray(0.0))
        jitted(m, replay, x0, None, js.Simulator(max_step=math.inf), 1)


def test_simulate_rejects_bad_arguments():
    m = Nomoto1(K=0.05, T=10.0)
    with pytest.raises(ValueError, match="delta"):
        js.simulate(m, js.Replay(np.zeros((3, 3)), dt=0.5, delta_hold=FOH),
                    simulator=per_sample())
    with pytest.raises(ValueError, match="substeps"):
        js.simulate(m, js.Replay(np.zeros(10), dt=0.5, delta_hold=FOH), simulator=per_sample(0))
