"""ARMAX (Astrom & Kallstrom 1979, eq. 7) by prediction-error minimisation."""

import numpy as np
import pytest
from scipy.signal import lfilter

import jaxship as js
from jaxship._estimate._armax import fit_armax
from jaxship._estimate._discrete import discretise
from jaxship._models._armax_model import ARMAXModel, simulate_armax


def _input(n=4000, seed=1):
    rng = np.random.default_rng(seed)
    return np.repeat(rng.choice([-0.1, 0.1], n // 20), 20)


def test_exact_recovery_noise_free():
    u = _input()
    A, B = [1.0, -1.5, 0.7], [1.0, 0.5]
    y = lfilter(B, A, np.r_[0.0, u[:-1]])
    res = fit_armax(y, u, na=2, nb=2, nc=0)
    np.testing.assert_allclose(res.A, A, rtol=1e-6)
    np.testing.assert_allclose(res.B, B, rtol=1e-6)
    np.testing.assert_allclose(res.simulate(u), y, rtol=1e-6, atol=1e-9)


def test_noise_model_within_standard_errors():
    rng = np.random.default_rng(2)
    u = _input()
    A, B, C = [1.0, -1.5, 0.7], [1.0, 0.5], [1.0, -0.6, 0.2]
    e = 0.01 * rng.standard_normal(u.size)
    y = lfilter(B, A, np.r_[0.0, u[:-1]]) + lfilter(C, A, e)
    res = fit_armax(y, u, na=2, nb=2, nc=2)
    assert res.converged
    theta = np.r_[res.A[1:], res.B, res.C[1:]]
    true = np.r_[A[1:], B, C[1:]]
    assert np.all(np.abs(theta - true) < 4 * res.std)
    assert res.noise_variance == pytest.approx(1e-4, rel=0.1)
    # the one-step predictor beats the simulation on data with coloured noise
    eps1 = y - res.one_step(y, u)
    epss = y - res.simulate(u)
    assert np.var(eps1) < np.var(epss)


@pytest.mark.parametrize("structure,params,orders", [
    ("linear1", dict(K=0.1, T=20.0), (1, 1)),
    ("linear2", dict(K=0.1, T1=25.0, T2=3.0, T3=5.0), (2, 2)),
])
def test_nomoto_from_zoh_sampled_model(structure, params, orders):
    h = 0.5
    c = discretise(structure, params, h)
    if structure == "linear1":
        A, B = [1.0, -c["a1"]], [c["a2"]]
    else:
        A, B = [1.0, -c["a1"], -c["a2"]], [c["b1"], c["b2"]]
    u = _input()
    y = lfilter(B, A, np.r_[0.0, u[:-1]])
    res = fit_armax(y, u, na=orders[0], nb=orders[1], nc=0, dt=h)
    got = res.nomoto()
    for k, v in params.items():
        assert got[k] == pytest.approx(v, rel=1e-6)


def test_bad_inputs():
    u = _input(400)
    with pytest.raises(ValueError, match="na"):
        fit_armax(u, u, na=-1)
    with pytest.raises(ValueError, match="one length"):
        fit_armax(u, u[:-1])
    with pytest.raises(ValueError, match="constant"):
        fit_armax(u, np.ones_like(u))
    with pytest.raises(ValueError, match="too few"):
        fit_armax(u[:20], u[:20])
    assert fit_armax(u, u, na=3, nb=1, nc=0).nomoto() is None


def test_armax_model_simulation_equals_the_recursion():
    """`simulate_armax` (one lfilter call for a batch of records) equals the explicit
    recursion r(k) = b0 d(k-1) + b1 d(k-2) - a1 r(k-1) - a2 r(k-2), started at r0 with
    r and the rudder before the first sample held at r0 and d(0)."""
    model = ARMAXModel(a1=-1.6, a2=0.65, b0=0.02, b1=0.015, dt=0.5)
    rng = np.random.default_rng(3)
    delta = np.stack([_input(200, seed) for seed in (4, 5)])
    r0 = rng.normal(0.0, 0.01, 2)
    got = simulate_armax(model, delta, r0)
    for d, start, row in zip(delta, r0, got):
        r = np.full(d.size + 2, start)  # two samples of history before sample 0
        x = np.r_[d[0], d[0], d]
        for k in range(3, d.size + 2):
            r[k] = 0.02 * x[k - 1] + 0.015 * x[k - 2] + 1.6 * r[k - 1] - 0.65 * r[k - 2]
        np.testing.assert_allclose(row, r[2:], rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(simulate_armax(model, delta[1], r0[1]), got[1])


def test_fit_with_the_armax_estimator_gives_a_fit_result():
    """`js.fit(js.ARMAXModel(), data, estimator=js.ARMAX())` is `fit_armax` on the record,
    as the one result type: coefficients with standard errors, one-step predictions."""
    rng = np.random.default_rng(5)
    u = np.repeat(rng.choice([-0.2, 0.2], 150), 4)
    e = 0.002 * rng.standard_normal(u.size)
    a, b, c = [1.0, -1.5, 0.56], [0.0, 0.02, 0.015], [1.0, 0.3, 0.1]
    y = lfilter(b, a, u) + lfilter(c, a, e)
    data = js.Experiment(0.5 * np.arange(u.size), u, r=y, psi=np.cumsum(y) * 0.5)
    direct = fit_armax(y, u, dt=0.5, na=2, nb=2, nc=2, nk=1)
    res = js.fit(js.ARMAXModel(), data, estimator=js.ARMAX())
    assert isinstance(res, js.FitResult) and res.success
    np.testing.assert_allclose(res.values, np.concatenate([direct.A[1:], direct.B,
                                                          direct.C[1:]]), rtol=1e-12)
    np.testing.assert_allclose(res.values[:2], a[1:], atol=0.05)
    assert res.metrics["r"].fit_percent > 90.0
    with pytest.raises(ValueError, match="ARMAXModel"):
        js.fit(js.Nomoto1(K=0.1, T=10.0), data, estimator=js.ARMAX())


def test_the_armax_estimator_takes_a_prior():
    """`ARMAX(prior=...)`: an infinitely wide prior is the plain fit, an infinitely narrow
    one its mean; in between, on a short record, the MAP is nearer the mean than the plain
    estimate, its posterior errors are narrower than the prior, and FPE charges the
    effective number of parameters, $\\mathrm{tr}\\,J(J^TJ + P)^{-1}J^T$."""
    rng = np.random.default_rng(6)
    u = np.repeat(rng.choice([-0.2, 0.2], 20), 4)  # 80 samples: a short record
    a, b, c = [1.0, -1.5, 0.56], [0.0, 0.02, 0.015], [1.0, 0.3, 0.1]
    y = lfilter(b, a, u) + lfilter(c, a, 0.004 * rng.standard_normal(u.size))
    data = js.Experiment(0.5 * np.arange(u.size), u, r=y, psi=np.cumsum(y) * 0.5)
    truth = ARMAXModel(a1=-1.5, a2=0.56, b0=0.02, b1=0.015, c1=0.3, c2=0.1, dt=0.5)
    fit = lambda prior=None: js.fit(truth, data, estimator=js.ARMAX(prior=prior))
    plain = fit()
    assert plain.prior is None and plain.effective_params is None
    wide = fit(js.strategies.Prior(scale=1e8))
    # the same optimum: c1 is near zero and flat in 80 samples, so compared in its errors
    assert wide.cost == pytest.approx(plain.cost, rel=1e-9)
    assert np.all(np.abs(wide.values - plain.values) < 1e-3 * plain.std)
    assert wide.effective_params == pytest.approx(6.0, abs=1e-6)
    mean = ARMAXModel(a1=-1.4, a2=0.5, b0=0.03, b1=0.01, c1=0.2, c2=0.05, dt=0.5)
    narrow = fit(js.strategies.Prior(mean=mean, scale=1e-8))
    np.testing.assert_allclose(narrow.values, [-1.4, 0.5, 0.03, 0.01, 0.2, 0.05], rtol=1e-5)
    assert narrow.effective_params < 1e-3
    fitted = fit(js.strategies.Prior(mean=mean, scale=0.2))
    assert fitted.success
    centre = np.array([-1.4, 0.5, 0.03, 0.01, 0.2, 0.05])
    distance = lambda v: np.sum(((v - centre) / (0.2 * np.abs(centre))) ** 2)
    assert distance(fitted.values) < distance(plain.values) and fitted.cost >= plain.cost
    assert 0.0 < fitted.effective_params < 6.0
    assert np.all(fitted.std < [row["prior_std"] for row in fitted.prior.values()])
    assert all(0.0 <= row["data_share"] <= 1.0 for row in fitted.prior.values())
    assert fitted.metrics["r"].num_params == fitted.effective_params
    # the posterior covariance by hand: lambda^2 (J^T J + P)^-1, P = lambda^2 / s^2
    direct = fit_armax(y, u, dt=0.5, **dict(na=2, nb=2, nc=2, nk=1),
                       prior=(centre, 0.2 * np.abs(centre)))
    np.testing.assert_allclose(direct.A[1:], fitted.values[:2], rtol=1e-12)
    jac, lam2 = direct.jacobian, direct.noise_variance
    by_hand = lam2 * np.linalg.inv(jac.T @ jac + np.diag(lam2 / (0.2 * centre) ** 2))
    np.testing.assert_allclose(direct.covariance, by_hand, rtol=1e-3)
