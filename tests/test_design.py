"""Experiment design: persistence of excitation and Fisher information."""

import jax
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship import (
    Nomoto1,
    Nomoto2,
    excitation_order,
    fisher_information,
    prbs,
    simulate,
)


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples


def test_excitation_order_known_signals():
    n = 2000
    t = np.arange(n)
    assert excitation_order(np.ones(n)) == 1
    assert excitation_order(np.r_[np.zeros(100), np.ones(n - 100)]) == 1
    for k, freqs in ((1, [0.3]), (2, [0.5, 2.0]), (3, [0.4, 1.4, 2.5])):
        u = sum(np.sin(w * t + i) for i, w in enumerate(freqs))
        assert excitation_order(u) == 2 * k
    # PRBS of period 31 samples (order 5 register, one bit per sample)
    u = np.asarray(simulate(Nomoto1(K=0.1, T=10.0),
                            prbs(1.0, bit_time=1.0, duration=31 * 40.0, order=5,
                                 dt=1.0)).state.delta)
    assert excitation_order(u[1:], max_order=60) == 31
    white = np.random.default_rng(0).standard_normal(n)
    assert excitation_order(white, max_order=50) == 50


def test_excitation_order_bad_input():
    with pytest.raises(ValueError, match="1-D"):
        excitation_order(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="max_order"):
        excitation_order(np.ones(100), max_order=80)


@pytest.mark.parametrize("model,free", [
    (Nomoto1(K=0.05, T=20.0), ("K", "T")),
    (Nomoto2(K=0.05, T1=20.0, T2=2.0, T3=4.0), ("K", "T1", "T2", "T3")),
])
def test_fisher_against_finite_differences(model, free):
    dt = 0.5
    zz = js.ZigZag(np.deg2rad(20), np.deg2rad(20), duration=300.0, dt=dt)
    sigma = 0.001
    rep = fisher_information(model, zz, sigma, free=free)
    delta = rep.delta
    cols = []
    for name in free:
        v = float(getattr(model, name))
        h = 1e-6 * abs(v)
        sim = lambda x: np.asarray(js.simulate(
            jax.tree_util.tree_map(lambda a: a, _with(model, name, x)),
            js.Replay(delta, dt=dt, delta_hold=FOH), simulator=per_sample()).state.r)
        cols.append((sim(v + h) - sim(v - h)) / (2 * h))
    jac = np.stack(cols, axis=1)
    fd = jac.T @ jac / sigma**2
    np.testing.assert_allclose(rep.fisher, fd, rtol=1e-6)
    np.testing.assert_allclose(rep.crb @ rep.fisher, np.eye(len(free)), atol=1e-8)


def _with(model, name, value):
    import equinox as eqx

    return eqx.tree_at(lambda m: getattr(m, name), model, value)


def test_fisher_bad_inputs():
    m = Nomoto1(K=0.05, T=20.0)
    with pytest.raises(ValueError, match="dt"):
        fisher_information(m, np.zeros(100), 0.01)
    with pytest.raises(ValueError, match="noise_std"):
        fisher_information(m, np.zeros(100), -1.0, dt=1.0)
    with pytest.raises(ValueError, match="outputs"):
        fisher_information(m, np.zeros(100), 0.01, dt=1.0, outputs=("v",))
    with pytest.raises(ValueError, match="steering model"):
        fisher_information("nomoto", np.zeros(100), 0.01, dt=1.0)
    # no rudder: no information on K, T, the bound is infinite
    rep = fisher_information(m, np.zeros(100), 0.01, dt=1.0)
    assert np.all(np.isinf(rep.std))
