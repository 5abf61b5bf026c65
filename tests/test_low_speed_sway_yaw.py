"""`LowSpeedSwayYaw`: its equations term by term, its steady turn, and fit-then-recover
on records of itself at low and changing speed and rpm."""

import warnings

import equinox as eqx
import jax.numpy as jnp
import numpy as np

import jaxship as js
from jaxship._models._vessel.sway_yaw import _cross_flow_integrals


DEG = np.pi / 180
# the values fitted on the Esso Osaka zig-zags and turns (studies.real_data), rounded
ESSO = {"n_v": -0.22, "n_r": -0.53, "n_delta": 0.11, "y_v": -0.20, "y_r": -0.49,
        "y_delta": -0.049, "race": 4.7e-4, "crossflow_y": 0.23, "crossflow_n": 0.25,
        "wind_y": -6.1e-4, "wind_1": 1.3e-4, "wind_2": -2.2e-4}
HULL = tuple(k for k in ESSO if not k.startswith("wind"))


def with_values(model, values):
    return eqx.tree_at(lambda m: tuple(getattr(m, k) for k in values), model,
                       tuple(float(v) for v in values.values()))


TRUTH = with_values(js.LowSpeedSwayYaw(), ESSO)


def test_each_term_of_the_equations():
    """At random states and inputs, (r_dot, v_dot) is the module docstring's sum: the
    linear terms in u, the rudder in u^2 + c_R n_+^2 (an astern propeller gives no
    race), Norrbin's cross-flow integrals, and the wind terms only where a wind is
    logged."""
    rng = np.random.default_rng(0)
    m = TRUTH
    for _ in range(10):
        r, v, d = 0.05 * rng.normal(), 0.1 * rng.normal(), 0.5 * rng.normal()
        u, n, wu, wv = rng.uniform(0.1, 0.5), rng.uniform(-5, 15), rng.normal(), rng.normal()
        iy, i_n = _cross_flow_integrals(v, r, 3.0)
        rudder = (u**2 + m.race * max(n, 0.0) ** 2) * d
        calm = [m.n_v * u * v + m.n_r * u * r + m.n_delta * rudder - m.crossflow_n * i_n,
                m.y_v * u * v + m.y_r * u * r + m.y_delta * rudder - m.crossflow_y * iy]
        x = jnp.array([r, v])
        np.testing.assert_allclose(m.rhs(x, d, js.AuxInputs(u=u, n=n)), calm, rtol=1e-12)
        speed = np.hypot(wu, wv)
        windy = [calm[0] + (2 * m.wind_2 * wu + m.wind_1 * speed) * wv,
                 calm[1] + m.wind_y * speed * wv]
        got = m.rhs(x, d, js.AuxInputs(u=u, n=n, wind_u=wu, wind_v=wv))
        np.testing.assert_allclose(got, windy, rtol=1e-12)


def test_steady_turn_is_an_equilibrium():
    """`steady_turn(r)` zeroes both equations at the model's speed and rpm; a straight
    run is the zero state; a starboard turn needs starboard rudder and drifts to port."""
    for r in (-0.04, 0.01, 0.04):
        v, d = TRUTH.steady_turn(r)
        aux = js.AuxInputs(u=TRUTH.speed, n=TRUTH.propeller_rate)
        np.testing.assert_allclose(TRUTH.rhs(jnp.array([r, v]), d, aux), 0.0, atol=1e-12)
        assert np.sign(d) == np.sign(r) and np.sign(v) == -np.sign(r)
    np.testing.assert_array_equal(TRUTH.initial_state(0.0), [0.0, 0.0])
    assert TRUTH.wind_loads and js.augment(TRUTH, js.RudderOffset()).wind_loads


def low_speed_record(seed):
    """Rudder steps of 10-35 deg held 20-60 s at 2 Hz, u wandering 0.15-0.45 m/s and
    the propeller at 8, 10 or 15 rev/s, from a straight run, without wind."""
    rng = np.random.default_rng(seed)
    dt, num = 0.5, 600
    t = dt * np.arange(num)
    delta, sign = [], 1.0
    while len(delta) < num:
        sign = -sign
        delta += [sign * rng.uniform(10, 35) * DEG] * int(rng.integers(40, 120))
    delta = np.array(delta[:num])
    u = 0.3 + 0.15 * np.sin(2 * np.pi * t / rng.uniform(80, 200) + seed)
    n = np.full(num, rng.choice([8.0, 10.0, 15.0]))
    tr = js.simulate_steering(TRUTH, delta, dt, aux=js.AuxInputs(u=u, n=n))
    return js.Experiment(t, delta, psi=np.asarray(tr.psi), r=np.asarray(tr.r), u=u, n=n,
                         v=np.asarray(tr.state[:, 1]))


def test_fit_recovers_the_hull_and_race_coefficients_from_its_own_records():
    """Output error on r and v from the class's start values recovers the nine hull,
    rudder, race and cross-flow coefficients of noise-free records to 1e-4."""
    records = [low_speed_record(s) for s in range(4)]
    est = js.PredictionError(horizon=None, channels=("r", "v"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", js.IdentifiabilityWarning)
        res = js.fit(js.LowSpeedSwayYaw(), records, estimator=est, free=HULL)
    assert res.success
    got = dict(zip(res.names, np.asarray(res.values)))
    np.testing.assert_allclose([got[k] for k in HULL], [ESSO[k] for k in HULL], rtol=1e-4)
