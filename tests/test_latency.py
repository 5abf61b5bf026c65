"""Issue 70: the everyday job's latency. The command loads matplotlib only to draw
figures; a fit's progress reaches the caller without a host callback in the compiled
program (the same iterates, and a program JAX's persistent cache can keep), so a second
run of the README's identify example compiles nothing (counted with JAX's own log of
persistent-cache misses) and traces its LM and prediction programs only once per
installation (`jax.export`, `_foundation/_exported.py`). Timings are
`benchmarks/latency.py`'s, never asserted here."""

import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from helpers import per_sample

import jaxship as js
from jaxship._estimate import _fit


ROOT = pathlib.Path(__file__).resolve().parents[1]
DATA = pathlib.Path(os.environ.get("JAXSHIP_DATA", ROOT.parent / "shared" / "data"))
FOH = js.strategies.FirstOrderHold()


def _record(path, *, noise=0.0, seed=0):
    """A trial CSV of Nomoto1(K=0.06, T=25) under 10-degree rudder steps every 30 s (0.5 s
    samples), with heading noise of `noise` rad."""
    t = np.arange(0.0, 300.0, 0.5)
    delta = np.where((t // 30.0) % 2 == 0, 1.0, -1.0) * np.deg2rad(10.0)
    tr = js.simulate(js.Nomoto1(K=0.06, T=25.0), js.Replay(delta, dt=0.5, delta_hold=FOH),
                     simulator=per_sample(20))
    rng = np.random.default_rng(seed)
    experiment = js.Experiment(t, delta, psi=np.asarray(tr.state.psi)
                               + rng.normal(0.0, noise, t.size),
                               r=np.asarray(tr.state.r) + rng.normal(0.0, noise / 10, t.size),
                               name=path.stem)
    if path.suffix == ".csv":
        js.write_trial_csv(path, experiment)
    return experiment


# `jaxship.cli.main(argv)` in a new process; prints its status and whether matplotlib
# was imported
_MAIN = ("import sys; from jaxship.cli import main; code = main(sys.argv[1:]); "
         "print(code, any(m.split('.')[0] == 'matplotlib' for m in sys.modules))")


@pytest.mark.parametrize("figures", [False, True])
def test_identify_imports_matplotlib_only_to_draw_figures(tmp_path, figures):
    """`jaxship identify --no-figures` never imports matplotlib; with figures it does
    (the check sees it)."""
    record = _record(tmp_path / "a.csv") and str(tmp_path / "a.csv")
    argv = ["identify", record, "--model", "nomoto1", "--quiet", "--out", str(tmp_path / "o")]
    done = subprocess.run([sys.executable, "-c", _MAIN, *argv]
                          + ([] if figures else ["--no-figures"]), capture_output=True,
                          text=True, cwd=ROOT, timeout=600,
                          env=dict(os.environ, JAXSHIP_CACHE_DIR=str(tmp_path / "cache")))
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[-2:] == ["0", str(figures)], done.stdout


@pytest.mark.parametrize("max_steps, options", [
    (256, {}), (3, {}),
    # the start of every window estimated (block-wise steps), with geodesic acceleration
    (256, dict(initial=js.EstimatedStarts(), solver=js.LevenbergMarquardt(
        rtol=1e-9, atol=1e-9, ftol=1e-10, geodesic=True))),
], ids=["converged", "max_steps", "estimated-starts-geodesic"])
def test_progress_reports_parts_of_the_same_run(monkeypatch, max_steps, options):
    """A fit with a progress callable runs its optimiser in parts (here of 2 steps) and
    reports between them: the same steps, estimates, cost, covariance and outcome, bit
    for bit, as the fit without one (run in one compiled loop); a fit stopped by
    `max_steps` says so in both."""
    monkeypatch.setattr(_fit, "PROGRESS_STEPS", 2)
    data = _record(pathlib.Path("noisy"), noise=0.01)
    estimator = js.PredictionError(horizon=20.0, max_steps=max_steps, **options)
    start = js.Nomoto1(K=0.02, T=60.0)
    plain = js.fit(start, data, estimator=estimator)
    events = []
    shown = js.fit(start, data, estimator=estimator, progress=events.append)
    assert plain.num_steps == shown.num_steps and plain.num_steps >= 3
    assert plain.code == shown.code
    assert (plain.code == js.RESULTS.successful) == (max_steps == 256), plain.message
    np.testing.assert_array_equal(shown.values, plain.values)
    np.testing.assert_array_equal(shown.covariance, plain.covariance)
    if plain.start_offsets is not None:
        np.testing.assert_array_equal(shown.start_offsets, plain.start_offsets)
    assert shown.cost == plain.cost
    steps = [e.step for e in events if not e.done]
    assert steps == [0] + sorted(set(range(2, plain.num_steps, 2)) | {plain.num_steps})
    assert events[-1].done and events[-1].step == plain.num_steps
    assert events[-1].cost == plain.cost


# the README's identify example in a new process, `--no-figures` (figures compile no
# XLA program); prints the modules JAX's persistent cache missed (each compiled by XLA)
_COUNT = """
import json, logging, sys
import jax
misses, traced = [], []
class Log(logging.Handler):
    def emit(self, record):
        message = record.getMessage()
        if message.startswith("PERSISTENT COMPILATION CACHE MISS"):
            misses.append(record.args[0])
        elif message.startswith("Finished tracing "):  # "Finished tracing NAME for jit"
            traced.append(message.split()[2])
for name in ("jax._src.compiler", "jax._src.dispatch"):
    logger = logging.getLogger(name)
    logger.setLevel(logging.DEBUG)
    logger.addHandler(Log())
from jaxship.cli import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "misses": misses, "traced": traced}))
"""


@pytest.mark.skipif(not (DATA / "esso_osaka_frt").is_dir(), reason="no $JAXSHIP_DATA")
def test_a_second_run_of_the_identify_example_compiles_nothing(tmp_path):
    """Two runs of `jaxship identify $1 $2 $3 --model nomoto1 --horizon 10 --validate $4
    $5` in new processes sharing a compilation cache: the first compiles (and its LM
    program, free of host callbacks, is stored), the second compiles nothing. Before
    issue 70 the second compiled the LM program again (it held the progress callback)."""
    files = sorted(str(p) for p in (DATA / "esso_osaka_frt" / "zigzag").glob("*.csv"))[:5]
    argv = ["identify", *files[:3], "--model", "nomoto1", "--horizon", "10", "--validate",
            *files[3:], "--no-figures", "--out", str(tmp_path / "out")]
    env = dict(os.environ, JAXSHIP_CACHE_DIR=str(tmp_path / "cache"))
    runs = []
    for _ in range(2):
        done = subprocess.run([sys.executable, "-c", _COUNT, *argv], capture_output=True,
                              text=True, cwd=ROOT, timeout=900, env=env)
        assert done.returncode == 0, done.stderr
        runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    assert runs[0]["code"] == 0 and runs[0]["misses"], runs[0]
    assert runs[1]["misses"] == [], runs[1]["misses"]
    # point 2: the LM and prediction programs are traced once per installation (the
    # first run exports them), and the second run loads them
    programs = {"_solve", "_predict_jit"}
    assert programs <= set(runs[0]["traced"]), runs[0]["traced"]
    assert not programs & set(runs[1]["traced"]), runs[1]["traced"]
    assert len(list((tmp_path / "cache" / "exported").glob("*.jaxexport"))) >= 2


def test_a_second_run_of_the_simulate_and_autopilot_examples_compiles_nothing(tmp_path):
    """The README's `simulate` and `autopilot` rows, each run twice in new processes
    sharing a compilation cache: the second run of each compiles nothing (issue 70's
    goal for every README example; `identify`'s is the test above, `discover` and
    `reproduce` are left to `benchmarks/cli.py`'s second-run column)."""
    from jaxship.cli import main

    assert main(["simulate", "--vessel", "thesis", "--manoeuvre", "zigzag:20/20", "--rpm",
                 "400", "--out", str(tmp_path / "trial")]) == 0
    assert main(["identify", str(tmp_path / "trial" / "trial.csv"), "--model", "nomoto1",
                 "--no-figures", "--quiet", "--out", str(tmp_path / "fit")]) == 0
    examples = {
        "simulate": ["simulate", "--vessel", "mariner", "--manoeuvre", "zigzag:20/20",
                     "--out", str(tmp_path / "zz")],
        "autopilot": ["autopilot", "--model", str(tmp_path / "fit" / "result.json"),
                      "--vessel", "thesis", "--rpm", "300", "400", "--quiet", "--out",
                      str(tmp_path / "ap")]}
    env = dict(os.environ, JAXSHIP_CACHE_DIR=str(tmp_path / "cache"))
    for name, argv in examples.items():
        runs = []
        for _ in range(2):
            done = subprocess.run([sys.executable, "-c", _COUNT, *argv], capture_output=True,
                                  text=True, cwd=ROOT, timeout=900, env=env)
            assert done.returncode == 0, (name, done.stderr)
            runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
        assert runs[0]["code"] == 0 and runs[0]["misses"], (name, runs[0])
        assert runs[1]["misses"] == [], (name, runs[1]["misses"])
