"""The package's layers (docs/architecture.md): every module imports only from its own
layer or the layers below it, there are no import cycles, no imports inside functions
(except optional dependencies), and nothing outside the package imports private names."""

import ast
import pathlib
import subprocess
import sys

import pytest


ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "jaxship"

# bottom to top: a layer is a folder of the package (the application is its top level)
LAYERS = {
    "foundation": ["_foundation"],
    "models": ["_models"],
    "simulate": ["_simulation"],
    "estimate": ["_estimate"],
    "analysis": ["_analysis"],
    # the public namespaces (effects, identification, indices, strategies, wind_loads) only
    # re-export, as __init__ does
    "application": ["_workflow", "thesis", "studies", "cli", "plotting", "__init__", "effects",
                    "identification", "indices", "strategies", "wind_loads"],
}
RANK = {name: i for i, names in enumerate(LAYERS.values()) for name in names}
PUBLIC = set(ast.literal_eval(next(  # the names of `jaxship.__all__`, read without importing
    n.value for n in ast.parse((PACKAGE / "__init__.py").read_text()).body
    if isinstance(n, ast.Assign) and n.targets[0].id == "__all__")))
# imported inside functions on purpose: optional dependencies, and the CLI's heavy imports
# deferred so that `jaxship --help` answers at once
OPTIONAL = {"pandas", "sklearn", "matplotlib", "tqdm", "shipmmg"}


def modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        yield ".".join(parts), path


def rank(module: str) -> int:
    top = module.split(".")[1] if "." in module else "__init__"
    if top not in RANK and top in PUBLIC:  # `from jaxship import fit`: the public API
        top = "__init__"
    return RANK[top]


def imports(module: str, path: pathlib.Path):
    """(imported jaxship module, line, inside a function) for every import."""
    tree = ast.parse(path.read_text())
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    functions = [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef,
                                                               ast.AsyncFunctionDef))]
    inner = {id(n) for f in functions for n in ast.walk(f)}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = package.split(".")
            if node.level:
                base = base[: len(base) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            targets = [name] if node.module else [f"{name}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        else:
            continue
        for target in targets:
            yield target, node.lineno, id(node) in inner


def test_every_module_has_a_layer():
    for module, _ in modules():
        rank(module)  # raises KeyError for a module outside the table


def test_imports_point_down_only():
    upward = []
    for module, path in modules():
        for target, line, _ in imports(module, path):
            if target.startswith("jaxship.") and rank(target) > rank(module):
                upward.append(f"{module}:{line} imports {target}")
    assert not upward, "\n".join(upward)


def test_no_import_cycles():
    graph = {}
    for module, path in modules():
        graph[module] = {t for t, _, inner in imports(module, path)
                         if t.startswith("jaxship") and not inner}
    names = set(graph)

    def resolve(target):  # "jaxship._models._steering.Nomoto1" -> its module
        while target and target not in names:
            target = target.rpartition(".")[0]
        return target

    graph = {m: {resolve(t) for t in ts} - {m, ""} for m, ts in graph.items()}
    state, cycles = {}, []

    def visit(m, stack):
        state[m] = 1
        for n in graph.get(m, ()):
            if n == "jaxship" or n.startswith("jaxship.") and n.count(".") == 0:
                continue
            if state.get(n) == 1 and n != "jaxship":
                cycles.append(" -> ".join(stack[stack.index(n):] + [n]))
            elif n not in state:
                visit(n, stack + [n])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    # the application layer imports the public package (`import jaxship as js`)
    cycles = [c for c in cycles if not c.startswith("jaxship ->") and " jaxship ->" not in c]
    assert not cycles, "\n".join(cycles)


def test_no_imports_inside_functions_but_optional_dependencies():
    found = []
    for module, path in modules():
        for target, line, inner in imports(module, path):
            if inner and target.split(".")[0] not in OPTIONAL:
                found.append(f"{module}:{line} imports {target} inside a function")
    assert not found, "\n".join(found)


# Outside the package (README, docs, notebooks, benchmarks) only public names of `jaxship`:
# the benchmarks that time the command itself may run it (its argv or `-m jaxship.cli`)
COMMAND_TIMERS = {
    "benchmarks/cli.py",  # the command's first and second runs, each a new process
    "benchmarks/discovery.py",  # `jaxship discover` end to end beside `js.discover`
    "benchmarks/gpu.py",  # the README's `discover` command on a GPU
}
COMMAND_NAMES = {"vessels", "simulate", "reproduce", "identify", "autopilot", "discover"}


def code_outside(root: pathlib.Path):
    """`(where, source)` of the Python code outside the package: benchmarks and notebook
    scripts, notebooks' code cells (IPython's `%`/`!` lines left out), and the `python`
    blocks of the README and the docs pages."""
    import json
    import re

    for path in sorted([*(root / "benchmarks").rglob("*.py"),
                        *(root / "notebooks").glob("*.py")]):
        yield str(path.relative_to(root)), path.read_text()
    for path in sorted((root / "notebooks").glob("*.ipynb")):
        cells = json.loads(path.read_text())["cells"]
        for i, cell in enumerate(c for c in cells if c["cell_type"] == "code"):
            text = "".join(cell["source"])
            yield (f"{path.relative_to(root)}:cell {i}",
                   "\n".join("" if line.lstrip()[:1] in "%!" else line
                             for line in text.splitlines()))
    for path in sorted([root / "README.md", *(root / "docs").rglob("*.md")]):
        if path.exists():
            for i, block in enumerate(re.findall(r"```python\n(.*?)```", path.read_text(),
                                                 flags=re.S)):
                yield f"{path.relative_to(root)}:block {i}", block


def _is_private(module: str) -> bool:
    """`jaxship.cli` (any of it) or a private module or name below `jaxship`."""
    parts = module.split(".")
    return parts[0] == "jaxship" and (parts[1:2] == ["cli"]
                                      or any(p.startswith("_") and not p.endswith("__")
                                             for p in parts[1:]))


def outside_offences(root: pathlib.Path = ROOT) -> list[str]:
    """Every way round the front door outside the package: an import of `jaxship.cli` or
    of a private module or name (`import jaxship._x`, `from jaxship._x import`, `from
    jaxship import _x`, `from jaxship.plotting._fits import`), a relative import, a call
    of the command's `main` (`jaxship.cli.main(argv)`, `cli.main(...)`, `main(argv)` of an
    imported `main`), and, except in `COMMAND_TIMERS`, a run of the command (`-m
    jaxship.cli`, an argv `["jaxship", "identify", ...]`); in the notebooks also an import
    of `benchmarks` or a change to `sys.path` (a notebook runs wherever jaxship is
    installed)."""
    found = []
    for where, source in code_outside(root):
        file = where.split(":")[0]
        try:
            tree = ast.parse(source)
        except SyntaxError:
            found.append(f"{where}: not Python")
            continue
        notebook = file.startswith("notebooks/")
        imported_main = False
        for node in sorted(ast.walk(tree), key=lambda n: getattr(n, "lineno", 0)):
            line = f"{where}:{getattr(node, 'lineno', 0)}"
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    found.append(f"{line} imports relatively")
                    continue
                module = node.module or ""
                names = [f"{module}.{a.name}" for a in node.names]
                if module.split(".")[0] == "jaxship" and any(a.name == "main"
                                                             for a in node.names):
                    imported_main = True
                if _is_private(module) or any(_is_private(n) for n in names):
                    found.append(f"{line} imports {module}")
                elif notebook and module.split(".")[0] == "benchmarks":
                    found.append(f"{line} imports {module}")
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if _is_private(a.name) or notebook and a.name.split(".")[0] == "benchmarks":
                        found.append(f"{line} imports {a.name}")
            elif isinstance(node, ast.Call):
                name = ast.unparse(node.func)
                if name.endswith("cli.main") or name == "main" and imported_main:
                    found.append(f"{line} calls {name}")
                elif notebook and name.startswith("sys.path."):
                    found.append(f"{line} changes sys.path")
            elif file not in COMMAND_TIMERS and isinstance(node, ast.Constant) and (
                    node.value == "jaxship.cli"):
                found.append(f"{line} runs the command (-m jaxship.cli)")
            elif file not in COMMAND_TIMERS and isinstance(node, (ast.List, ast.Tuple)):
                head = [e.value for e in node.elts[:2] if isinstance(e, ast.Constant)]
                if len(head) == 2 and head[0] == "jaxship" and head[1] in COMMAND_NAMES:
                    found.append(f"{line} runs the command (jaxship {head[1]})")
            if notebook and isinstance(node, ast.Assign) and "sys.path" in ast.unparse(node):
                found.append(f"{line} changes sys.path")
    return found


def test_nothing_outside_the_package_goes_round_the_front_door():
    """Issue 68: no notebook, docs page, README example or benchmark imports `jaxship.cli`
    or a private module, imports relatively, calls the command's `main` or runs the
    command, except the benchmarks that time the command itself (`COMMAND_TIMERS`)."""
    found = outside_offences()
    assert not found, f"{len(found)} ways round:\n" + "\n".join(found)
    files = {w.split(":")[0] for w, _ in code_outside(ROOT)}
    assert COMMAND_TIMERS <= files, COMMAND_TIMERS
    assert any(f.endswith(".ipynb") for f in files) and "README.md" in files


def test_the_checker_outside_the_package_catches_each_spelling(tmp_path, monkeypatch):
    """The checker above sees each spelling, in a benchmark, a notebook's cell and a
    docs page's `python` block; a benchmark that times the command may run it."""
    import json

    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "notebooks").mkdir()
    (tmp_path / "docs").mkdir()
    bad = ["import jaxship.cli._identification", "from jaxship.cli._compiler import x",
           "from jaxship.cli import main", "import jaxship._models",
           "from jaxship._workflow._identify import identify", "from jaxship import _workflow",
           "from jaxship.plotting._fits import f", "from .. import fit", "from . import x",
           "jaxship.cli.main(['identify'])", "cli.main(argv)", "import jaxship.cli",
           "run([sys.executable, '-m', 'jaxship.cli', 'identify'])",
           "run(['jaxship', 'identify', 'a.csv'])"]
    good = ["import jaxship as js", "from jaxship import fit, __version__",
            "from jaxship.studies import svm", "from jaxship.thesis import autopilot",
            "from jaxship.plotting import plot_trajectory", "main(parser.parse_args())",
            "run(['jaxship-other', 'x'])"]
    (tmp_path / "benchmarks" / "b.py").write_text("\n".join(bad) + "\n")
    (tmp_path / "benchmarks" / "g.py").write_text("\n".join(good) + "\n")
    (tmp_path / "benchmarks" / "cli.py").write_text(  # a command timer runs the command
        "run(['jaxship', 'simulate'])\nrun(['python', '-m', 'jaxship.cli'])\n")
    main_call = "from jaxship.cli import main\nmain(['vessels'])\n"
    (tmp_path / "benchmarks" / "m.py").write_text(main_call)
    cell = {"cell_type": "code", "metadata": {}, "outputs": [], "execution_count": None}
    notebook = {"cells": [cell | {"source": "%matplotlib inline\nimport jaxship._foundation"},
                          cell | {"source": "import sys\nsys.path.insert(0, '..')\n"
                                            "from benchmarks.studies import svm"},
                          cell | {"source": "import jaxship as js"}]}
    (tmp_path / "notebooks" / "n.ipynb").write_text(json.dumps(notebook))
    (tmp_path / "README.md").write_text("```python\nfrom jaxship._x import y\n```\n")
    (tmp_path / "docs" / "d.md").write_text("```python\nimport jaxship as js\n```\n")
    found = outside_offences(tmp_path)
    in_b = [f for f in found if f.startswith("benchmarks/b.py")]
    assert [int(f.split(":")[1].split()[0]) for f in in_b] == list(
        range(1, len(bad) + 1)), in_b
    assert not [f for f in found if f.startswith(("benchmarks/cli.py", "benchmarks/g.py"))]
    assert [f.split(" ", 1)[1] for f in found if f.startswith("benchmarks/m.py")] == [
        "imports jaxship.cli", "calls main"]
    notes = [f for f in found if f.startswith("notebooks/")]
    assert [f.split(":", 1)[1] for f in notes] == [
        "cell 0:2 imports jaxship._foundation", "cell 1:2 changes sys.path",
        "cell 1:3 imports benchmarks.studies"], notes
    assert [f for f in found if f.startswith(("README", "docs"))] == [
        "README.md:block 0:1 imports jaxship._x"]


def test_the_top_level_holds_only_the_application():
    """Library modules live in their layer's folder; the package's top level holds the
    public API and the application (docs/architecture.md)."""
    top = {p.stem for p in PACKAGE.glob("*.py")} | {p.name for p in PACKAGE.iterdir()
                                                    if (p / "__init__.py").exists()}
    library = set(top) - set(LAYERS["application"])
    assert library == {n for layer in list(LAYERS.values())[:-1] for n in layer}, library


def calls(path: pathlib.Path):
    """(dotted name, line) of every call in the module at `path`."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call):
            yield ast.unparse(node.func), node.lineno


def test_no_hasattr_in_the_package():
    """Models are told apart by the contract (`AbstractModel` and its subclasses),
    never by the attributes they happen to have."""
    found = [f"{m}:{line}" for m, path in modules() for name, line in calls(path)
             if name == "hasattr"]
    assert not found, "\n".join(found)



def test_one_assembler_builds_the_fit_result():
    """Every estimator's `fit` ends in one assembler (issue 33), `assemble_result`, which
    validates each channel and builds the `FitResult`: the class is constructed in exactly
    one place in the package (`dataclasses.replace` of a result does not count)."""
    found = [f"{m}:{line}" for m, path in modules() for name, line in calls(path)
             if name == "FitResult" or name.endswith(".FitResult")]
    assert len(found) == 1, "\n".join(found) or "FitResult is never constructed"
    assert found[0].startswith("jaxship._estimate._result:"), found


# loaded on first use only: the scipy parts cost 0.2-0.3 s each, pyplot 0.7 s
NOT_AT_IMPORT = ("scipy.special", "scipy.stats", "scipy.signal", "scipy.linalg",
                 "matplotlib", "pandas")


def test_import_computes_nothing_and_changes_no_jax_setting():
    """`import jaxship` (in a new process) loads none of the heavy optional parts, starts
    no XLA backend and leaves float64 off (the brief: nothing changed on import)."""
    code = ("import sys, jax, jaxship; from jax._src import xla_bridge; "
            f"print([m for m in {NOT_AT_IMPORT!r} if m in sys.modules], "
            "xla_bridge.backends_are_initialized(), jax.config.jax_enable_x64)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["[]", "False", "False"], done.stdout


def test_the_library_never_prints_or_warns():
    """Outcomes are result codes and progress goes to a callable the caller passes: no
    print, warnings.warn or jax.debug.print below the application layer."""
    banned = {"print", "warnings.warn", "warnings.warn_explicit", "jax.debug.print"}
    found = [f"{m}:{line} calls {name}" for m, path in modules()
             if rank(m) < RANK["cli"] or m.split(".")[1] == "plotting"
             for name, line in calls(path) if name in banned]
    assert not found, "\n".join(found)


def subclasses(cls) -> set[type]:
    """Every class of the package derived from `cls` (classes that tests define left out)."""
    found = {c for c in cls.__subclasses__() if c.__module__.startswith("jaxship")}
    return found.union(*(subclasses(c) for c in found))


def test_every_model_implements_the_one_contract():
    """Every vessel and steering model class of the package derives from the one
    contract, `jaxship.AbstractModel` (tests/test_contracts.py runs each through it)."""
    import jaxship as js

    classes = subclasses(js.AbstractSteeringModel) | subclasses(js.AbstractVessel)
    assert len(classes) >= 15
    assert all(issubclass(c, js.AbstractModel) for c in classes)


PLACES = ("AbstractRudderEffect", "AbstractLoadEffect", "AbstractYawTermEffect",
          "AbstractVesselPropertyEffect", "AbstractSensorEffect")


def test_every_effect_acts_through_the_small_classes_of_its_places():
    """The effect seam is split by where an effect acts: every public effect derives
    from at least one place class, `AbstractEffect` itself carries no hook, and a new
    effect implements one small abstract class: a yaw term written by a user (an
    offset $f = c$ in Nomoto's equation) runs on a steering model, equals a rudder
    offset of $c/K$, and one that leaves its abstract method out cannot be made."""
    from typing import ClassVar

    import numpy as np
    import pytest

    import jaxship as js

    places = tuple(getattr(js.effects, n) for n in PLACES)
    effects = [v for v in vars(js.effects).values() if isinstance(v, type)
               and issubclass(v, js.effects.AbstractEffect)
               and v is not js.effects.AbstractEffect and v not in places]
    assert len(effects) >= 20
    assert all(issubclass(e, places) for e in effects), [
        e.__name__ for e in effects if not issubclass(e, places)]
    hooks = {"rudder", "loads", "yaw_term", "mass", "environment", "wind_areas", "measure",
             "unmeasure", "initial_state", "state_rate"}
    assert not hooks & set(vars(js.effects.AbstractEffect))

    class ConstantTerm(js.effects.AbstractYawTermEffect):
        c: float = 0.0
        id: ClassVar[str] = "constant_term"

        def yaw_term(self, model, x, delta, aux):
            return self.c

    class Forgotten(js.effects.AbstractYawTermEffect):
        id: ClassVar[str] = "forgotten"

    with pytest.raises(TypeError):
        Forgotten()
    K, c = 0.06, 1e-3
    delta = np.deg2rad(10) * np.sign(np.sin(np.arange(200) / 20.0) + 1e-9)
    psi = [js.simulate(js.augment(js.Nomoto1(K=K, T=25.0), effect),
                       js.Replay(delta, dt=0.5)).state.psi
           for effect in (ConstantTerm(c=c), js.effects.RudderOffset(delta0=c / K))]
    np.testing.assert_allclose(psi[0], psi[1], rtol=1e-12, atol=1e-12)


def test_each_command_is_one_module_that_main_only_registers():
    """`jaxship/cli/<command>.py` owns its parser (`register`) and its `run`; the
    package's `main` registers them and maps errors to exit statuses."""
    from jaxship import cli

    assert {c.__name__.rsplit(".", 1)[1] for c in cli.COMMANDS} == {
        "vessels", "simulate", "reproduce", "identify", "autopilot", "discover"}
    for command in cli.COMMANDS:
        assert callable(command.register) and callable(command.run)
    main = [name for name, _ in calls(PACKAGE / "cli" / "__init__.py")]
    assert "parser.add_argument" in main and not any(
        name.endswith(".add_argument") and name != "parser.add_argument" for name in main)


def test_the_package_never_imports_the_benchmarks_nor_loads_its_studies_on_import():
    """The studies are public namespaces of the application (`jaxship.thesis`, the thesis
    study; `jaxship.studies`, the published ones), imported by name: `import jaxship`
    loads neither, and no module of the package imports `benchmarks/`."""
    found = [f"{m}:{line} imports {t}" for m, path in modules()
             for t, line, _ in imports(m, path) if t.split(".")[0] == "benchmarks"]
    assert not found, "\n".join(found)
    assert not (PACKAGE / "identification").exists()
    assert not (ROOT / "benchmarks" / "studies").exists()
    code = ("import sys, jaxship; print(sorted(m for m in sys.modules "
            "if m.split('.')[:2] in (['jaxship', 'studies'], ['jaxship', 'thesis'])))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]", done.stdout
    from jaxship.studies import astrom, discovery, published_splits, real_data, svm  # noqa: F401
    from jaxship.thesis import autopilot, discovery_case, identification  # noqa: F401


def test_the_identification_is_a_library_verb():
    """The identification the command runs is the library verb `jaxship.identify`, its
    result `jaxship.Identification` (issue 68)."""
    import jaxship as js

    assert js.identify.__module__ == "jaxship._workflow._identify.workflow"
    assert not hasattr(js, "IdentificationResult")


def test_every_public_estimator_is_accepted_by_fit_and_predict():
    """One door per verb: each estimator of the public API fits through `jaxship.fit`,
    and `jaxship.predict` of its `FitResult` with that estimator gives back the
    predictions and fit % the fit reported."""
    import jax
    import numpy as np

    import jaxship as js

    jax.config.update("jax_enable_x64", True)
    estimators = {v for v in vars(js).values() if isinstance(v, type)
                  and issubclass(v, js.AbstractEstimator) and v is not js.AbstractEstimator}
    assert estimators == {js.PredictionError, js.Innovations, js.ARMAX, js.DiscreteResponse}
    t = np.arange(0.0, 240.0, 1.0)
    delta = np.deg2rad(10.0) * np.sign(np.sin(2 * np.pi * t / 120.0))
    truth = js.simulate(js.Nomoto1(K=0.06, T=25.0),
                        js.Replay(delta, dt=1.0, delta_hold=js.strategies.FirstOrderHold()),
                        simulator=js.Simulator(max_step=float("inf"), substeps=4))
    noise = np.random.default_rng(0).standard_normal((2, t.size))
    record = js.Experiment(t, delta, psi=np.asarray(truth.state.psi) + 0.01 * noise[0],
                           r=np.asarray(truth.state.r) + 0.001 * noise[1])
    start = js.Nomoto1(K=0.05, T=20.0)
    for estimator, model in ((js.PredictionError(), start), (js.Innovations(), start),
                             (js.DiscreteResponse(), start),
                             (js.ARMAX(), js.ARMAXModel(dt=1.0))):
        result = js.fit(model, [record], estimator=estimator)
        assert result.success, (estimator, result.message)
        again = js.predict(result, [record], estimator=estimator)
        for channel, metrics in result.metrics.items():
            assert again.metrics[channel].fit_percent == pytest.approx(
                metrics.fit_percent, abs=1e-6), (estimator, channel)
    with pytest.raises(ValueError, match="needs every noise variance; missing rudder"):
        js.predict(start, [record], estimator=js.Innovations())


def test_the_public_simulation_doors_are_simulate_and_simulate_batch():
    """Two doors to simulate (issue 33): `simulate` and `simulate_batch`, for vessels and
    steering models alike, and one result type, `Trajectory` (a trial spec is a
    manoeuvre, a record replay is a manoeuvre)."""
    import jaxship as js

    doors = {name for name, obj in vars(js).items() if callable(obj) and not isinstance(obj, type)
             and name.startswith(("simulate", "steer", "run_"))}
    assert doors == {"simulate", "simulate_batch"}, doors
    results = {name for name, obj in vars(js).items() if isinstance(obj, type)
               and name.endswith("Trajectory")}
    assert results == {"Trajectory"}, results


def test_a_replay_of_a_closed_loop_run_reproduces_it():
    """The two semantics of the one door agree: a Nomoto 2 model through a rate-limited
    ZigZag (the manoeuvre sees the heading), then the same model through a `Replay` of
    that run's actual rudder. With samples every `max_step` (0.1 s) the closed loop
    takes one RK4 step per sample with the rudder held over it, which is what a
    zero-order-hold replay of the recorded rudder at one step per sample integrates: the
    headings and yaw rates agree to rounding."""
    import jax
    import numpy as np

    import jaxship as js

    jax.config.update("jax_enable_x64", True)
    model = js.Nomoto2(K=0.06, T1=25.0, T2=3.0, T3=5.0)
    deg = np.pi / 180
    zigzag = js.ZigZag(10 * deg, 10 * deg, duration=200.0, dt=0.1, rudder_rate=2.0 * deg)
    closed = js.simulate(model, zigzag)
    delta = np.asarray(closed.state.delta)
    assert np.ptp(delta) > 15 * deg  # the rudder was reversed
    assert np.max(np.abs(np.diff(delta))) <= 2.0 * deg * 0.1 + 1e-12  # at the gear's rate
    replay = js.simulate(model, js.Replay(delta, dt=0.1, delta_hold=js.strategies.ZeroOrderHold()))
    np.testing.assert_allclose(replay.state.psi, closed.state.psi, rtol=0, atol=1e-9)
    np.testing.assert_allclose(replay.state.r, closed.state.r, rtol=0, atol=1e-9)
    np.testing.assert_allclose(replay.internal, closed.internal, rtol=0, atol=1e-9)
    assert bool(replay.success) and bool(closed.success)
    np.testing.assert_array_equal(replay.state.x, 0.0)  # a response model has no track


# the public surface (issue 59): `jaxship.__all__`, the namespaces that re-export, and the
# command line that goes through them
NAMESPACES = ("effects", "identification", "indices", "plotting", "strategies", "wind_loads")
MAX_PUBLIC_NAMES = 125  # issue 68: the workflow verbs
STUDIES = ("thesis", "studies")  # public namespaces of modules, imported by name


def cli_private_imports() -> list[str]:
    """Every import in `jaxship/cli` of something that is not a public name: a private
    module or name of the library (`from jaxship._x`, `from .._x`, `from jaxship import
    _x`, `import jaxship._x`, `from ..plotting._fits`), or a name that `jaxship.__all__`
    (or a namespace's) does not list. The CLI's own modules (`jaxship.cli.*`) are its
    own; `__version__` is public."""
    import importlib

    import jaxship as js

    found = []
    for module, path in modules():
        if not module.startswith("jaxship.cli"):
            continue
        tree = ast.parse(path.read_text())
        package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")
                if node.level:
                    base = base[: len(base) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                pairs = [(source, a.name) for a in node.names]
            elif isinstance(node, ast.Import):
                pairs = [(a.name, None) for a in node.names]
            else:
                continue
            for source, name in pairs:
                if source.split(".")[0] != "jaxship" or source.startswith("jaxship.cli"):
                    continue
                parts = source.split(".")[1:]
                where = f"{path.relative_to(ROOT)}:{node.lineno}"
                if parts and parts[0] in STUDIES and not any(p.startswith("_") for p in parts):
                    continue  # the studies' public modules (`jaxship.thesis.autopilot`)
                if parts and (len(parts) > 1 or parts[0] not in NAMESPACES):
                    found.append(f"{where} imports {source}")  # a module below the surface
                    continue
                if name is None or name == "__version__":
                    continue
                exported = getattr(importlib.import_module(source), "__all__", None)
                if exported is None:  # plotting: its public functions
                    exported = [n for n in vars(importlib.import_module(source))
                                if not n.startswith("_")]
                if name not in exported or name.startswith("_"):
                    found.append(f"{where} imports {name} from {source}")
    assert js.__all__  # the public surface was read
    return found


def counts() -> dict:
    """The numbers issue 59 asks to show (`python tests/test_architecture.py` prints them)."""
    import dataclasses

    import jaxship as js

    oversized = _oversized()
    codes = {c.__name__: "result" in {f.name for f in dataclasses.fields(c)}
             for c in (js.Trajectory, js.ClosedLoop)}
    return {"public names (jaxship.__all__)": len(js.__all__),
            "string-valued strategy defaults": len(
                [1 for _, p, _ in _string_defaults() if p not in NOT_STRATEGIES]),
            "private imports from jaxship/cli": len(cli_private_imports()),
            "functions over 80 lines": sum(n > MAX_LINES for n, _ in oversized.values()),
            "functions over 8 parameters": sum(k > MAX_PARAMETERS
                                               for _, k in oversized.values()),
            "  of them on the allow-list": len(set(oversized) & set(OVER_THE_LIMITS)),
            "a result code on Trajectory, ClosedLoop": codes,
            "jaxship/cli/_studies exists": (PACKAGE / "cli" / "_studies").exists()}


def test_the_public_surface_is_all_of_at_most_110_names_without_aliases():
    """`jaxship.__all__` lists the public names, at most 110, each once, each naming
    something different (no second name for one function, as `vessel = get_vessel` was);
    after `import jaxship` (a new process) the package holds exactly those names, and
    each namespace's `__all__` names what it holds."""
    import jaxship as js

    names = js.__all__
    assert len(names) <= MAX_PUBLIC_NAMES, len(names)
    assert len(set(names)) == len(names), sorted(n for n in names if names.count(n) > 1)
    objects = {}
    for name in names:
        objects.setdefault(id(getattr(js, name)), []).append(name)
    aliases = [n for n in objects.values() if len(n) > 1]
    assert not aliases, aliases
    code = ("import jaxship, types; print(sorted(n for n, v in vars(jaxship).items() "
            "if not n.startswith('_')))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str(sorted(names))
    for space in ("effects", "identification", "indices", "strategies", "wind_loads"):
        module = getattr(js, space)
        held = {n for n, v in vars(module).items() if not n.startswith("_")}
        assert held == set(module.__all__), held ^ set(module.__all__)


def test_the_command_line_imports_only_public_names():
    """`jaxship/cli` is a layer over the public API: it imports `jaxship`'s public names
    and its own modules, nothing private of the library (the docstring of `jaxship.cli`).
    Issue 59: 46 import statements (55 names) before it; the last 15 names (the parameter
    helpers of identify's result.json, the vessel file's dict and text, the record checks
    of identify's reader) went through public doors (`AbstractModel.parameter_names`,
    `get_parameter`, `with_parameters`; `save_vessel(vessel)`'s text, `load_vessel` of a
    parsed dict; `Experiment.renamed`, `with_velocities`, `check_uniform`;
    `measurement_files`)."""
    found = cli_private_imports()
    assert not found, f"{len(found)} private imports:\n" + "\n".join(found)


def test_the_checker_of_the_command_line_catches_each_way_round_the_front_door(tmp_path,
                                                                                 monkeypatch):
    """The checker above sees every spelling of a private import (a module written into a
    copy of the tree's layout)."""
    cli = tmp_path / "jaxship" / "cli"
    cli.mkdir(parents=True)
    (cli / "__init__.py").write_text("")
    (cli / "x.py").write_text(
        "from jaxship._foundation import _params\nfrom .._estimate._fit import fit\n"
        "from jaxship import _foundation\nfrom .. import parameter_fields\n"
        "import jaxship._models\nfrom ..plotting._fits import identification_figure_names\n"
        "from jaxship import fit, __version__\nfrom ..plotting import plot_trajectory\n"
        "from ._files import staged_folder\nfrom jaxship.effects import RudderOffset\n")
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", tmp_path / "jaxship")
    found = cli_private_imports()
    assert [f.split(":")[1].split()[0] for f in found] == ["1", "2", "3", "4", "5", "6"], found


def test_the_studies_are_gone_from_the_command_line():
    """`jaxship/cli/_studies` is no more: what `reproduce` and `autopilot` run is
    `jaxship/cli/reproduction`, the other studies live in `jaxship/studies/`."""
    assert not (PACKAGE / "cli" / "_studies").exists()
    assert not list((PACKAGE / "cli").rglob("svm.py"))


# Strings that name data, not an algorithm: a parameter whose string default is one of
# these is not a strategy (issue 59: every strategy is an object carrying its algorithm)
NOT_STRATEGIES = {
    "rudder",  # the channel a record's rudder is read from ("delta" or "delta_c")
    "channel",  # a channel's name in a validation report
    "name",  # an experiment's name
    "unit",  # a parameter's unit label
    "source",  # a vessel file's citation
    "separate",  # a catalogue entry's sentence on telling it apart
    "criterion",  # FitResult: the label of what was minimised (a report, not an input)
    "basis",  # AutopilotDesign: the sentence on how its numbers were chosen
}


def _string_defaults():
    """`(public name, parameter, default)` for every str default in the signatures of the
    public names of `jaxship` (functions, classes' fields and public methods)."""
    import inspect

    import jaxship as js

    found = []
    for name in sorted(n for n in dir(js) if not n.startswith("_")):
        obj = getattr(js, name)
        targets = [(name, obj)] if callable(obj) else []
        if inspect.isclass(obj):
            targets += [(f"{name}.{m}", f) for m, f in vars(obj).items()
                        if inspect.isfunction(f) and not m.startswith("_")]
        for label, f in targets:
            try:
                parameters = inspect.signature(f).parameters.values()
            except (TypeError, ValueError):  # builtins without a signature
                continue
            found += [(label, p.name, p.default) for p in parameters
                      if isinstance(p.default, str)]
    return found


def test_no_string_valued_strategy_default():
    """Issue 59 (point 2): a strategy (a hold, a switch rule, a covariance, a criterion, a
    noise model, a unit system...) is an object, never a string the library dispatches
    on. Before: 9 string strategy defaults (Replay.delta_hold/n_hold, ZigZag.switch_at,
    prediction_bands/calibrate_disturbance.covariance, turning_indices.steady,
    write_trial_csv.units, Innovations.process/noise); now none."""
    strategies = [f"{label}({p}={d!r})" for label, p, d in _string_defaults()
                  if p not in NOT_STRATEGIES]
    assert not strategies, "\n".join(strategies)


def test_every_outcome_carries_a_result_code():
    """Issue 59 (point 3): simulate, closed_loop, tune_autopilot and fit return a `RESULTS`
    code (`success` derived from it), discover a `Verdict` code."""
    import dataclasses

    import jaxship as js
    from jaxship._analysis._autopilot import TunedAutopilot

    for result in (js.Trajectory, js.ClosedLoop, TunedAutopilot, js.FitResult):
        fields = {f.name: f.type for f in dataclasses.fields(result)}
        assert fields.get("result") in (js.RESULTS, "RESULTS") or "RESULTS" in str(
            fields.get("result")), result
        assert isinstance(vars(result).get("success") or getattr(result, "success"), property)
    verdict = {f.name: f.type for f in dataclasses.fields(js.DiscoveryReport)}["verdict"]
    assert "Verdict" in str(verdict)
    assert set(js.Verdict._name_to_item) == {"missing_effect", "nothing_missing",
                                             "cannot_judge"}


MAX_LINES, MAX_PARAMETERS = 80, 8
# functions over the limits, each with the case for it; the rest of the package holds them
OVER_THE_LIMITS = {
    # the study's settings (decimation, horizon, free coefficients, wind, substeps, the
    # solver's steps and tolerance, the Nomoto fits beside), each with a default
    "jaxship/studies/real_data.py:identify_esso_osaka": "keyword options of one study call",
    # the pole placement's keywords (bandwidth or natural_frequency, damping,
    # subtract_damping, the operating point speed and n, feedforward) and those of the
    # `HeadingAutopilot` it returns (reference, steps, limits, interval, anti-windup, wave
    # filter), each with a default: one call, as diffrax.diffeqsolve takes its options
    "jaxship/_analysis/_autopilot.py:design_autopilot": "keyword options of one call",
    # the runs tuned on (speeds or rpm, duration, dt, a disturbance), the objective's
    # rudder weight and the solver's options (max_steps, rtol, atol, simulator, throw)
    "jaxship/_analysis/_autopilot.py:tune_autopilot": "keyword options of one call",
    # the data record's constructor: one keyword per measured channel (t, delta and the
    # 13 optional channels a trial logs), as the CSV's columns
    "jaxship/_simulation/_data.py:__init__": "one keyword per measured channel",
    # optimistix's AbstractGaussNewton fields (rtol, atol, norm, descent, search, verbose)
    # and this solver's own (ftol, geodesic, damping): an equinox dataclass's __init__
    "jaxship/_estimate/_lm.py:__init__": "the solver's dataclass fields",
    # the command's reference: 66 of its 102 lines are the docstring (every option and
    # the result's JSON); the body is 31 lines of named steps. Its 12 parameters are the
    # command's options, keywords of one call
    "jaxship/_workflow/_identify/workflow.py:identify": "the docstring is the reference; "
    "keyword options of one call",
    # public calls whose options are keywords of one call, each with a default, as
    # diffrax.diffeqsolve takes its options (saveat, stepsize_controller, max_steps, ...):
    # grouping them would make each caller build an object to change one option
    "jaxship/_estimate/_kalman.py:ekf": "keyword options (noise, channels, rudder, P0, ...)",
    "jaxship/_estimate/_kalman.py:smooth_states": "keyword options, as ekf",
    "jaxship/_estimate/_bands.py:prediction_bands": "keyword options of one call",
    "jaxship/_estimate/_bands.py:calibrate_disturbance": "keyword options of one call",
    "jaxship/_analysis/_closed_loop.py:closed_loop": "keyword options of one call",
    "jaxship/_simulation/_batch.py:simulate_batch": "simulate's options, in_axes, devices",
    "jaxship/plotting/_tracks.py:plot_trajectory": "keyword options of one figure",
    # ARMAX(na, nb, nc, nk): the four orders of the model structure (Astrom & Kallstrom
    # 1979, eq. 7; MATLAB's armax(data, [na nb nc nk])) and the iteration's dt, max_iter,
    # tol, arx_order, each a keyword with a default
    "jaxship/_estimate/_armax.py:fit_armax": "the four ARMAX orders and the iteration's",
    # the innovations fit behind `Innovations.fit`: the estimator's fields as keywords
    # (criterion, process, noise, noise_start, channels, rudder, substeps, hold, solver,
    # max_steps), so that it is also called as a function
    "jaxship/_estimate/_likelihood.py:fit_ml": "the Innovations estimator's fields",
    # the windows of a prediction-error fit from the estimator's fields (horizon,
    # channels, weights, rudder, simulator, hold, wind) and the smoothed starts; tests
    # build windows without an estimator
    "jaxship/_estimate/_windows.py:build_windows": "the estimator's fields as keywords",
}


def _oversized():
    """`{"path:function": (lines, parameters)}` of the package's functions (the command
    line included) over `MAX_LINES` lines or `MAX_PARAMETERS` parameters (self and cls
    not counted; *args and **kwargs counted)."""
    found = {}
    for _, path in modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            a = node.args
            names = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
            count = len([n for n in names if n not in ("self", "cls")])
            count += (a.vararg is not None) + (a.kwarg is not None)
            lines = node.end_lineno - node.lineno + 1
            if lines > MAX_LINES or count > MAX_PARAMETERS:
                found[f"{path.relative_to(ROOT).as_posix()}:{node.name}"] = (lines, count)
    return found


def test_functions_the_size_of_one_idea():
    """Issue 59 (point 5): no function of the package over 80 lines or 8 parameters but
    those of `OVER_THE_LIMITS`, each with its case; an entry that no longer needs its
    place fails too, so the list only shrinks. Counts at issue 59's start: 12 functions
    over 80 lines, 30 over 8 parameters."""
    found = _oversized()
    new = {k: v for k, v in found.items() if k not in OVER_THE_LIMITS}
    assert not new, "over 80 lines or 8 parameters: " + ", ".join(
        f"{k} ({lines} lines, {count} parameters)" for k, (lines, count) in new.items())
    stale = sorted(set(OVER_THE_LIMITS) - set(found))
    assert not stale, f"within the limits now, take off OVER_THE_LIMITS: {stale}"


if __name__ == "__main__":
    for key, value in counts().items():
        print(f"{key}: {value}")
