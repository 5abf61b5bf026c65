"""A fit's result code says what happened: one case for each code a fit adds to
optimistix's, each of which a fit once reported as converged."""

import warnings

import numpy as np
import pytest

import jaxship as js


DEG = np.pi / 180


def zigzag_record(dt, *, model=js.Nomoto1(K=0.06, T=25.0), duration=300.0, noise=0.0):
    """A noise-free (or noisy) 10/10-like record of `model`, sampled every `dt` s."""
    t = np.arange(0.0, duration, dt)
    delta = np.where((t // 30.0) % 2 == 0, 10 * DEG, -10 * DEG)
    out = js.simulate_steering(model, delta, dt, psi0=0.0, substeps=20, hold="foh")
    rng = np.random.default_rng(0)
    return js.Experiment(t, delta, psi=np.asarray(out.psi) + rng.normal(0, noise, t.size),
                         r=np.asarray(out.r) + rng.normal(0, noise / 10, t.size))


def quiet_fit(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", (js.IdentifiabilityWarning, js.ConvergenceWarning))
        return js.fit(*args, **kwargs)


def test_pure_noise_fitted_at_one_second_is_not_converged():
    """The trust audit's case: Nomoto 1 on 300 s of pure noise at 1 s samples, started at
    T = 0.31 s (what the linear start gives there). One RK4 step per sample is unstable
    for that T (|dt/T| = 3.2, beyond RK4's 2.79), the simulation blows up, and the fit
    said "converged" with a cost of 1e122; now its code says it blew up."""
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 300.0, 1.0)
    noise = js.Experiment(t, np.where((t // 30) % 2 == 0, 10 * DEG, -10 * DEG),
                          psi=rng.normal(0, 0.05, t.size), r=rng.normal(0, 0.01, t.size))
    res = quiet_fit(js.Nomoto1(K=0.1, T=0.31), noise)
    assert not res.success and res.code == js.RESULTS.simulation_blew_up
    assert "blew up" in res.message and res.to_dict()["success"] is False
    # the same start on records at 0.1 s is stable and fits (the noise: K near zero)
    fine = js.Experiment(t[:100] / 10, noise.delta[:100], psi=noise.psi[:100],
                         r=noise.r[:100])
    assert quiet_fit(js.Nomoto1(K=0.1, T=0.31), fine).code != js.RESULTS.simulation_blew_up


def test_a_start_that_never_moves_is_not_converged():
    """K = 1e-12, T = 1e6: the optimiser's steps are relative to the start's scale, so
    it stopped at once and said converged (cost 1173 against 0 at the truth)."""
    data = zigzag_record(0.5)
    res = quiet_fit(js.Nomoto1(K=1e-12, T=1e6), data)
    assert not res.success and res.code == js.RESULTS.did_not_move
    assert res.values == pytest.approx([1e-12, 1e6])
    # a start at the optimum does not move either, and is converged
    exact = quiet_fit(js.Nomoto1(K=0.06, T=25.0), data)
    assert exact.success and exact.cost < 1e-12


def test_a_simulation_that_blows_up_is_not_converged():
    """An unstable nonlinear Nomoto (n1 = -1) whose cubic term drives the yaw rate to
    infinity in finite time: no estimate of K and T keeps it finite."""
    data = zigzag_record(0.5)
    start = js.NonlinearNomoto(K=0.06, T=25.0, n1=-1.0, n3=-50.0)
    res = quiet_fit(start, data, free=("K", "T"))
    assert not res.success and res.code == js.RESULTS.simulation_blew_up, res.message
