"""Issue 70, point 2: programs traced and lowered once per installation. The store
(`jaxship/_foundation/_exported.py`) keeps `jax.export`'s StableHLO of the fit's LM and
prediction programs; a later call loads it. A loaded program gives the same numbers bit
for bit, a damaged file or a call inside a trace falls back to the plain program, and
the key follows the static arguments and the shapes."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship._foundation import _exported


FOH = js.strategies.FirstOrderHold()


@pytest.fixture
def store(tmp_path):
    """The store on in `tmp_path`, emptied of what this process loaded; off afterwards."""
    _exported.use_store(tmp_path)
    _exported._LOADED.clear()
    yield tmp_path
    _exported.use_store(None)
    _exported._LOADED.clear()


def _experiment(seed=0):
    """Nomoto1(K=0.06, T=25) under 10-degree rudder steps every 30 s, 0.5 s samples, with
    heading noise."""
    t = np.arange(0.0, 240.0, 0.5)
    delta = np.where((t // 30.0) % 2 == 0, 1.0, -1.0) * np.deg2rad(10.0)
    tr = js.simulate(js.Nomoto1(K=0.06, T=25.0), js.Replay(delta, dt=0.5, delta_hold=FOH),
                     simulator=per_sample(20))
    rng = np.random.default_rng(seed)
    return js.Experiment(t, delta, psi=np.asarray(tr.state.psi) + rng.normal(0, 2e-3, t.size),
                         r=np.asarray(tr.state.r), name=f"steps{seed}")


def _fit():
    return js.fit(js.Nomoto1(K=0.1, T=10.0), [_experiment(0), _experiment(1)],
                  estimator=js.PredictionError(horizon=20.0))


def _same(a, b):
    for name in ("K", "T"):
        assert float(getattr(a.model, name)) == float(getattr(b.model, name))
    assert a.cost == b.cost and a.num_steps == b.num_steps
    np.testing.assert_array_equal(np.asarray(a.predictions["psi"]),
                                  np.asarray(b.predictions["psi"]))


def test_a_stored_program_gives_the_same_fit_bit_for_bit(store):
    """Off, exported (first call) and loaded from the file (a new process's path): the
    same estimates, cost, steps and predictions."""
    _exported.use_store(None)
    plain = _fit()
    _exported.use_store(store)
    exported = _fit()
    files = sorted(store.glob("*.jaxexport"))
    assert files  # the LM program
    _exported._LOADED.clear()  # as a new process: read from the files
    loaded = _fit()
    assert sorted(store.glob("*.jaxexport")) == files  # nothing exported again
    assert plain.success and exported.success
    _same(plain, exported)
    _same(plain, loaded)


def test_a_damaged_file_is_exported_again(store):
    """A truncated file is not a program: the call falls back to exporting it again and
    gives the same fit."""
    first = _fit()
    for file in store.glob("*.jaxexport"):
        file.write_bytes(file.read_bytes()[:100])
    _exported._LOADED.clear()
    again = _fit()
    _same(first, again)
    assert all(f.stat().st_size > 100 for f in store.glob("*.jaxexport"))


@jax.jit
def _double(x):
    return 2 * x


def test_the_key_follows_static_arguments_and_shapes_and_a_trace_falls_back(store):
    """One file per argument shape; a static argument that differs is another key; a call
    inside `jax.jit` (tracers) uses the plain program and stores nothing."""
    import equinox as eqx

    @_exported.persistent
    @eqx.filter_jit
    def scaled(x, factor):
        return x * factor

    np.testing.assert_array_equal(scaled(jnp.ones(3), 2.0), np.full(3, 2.0))
    np.testing.assert_array_equal(scaled(jnp.ones(3), 2.0), np.full(3, 2.0))  # loaded
    np.testing.assert_array_equal(scaled(jnp.ones(4), 2.0), np.full(4, 2.0))
    np.testing.assert_array_equal(scaled(jnp.ones(3), 3.0), np.full(3, 3.0))
    assert len(list(store.glob("*.jaxexport"))) == 3
    traced = jax.jit(lambda x: scaled(x, 5.0))(jnp.ones(2))
    np.testing.assert_array_equal(traced, np.full(2, 5.0))
    assert len(list(store.glob("*.jaxexport"))) == 3


def test_a_store_that_cannot_be_written_costs_nothing_but_time(tmp_path):
    """The store's folder is a file: the program is exported and called all the same,
    and nothing is written."""
    import equinox as eqx

    blocked = tmp_path / "not-a-folder"
    blocked.write_text("mine")
    _exported.use_store(blocked)
    try:
        @_exported.persistent
        @eqx.filter_jit
        def shifted(x, by):
            return x + by

        np.testing.assert_array_equal(shifted(jnp.zeros(2), 1.5), np.full(2, 1.5))
    finally:
        _exported.use_store(None)
    assert blocked.read_text() == "mine" and sorted(tmp_path.iterdir()) == [blocked]
