"""`jaxship reproduce`: the thesis (Odegard 2009, seed 000) end to end on the built-in
thesis vessel, written up as `report.md` with the thesis' numbers beside ours.

1. **Trials** (thesis sec. 4.1): turning circles at 5, 10, 20 and 40 deg, zig-zags 5/5
   to 40/40 and the thesis manoeuvre, each at 200 and 500 rpm (`trials/*.csv`,
   `indices.json`), with what the thesis' figs. 4.2-4.7 state about them.
2. **Identification** (chapter 4, `jaxship.cli.reproduction.thesis`): Nomoto and Ross models from
   the single 40 deg / 500 rpm record of each family and from the merged records
   (200 + 500 rpm) of each family; their yaw-rate fit % next to the fit % in the
   legends of the thesis' figs. 4.8-4.30 (`identification.json`).
3. **Heading autopilot** (chapter 5, `jaxship.cli.reproduction.autopilot_thesis`): a PID
   with reference feed-forward from each merged model, run on the vessel at 300 and 400 rpm;
   our residuals next to the thesis' Tables 5.2-5.7 (`autopilot.json`).
4. **Discovery** (`jaxship.discover`): a synthetic Nomoto case with cubic yaw damping
   hidden, as the discovery tests use it (`jaxship.thesis.discovery_case`;
   `discovery.json`).

The trials are those of chapter 4's experiment design (`thesis.simulate_design`), so
the identification fits noisy records of the very trials the report shows. `report.md`
embeds the figures (`figures/*.png`) and explains each large difference from the
thesis in a sentence; `run.json` holds the timings. The discovery case and one trial
family of chapter 4 run in a second process (2 cores; compiling dominates). `quick`:
the reduced design of `QUICK_FAMILIES`, `QUICK_MODELS` and `QUICK_CASES` (CI runs it).
"""

import contextlib
import ctypes
import dataclasses
import json
import multiprocessing
import os
import pathlib
import platform
import signal
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import resource_tracker

import jax
import numpy as np
from tqdm import tqdm  # the terminal bar (tqdm.auto warns in a kernel without ipywidgets)

import jaxship as js

from ...thesis import autopilot as chapter5, identification as thesis
from ...thesis.discovery_case import hidden_effect_records
from .._files import staged_folder
from .reproduce_report import (
    DISCOVERY_HIDDEN,
    DISCOVERY_SEED,
    THESIS_FIGURE,
    autopilot_section,
    discovery_figure,
    discovery_section,
    header,
    identification_section,
    left_out,
    trials_section,
)


RPMS = thesis.RPMS  # 200 and 500 rpm
# the quick design: one trial per family (the 40 deg one, at both rates), the merged
# experiments only and two models in chapter 4, one discovery iteration
QUICK_FAMILIES = {"turning": ("turn:40",), "zigzag": ("zigzag:40/40",), "thesis": ("thesis",)}
QUICK_MODELS = ("nomoto", "ross")
QUICK_CASES = ("merged",)


def _file_name(spec, rpm):
    return f"{spec.replace(':', '').replace('/', '-')}_{rpm:.0f}rpm"


class _Stage:
    """A tqdm bar fed by a study's progress messages (each message starts a step); as a
    context, filled on success and closed as it stands after an error or Ctrl-C (so
    that nothing redraws it after the command's last line)."""

    def __init__(self, desc, total, enabled):
        self.bar = tqdm(desc=desc, total=total, disable=not enabled, unit="step")
        self.started = False

    def __call__(self, message):
        if self.started:
            self.bar.update()
        self.started = True
        self.bar.set_postfix_str(str(message)[:60])

    def __enter__(self):
        return self

    def __exit__(self, kind, error, traceback):
        if kind is None and self.bar.total is not None:
            self.bar.update(max(self.bar.total - self.bar.n, 0))
        elif kind is None and self.started:
            self.bar.update()
        self.bar.close()


def reproduce(out, *, quick=False, progress=False, identification=True,
              closed_loop=True, discover=True, parallel=True) -> dict:
    """Run the pipeline into the folder `out` and write `out/report.md`; returns the
    JSON-ready results `{"indices", "identification", "autopilot", "discovery", "run"}`
    (the stages not run are None).

    `quick`: the 40 deg trial of each family (3 per rate), the merged experiments with
    the Nomoto and Ross models in chapter 4, one discovery iteration. `identification`,
    `closed_loop` (needs `identification`), `discover`: run those stages; `parallel`:
    the discovery and one family of chapter 4 in a second process alongside the rest.
    `progress`: tqdm bars on stderr. Written whole: into a temporary folder inside
    `out` whose entries replace those of `out` at the end (nothing after an error)."""
    out = pathlib.Path(out)
    with staged_folder(out) as stage:
        results = _run(stage, quick, progress, identification, closed_loop, discover,
                       parallel)
    if progress:
        tqdm.write(f"wrote {out}/report.md ({results['run']['seconds']:.0f} s), beside it "
                   + ", ".join(f"{k}.json" for k, v in results.items() if v is not None)
                   + ", figures/*.png and trials/*.csv")
    return results


@dataclasses.dataclass
class _Ledger:
    """What `reproduce`'s stages give: wall and CPU seconds per stage, the JSON results,
    the report's sections and the CPU time of the second process' jobs."""

    timings: dict = dataclasses.field(default_factory=dict)
    cpu: dict = dataclasses.field(default_factory=dict)
    results: dict = dataclasses.field(default_factory=dict)
    sections: list = dataclasses.field(default_factory=list)
    second_cpu: float = 0.0

    def done(self, name, clock) -> None:
        """Stage `name`, begun at `clock` (wall, CPU), has ended."""
        self.timings[name] = time.perf_counter() - clock[0]
        self.cpu[name] = time.process_time() - clock[1]


def _clock():
    return time.perf_counter(), time.process_time()


def _run(out, quick, progress, identification, closed_loop, discover, parallel) -> dict:
    """`reproduce` into the folder `out`."""
    (out / "trials").mkdir(parents=True, exist_ok=True)
    (out / "figures").mkdir(exist_ok=True)
    load = os.getloadavg()[0] if sys.platform != "win32" else None
    began, cpu0 = _clock()
    ledger = _Ledger()
    vessel = js.get_vessel("thesis")
    families = QUICK_FAMILIES if quick else thesis.FAMILIES
    worker = _Worker() if parallel and (discover or identification) else None
    discovery_job = worker.submit(_discovery_job, quick, str(out)) if worker and discover \
        else None
    if discovery_job is not None and progress:
        tqdm.write("discovery: started in a second process")
    try:
        clock = _clock()
        design, indices = _trials(vessel, families, out, progress)
        ledger.sections.append(trials_section(indices, out, design))
        ledger.results["indices"] = indices
        ledger.done("trials", clock)
        study = None
        if identification:
            clock = _clock()
            study, experiments, extra = _identification(vessel, design, families, quick,
                                                        progress, worker)
            ledger.second_cpu += extra
            ledger.results["identification"] = _identification_json(study)
            ledger.sections.append(identification_section(study, experiments, out, quick))
            ledger.done("identification", clock)
        if identification and closed_loop:
            _autopilot_stage(vessel, study, out, quick, progress, ledger)
        if discover:
            _discovery_stage(quick, out, progress, (worker, discovery_job), ledger)
    except BaseException:  # Ctrl-C or an error: do not wait for the second process' job
        if worker is not None:
            worker.close(wait=False)
        raise
    if worker is not None:
        worker.close()
    results = ledger.results
    results["run"] = {
        "quick": bool(quick), "seconds": time.perf_counter() - began,
        "cpu_seconds": time.process_time() - cpu0 + ledger.second_cpu,
        "second_process": worker is not None, "stages_seconds": ledger.timings,
        "stages_cpu_seconds": ledger.cpu, "cpu_count": os.cpu_count(),
        "load_average_at_start": load, "jaxship": js.__version__,
        "python": platform.python_version(),
    }
    _write_results(out, results)
    stages = [k for k in ("trials", "identification", "autopilot", "discovery")
              if k in ledger.timings]
    text = header(results["run"], quick, len(indices) // len(RPMS), stages)
    text += "\n".join(ledger.sections) + left_out(quick, identification, closed_loop, discover)
    (out / "report.md").write_text(text)
    return results


def _autopilot_stage(vessel, study, out, quick, progress, ledger: _Ledger) -> None:
    """Chapter 5: the autopilots designed on the identified models, in closed loop."""
    clock = _clock()
    with _Stage("chapter 5: closed loop", 2 * 3 + 1, progress) as stage:
        evaluation = chapter5.autopilot_study(vessel, identification=study, progress=stage)
    ledger.results["autopilot"] = chapter5.to_json(evaluation)
    ledger.sections.append(autopilot_section(evaluation, study, out, quick))
    ledger.done("autopilot", clock)


def _discovery_stage(quick, out, progress, job, ledger: _Ledger) -> None:
    """The discovery case, here or (`job = (worker, submitted)`, submitted not None) the
    result of the second process, whose own run time is then the stage's and the wait
    for it a stage of its own."""
    worker, discovery_job = job
    clock = _clock()
    with _Stage("discovery", None, progress) as stage:
        here = lambda: _discovery(quick, out, stage)
        if discovery_job is not None:
            worker.listen("discovery", stage)
            data = worker.result(discovery_job, here)
            ledger.second_cpu += data["case"]["cpu_seconds"]
        else:
            data = here()
    ledger.results["discovery"] = data
    ledger.sections.append(discovery_section(data))
    ledger.done("discovery", clock)
    if discovery_job is not None:  # its own run, in parallel; and the wait for it
        ledger.timings["waiting for the discovery"] = ledger.timings["discovery"]
        ledger.timings["discovery"] = data["case"]["seconds"]
        ledger.cpu["discovery"] = data["case"]["cpu_seconds"]


def _write_results(out, results) -> None:
    """Each stage's JSON file (None for a stage not run: no file)."""
    for name in ("indices", "identification", "autopilot", "discovery", "run"):
        results.setdefault(name, None)
        if results[name] is not None:
            (out / f"{name}.json").write_text(json.dumps(results[name], indent=2) + "\n")


# ----------------------------------------------------------------------------- stages


def _finite(d):
    return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in d.items()}


def _trials(vessel, families, out, progress):
    """Simulate the experiment design of chapter 4 (no noise); write the trial CSVs;
    returns the design and the indices `{file name: indices}` (200 rpm first)."""
    with _Stage("thesis trials", len(RPMS) * sum(map(len, families.values())),
                progress) as stage:
        design = thesis.simulate_design(vessel, families=families, progress=stage)
    indices = {}
    for family, spec, rpm, manoeuvre, traj in sorted(design.values(), key=lambda d: d[2]):
        name = _file_name(spec, rpm)
        js.write_trial_csv(out / "trials" / f"{name}.csv", traj)
        indices[name] = _finite(js.StandardTrial.parse(spec).indices(manoeuvre, traj))
    return design, indices


def _identification(vessel, design, families, quick, progress, worker):
    """Chapter 4 on noisy records of the trials; the last family in `worker` (if any)."""
    models = QUICK_MODELS if quick else thesis.MODELS
    cases = QUICK_CASES if quick else ("single", "merged")
    with _Stage("chapter 4: identification", len(cases) * len(families) * len(models),
                progress) as stage:
        experiments = thesis.noisy_records(design)
        here, there, future = dict(families), {}, None
        if worker is not None and len(families) > 1:
            name = list(families)[-1]
            there = {name: here.pop(name)}
            records = {k: e for k, e in experiments.items() if dict(e.metadata)["family"] == name}
            future = worker.submit(_identification_job, records, there, models, cases)
            worker.listen("identification", stage)
        say = (lambda message: (stage(message), worker.poll())) if future else stage
        run = lambda part, report: thesis.identification_study(
            vessel, experiments=experiments, progress=report, families=part, models=models,
            cases=cases)
        parts = [run(here, say)]
        if there:
            parts.append(worker.result(future, lambda: run(there, stage)))
    second_cpu = sum(p.get("cpu_seconds", 0.0) for p in parts)
    study = _combine(parts, families, models, cases) | {"quick": bool(quick)}
    return study, experiments, second_cpu


def _identification_json(study):
    data = thesis.to_json(study)
    for row in data["table"]:
        key = (row["case"], row["model"], row["family"])
        row["thesis_figure"] = THESIS_FIGURE.get(key)
    data["sign_flips"] = thesis.sign_flips(study["parameters"])
    return data


def _discovery(quick, out, say=None) -> dict:
    """The discovery case: `{"case": ..., **DiscoveryReport.to_dict()}`; draws
    `figures/discovery_holdout.png` into `out`. `say`: progress messages, or None."""
    say = say or (lambda message: None)
    clock, cpu = time.perf_counter(), time.process_time()
    base = js.Nomoto1(K=0.06, T=25.0)  # as `discovery.run_case`
    hidden = js.effects.YawCubicDamping(beta=DISCOVERY_HIDDEN)
    say("simulating the records")
    train, holdout = hidden_effect_records(js.augment(base, hidden), DISCOVERY_SEED)
    report = js.discover(js.Nomoto1(K=0.05, T=20.0), train, holdout,
                         options=js.DiscoveryOptions(max_effects=1 if quick else 3),
                         progress=say)
    say("drawing the held-out records")
    discovery_figure(report, holdout, pathlib.Path(out) / "figures" / "discovery_holdout.png")
    case = {"truth": "Nomoto1(K=0.06 1/s, T=25 s) + YawCubicDamping(beta=300)",
            "hidden": {"id": "yaw_cubic_damping", "beta": DISCOVERY_HIDDEN},
            "start": "Nomoto1(K=0.05, T=20)", "seed": DISCOVERY_SEED,
            "train": [e.name for e in train], "holdout": [e.name for e in holdout],
            "max_effects": 1 if quick else 3, "seconds": time.perf_counter() - clock,
            "cpu_seconds": time.process_time() - cpu}
    return {"case": case, **report.to_dict()}


_QUEUE = None  # in the second process: where its progress messages go


def _start_worker(queue, x64, cache, parent):
    # the worker dies with its parent (Linux: PR_SET_PDEATHSIG = 1), so that a parent
    # killed with SIGKILL leaves no orphan writing into its results; a parent that died
    # while this process was still importing is gone already (it was reparented): end
    # now. Ctrl-C is the parent's to handle (it ends the pool)
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)
    if os.getppid() != parent:
        os._exit(1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    global _QUEUE
    _QUEUE = queue
    jax.config.update("jax_enable_x64", x64)  # as the parent (the CLI: float64)
    if cache:  # the parent's compilation cache
        js.enable_compilation_cache(cache)


def _discovery_job(quick, out):
    return _discovery(quick, out, lambda message: _QUEUE.put(("discovery", message)))


def _identification_job(experiments, families, models, cases):
    cpu = time.process_time()
    study = thesis.identification_study(
        experiments=experiments, families=families, models=models, cases=cases,
        progress=lambda message: _QUEUE.put(("identification", message)))
    return study | {"cpu_seconds": time.process_time() - cpu}


class _Worker:
    """A second process (spawned: JAX does not survive a fork) for the jobs that run on
    the second core alongside the main line: the discovery case and one trial family of
    chapter 4 (compiling dominates both, and it does not share a core). Its progress
    messages come back tagged with their stage."""

    def __init__(self):
        _start_quiet_resource_tracker()
        context = multiprocessing.get_context("spawn")
        self.queue = context.Queue()
        self.pool = ProcessPoolExecutor(1, mp_context=context, initializer=_start_worker,
                                        initargs=(self.queue, bool(jax.config.jax_enable_x64),
                                                  jax.config.jax_compilation_cache_dir,
                                                  os.getpid()))
        self.pending, self.listeners = [], {}

    def submit(self, job, *args):
        """The future of `job(*args)` there, or None when no process can start."""
        try:
            return self.pool.submit(job, *args)
        except (OSError, BrokenProcessPool):
            return None

    def listen(self, tag, say):
        """Pass the messages of stage `tag` (and those already received) to `say`."""
        self.listeners[tag] = say
        self.poll()

    def poll(self):
        while not self.queue.empty():
            self.pending.append(self.queue.get())
        keep = []
        for tag, message in self.pending:
            if tag in self.listeners:
                self.listeners[tag](message)
            else:
                keep.append((tag, message))
        self.pending = keep

    def result(self, future, here):
        """The result of `future`, passing on progress meanwhile; `here()` if the
        process failed or never started."""
        if future is not None:
            while not future.done():
                self.poll()
                time.sleep(0.2)
            self.poll()
            try:
                return future.result()
            except BrokenProcessPool:
                pass
        return here()

    def close(self, wait: bool = True):
        """End the process: after its job, or at once (`wait=False`: killed, before the
        semaphores it shares are unlinked, which a process still starting would meet
        with a traceback)."""
        if not wait:  # `kill_workers` is Python 3.14's; the pool's processes until then
            for process in list(getattr(self.pool, "_processes", {}).values()):
                process.kill()
                process.join(1.0)
        self.pool.shutdown(wait=wait, cancel_futures=True)


def _start_quiet_resource_tracker():
    """Start multiprocessing's resource tracker (the process that unlinks the pool's
    semaphores when this one ends without its finalizers, as after Ctrl-C: `os._exit`)
    with its warnings off: it would report those semaphores as leaked while it cleans
    them up. No-op if it runs already."""
    options = list(sys.warnoptions)
    sys.warnoptions.append("ignore::UserWarning")  # passed on to the tracker's command line
    try:
        resource_tracker.ensure_running()
    finally:
        sys.warnoptions[:] = options


def _combine(parts, families, models, cases) -> dict:
    """One identification study from studies of parts of the families."""
    order = [(c, f, m) for c in cases for f in families for m in models]
    study = {k: v for k, v in parts[0].items() if k != "cpu_seconds"}
    study["table"] = sorted((r for p in parts for r in p["table"]),
                            key=lambda r: order.index((r["case"], r["family"], r["model"])))
    for key in ("parameters", "models"):
        study[key] = {k: v for p in parts for k, v in p[key].items()}
    study["records"] = sorted({r for p in parts for r in p["records"]})
    return study


# ----------------------------------------------------------------------------- report
