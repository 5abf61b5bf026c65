"""A Gaussian prior in the prediction-error fit (`PredictionError(prior=...)`,
`jaxship.strategies.Prior`, `identify --prior`): its limits (an infinitely wide prior is
least squares, an infinitely narrow one its mean), the posterior covariance, the effective
number of parameters and the data's share checked against a hand computation, the report,
and the command."""

import json
import math

import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship._foundation._covariance import (
    effective_parameters,
    information_share,
    least_squares_covariance,
)
from jaxship.cli import main


DEG = np.pi / 180
DT = 0.5
TRUTH = js.Nomoto1(K=0.06, T=25.0)
FOH = js.strategies.FirstOrderHold()


def _record(seed=0, num=600, name="train"):
    """A zig-zag-like record of `TRUTH` with white noise (0.3 deg on psi, 0.03 deg/s on r)."""
    rng = np.random.default_rng(seed)
    delta, sign = [], 1.0
    while len(delta) < num:
        sign = -sign if rng.random() < 0.8 else sign
        delta.extend([sign * 10 * DEG] * int(rng.integers(16, 48)))
    delta = np.array(delta[:num])
    tr = js.simulate(TRUTH, js.Replay(delta, dt=DT, delta_hold=FOH),
                     js.straight_state(0.0, psi=0.1), simulator=per_sample())
    psi = np.asarray(tr.state.psi) + 0.3 * DEG * rng.standard_normal(num)
    r = np.asarray(tr.state.r) + 0.03 * DEG * rng.standard_normal(num)
    return js.Experiment(np.asarray(tr.t), delta, psi=psi, r=r, name=name)


def _exact_record(seed, num):
    """`TRUTH`'s record under a zero-order-hold rudder, sampled exactly in NumPy (no
    jaxship simulator): $r_{k+1} = ar_k + K(1 - a)\\delta_k$, $a = e^{-h/T}$, and $\\psi$ the
    exact integral of r over each interval; noise as `_record`."""
    rng = np.random.default_rng(seed)
    delta = np.repeat(rng.choice([-10 * DEG, 10 * DEG], num // 20 + 1), 20)[:num]
    K, T = TRUTH.K, TRUTH.T
    a = np.exp(-DT / T)
    r, psi = np.zeros(num), np.full(num, 0.1)
    for k in range(num - 1):
        steady = K * delta[k]
        r[k + 1] = a * r[k] + (1 - a) * steady
        psi[k + 1] = psi[k] + steady * DT + (r[k] - steady) * T * (1 - a)
    return js.Experiment(DT * np.arange(num), delta,
                         psi=psi + 0.3 * DEG * rng.standard_normal(num),
                         r=r + 0.03 * DEG * rng.standard_normal(num), name="exact")


DATA = _record()
START = js.Nomoto1(K=0.08, T=18.0)  # about 30 % off the truth
FREE = ("K", "T")


def _fit(prior=None):
    return js.fit(START, DATA, free=FREE,
                  estimator=js.PredictionError(horizon=20.0, prior=prior))


def test_a_wide_prior_is_least_squares_and_a_narrow_one_its_mean():
    plain = _fit()
    wide = _fit(js.strategies.Prior(scale=1e8))
    assert plain.success and wide.success
    np.testing.assert_allclose(wide.values, plain.values, rtol=1e-7)
    np.testing.assert_allclose(wide.std, plain.std, rtol=1e-5)
    assert wide.effective_params == pytest.approx(2.0, abs=1e-6)
    assert plain.effective_params is None and plain.prior is None
    mean = js.Nomoto1(K=0.05, T=30.0)
    narrow = _fit(js.strategies.Prior(mean=mean, scale=1e-7))
    np.testing.assert_allclose(narrow.values, [0.05, 30.0], rtol=1e-5)
    assert narrow.effective_params < 1e-3
    assert all(row["data_share"] < 1e-3 for row in narrow.prior.values())


def test_the_map_lies_between_the_mean_and_least_squares_and_is_reported():
    plain = _fit()
    fitted = _fit(js.strategies.Prior(scale=0.3))
    assert fitted.success
    # the MAP trades fit for closeness to the mean: a larger residual cost than least
    # squares', a smaller prior term
    mean = np.array([START.get_parameter(n) for n in FREE])
    distance = lambda values: np.sum(((values - mean) / (0.3 * mean)) ** 2)
    assert fitted.cost >= plain.cost and distance(fitted.values) < distance(plain.values)
    for i, name in enumerate(FREE):
        row = fitted.prior[name]
        assert row["prior_mean"] == mean[i] and row["prior_std"] == pytest.approx(0.3 * mean[i])
        assert 0.0 <= row["data_share"] <= 1.0
        assert fitted.std[i] <= row["prior_std"]  # the posterior is narrower than the prior
    assert 0.0 < fitted.effective_params < 2.0
    # FPE charges the effective number of parameters, not the count
    for m in fitted.metrics.values():
        assert m.num_params == fitted.effective_params
        n = m.num_samples
        assert m.fpe == pytest.approx(m.loss * (1 + m.num_params / n) / (1 - m.num_params / n))
    text = fitted.summary()
    assert "data share" in text and "effective number of parameters" in text
    report = fitted.to_dict()
    assert set(report["parameters"]["K"]) >= {"prior_mean", "prior_std", "data_share"}
    assert report["prior"]["scale"] == 0.3 and report["effective_params"] < 2.0
    json.dumps(report)


def test_per_coefficient_and_absolute_scales():
    fitted = _fit(js.strategies.Prior(scale={"T": 1.0}, relative=False))
    assert math.isinf(fitted.prior["K"]["prior_std"]) and fitted.prior["K"]["data_share"] == 1
    assert fitted.prior["T"]["prior_std"] == 1.0
    with pytest.raises(ValueError, match="positive number"):
        js.strategies.Prior(scale=0.0)
    with pytest.raises(ValueError, match="'Tau'"):
        _fit(js.strategies.Prior(scale={"Tau": 1.0}))


@pytest.mark.parametrize("criterion", [js.MaximumLikelihood(), js.InnovationsLeastSquares()],
                         ids=["ml", "pem"])
def test_the_innovations_estimators_take_a_prior(criterion):
    """`Innovations(prior=...)`: the same limits as the prediction-error fit's, the MAP
    between the mean and the plain estimate on a short record, and the effective number
    of parameters charged by FPE (the noise variances count in full: no prior on them).
    The record is not jaxship's: Nomoto 1's exact zero-order-hold recursion in NumPy."""
    short = _exact_record(seed=4, num=160)
    fit = lambda prior=None: js.fit(START, short, free=FREE, estimator=js.Innovations(
        criterion=criterion, prior=prior))
    plain = fit()
    estimated = len(plain.noise) - (criterion.name == "pem")  # PEM holds the first channel's
    assert plain.prior is None and plain.effective_params is None
    wide = fit(js.strategies.Prior(scale=1e8))
    np.testing.assert_allclose(wide.values, plain.values, rtol=1e-6)
    assert wide.effective_params == pytest.approx(2 + estimated, abs=1e-5)
    mean = js.Nomoto1(K=0.05, T=30.0)
    narrow = fit(js.strategies.Prior(mean=mean, scale=1e-7))
    np.testing.assert_allclose(narrow.values, [0.05, 30.0], rtol=1e-5)
    assert narrow.effective_params == pytest.approx(estimated, abs=1e-3)
    assert all(row["data_share"] < 1e-3 for row in narrow.prior.values())
    fitted = fit(js.strategies.Prior(scale=0.1))
    assert fitted.success and plain.success
    centre = np.array([START.get_parameter(n) for n in FREE])
    distance = lambda values: np.sum(((values - centre) / (0.1 * centre)) ** 2)
    assert distance(fitted.values) < distance(plain.values) and fitted.cost >= plain.cost
    assert 2 + estimated - 2 < fitted.effective_params < 2 + estimated
    for i, name in enumerate(FREE):
        row = fitted.prior[name]
        assert row["prior_std"] == pytest.approx(0.1 * centre[i])
        assert 0.0 < row["data_share"] < 1.0 and fitted.std[i] < row["prior_std"]
        if criterion.name == "ml":  # the inverse Hessian of the log posterior
            assert row["data_share"] == pytest.approx(1 - (fitted.std[i] / row["prior_std"]) ** 2)
    for m in fitted.metrics.values():
        assert m.num_params == fitted.effective_params
    assert "data share" in fitted.summary()
    json.dumps(fitted.to_dict())


def test_posterior_covariance_and_effective_parameters_by_hand():
    """A linear-in-parameters problem with a known Jacobian: y = J theta + e."""
    rng = np.random.default_rng(3)
    jac = np.column_stack([np.ones(30), np.linspace(0, 1, 30), np.linspace(0, 1, 30) ** 2])
    res = 0.1 * rng.standard_normal(30)
    precision = np.array([4.0, 0.0, 25.0])  # none on the second
    a = jac.T @ jac + np.diag(precision)
    inverse = np.linalg.inv(a)
    d_eff = float(np.trace(jac @ inverse @ jac.T))
    assert effective_parameters(jac, precision) == pytest.approx(d_eff, rel=1e-10)
    assert 0 < d_eff < 3
    sigma2 = np.sum(res**2) / (30 - d_eff)
    cov, null = least_squares_covariance(jac, res, prior_precision=precision)
    np.testing.assert_allclose(cov, sigma2 * inverse, rtol=1e-9)
    assert null == []
    share = information_share(jac, precision)
    np.testing.assert_allclose(share, 1 - np.diag(inverse) * precision, rtol=1e-9)
    assert share[1] == 1.0 and np.all((share >= 0) & (share <= 1))
    # without a prior: the least-squares covariance and d
    plain, _ = least_squares_covariance(jac, res)
    np.testing.assert_allclose(least_squares_covariance(jac, res, prior_precision=np.zeros(3))[0],
                               plain, rtol=1e-9)
    assert effective_parameters(jac, np.zeros(3)) == pytest.approx(3.0)


def _run(args, capsys):
    code = main(["identify", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_identify_with_a_prior(tmp_path, capsys):
    train = tmp_path / "train.csv"
    js.write_trial_csv(train, DATA)
    out = tmp_path / "out"
    code, stdout, _ = _run([str(train), "--model", "nomoto1", "--horizon", "20", "--prior",
                            "0.3", "--out", str(out), "--no-figures", "--quiet"], capsys)
    assert code == 0, stdout
    report = json.loads((out / "result.json").read_text())
    assert report["options"]["prior_scale"] == 0.3
    assert report["fit"]["prior"]["scale"] == 0.3 and report["fit"]["prior"]["mean"] == "start"
    assert 0 < report["fit"]["effective_params"] < 2
    for row in report["parameters"].values():
        assert 0 <= row["data_share"] <= 1
        assert row["prior_mean"] == pytest.approx(row["start"])
    assert "data share" in stdout
    for bad in ("-1", "0", "abc"):
        code, _, err = _run([str(train), "--model", "nomoto1", "--prior", bad, "--out",
                             str(tmp_path / "no"), "--no-figures", "--quiet"], capsys)
        assert code == 2 and "--prior" in err and len(err.strip().splitlines()) == 1
        assert not (tmp_path / "no").exists()
    code, _, _ = _run([str(train), "--model", "nomoto1", "--horizon", "20", "--prior", "inf",
                       "--out", str(tmp_path / "inf"), "--no-figures", "--quiet"], capsys)
    report = json.loads((tmp_path / "inf" / "result.json").read_text())
    assert code == 0 and "prior_scale" not in report["options"] and "prior" not in report["fit"]


def test_a_presets_prior_is_its_protocols_choice_unless_one_is_given():
    """Issue 69, point 2: the esso_osaka preset's fit settings hold the prior's scale the
    leave-one-run-out protocol chose (`benchmarks/results/published_splits.json`,
    `tests/test_published_splits.py`); `identify` takes it where no prior is given (its
    note says so), a given scale wins, None or inf is no prior, and a model without fit
    settings has none."""
    chosen = js.VESSELS["esso_osaka"].fit_settings.prior
    assert chosen is not None and chosen > 0
    fit_settings = js.identification.fit_settings
    default = fit_settings("esso_osaka")
    assert default.prior == chosen and f"--prior {chosen}" in default.note
    for given in (None, 0.3):
        settings = fit_settings("esso_osaka", prior=given)
        assert settings.prior == given and "--prior" not in settings.note
    assert fit_settings("nomoto1").prior is None
    assert fit_settings("nomoto1", prior=0.3).prior == 0.3
    assert fit_settings(js.get_vessel("esso_osaka"), name="esso_osaka").prior == chosen
