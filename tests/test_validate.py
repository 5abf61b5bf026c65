"""Validation figures (thesis eq. 3.18-3.23, Ljung 1999 ch. 16) on known arrays."""

import json
import math
import warnings

import numpy as np
import pytest

from jaxship._foundation._covariance import (
    bartlett_long_run,
    cluster_from_windows,
    hac_covariance,
    hac_from_windows,
    least_squares_covariance,
)
from jaxship._foundation._parameter_report import RobustErrors, parameter_report
from jaxship._foundation._validate import (
    Z99,
    chi2_quantile_99,
    final_prediction_error,
    fit_percent,
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


def test_a_prediction_that_blew_up_fits_minus_infinity_without_a_warning():
    """The thesis study's diverged simulations: the squared error overflows to inf and
    the fit % is -inf (the tables print "diverges"), with no RuntimeWarning."""
    y = np.sin(np.linspace(0, 10, 200))
    blown = y.copy()
    blown[-1] = 1e300
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert fit_percent(y, blown) == -math.inf


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


# ---------------------------------------------------------------------------------------
# robust (Newey-West HAC) standard errors


def _ar1(rng, n, phi, burn=200):
    w = rng.standard_normal(n + burn)
    e = np.zeros_like(w)
    for k in range(1, w.size):
        e[k] = phi * e[k - 1] + w[k]
    return e[burn:]


def _monte_carlo(phi_e, *, n=1000, seeds=200, lags=None):
    """y = b0 + b1 x + e with x AR(1) (phi 0.9) and e AR(1) (phi_e): empirical std of the
    LS estimates over the seeds against the root-mean-square reported std."""
    est, var_ls, var_hac, used = [], [], [], []
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        x = np.stack([np.ones(n), _ar1(rng, n, 0.9)], axis=1)
        y = x @ np.array([1.0, 2.0]) + _ar1(rng, n, phi_e)
        b = np.linalg.lstsq(x, y, rcond=None)[0]
        res = y - x @ b
        var_ls.append(np.diag(least_squares_covariance(x, res)[0]))
        hac, lag = hac_covariance(x, res, lags=lags)
        var_hac.append(np.diag(hac))
        est.append(b)
        used.append(lag)
    empirical = np.std(est, axis=0, ddof=1)
    return (np.sqrt(np.mean(var_ls, axis=0)) / empirical,
            np.sqrt(np.mean(var_hac, axis=0)) / empirical, np.mean(used))


def test_hac_std_matches_the_spread_of_estimates_with_ar1_errors():
    """AR(1) errors (phi 0.9) and a correlated regressor: the white-noise std is 3-4
    times too small, the HAC std (automatic bandwidth) within 25 % of the truth; the
    fixed rule floor(4 (N/100)^(2/9)) = 6 lags is not enough."""
    ls, hac, lags = _monte_carlo(0.9)
    assert np.all(ls < 0.4), ls  # measured 0.24, 0.30
    assert np.all(np.abs(hac - 1) < 0.25), hac  # measured 0.90, 0.81
    assert 30 < lags < 70  # Andrews' AR(1) rule, measured 47
    _, fixed, _ = _monte_carlo(0.9, lags=int(4 * (1000 / 100) ** (2 / 9)))
    assert np.all(fixed < 0.75), fixed


def test_hac_std_equals_plain_std_with_white_errors():
    ls, hac, lags = _monte_carlo(0.0)
    np.testing.assert_allclose(hac, ls, rtol=0.15)
    assert np.all(np.abs(hac - 1) < 0.15), hac
    assert lags < 5
    # lag 0 alone on homoscedastic white residuals: White's estimator, close to plain
    rng = np.random.default_rng(7)
    x = np.stack([np.ones(2000), rng.standard_normal(2000)], axis=1)
    res = rng.standard_normal(2000)
    plain = np.diag(least_squares_covariance(x, res)[0])
    white = np.diag(hac_covariance(x, res, lags=0)[0])
    np.testing.assert_allclose(white, plain, rtol=0.15)


def _naive_hac(jac, res, mask, lags):
    """The textbook formula, lag by lag, per experiment: jac (C, E, N, d)."""
    jac = np.where(mask[..., None], jac, 0.0)
    g = np.einsum("cenp,cen->enp", jac, np.where(mask, res, 0.0))
    s = np.zeros((jac.shape[-1],) * 2)
    for ge in g:
        s += ge.T @ ge
        for lag in range(1, lags + 1):
            gamma = ge[lag:].T @ ge[:-lag]
            s += (1 - lag / (lags + 1)) * (gamma + gamma.T)
    rows = np.concatenate([jac[c][mask[c]] for c in range(jac.shape[0])])
    bread = np.linalg.inv(rows.T @ rows)
    return bread @ s @ bread * rows.shape[0] / (rows.shape[0] - jac.shape[-1])


def test_hac_equals_the_lag_by_lag_formula():
    rng = np.random.default_rng(8)
    jac = rng.standard_normal((2, 3, 60, 3)) * np.array([1.0, 1e3, 1e-2])
    res = rng.standard_normal((2, 3, 60)).cumsum(axis=-1)
    mask = np.ones((2, 3, 60), dtype=bool)
    mask[:, 1, 45:] = False  # a shorter experiment
    mask[1, 2, 10:20] = False  # a channel missing for a while
    for lags in (0, 1, 7, 80):
        got, used = hac_covariance(jac, res, mask, lags=lags)
        assert used == lags
        np.testing.assert_allclose(got, _naive_hac(jac, res, mask, lags), rtol=1e-9)
    g = rng.standard_normal((2, 50, 2))
    naive = sum(x.T @ x + sum((1 - k / 6) * (x[k:].T @ x[:-k] + x[:-k].T @ x[k:])
                              for k in range(1, 6)) for x in g)
    np.testing.assert_allclose(bartlett_long_run(g, 5), naive, rtol=1e-10)


def test_hac_experiments_are_independent_and_padding_is_ignored():
    """Two experiments padded to a common length give the same covariance as one
    timeline with the second experiment after a masked gap longer than the lags, and
    differ from the two glued together (lagged products would straddle them)."""
    rng = np.random.default_rng(9)
    n1, n2, lags = 80, 50, 6
    j1, j2 = rng.standard_normal((n1, 2)), rng.standard_normal((n2, 2))
    e1, e2 = _ar1(rng, n1, 0.8), _ar1(rng, n2, 0.8)
    jac = np.zeros((2, n1, 2)) + 1e6  # padding holds garbage
    res = np.full((2, n1), -1e6)
    jac[0], jac[1, :n2], res[0], res[1, :n2] = j1, j2, e1, e2
    mask = np.arange(n1)[None] < np.array([[n1], [n2]])
    got, _ = hac_covariance(jac, res, mask, lags=lags)
    gap = np.zeros((lags + 1, 2))
    glued_gap = np.concatenate([j1, gap, j2]), np.concatenate([e1, gap[:, 0], e2])
    gap_mask = np.concatenate([np.ones(n1), np.zeros(lags + 1), np.ones(n2)]).astype(bool)
    np.testing.assert_allclose(hac_covariance(*glued_gap, gap_mask, lags=lags)[0], got,
                               rtol=1e-10)
    glued = hac_covariance(np.concatenate([j1, j2]), np.concatenate([e1, e2]), lags=lags)[0]
    assert not np.allclose(glued, got, rtol=1e-6)
    # (E, N) and (N,) layouts and the automatic bandwidth on padded data
    auto, used = hac_covariance(jac, res, mask)
    assert 0 < used < n1 and np.all(np.isfinite(auto))
    with pytest.raises(ValueError, match="non-finite"):
        hac_covariance(np.where(mask[..., None], jac, np.nan), res)


def test_hac_undetermined_parameter_is_infinite():
    rng = np.random.default_rng(10)
    a = rng.standard_normal(200)
    jac = np.stack([a, 2 * a, rng.standard_normal(200)], axis=1)
    cov, _ = hac_covariance(jac, rng.standard_normal(200), lags=3)
    assert np.isinf(np.diag(cov)[:2]).all() and np.isfinite(cov[2, 2])


def _window_layout(lengths, horizon_samples, num):
    """The index arrays of `_estimate._windows.build_windows`: window w of experiment
    e starts at sample w L and predicts samples wL + 1 .. wL + L."""
    counts = [len(range(0, n - 1, L)) for n, L in zip(lengths, horizon_samples)]
    w_idx = np.arange(max(counts))[None, :, None]
    l_idx = np.arange(max(horizon_samples))[None, None, :]
    size = np.array(horizon_samples)[:, None, None]
    target = w_idx * size + l_idx + 1
    mask = ((l_idx < size) & (target <= np.array(lengths)[:, None, None] - 1)
            & (w_idx < np.array(counts)[:, None, None]))
    return {"target": np.clip(target, 0, num - 1), "mask": mask}


def test_hac_from_windows_equals_the_timeline_computation():
    rng = np.random.default_rng(11)
    lengths, num, d = (40, 27), 40, 3
    layout = _window_layout(lengths, (4, 5), num)
    jac_t = rng.standard_normal((2, 2, num, d))  # (C, E, N, d) in time order
    res_t = rng.standard_normal((2, 2, num)).cumsum(axis=-1)
    e_idx = np.arange(2)[:, None, None]
    jac_w = jac_t[:, e_idx, layout["target"]]  # (C, E, W, L, d)
    res_w = res_t[:, e_idx, layout["target"]]
    jac_w[:, ~layout["mask"]] = np.nan  # never read
    hit = np.zeros((2, num), dtype=bool)
    hit[np.broadcast_to(e_idx, layout["mask"].shape)[layout["mask"]],
        layout["target"][layout["mask"]]] = True
    assert hit.sum() == sum(lengths) - 2  # every sample but the first of each experiment
    for lags in (0, 5, None):
        want, want_lags = hac_covariance(jac_t, res_t, hit, lags=lags)
        got, got_lags = hac_from_windows(jac_w, res_w, layout, lags=lags)
        assert got_lags == want_lags
        np.testing.assert_allclose(got, want, rtol=1e-10)
    # one channel given without the channel axis
    got, _ = hac_from_windows(jac_w[0], res_w[0], layout, lags=5)
    np.testing.assert_allclose(got, hac_covariance(jac_t[0], res_t[0], hit, lags=5)[0],
                               rtol=1e-10)


def test_not_white_flag_and_robust_std_in_the_report():
    cov = np.diag([1e-6, 1e-2])
    robust = np.diag([1.44e-4, 4e-2])  # 12x and 2x the plain std
    for white in (None, True):
        rep = parameter_report(["K", "T"], [0.05, 10.0], cov,
                               robust=RobustErrors(white=white, covariance=robust))
        assert rep.flags == () and rep.identifiable and rep.residuals_white is white
        np.testing.assert_allclose(rep.std_robust, [0.012, 0.2])
    plain = parameter_report(["K", "T"], [0.05, 10.0], cov)
    assert np.isnan(plain.std_robust).all() and "std robust" not in plain.table()
    assert plain.residuals_white is None and plain.hac_lags is None
    rep = parameter_report(["K", "T"], [0.05, 10.0], cov,
                           robust=RobustErrors(white=False, covariance=robust, hac_lags=25))
    assert len(rep.flags) == 1 and rep.uncertainty_flags == rep.flags
    flag = rep.flags[0]
    assert "not white" in flag and "too small by up to 12x (K)" in flag and "25 lags" in flag
    assert rep.identifiable  # correlated residuals are not an identifiability problem
    assert "std robust" in rep.table() and rep.residuals_white is False
    data = json.loads(json.dumps(rep.to_dict()))
    assert data["std_robust"] == pytest.approx([0.012, 0.2]) and data["hac_lags"] == 25
    # the relative-error check uses the robust std when the residuals are not white
    rep = parameter_report(["K", "T"], [0.02, 10.0], cov,
                           robust=RobustErrors(white=False, covariance=robust))
    assert any("K = 0.02 is poorly determined: robust" in f for f in rep.flags)
    assert not rep.identifiable
    # not white without robust errors: still flagged
    rep = parameter_report(["K", "T"], [0.05, 10.0], cov, robust=RobustErrors(white=False))
    assert len(rep.flags) == 1 and "no robust standard errors" in rep.flags[0]


def test_window_cluster_covariance_is_the_sandwich_over_windows():
    """`cluster_from_windows` equals G/(G-1) (J'J)^-1 (sum_w s_w s_w') (J'J)^-1 written
    out, ignores padding, and under errors correlated within windows (independent
    between them) its standard errors match the spread of the estimates over seeds."""
    rng = np.random.default_rng(3)
    E, W, L = 2, 30, 12
    x = rng.standard_normal((E, W, L))
    jac = np.stack([np.ones((E, W, L)), x], axis=-1)[None]  # (1, E, W, L, 2)
    mask = np.ones((E, W, L), dtype=bool)
    mask[1, -3:] = False
    estimates, stds = [], []
    for seed in range(300):
        r = np.random.default_rng(seed)
        common = r.standard_normal((E, W, 1))  # shared within a window
        y = 0.5 + 2.0 * x + common + 0.3 * r.standard_normal((E, W, L))
        rows = jac[0][mask]
        beta = np.linalg.lstsq(rows, y[mask], rcond=None)[0]
        res = np.where(mask, y - jac[0] @ beta, 0.0)[None]
        cov, count = cluster_from_windows(jac, res, mask)
        estimates.append(beta)
        stds.append(np.sqrt(np.diag(cov)))
        if seed == 0:
            assert count == 2 * W - 3
            s = np.einsum("ewlp,ewl->ewp", jac[0] * mask[..., None], res[0])[mask.any(-1)]
            bread = np.linalg.inv(rows.T @ rows)
            explicit = bread @ (s.T @ s) @ bread * count / (count - 1)
            np.testing.assert_allclose(cov, explicit, rtol=1e-10)
    ratio = np.mean(stds, axis=0) / np.std(estimates, axis=0)
    assert np.all((ratio > 0.85) & (ratio < 1.15)), ratio
