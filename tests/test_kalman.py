"""Extended Kalman filter, RTS smoother and the innovations (PEM / ML) fits: against a
NumPy linear Kalman filter, smoothing gains, recovery of parameters and noise variances,
PEM beating output error under process noise, bad input, no retracing."""

import math

import numpy as np
import pytest
from helpers import per_sample
from test_estimate import zigzag_like

import jaxship as js
from jaxship import Nomoto1, NonlinearNomoto
from jaxship._estimate import _likelihood
from jaxship._estimate._kalman import rts_smoother
from jaxship._estimate._likelihood import fit_ml


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples
ZOH = js.strategies.ZeroOrderHold()  # the replayed rudder held over each interval


DEG = np.pi / 180
DT = 0.5
TRUTH = Nomoto1(K=0.06, T=25.0)
Q_RUDDER = (1.0 * DEG) ** 2  # rudder-equivalent disturbance [rad^2]
R_PSI, R_R = (0.2 * DEG) ** 2, (0.02 * DEG) ** 2  # measurement noise [rad^2, (rad/s)^2]


def noisy_record(model, num, seed, *, q=Q_RUDDER, r_psi=R_PSI, r_r=R_R, dt=DT):
    """A record of `model` driven by the rudder plus a held N(0, q) disturbance, measured
    with white noise; returns (experiment, true psi, true r)."""
    rng = np.random.default_rng(seed)
    delta = zigzag_like(num, seed)
    noisy = delta + math.sqrt(q) * rng.standard_normal(num)  # process noise on the rudder
    tr = js.simulate(model, js.Replay(noisy, dt=dt, delta_hold=FOH), simulator=per_sample())
    psi, r = np.asarray(tr.state.psi), np.asarray(tr.state.r)
    exp = js.Experiment(np.asarray(tr.t), delta,
                        psi=psi + math.sqrt(r_psi) * rng.standard_normal(num),
                        r=r + math.sqrt(r_r) * rng.standard_normal(num), name=f"seed {seed}")
    return exp, psi, r


def numpy_kalman(K, T, delta, y, dt, q, R):
    """Linear Kalman filter and RTS smoother of Nomoto 1 with z = (r, psi), written out in
    NumPy; the transition is the one RK4 step the filter uses: for z' = Az + Bd,
    Phi = sum_{i<=4} (Ah)^i / i!, Gamma = sum_{i=1..4} A^(i-1) h^i / i! B."""
    A = np.array([[-1.0 / T, 0.0], [1.0, 0.0]])
    B = np.array([K / T, 0.0])
    Phi = sum(np.linalg.matrix_power(A * dt, i) / math.factorial(i) for i in range(5))
    Gamma = sum(np.linalg.matrix_power(A, i - 1) @ B * dt**i / math.factorial(i)
                for i in range(1, 5))
    H = np.array([[0.0, 1.0], [1.0, 0.0]])  # channels (psi, r)
    z, P = np.array([y[0, 1], y[0, 0]]), np.diag([R[1, 1], R[0, 0]])
    zf, Pf, zp, Pp, innov, nll = [z], [P], [z], [P], [np.zeros(2)], 0.0
    for k in range(1, len(delta)):
        z = Phi @ z + Gamma * delta[k - 1]
        P = Phi @ P @ Phi.T + q * np.outer(Gamma, Gamma)
        zp.append(z)
        Pp.append(P)
        e = y[k] - H @ z
        S = H @ P @ H.T + R
        gain = P @ H.T @ np.linalg.inv(S)
        z = z + gain @ e
        P = (np.eye(2) - gain @ H) @ P
        nll += 0.5 * (np.log(np.linalg.det(S)) + e @ np.linalg.solve(S, e) + 2 * np.log(2 * np.pi))
        zf.append(z)
        Pf.append(P)
        innov.append(e)
    zs, Ps = [zf[-1]], [Pf[-1]]
    for k in range(len(delta) - 2, -1, -1):
        G = Pf[k] @ Phi.T @ np.linalg.inv(Pp[k + 1])
        zs.insert(0, zf[k] + G @ (zs[0] - zp[k + 1]))
        Ps.insert(0, Pf[k] + G @ (Ps[0] - Pp[k + 1]) @ G.T)
    return np.array(zf), np.array(innov), nll, np.array(zs), np.array(Ps)


# -- the filter and the smoother --------------------------------------------------------


def test_ekf_of_a_linear_model_is_the_linear_kalman_filter():
    exp, _, _ = noisy_record(TRUTH, 300, 1)
    # the reference discretises the rudder held over each interval (zero-order hold)
    out = js.ekf(TRUTH, exp, process_noise={"rudder": Q_RUDDER},
                 measurement_noise={"psi": R_PSI, "r": R_R}, hold=ZOH)
    zs, Ps = rts_smoother(out)
    y = np.stack([exp.psi, exp.r], axis=-1)
    zf, innov, nll, zs_ref, Ps_ref = numpy_kalman(0.06, 25.0, exp.delta, y, DT, Q_RUDDER,
                                                  np.diag([R_PSI, R_R]))
    assert out.names == ("r", "psi")
    np.testing.assert_allclose(out.filtered, zf, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(out.innovations, innov, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(float(out.neg_log_likelihood), nll, rtol=1e-10)
    np.testing.assert_allclose(zs, zs_ref, rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(Ps, Ps_ref, rtol=1e-6, atol=1e-16)


def test_filtering_and_smoothing_reduce_the_state_error_of_a_nonlinear_model():
    """EKF and RTS smoother on the Norrbin nonlinear Nomoto model: the smoothed yaw rate
    is closer to the truth than the filtered one, which beats the measurement."""
    model = NonlinearNomoto(K=0.06, T=25.0, n3=400.0)
    exp, psi, r = noisy_record(model, 600, 2, r_r=(0.05 * DEG) ** 2)
    noise = dict(process_noise={"rudder": Q_RUDDER},
                 measurement_noise={"psi": R_PSI, "r": (0.05 * DEG) ** 2})
    out = js.ekf(model, exp, **noise)
    smoothed = js.smooth_states(model, exp, **noise)[0]
    rms = lambda a: float(np.sqrt(np.mean((a - r) ** 2)))
    measured, filtered, smooth = rms(exp.r), rms(np.asarray(out.filtered)[:, 0]), rms(
        smoothed.state("r"))
    assert smooth < 0.8 * filtered < 0.8 * measured, (measured, filtered, smooth)
    # the smoothed standard deviation describes the error it makes
    ratio = np.sqrt(np.mean((smoothed.state("r") - r) ** 2 / smoothed.std("r")[1:-1].mean() ** 2))
    assert 0.5 < ratio < 2.0, ratio
    np.testing.assert_allclose(smoothed.t, exp.t)


def test_smooth_states_cuts_merged_records_of_different_lengths():
    a, _, _ = noisy_record(TRUTH, 200, 3)
    b, _, _ = noisy_record(TRUTH, 320, 4)
    noise = dict(process_noise={"rudder": Q_RUDDER}, measurement_noise={"psi": R_PSI, "r": R_R})
    both = js.smooth_states(TRUTH, [a, b], **noise)
    assert [s.mean.shape[0] for s in both] == [200, 320]
    for s, exp in zip(both, (a, b)):
        alone = js.smooth_states(TRUTH, exp, **noise)[0]
        np.testing.assert_allclose(s.mean, alone.mean, rtol=1e-10, atol=1e-14)
        assert s.name == exp.name


# -- estimation -------------------------------------------------------------------------


@pytest.fixture(scope="module")
def process_noise_record():
    return noisy_record(TRUTH, 1200, 0)


def test_ml_recovers_parameters_and_noise_variances(process_noise_record):
    exp, _, _ = process_noise_record
    res = fit_ml(Nomoto1(K=0.04, T=15.0), exp)
    assert res.success, res.message
    truth = {"K": 0.06, "T": 25.0}
    for name, value, std in zip(res.names, res.values, res.std):
        assert abs(value - truth[name]) < 3 * std, (name, value, std)
    for name, value in {"rudder": Q_RUDDER, "psi": R_PSI, "r": R_R}.items():
        assert abs(res.noise[name] - value) < 3 * res.noise_std[name], (name, res.noise)
    assert res.noise_std["psi"] < 0.1 * res.noise["psi"]


def test_innovations_pem_beats_output_error_under_process_noise(process_noise_record):
    """Astrom & Kallstrom (1979, sec. 5): with process noise, the output-error estimate is
    off by many of its own standard errors; the innovations predictor is not."""
    exp, _, _ = process_noise_record
    start = Nomoto1(K=0.04, T=15.0)
    pem = fit_ml(start, exp, criterion=js.InnovationsLeastSquares())
    oe = js.fit(start, exp, estimator=js.PredictionError(horizon=None))
    truth = np.array([0.06, 25.0])
    assert pem.success and oe.success
    pem_err, oe_err = np.abs(pem.values - truth), np.abs(oe.values - truth)
    assert np.all(pem_err < 3 * pem.std), (pem.values, pem.std)
    assert np.all(pem_err < oe_err), (pem.values, oe.values)
    assert np.max(oe_err / oe.std) > 3.0  # output error's intervals miss the truth
    assert pem.noise_std["psi"] == 0.0  # held: the innovations do not fix the scale


def test_ml_intervals_cover_the_truth_at_about_the_nominal_rate():
    covered, sizes = [], set()
    for seed in range(12):
        exp, _, _ = noisy_record(TRUTH, 400, 100 + seed)
        res = fit_ml(Nomoto1(K=0.05, T=20.0), exp)
        lower = res.values - 1.96 * res.std
        upper = res.values + 1.96 * res.std
        covered.extend((lower <= [0.06, 25.0]) & ([0.06, 25.0] <= upper))
        sizes.add(_likelihood._ml_solve._cached._cache_size())
    assert np.mean(covered) >= 0.8, np.mean(covered)
    assert len(sizes) == 1  # one trace for every data set and start


def test_noise_can_be_held_fixed_and_states_can_carry_process_noise():
    exp, _, _ = noisy_record(TRUTH, 400, 7)
    res = fit_ml(Nomoto1(K=0.05, T=20.0), exp, process=js.strategies.ProcessNoise(states=("r",)),
                    noise=js.strategies.HeldNoise({"psi": R_PSI}), channels=("psi", "r"))
    assert set(res.noise) == {"rudder", "Q_r", "psi", "r"}
    assert res.noise["psi"] == pytest.approx(R_PSI) and res.noise_std["psi"] == 0.0
    assert "rudder" in res.summary()


# -- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs, match", [
    (dict(channels=("psi", "x")), "unknown channel 'x'"),
    (dict(channels=()), "empty"),
    (dict(process_noise={"rudder": -1.0}), "cannot be negative"),
    (dict(process_noise={"sway": 1.0}), "neither a state"),
    (dict(process_noise={"rudder": float("nan")}), "finite"),
    (dict(measurement_noise={"psi": R_PSI}), "no variance for channel 'r'"),
    (dict(measurement_noise={"psi": R_PSI, "r": 0.0}), "positive definite"),
    (dict(measurement_noise=np.eye(3)), "shape"),
    (dict(initial_covariance=[[1.0, 2.0], [0.0, 1.0]]), "symmetric"),
])
def test_ekf_rejects_bad_noise_specifications(kwargs, match):
    exp, _, _ = noisy_record(TRUTH, 50, 8)
    args = dict(process_noise={"rudder": Q_RUDDER}, measurement_noise={"psi": R_PSI, "r": R_R})
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        js.ekf(TRUTH, exp, **args)


def test_fit_ml_rejects_bad_arguments_and_data():
    exp, _, _ = noisy_record(TRUTH, 50, 9)
    with pytest.raises(ValueError, match="MaximumLikelihood\\(\\) or InnovationsLeastSquares"):
        fit_ml(TRUTH, exp, criterion="ml")
    with pytest.raises(ValueError, match="not a noise term"):
        fit_ml(TRUTH, exp, noise=js.strategies.HeldNoise({"wind": 1.0}))
    with pytest.raises(ValueError, match="AbstractSteeringModel"):
        fit_ml("nomoto1", exp)
    with pytest.raises(ValueError, match="Experiment"):
        js.ekf(TRUTH, [exp], process_noise={"rudder": 1e-4},
               measurement_noise={"psi": R_PSI, "r": R_R})
    dropped = js.Experiment(exp.t, exp.delta, psi=exp.psi, name="no yaw rate")
    with pytest.raises(ValueError, match="'no yaw rate'.*'r' was not measured"):
        fit_ml(TRUTH, dropped)
    fit_ml(TRUTH, dropped, channels="psi", max_steps=2)  # heading alone is accepted


def test_smoothed_window_starts_remove_the_bias_of_noisy_starts():
    """Prediction error with T_p = 10 s on a yaw rate with 0.2 deg/s noise: windows that
    start from the measured r are biased by tens of standard errors (errors in
    variables); starting them from the EKF + RTS smoothed states (smoothed with the
    start model, not the truth) recovers K and T within their intervals."""
    q, r_r = (0.2 * DEG) ** 2, (0.2 * DEG) ** 2
    exp, _, _ = noisy_record(TRUTH, 1200, 20, q=q, r_r=r_r)
    start = Nomoto1(K=0.05, T=20.0)
    smoothed = js.smooth_states(start, exp, process_noise={"rudder": q},
                                measurement_noise={"psi": R_PSI, "r": r_r})
    truth = np.array([0.06, 25.0])
    errors = {}
    for label, initial in (("measured", js.MeasuredStates()), ("smoothed", smoothed)):
        res = js.fit(start, exp, estimator=js.PredictionError(horizon=10.0, initial=initial))
        errors[label] = np.abs(res.values - truth) / res.std
    assert np.all(errors["measured"] > 10), errors
    assert np.all(errors["smoothed"] < 3), errors
    with pytest.raises(ValueError, match="one SmoothedStates per experiment"):
        js.fit(start, [exp, exp], estimator=js.PredictionError(horizon=10.0, initial=smoothed))


def test_fit_with_the_innovations_estimator_is_fit_ml():
    """`fit(..., estimator=Innovations(...))` is `fit_ml`, with one result type: the
    FitResult carries the noise, the criterion and the filter's one-step predictions."""
    exp, _, _ = noisy_record(TRUTH, 400, 11)
    start = Nomoto1(K=0.05, T=20.0)
    direct = fit_ml(start, exp, criterion=js.InnovationsLeastSquares())
    res = js.fit(start, exp, estimator=js.Innovations(criterion=js.InnovationsLeastSquares()))
    assert isinstance(res, js.FitResult) and res.criterion == "pem"
    np.testing.assert_allclose(res.values, direct.values, rtol=1e-12)
    assert res.noise == direct.noise and set(res.metrics) == {"psi", "r"}
    assert not res.predicted[0, 0] and res.predicted[0, 1:].all()
    assert res.metrics["psi"].fit_percent > 90.0  # one step ahead
    assert "innovations (pem" in res.summary()
    with pytest.raises(ValueError, match="estimator"):
        js.fit(start, exp, estimator="pem")


def test_a_vessels_smoother_recovers_the_unlogged_drift_and_a_fit_needs_no_logged_v():
    """Mariner zig-zags logged with psi, r, u and the track x, y but no v: the EKF + RTS
    smoother of the vessel (the track makes the drift observable) recovers v as closely
    as the logged v's own 0.02 m/s noise lets us check (RMS difference 0.022 m/s, below
    0.025; v spreads 0.12-0.40 m/s), and a fit whose windows start from the smoothed
    states recovers Y_v, Y_r, N_v, N_r from a start 30 % / 20 % off within 5 % (3.4 %
    at worst; with v logged 4.6 %). Without smoothed starts the fit says what is
    missing."""
    import equinox as eqx

    from jaxship.studies.discovery import vessel_records

    mariner = js.get_vessel("mariner")
    logged, _ = vessel_records(mariner, 0)
    records = [js.Experiment(e.t, e.delta, psi=e.psi, r=e.r, u=e.u, x=e.x, y=e.y, n=e.n,
                             name=e.name) for e in logged]
    q = 1e-4  # (m/s)^2 per 0.5 s interval
    smoothed = js.smooth_states(
        mariner, records, process_noise={"u": q, "v": q, "r": q / mariner.length ** 2},
        measurement_noise={"psi": (0.1 * DEG) ** 2, "r": (0.05 * DEG) ** 2, "u": 0.02 ** 2,
                           "x": 1.0, "y": 1.0},
        channels=("psi", "r", "u", "x", "y"),
        initial_covariance=np.diag([4e-4, 0.6, 1e-6, 1.0, 1.0, 1e-6, 0.0, 0.0]))
    for s, e in zip(smoothed, logged):
        assert np.sqrt(np.mean((s.state("v") - e.v) ** 2)) < 0.025
    free = ["y_v", "y_r", "n_v", "n_r"]
    start = eqx.tree_at(lambda m: (m.n_v, m.n_r), mariner, (1.3 * mariner.n_v, 0.8 * mariner.n_r))
    estimator = js.PredictionError(horizon=60.0, channels=("psi", "r", "u"), initial=smoothed)
    res = js.fit(start, records, estimator=estimator, free=free)
    truth = np.array([float(getattr(mariner, n)) for n in res.names])
    assert np.all(np.abs(res.values / truth - 1) < 0.05), (res.names, res.values, truth)
    with pytest.raises(ValueError, match="no measured 'v'.*smooth_states"):
        js.fit(start, records, estimator=js.PredictionError(horizon=60.0, channels=("r",)),
               free=free)
