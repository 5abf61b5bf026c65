"""Validation figures (thesis eq. 3.18-3.23, Ljung 1999 ch. 16) on known arrays."""

import json
import math

import numpy as np
import pytest

from jaxship._validate import (
    Z99,
    chi2_quantile_99,
    final_prediction_error,
    fit_percent,
    least_squares_covariance,
    parameter_report,
    residual_autocorrelation,
    residual_input_correlation,
    validate,
)


def test_fit_percent_perfect_mean_and_worse():
    y = np.sin(np.linspace(0, 10, 200))
    assert fit_percent(y, y) == 100.0
    assert abs(fit_percent(y, np.full_like(y, y.mean()))) < 1e-12
    assert fit_percent(y, -y) < 0
    # 100 (1 - |y - yhat| / |y - mean y|) on a hand example: y = (0, 2), yhat = (1, 1)
    assert fit_percent([0.0, 2.0], [0.5, 2.0]) == pytest.approx(100 * (1 - 0.5 / math.sqrt(2)))


def test_fit_percent_uses_each_experiments_mean():
    """Two experiments at different heading levels: predicting each one's own mean is 0 %."""
    y = np.stack([np.linspace(0, 1, 50), 10 + np.linspace(0, 2, 50)])
    mean_each = np.broadcast_to(y.mean(axis=1, keepdims=True), y.shape)
    assert abs(fit_percent(y, mean_each)) < 1e-12


def test_loss_fpe_aic_bic_on_known_residuals():
    y = np.array([1.0, -1.0, 2.0, -2.0])
    rep = validate(y, np.zeros(4), num_params=1, max_lag=2)
    assert rep.loss == pytest.approx(2.5)  # eq. 3.18
    assert rep.abs_sum == pytest.approx(6.0)  # eq. 3.19
    assert rep.rms == pytest.approx(math.sqrt(2.5))  # eq. 3.20
    assert rep.mean == 0.0 and rep.std == pytest.approx(math.sqrt(2.5))
    assert rep.fpe == pytest.approx(2.5 * (1 + 0.25) / (1 - 0.25))  # eq. 3.21
    const = 4 * (math.log(2 * math.pi) + 1)
    assert rep.aic == pytest.approx(4 * math.log(2.5) + 2 + const)
    assert rep.bic == pytest.approx(4 * math.log(2.5) + math.log(4) + const)
    assert final_prediction_error(1.0, 5, 5) == math.inf


def test_mask_excludes_padding():
    rng = np.random.default_rng(0)
    y, yhat = rng.standard_normal(300), rng.standard_normal(300)
    ref = validate(y, yhat, num_params=2, u=y, max_lag=10)
    pad = lambda a: np.stack([np.concatenate([a, np.full(50, 1e6)])])
    mask = np.concatenate([np.ones(300, bool), np.zeros(50, bool)])[None]
    got = validate(pad(y), pad(yhat), mask, num_params=2, u=pad(y), max_lag=10)
    assert got.num_samples == 300
    for name in ("loss", "abs_sum", "fpe", "aic", "fit_percent"):
        assert getattr(got, name) == pytest.approx(getattr(ref, name), rel=1e-12)
    np.testing.assert_allclose(got.autocorrelation.values, ref.autocorrelation.values,
                               rtol=1e-12)
    np.testing.assert_allclose(got.cross_correlation.values, ref.cross_correlation.values,
                               rtol=1e-12)


def test_chi2_quantile():
    """Against 99 % quantiles of the chi-square distribution (scipy.stats.chi2.ppf)."""
    for dof, exact in [(5, 15.0863), (10, 23.2093), (25, 44.3141), (51, 77.3860)]:
        assert chi2_quantile_99(dof) == pytest.approx(exact, rel=3e-3)


def test_whiteness_accepts_white_noise_and_rejects_ar1():
    rng = np.random.default_rng(1)
    passed = [residual_autocorrelation(rng.standard_normal(1000), max_lag=25).passed
              for _ in range(100)]
    assert np.mean(passed) >= 0.95  # 99 % nominal
    e = np.zeros(1000)
    w = rng.standard_normal(1000)
    for k in range(1, 1000):
        e[k] = 0.9 * e[k - 1] + w[k]
    ac = residual_autocorrelation(e, max_lag=25)
    assert not ac.passed
    assert ac.values[1] == pytest.approx(0.9, abs=0.05)
    assert ac.band == pytest.approx(Z99 / math.sqrt(1000))
    assert ac.num_outside > 10


def test_cross_correlation_with_a_held_input():
    """White residuals independent of a slowly varying (held) input pass the Ljung test
    at about the nominal rate; residuals that echo the input two samples back fail."""
    rng = np.random.default_rng(2)
    passed = []
    for _ in range(60):
        u = np.repeat(rng.choice([-1.0, 1.0], 50), 20)
        passed.append(residual_input_correlation(rng.standard_normal(1000), u,
                                                 max_lag=20).passed)
    assert np.mean(passed) >= 0.9
    u = rng.standard_normal(1000)
    e = 0.3 * np.roll(u, 2) + rng.standard_normal(1000)
    cc = residual_input_correlation(e, u, max_lag=10)
    assert not cc.passed
    assert cc.lags[np.argmax(np.abs(cc.values))] == 2


def test_covariance_of_linear_regression():
    """sigma^2 (X^T X)^-1 with sigma^2 = SSR / (N - d) for a linear model."""
    rng = np.random.default_rng(3)
    x = np.stack([np.ones(200), rng.standard_normal(200) * 1e3], axis=1)
    res = rng.standard_normal(200) * 0.1
    cov, null = least_squares_covariance(x, res)
    expected = np.sum(res**2) / 198 * np.linalg.inv(x.T @ x)
    np.testing.assert_allclose(cov, expected, rtol=1e-10)
    assert null == []
    # two groups with their own variance: the sandwich A^-1 (sum s_g^2 J_g^T J_g) A^-1
    groups = np.repeat([0, 1], 100)
    res2 = res * np.where(groups == 0, 1.0, 10.0)
    cov2, _ = least_squares_covariance(x, res2, groups)
    s2 = [np.sum(res2[groups == g] ** 2) * 200 / (100 * 198) for g in (0, 1)]
    a_inv = np.linalg.inv(x.T @ x)
    middle = sum(s2[g] * x[groups == g].T @ x[groups == g] for g in (0, 1))
    np.testing.assert_allclose(cov2, a_inv @ middle @ a_inv, rtol=1e-10)


def test_undetermined_parameters_are_flagged():
    rng = np.random.default_rng(4)
    a = rng.standard_normal(100)
    jac = np.stack([a, 2 * a, rng.standard_normal(100), np.zeros(100)], axis=1)
    cov, null = least_squares_covariance(jac, rng.standard_normal(100))
    rep = parameter_report(["K", "T", "c", "z"], [1.0, 2.0, 3.0, 4.0], cov,
                           null_directions=null)
    assert np.isinf(rep.std[[0, 1, 3]]).all() and np.isfinite(rep.std[2])
    assert not rep.identifiable
    text = " ".join(rep.flags)
    assert "z does not affect" in text and "combination" in text and "K" in text
    assert rep.condition_number == math.inf


def test_parameter_report_correlation_and_relative_std_flags():
    cov = np.array([[1.0, 0.98 * 2.0], [0.98 * 2.0, 4.0]]) * 1e-4
    rep = parameter_report(["K", "T"], [0.05, 10.0], cov)
    assert rep.correlation[0, 1] == pytest.approx(0.98)
    assert rep.std == pytest.approx([0.01, 0.02])
    assert rep.condition_number == pytest.approx(1.98 / 0.02)
    assert len(rep.flags) == 1 and "strongly correlated" in rep.flags[0]
    rep = parameter_report(["K", "T"], [0.015, 10.0], np.diag([1e-4, 1e-4]))
    assert len(rep.flags) == 1 and rep.flags[0].startswith("K = 0.015 is poorly determined")
    assert parameter_report(["K", "T"], [0.05, 10.0], np.diag([1e-6, 1e-2])).identifiable


def test_reports_serialise_to_json():
    rng = np.random.default_rng(5)
    rep = validate(rng.standard_normal(100), np.zeros(100), u=rng.standard_normal(100))
    json.dumps(rep.to_dict())
    prep = parameter_report(["K"], [1.0], np.array([[np.inf]]))
    assert json.loads(json.dumps(prep.to_dict()))["std"] == ["inf"]
    assert "condition number" in prep.table()
