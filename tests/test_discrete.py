"""Lu & Zhao (2008) discrete response models: exact recovery and conversion."""

import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship import Experiment, Nomoto1, Nomoto2
from jaxship._estimate._discrete import (
    COEFFICIENTS,
    DiscreteResponseFit,
    continuous_parameters,
    discretise,
    regressors,
)


EXACT, EULER = js.strategies.ExactDiscretisation(), js.strategies.EulerDiscretisation()


def fit_discrete_response(structure, data, *, method=js.LeastSquaresRegression(),
                          discretisation=None):
    """Lu & Zhao's regression through its public door, the estimator's `regress`."""
    return js.DiscreteResponse(method=method, discretisation=discretisation).regress(
        structure, data)


ZOH = js.strategies.ZeroOrderHold()  # the replayed rudder held over each interval


H = 0.2
CASES = {
    "linear1": dict(K=0.1, T=20.0, delta_r=0.01),
    "nonlinear1": dict(alpha1=0.05, beta1=30.0, alpha2=0.005, delta_r=0.01),
    "linear2": dict(K=0.1, T1=25.0, T2=3.0, T3=5.0, delta_r=0.01),
    "nonlinear2": dict(K=0.1, T1=25.0, T2=3.0, T3=5.0, beta1=200.0, delta_r=0.01),
}


def _rudder(n=3000, seed=0):
    rng = np.random.default_rng(seed)
    return np.repeat(rng.choice([-0.2, 0.2], n // 50), 50)


def _record(structure, how=None):
    how = how or (EXACT if structure.startswith("linear") else EULER)
    c = discretise(structure, CASES[structure], H, discretisation=how)
    model = DiscreteResponseFit(structure, js.LeastSquaresRegression(), how, H, c, {}, 0.0, 0)
    d = _rudder()
    return c, Experiment(np.arange(d.size) * H, d, r=model.simulate(d))


@pytest.mark.parametrize("structure", list(CASES))
def test_ls_exact_recovery(structure):
    c, e = _record(structure)
    f = fit_discrete_response(structure, e)
    for k in COEFFICIENTS[structure]:
        assert f.coefficients[k] == pytest.approx(c[k], rel=1e-6)
    for k, v in CASES[structure].items():
        assert f.parameters[k] == pytest.approx(v, rel=1e-6)


@pytest.mark.parametrize("structure", ["linear1", "linear2"])
def test_euler_linear_roundtrip(structure):
    c, e = _record(structure, EULER)
    f = fit_discrete_response(structure, e, discretisation=EULER)
    for k, v in CASES[structure].items():
        assert f.parameters[k] == pytest.approx(v, rel=1e-6)


def test_zoh_matches_continuous_models():
    """ZOH coefficients reproduce the continuous Nomoto models they were sampled from
    (reference: simulate with fine RK4 substeps), and the fit recovers K, T."""
    d = _rudder(1500)
    for structure, model in (("linear1", Nomoto1(K=0.1, T=20.0, delta0=0.01)),
                             ("linear2", Nomoto2(K=0.1, T1=25.0, T2=3.0, T3=5.0, delta0=0.01))):
        r = np.asarray(js.simulate(model, js.Replay(d, dt=H, delta_hold=ZOH),
                                   simulator=per_sample(40)).state.r)
        e = Experiment(np.arange(d.size) * H, d, r=r)
        f = fit_discrete_response(structure, e)
        for k, v in CASES[structure].items():
            assert f.parameters[k] == pytest.approx(v, rel=1e-6), k
        assert isinstance(f.to_steering(), type(model))
    # the difference equation from rest equals the continuous model from rest
    for structure, model in (("linear1", Nomoto1(K=0.1, T=20.0)),
                             ("linear2", Nomoto2(K=0.1, T1=25.0, T2=3.0, T3=5.0))):
        params = {k: v for k, v in CASES[structure].items() if k != "delta_r"}
        c = discretise(structure, params, H)
        r = np.asarray(js.simulate(model, js.Replay(d, dt=H, delta_hold=ZOH),
                                   simulator=per_sample(40)).state.r)
        sim = DiscreteResponseFit(structure, js.LeastSquaresRegression(), EXACT, H, c, {}, 0.0,
                                  0).simulate(d)
        assert np.max(np.abs(sim - r)) < 1e-9 * np.max(np.abs(r))


def test_to_steering_nonlinear1_matches_norrbin():
    p = continuous_parameters("nonlinear1", discretise("nonlinear1", CASES["nonlinear1"], H), H)
    f = DiscreteResponseFit("nonlinear1", js.LeastSquaresRegression(), EULER, H, {}, p, 0.0, 0)
    m = f.to_steering()
    assert m.K == pytest.approx(0.1) and m.T == pytest.approx(20.0)
    assert m.n3 == pytest.approx(600.0) and m.n0 == pytest.approx(-0.001)


@pytest.mark.parametrize("structure", list(CASES))
def test_svr_recovers_noise_free(structure):
    pytest.importorskip("sklearn")
    c, e = _record(structure)
    ls = fit_discrete_response(structure, e)
    svr = fit_discrete_response(structure, e, method=js.SupportVectorRegression())
    assert svr.converged
    # an iterative QP solver (liblinear, tol 1e-8): agreement to its tolerance
    for k in COEFFICIENTS[structure]:
        assert svr.coefficients[k] == pytest.approx(ls.coefficients[k], rel=1e-5, abs=1e-12)
    # the same through the one door, with the method as a strategy object
    door = js.fit(STEERING[structure](), e,
                  estimator=js.DiscreteResponse(method=js.SupportVectorRegression()))
    assert door.criterion.startswith("equation error (svr")
    least_squares = js.fit(STEERING[structure](), e, estimator=js.DiscreteResponse())
    assert door.values == pytest.approx(least_squares.values, rel=1e-4, abs=1e-9)


def test_bad_inputs():
    _, e = _record("linear1")
    with pytest.raises(ValueError, match="structure"):
        fit_discrete_response("cubic", e)
    with pytest.raises(ValueError, match="method"):
        fit_discrete_response("linear1", e, method="svr")
    with pytest.raises(ValueError, match="zero-order-hold"):
        fit_discrete_response("nonlinear1", e, discretisation=EXACT)
    with pytest.raises(ValueError, match="ExactDiscretisation\\(\\) or EulerDiscretisation"):
        fit_discrete_response("linear1", e, discretisation="zoh")
    with pytest.raises(ValueError, match="Experiment"):
        fit_discrete_response("linear1", np.zeros(10))
    const = Experiment(e.t, np.zeros_like(e.t), r=np.zeros_like(e.t))
    with pytest.raises(ValueError, match="excitation|zero"):
        fit_discrete_response("linear1", const)
    other = Experiment(e.t * 2, e.delta, r=e.r)
    with pytest.raises(ValueError, match="sample intervals"):
        fit_discrete_response("linear1", [e, other])


STEERING = {
    "linear1": lambda: Nomoto1(K=0.05, T=10.0),
    "nonlinear1": lambda: js.NonlinearNomoto(K=0.05, T=10.0),
    "linear2": lambda: Nomoto2(K=0.05, T1=10.0, T2=2.0, T3=1.0),
    "nonlinear2": lambda: js.effects.nonlinear_nomoto2(0.05, 10.0, 2.0, 1.0),
}


@pytest.mark.parametrize("structure", list(CASES))
def test_the_discrete_response_estimator_returns_a_fit_result(structure):
    """`fit(model, data, estimator=DiscreteResponse())`: the model's class picks the
    structure; the estimates are `regress`'s, converted to the fitted model, to the bit."""
    _, e = _record(structure)
    result = js.fit(STEERING[structure](), e, estimator=js.DiscreteResponse())
    direct = fit_discrete_response(structure, e)
    assert isinstance(result, js.FitResult) and result.success
    values = dict(zip(result.names, result.values))
    model = direct.to_steering()
    for name, value in values.items():
        expected = (float(model.lookup("yaw_cubic_damping").beta) if "." in name
                    else float(getattr(model, name) if not hasattr(model, "base")
                               else getattr(model.base, name)))
        assert value == expected, name
    assert result.metrics["r"].fit_percent > 99.99  # one-step predictions, noise-free
    assert np.all(np.isfinite(result.std)) and np.all(result.std >= 0)


def test_discrete_response_standard_errors_by_the_delta_method():
    """linear1 with equation noise: $K = a_2/(1 - a_1)$, $T = -h/\\ln a_1$; the reported
    std equals the delta method written out from the least-squares covariance."""
    rng = np.random.default_rng(3)
    c = discretise("linear1", CASES["linear1"], H, discretisation=EXACT)
    d = _rudder()
    r = np.zeros(d.size)
    for k in range(1, d.size):
        r[k] = c["a1"] * r[k - 1] + c["a2"] * d[k - 1] + c["b0"] + 2e-4 * rng.normal()
    e = Experiment(np.arange(d.size) * H, d, r=r)
    result = js.fit(Nomoto1(K=0.1, T=20.0), e, estimator=js.DiscreteResponse())
    f = fit_discrete_response("linear1", e)
    x, _ = regressors("linear1", r, d)
    cov = f.rms**2 * f.num_rows / (f.num_rows - 3) * np.linalg.inv(x.T @ x)
    a1, a2 = f.coefficients["a1"], f.coefficients["a2"]
    grad_k = np.array([a2 / (1 - a1) ** 2, 1 / (1 - a1), 0.0])
    grad_t = np.array([H / (a1 * np.log(a1) ** 2), 0.0, 0.0])
    std = dict(zip(result.names, result.std))
    assert std["K"] == pytest.approx(np.sqrt(grad_k @ cov @ grad_k), rel=1e-5)
    assert std["T"] == pytest.approx(np.sqrt(grad_t @ cov @ grad_t), rel=1e-5)


def test_one_door_fits_lu_and_zhaos_models():
    """`jaxship.fit` is the one fit door: no `fit_discrete_response` beside it; the
    estimator's `regress` takes a structure's name or a model of it, the same
    regression."""
    assert not hasattr(js, "fit_discrete_response")
    _, e = _record("linear2")
    by_name = js.DiscreteResponse().regress("linear2", e)
    by_model = js.DiscreteResponse().regress(STEERING["linear2"](), e)
    assert by_name.coefficients == by_model.coefficients
    assert by_name.parameters == by_model.parameters


def test_the_discrete_response_estimator_rejects_other_models():
    with pytest.raises(ValueError, match="DiscreteResponse estimator fits"):
        js.fit(js.RossAutopilot(length=4.0, speed=1.5, rate=8.0), _record("linear1")[1],
               estimator=js.DiscreteResponse())
