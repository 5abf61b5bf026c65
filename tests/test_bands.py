"""Prediction bands (`jaxship.prediction_bands`, the real-data issue's point 4): computed
right where the noise is known, calibrated on training records, and refusing what they
cannot do."""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid
from scipy.signal import lfilter

import jaxship as js


DEG = np.pi / 180
TRUTH = js.Nomoto1(K=0.06, T=25.0)
DT = 0.5
NOISE = {"psi": 0.2 * DEG, "r": 0.02 * DEG}  # sensor noise [rad, rad/s]
DISTURBANCE = js.Disturbance(std=0.15 * DEG, tau=20.0)  # yaw-rate disturbance [rad/s]


def records_of(seeds, num=200):
    """Nomoto 1 records under random rudder steps, with the output disturbance of the
    yaw rate (from zero at the start) and white sensor noise, written out independently of
    jaxship's: the Gauss-Markov recursion by `scipy.signal.lfilter`, its integral by
    `scipy.integrate.cumulative_trapezoid`."""
    rngs = [np.random.default_rng(seed) for seed in seeds]
    delta = np.stack([np.repeat(np.where(rng.random(num // 40) < 0.5, -1.0, 1.0) * 10 * DEG,
                                40) for rng in rngs])
    replays = js.stack([js.Replay(d, dt=DT, delta_hold=js.strategies.FirstOrderHold())
                        for d in delta])
    tr = js.simulate_batch(TRUTH, replays,
                           simulator=js.Simulator(substeps=4), in_axes=(None, 0, None, None))
    a = np.exp(-DT / DISTURBANCE.tau)
    out = []
    for i, (seed, rng) in enumerate(zip(seeds, rngs)):
        e = np.concatenate([[0.0], rng.standard_normal(num - 1)])
        b = DISTURBANCE.std * np.sqrt(1 - a**2) * lfilter([1.0], [1.0, -a], e)
        psi = np.asarray(tr.state.psi[i]) + cumulative_trapezoid(b, dx=DT, initial=0.0)
        r = np.asarray(tr.state.r[i]) + b
        out.append(js.Experiment(
            np.asarray(tr.t[i]), delta[i], psi=psi + NOISE["psi"] * rng.standard_normal(num),
            r=r + NOISE["r"] * rng.standard_normal(num), name=f"run{seed}"))
    return out


def pooled(bands, records):
    cov, hits = bands.coverage(records), bands.predicted.sum(axis=1)
    return {c: float(np.sum(v * hits) / np.sum(hits)) for c, v in cov.items()}


def test_the_bands_of_the_true_model_cover_the_nominal_share_of_samples():
    """With the true model, disturbance and sensor noise, the 90 % band holds 90 % of the
    samples of 200 records, within 3 points for each of two seeds of the draws; the
    50 % band half; without the disturbance the band is far too narrow."""
    records = records_of(range(200))
    for seed in range(2):
        bands = js.prediction_bands(TRUTH, records, disturbance=DISTURBANCE,
                                    measurement_std=NOISE, num_samples=300, seed=seed)
        assert bands.num_dropped == 0
        for c, share in pooled(bands, records).items():
            assert abs(share - 0.9) < 0.03, (seed, c, share)
        assert np.all(bands.lower["r"] <= bands.nominal["r"] + 1e-12)
    half = js.prediction_bands(TRUTH, records, level=0.5, disturbance=DISTURBANCE,
                               measurement_std=NOISE, num_samples=300)
    assert all(abs(share - 0.5) < 0.03 for share in pooled(half, records).values())
    narrow = js.prediction_bands(TRUTH, records, measurement_std=NOISE, num_samples=300)
    assert all(share < 0.6 for share in pooled(narrow, records).values())


def test_the_draws_give_the_spread_of_a_correct_models_per_record_coverage():
    """The yardstick of issue 58: with the true model and noise model, each independent
    record's coverage falls inside the central 90 % range of its draws' coverage
    (`coverage_range`) for about 90 % of 200 records (binomial sd 2 points); without the
    disturbance the model is wrong, and far fewer do. The ranges have a real width (runs
    of 100 s scatter) and the draws' coverage is about the level on average."""
    records = records_of(range(200))
    bands = js.prediction_bands(TRUTH, records, disturbance=DISTURBANCE,
                                measurement_std=NOISE, num_samples=300)
    covered, ranges = bands.coverage(records), bands.coverage_range(0.9)
    for c in ("r", "psi"):
        low, high = ranges[c][:, 0], ranges[c][:, 1]
        inside = np.mean((covered[c] >= low) & (covered[c] <= high))
        assert abs(inside - 0.9) < 0.07, (c, inside)
        assert np.median(high - low) > 0.1, c
        assert abs(np.mean(bands.draw_coverage[c]) - 0.9) < 0.02, c
    wrong = js.prediction_bands(TRUTH, records, measurement_std=NOISE, num_samples=300)
    covered, ranges = wrong.coverage(records), wrong.coverage_range(0.9)
    inside = np.mean((covered["psi"] >= ranges["psi"][:, 0])
                     & (covered["psi"] <= ranges["psi"][:, 1]))
    assert inside < 0.3, inside


def test_a_disturbance_calibrated_on_training_records_holds_on_new_ones():
    """Fitted on 6 records, the disturbance calibrated on them (with the fit's robust
    parameter covariance) comes within a factor 2 of the truth, and its bands cover
    80-95 % of the r and psi samples of 100 new records (the goal on real data)."""
    train = records_of(range(1000, 1006), num=600)
    fit = js.fit(js.Nomoto1(K=0.05, T=20.0), train,
                 estimator=js.PredictionError(horizon=None))
    assert fit.success, fit.message
    found = js.calibrate_disturbance(fit, train, measurement_std=NOISE)
    assert 0.5 < found.std / DISTURBANCE.std < 2 and 0.5 < found.tau / DISTURBANCE.tau < 2, found
    test = records_of(range(2000, 2100))
    bands = js.prediction_bands(fit, test, disturbance=found, measurement_std=NOISE)
    assert all(0.8 <= share <= 0.95 for share in pooled(bands, test).values()), \
        pooled(bands, test)


def test_bands_refuse_what_they_cannot_do():
    (rec,) = records_of([0], num=80)
    with pytest.raises(ValueError, match="`level` must be between 0 and 1"):
        js.prediction_bands(TRUTH, rec, level=90)
    with pytest.raises(ValueError, match="`num_samples` must be at least 2"):
        js.prediction_bands(TRUTH, rec, num_samples=1)
    with pytest.raises(ValueError, match="names \\['u'\\], which the estimator does not"):
        js.prediction_bands(TRUTH, rec, measurement_std={"u": 0.01})
    with pytest.raises(ValueError, match="`tau` must be a positive number of seconds"):
        js.Disturbance(std=0.01, tau=0.0)
    with pytest.raises(ValueError, match="needs the estimator to predict r and psi"):
        js.calibrate_disturbance(TRUTH, rec, estimator=js.PredictionError(channels=("r",)))
    # the covariance is a strategy object (issue 59), not a string
    with pytest.raises(ValueError, match="must be RobustCovariance\\(\\), WhiteCovariance"):
        js.prediction_bands(TRUTH, rec, covariance="robust")
    with pytest.raises(ValueError, match="a `covariance` array needs the `FitResult`"):
        js.prediction_bands(TRUTH, rec, covariance=js.strategies.GivenCovariance(np.eye(2)))
