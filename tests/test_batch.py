"""The batching layer: vmap equals a loop, sharding equals one device, no retracing."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import equinox as eqx
import jax
import numpy as np
import pytest
from helpers import tree_allclose

import jaxship as js
import jaxship._simulation._batch as jb
from jaxship._analysis._indices import turning_indices
from jaxship._models._vessel.mariner import mariner
from jaxship._simulation._integrate import WRITTEN_OUT_BATCH


DEG = np.pi / 180
ANGLES = (5.0, 10.0, -15.0, 20.0, 25.0, -30.0)  # six runs: four devices need padding to eight
SPEEDS = np.linspace(6.0, 8.0, len(ANGLES))


def _inputs():
    vessel = mariner()
    manoeuvres = jb.stack([js.ZigZag(a * DEG, 10 * DEG, duration=60.0, dt=0.5) for a in ANGLES])
    return vessel, manoeuvres, js.straight_state(SPEEDS)


@pytest.fixture(scope="module")
def batch():
    return jb.simulate_batch(*_inputs())


def test_stack_builds_a_leading_axis_and_rejects_mismatches():
    a, b = js.ZigZag(0.1, 0.2, duration=10.0), js.ZigZag(0.3, 0.2, duration=10.0)
    s = jb.stack([a, b])
    np.testing.assert_array_equal(s.angle, [0.1, 0.3])
    assert s.num_samples == a.num_samples
    with pytest.raises(ValueError, match="structure"):
        jb.stack([a, js.ZigZag(0.3, 0.2, duration=20.0)])  # num_samples is static
    with pytest.raises(ValueError, match="at least one"):
        jb.stack([])


def test_batch_equals_python_loop(batch):
    vessel, _, _ = _inputs()
    assert batch.state.psi.shape == (len(ANGLES), 121)
    for i, (angle, speed) in enumerate(zip(ANGLES, SPEEDS)):
        man = js.ZigZag(angle * DEG, 10 * DEG, duration=60.0, dt=0.5)
        one = js.simulate(vessel, man, js.straight_state(speed))
        assert tree_allclose(jax.tree.map(lambda a: a[i], batch), one, rtol=1e-12, atol=1e-12)
    # the runs differ: the test compares something
    assert np.ptp(np.asarray(batch.state.psi[:, -1])) > 0.1


def test_a_large_batch_takes_rk4s_stages_written_out_with_the_same_numbers(monkeypatch):
    """From `WRITTEN_OUT_BATCH` runs, the default `RK4()` writes its stages out in a
    batch: the solver the batch compiles is `RK4(rolled=False)`, and its runs equal
    those of the rolled stages to rounding; a small batch keeps them rolled."""
    vessel = mariner()
    angles = np.linspace(-30.0, 30.0, WRITTEN_OUT_BATCH) * DEG
    manoeuvres = js.ZigZag(angles, 10 * DEG, duration=20.0, dt=0.5)
    x0 = js.straight_run(vessel)
    seen = []
    batched = jb._batched
    monkeypatch.setattr(jb, "_batched",
                        lambda *a: seen.append(a[4].simulator.solver) or batched(*a))
    written = jb.simulate_batch(vessel, manoeuvres, x0, in_axes=(None, 0, None, None))
    rolled = jb.simulate_batch(vessel, manoeuvres, x0, in_axes=(None, 0, None, None),
                               simulator=js.Simulator(solver=js.RK4(rolled=True)))
    assert seen == [js.RK4(rolled=False), js.RK4(rolled=True)]
    # the same arithmetic, its sums in another order, over 40 steps: rounding, as a
    # batch against its loop
    assert tree_allclose(written, rolled, rtol=1e-12, atol=1e-12)
    few = jb.simulate_batch(vessel, jb.stack([js.ZigZag(a, 10 * DEG, duration=20.0, dt=0.5)
                                             for a in angles[:2]]), x0,
                            in_axes=(None, 0, None, None))
    assert seen[-1] == js.RK4() and few.state.psi.shape[0] == 2  # a small batch stays rolled


def test_rk4_writes_its_stages_out_on_an_accelerator(monkeypatch):
    """`RK4()` (rolled=None) chooses by the backend it is traced for: the vector field
    traced once (rolled stages) on the CPU, four times (written out) on a GPU or TPU;
    `rolled=True` and `False` whatever the backend (issue 56)."""
    import diffrax as dfx
    import jax.numpy as jnp

    calls = []
    term = dfx.ODETerm(lambda t, y, args: calls.append(1) or -y)
    for backend, solver, traced in (("cpu", js.RK4(), 1), ("gpu", js.RK4(), 4),
                                    ("tpu", js.RK4(), 4), ("gpu", js.RK4(rolled=True), 1),
                                    ("cpu", js.RK4(rolled=False), 4)):
        monkeypatch.setattr(jax, "default_backend", lambda b=backend: b)
        calls.clear()
        jax.make_jaxpr(lambda y, s=solver: s.step(term, 0.0, 0.1, y, None, None, False)[0])(
            jnp.ones(2))
        assert len(calls) == traced, (backend, solver)


def test_batched_vessel_and_shared_manoeuvre():
    """A vessel batched over one coefficient (in_axes prefix), one manoeuvre for all."""
    vessel = mariner()
    factors = np.array([0.8, 1.0, 1.25])
    perturbed = eqx.tree_at(lambda v: v.n_r, vessel, vessel.n_r * factors)
    no_axes = jax.tree.map(lambda _: None, vessel)
    axes = eqx.tree_at(lambda v: v.n_r, no_axes, 0, is_leaf=lambda x: x is None)
    man, x0 = js.Turn(20 * DEG, duration=50.0, dt=0.5), js.straight_run(vessel)
    out = jb.simulate_batch(perturbed, man, x0, in_axes=(axes, None, None, None))
    for i, f in enumerate(factors):
        one = js.simulate(eqx.tree_at(lambda v: v.n_r, vessel, vessel.n_r * f), man, x0)
        np.testing.assert_allclose(out.state.r[i], one.state.r, rtol=1e-12, atol=1e-15)
    # the 0-d rule: the same with in_axes=0 on the whole vessel
    same = jb.simulate_batch(perturbed, man, x0, in_axes=(0, None, None, None))
    np.testing.assert_array_equal(same.state.r, out.state.r)


def test_inconsistent_batch_sizes_are_rejected():
    vessel, manoeuvres, _ = _inputs()
    with pytest.raises(ValueError, match="batch size"):
        jb.simulate_batch(vessel, manoeuvres, js.straight_state(np.ones(4) * 7.0))
    with pytest.raises(ValueError, match="nothing is batched"):
        jb.simulate_batch(vessel, js.Turn(0.1, duration=5.0), js.straight_run(vessel))


def test_output_and_chunks_equal_the_full_batch(batch):
    vessel, manoeuvres, x0s = _inputs()
    last = jb.simulate_batch(vessel, manoeuvres, x0s, output=lambda t: t.state.psi[-1])
    np.testing.assert_allclose(last, batch.state.psi[:, -1], rtol=1e-12, atol=1e-12)
    chunked = jb.simulate_batch(vessel, manoeuvres, x0s, chunk_size=4)
    assert tree_allclose(chunked, batch, rtol=1e-12, atol=1e-12)


def test_new_values_do_not_retrace(monkeypatch):
    counted = eqx.filter_jit(eqx.debug.assert_max_traces(jb._batched.__wrapped__, max_traces=1))
    monkeypatch.setattr(jb, "_batched", counted)
    vessel, manoeuvres, x0s = _inputs()
    for scale in (1.0, 0.5, 1.5):
        v = eqx.tree_at(lambda m: m.n_r, vessel, vessel.n_r * scale)
        m = eqx.tree_at(lambda m: m.angle, manoeuvres, manoeuvres.angle * scale)
        jb.simulate_batch(v, m, js.straight_state(SPEEDS * scale))
    assert eqx.debug.get_num_traces(counted.__wrapped__) == 1


def test_turning_indices_match_numpy_indices():
    vessel = mariner()
    rudders = np.array([15.0, 35.0, -25.0]) * DEG
    traj = jb.simulate_batch(
        vessel, js.Turn(rudders, duration=400.0, dt=0.5, execute=np.array([0.0, 10.0, 5.0])),
        js.straight_run(vessel), in_axes=(None, 0, None, None),
    )
    got = jax.jit(jb.batch_turning_indices)(traj)
    for i in range(len(rudders)):
        ref = turning_indices(jax.tree.map(lambda a: a[i], traj))
        for name in ("advance", "transfer", "tactical_diameter", "steady_turning_diameter",
                     "speed_loss", "time_to_90", "time_to_180", "execute_time"):
            np.testing.assert_allclose(got[name][i], getattr(ref, name), rtol=1e-10, err_msg=name)
    cut = jax.tree.map(lambda a: a[:, :100] if a.ndim == 2 else a, traj)  # 50 s: no 180 deg
    short = jb.batch_turning_indices(cut)
    assert np.all(np.isnan(short["tactical_diameter"]))


def test_straight_run_of_arrays_matches_straight_run_of_each():
    from jaxship._models._vessel.catalogue import get_vessel

    vessel = get_vessel("kvlcc2")
    rates = np.array([0.8, 1.0, 1.2]) * vessel.nominal_n
    got = js.straight_run(vessel, n=rates)
    for i, n in enumerate(rates):
        np.testing.assert_allclose(got.u[i], js.straight_run(vessel, n=n).u, rtol=1e-10)
    back = js.straight_run(vessel, speed=got.u)
    np.testing.assert_allclose(back.n, rates, rtol=1e-9)


_SHARDED = """
import json, sys
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
sys.path.insert(0, {tests!r})
from test_batch import _inputs
import jaxship._simulation._batch as jb
vessel, manoeuvres, x0s = _inputs()
traj = jb.simulate_batch(vessel, manoeuvres, x0s)
take = lambda tree, index: jax.tree.map(lambda a: np.asarray(a)[index], tree)
index = np.arange(8) % 6  # eight runs: no padding, the result stays split
eight = jb.simulate_batch(vessel, take(manoeuvres, index), take(x0s, index))
json.dump(dict(
    count=jax.device_count(),
    psi=np.asarray(traj.state.psi).tolist(),
    x=np.asarray(traj.state.x).tolist(),
    delta=np.asarray(traj.command.delta).tolist(),
    eight_devices=len(eight.state.psi.sharding.device_set),
    eight_psi=np.asarray(eight.state.psi).tolist(),
), sys.stdout)
"""


def test_sharded_equals_single_device(batch):
    """Four XLA host devices in a subprocess: same numbers as one device (padding 6 -> 8)."""
    flags = os.environ.get("XLA_FLAGS", "")  # the test run's compiler flags (conftest)
    env = dict(os.environ, XLA_FLAGS=f"{flags} --xla_force_host_platform_device_count=4",
               JAX_PLATFORMS="cpu", JAX_ENABLE_X64="1")
    code = textwrap.dedent(_SHARDED.format(tests=str(Path(__file__).parent)))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    got = json.loads(done.stdout)
    assert got["count"] == 4
    assert got["eight_devices"] == 4  # an even batch stays split over the devices
    for name, ref in (("psi", batch.state.psi), ("x", batch.state.x),
                      ("delta", batch.command.delta)):
        np.testing.assert_allclose(got[name], ref, rtol=1e-12, atol=1e-12, err_msg=name)
    np.testing.assert_allclose(np.asarray(got["eight_psi"])[:6], batch.state.psi,
                               rtol=1e-12, atol=1e-12)


def test_a_batch_of_steering_runs_equals_the_single_runs():
    """`simulate_batch` takes steering models too: zig-zags of a Nomoto 1 model (closed
    on its heading) and replays of rudder records, vmapped over the manoeuvres."""
    model = js.Nomoto1(K=0.06, T=25.0)
    zigzags = [js.ZigZag(a * DEG, 10 * DEG, duration=120.0, dt=0.5, rudder_rate=3 * DEG)
               for a in (10.0, -15.0, 20.0)]
    batch = jb.simulate_batch(model, jb.stack(zigzags), in_axes=(None, 0, None, None))
    records = [np.asarray(js.simulate(model, z).state.delta) for z in zigzags]
    replays = [js.Replay(d, dt=0.5, delta_hold=js.strategies.FirstOrderHold()) for d in records]
    replayed = jb.simulate_batch(model, jb.stack(replays), in_axes=(None, 0, None, None))
    for i, (z, r) in enumerate(zip(zigzags, replays)):
        for got, single in ((batch, js.simulate(model, z)), (replayed, js.simulate(model, r))):
            np.testing.assert_allclose(got.state.psi[i], single.state.psi, rtol=1e-12,
                                       atol=1e-15)
            np.testing.assert_allclose(got.internal[i], single.internal, rtol=1e-12, atol=1e-15)
