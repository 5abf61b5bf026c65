"""Merged fits and the Kalman filter split their batch axis (windows, experiments) across
devices: four XLA host devices in a subprocess give the numbers of one device."""

import json
import os
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import jax
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship._estimate import _fit
from jaxship._models._vessel.catalogue import get_vessel


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples


DEG = np.pi / 180


def results() -> dict:
    """Three small merged problems whose windows or experiments do not divide evenly by
    four devices (so the padding is exercised): a Nomoto 1 fit, a thesis-vessel fit with
    two free coefficients and a maximum-likelihood fit with the Kalman filter."""
    truth = js.Nomoto1(K=0.06, T=25.0)
    rng = np.random.default_rng(0)
    records = []
    for k, num in enumerate((170, 230, 310)):
        delta = np.where((np.arange(num) // 40) % 2 == 0, 10.0, -10.0) * DEG * (1 + 0.2 * k)
        tr = js.simulate(truth, js.Replay(delta, dt=0.5, delta_hold=FOH), simulator=per_sample())
        records.append(js.Experiment(np.asarray(tr.t), delta,
                                     psi=np.asarray(tr.state.psi) + 1e-3 * rng.standard_normal(num),
                                     r=np.asarray(tr.state.r) + 1e-4 * rng.standard_normal(num),
                                     name=f"record {k}"))
    start = js.Nomoto1(K=0.04, T=15.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nomoto = js.fit(start, records, estimator=js.PredictionError(horizon=9.5))
        ml = js.fit(start, records, estimator=js.Innovations(max_steps=64))
        thesis = get_vessel("thesis")
        n = 500 / 60
        x0 = js.straight_run(thesis, n=n)
        manoeuvres = (js.ZigZag(20 * DEG, 20 * DEG, duration=30.0, dt=0.1, n=n),
                      js.prbs(15 * DEG, 3.0, 23.0, n=n))
        trials = [noisy(js.Experiment.from_trajectory(js.simulate(thesis, m, x0), name=str(i)),
                        rng) for i, m in enumerate(manoeuvres)]
        vessel = js.fit(eqx_scaled(thesis, ("n_ur", "rudder_area"), 1.2), trials,
                        estimator=js.PredictionError(horizon=2.0, rudder="delta_c"),
                        free=("n_ur", "rudder_area"))
    jaxpr = str(jax.make_jaxpr(lambda w: _fit._residuals(truth, w))(
        _windows(records)))
    return dict(devices=jax.device_count(), sharded="shard_map" in jaxpr,
                nomoto=nomoto.values.tolist(), nomoto_std=nomoto.std.tolist(),
                ml=ml.values.tolist(), ml_noise=list(ml.noise.values()),
                vessel=vessel.values.tolist(), vessel_cost=float(vessel.cost))


def noisy(e, rng):
    """The experiment with white noise on psi, r [0.05 deg, 0.02 deg/s], u and v [1 mm/s]."""
    out = {c: getattr(e, c) + s * rng.standard_normal(e.num_samples)
           for c, s in (("psi", 0.05 * DEG), ("r", 0.02 * DEG), ("u", 1e-3), ("v", 1e-3))}
    return js.Experiment(e.t, e.delta, delta_c=e.delta_c, n=e.n, name=e.name, **out)


def eqx_scaled(module, names, factor):
    import equinox as eqx

    return eqx.tree_at(lambda m: [getattr(m, k) for k in names], module,
                       [float(getattr(module, k)) * factor for k in names])


def _windows(records):
    from jaxship._estimate._windows import build_windows

    ds = js.Dataset.from_experiments(records)
    return build_windows(ds, horizon=9.5, channels=("psi", "r"), weights=None)[0]


@pytest.mark.slow
def test_sharded_fits_equal_single_device():
    """The four-device run in a subprocess, beside this process' single-device run (the
    slow tier is one process: the second core would idle)."""
    flags = os.environ.get("XLA_FLAGS", "")  # the test run's compiler flags (conftest)
    env = dict(os.environ, XLA_FLAGS=f"{flags} --xla_force_host_platform_device_count=4",
               JAX_PLATFORMS="cpu", JAX_ENABLE_X64="1")
    code = textwrap.dedent(f"""
        import json, sys
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        from test_sharding import results
        json.dump(results(), sys.stdout)
    """)
    with subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True) as done:
        single = results()
        stdout, stderr = done.communicate(timeout=600)
    assert single["devices"] == 1 and not single["sharded"]
    assert done.returncode == 0, stderr[-3000:]
    four = json.loads(stdout.strip().splitlines()[-1])
    assert four["devices"] == 4 and four["sharded"]
    for key in ("nomoto", "nomoto_std", "ml", "ml_noise", "vessel", "vessel_cost"):
        np.testing.assert_allclose(four[key], single[key], rtol=1e-7, atol=0, err_msg=key)
