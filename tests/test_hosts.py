"""Several hosts (issue 56, point 5): two processes on localhost joined by
`jax.distributed.initialize`, two CPU devices each, split `simulate_batch`, the sweep's
reduction and a merged fit over the four global devices; each process gets the numbers
of one process with one device."""

import json
import os
import socket
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import jax
import numpy as np
import pytest
from helpers import per_sample

import jaxship as js


DEG = np.pi / 180
ROOT = Path(__file__).parent.parent


def results() -> dict:
    """Eight Mariner zig-zags (padded to four devices' multiple: none needed), six
    turning indices from the sweep's grid (padded: 6 -> 8), and a merged Nomoto 1 fit
    of three records whose 2 x 67 windows do not divide by four."""
    from benchmarks import sweep

    vessel = js.get_vessel("mariner")
    zigzags = js.stack([js.ZigZag(a * DEG, 10 * DEG, duration=60.0, dt=0.5)
                        for a in np.linspace(-25.0, 25.0, 8)])
    traj = js.simulate_batch(vessel, zigzags, js.straight_state(np.linspace(6.0, 8.0, 8)))
    grid = SimpleNamespace(vessel="thesis", angles=3, rates=2, perturbations=1, duration=60.0)
    sv, sm, sx, _ = sweep.build(grid, 0.5)
    indices = js.simulate_batch(sv, sm, sx, in_axes=(0, 0, 0, None),
                                output=js.indices.batch_turning_indices)
    truth, start = js.Nomoto1(K=0.06, T=25.0), js.Nomoto1(K=0.04, T=15.0)
    records = []
    for k, num in enumerate((170, 230, 310)):
        delta = np.where((np.arange(num) // 40) % 2 == 0, 10.0, -10.0) * DEG * (1 + 0.2 * k)
        tr = js.simulate(truth, js.Replay(delta, dt=0.5, delta_hold=js.strategies.FirstOrderHold()),
                         simulator=per_sample())
        noise = 1e-3 * np.sin(np.arange(num) * (1.3 + k))
        records.append(js.Experiment(np.asarray(tr.t), delta,
                                     psi=np.asarray(tr.state.psi) + noise,
                                     r=np.asarray(tr.state.r), name=f"record {k}"))
    fit = js.fit(start, records, estimator=js.PredictionError(horizon=9.5))
    return dict(devices=jax.device_count(), processes=jax.process_count(),
                psi=np.asarray(traj.state.psi).tolist(),
                tactical=np.asarray(indices["tactical_diameter"]).tolist(),
                fit=np.asarray(fit.values).tolist(), cost=float(fit.cost),
                fit_result=str(fit.result))


_PROCESS = """
import json, sys
import jax
jax.config.update("jax_enable_x64", True)
jax.distributed.initialize(coordinator_address={address!r}, num_processes=2, process_id={i})
sys.path[:0] = [{tests!r}, {root!r}]
from test_hosts import results
print("RESULT " + json.dumps(results()))
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_two_processes_get_the_numbers_of_one():
    address = f"127.0.0.1:{free_port()}"
    flags = os.environ.get("XLA_FLAGS", "")  # the test run's compiler flags (conftest)
    env = dict(os.environ, XLA_FLAGS=f"{flags} --xla_force_host_platform_device_count=2",
               JAX_PLATFORMS="cpu")
    procs = [subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(_PROCESS.format(
            address=address, i=i, tests=str(Path(__file__).parent), root=str(ROOT)))],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for i in range(2)]
    single = results()
    outs = [p.communicate(timeout=600) for p in procs]
    assert single["devices"] == 1
    for p, (stdout, stderr) in zip(procs, outs):
        assert p.returncode == 0, stderr[-3000:]
        got = json.loads(next(line[7:] for line in stdout.splitlines()
                              if line.startswith("RESULT ")))
        assert got["devices"] == 4 and got["processes"] == 2
        for key in ("psi", "tactical"):
            np.testing.assert_allclose(got[key], single[key], rtol=1e-12, atol=1e-12,
                                       err_msg=key)
        np.testing.assert_allclose(got["fit"], single["fit"], rtol=1e-7, err_msg="fit")
        np.testing.assert_allclose(got["cost"], single["cost"], rtol=1e-7)
        assert got["fit_result"] == single["fit_result"]
