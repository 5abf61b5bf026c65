"""The README works as written: its two commands, its ten-line example (run), every example
of its command table (parsed by the `jaxship` parser, the names in it checked, the cheap
ones run) and its links."""

import os
import pathlib
import re
import shlex
import subprocess
import sys

import pytest

import jaxship.cli as cli
from jaxship._models._vessel.catalogue import get_vessel
from jaxship.cli import main
from jaxship.cli._identification import MODELS
from jaxship.cli._trials import TrialSpec


ROOT = pathlib.Path(__file__).parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
COMMANDS = {"pip install . && jaxship reproduce --out out/reproduce",
            'pip install ".[test]" && python -m pytest -q'}


def block(language: str, after: str = "") -> str:
    """The first ```language block of the README after the text `after`."""
    text = README[README.index(after):] if after else README
    return text.split(f"```{language}\n", 1)[1].split("```", 1)[0]


def table_rows() -> list[tuple[str, str]]:
    """(command, example) of every row of the command table."""
    rows = []
    for line in README.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 4 and cells[0].startswith("`") and cells[1].startswith("`jaxship "):
            rows.append((cells[0].strip("`"), cells[1].strip("`")))
    return rows


def argv_of(example: str) -> list[list[str]]:
    """The argument lists an example stands for: `[--flag]` with and without the flag,
    placeholders (`$1`, `TRAIN...`) as file names."""
    variants = [example]
    for optional in re.findall(r"\[([^\]]+)\]", example):
        variants = [v.replace(f"[{optional}]", o) for v in variants for o in ("", optional)]
    found = []
    for v in variants:
        words = shlex.split(v.replace("TRAIN...", "train1.csv train2.csv")
                            .replace("TEST...", "test1.csv"))
        assert words[0] == "jaxship", v
        found.append([re.sub(r"^\$(\d)$", r"record\1.csv", w) for w in words[1:]])
    return found


def test_the_two_commands_open_the_readme():
    """CI (`.ci/run`) and users copy these two lines; they stay byte for byte."""
    lines = {line for line in block("bash").splitlines() if not line.startswith("#")}
    assert lines == COMMANDS
    assert README.index("```bash") < README.index("## ")


def test_the_example_runs_as_written(tmp_path):
    """The ten-line example, in a new process as a user runs it."""
    code = block("python", after="## Example")
    assert len(code.strip().splitlines()) <= 10, code
    env = os.environ | {"PYTHONPATH": os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "Nomoto1 fitted to 1 experiment(s)" in done.stdout, done.stdout
    assert ": successful," in done.stdout, done.stdout


def test_the_table_has_every_command():
    names = [command for command, _ in table_rows()]
    assert sorted(names) == sorted(m.__name__.rsplit(".", 1)[1] for m in cli.COMMANDS)
    assert all(example.split()[1] == command for command, example in table_rows())


@pytest.mark.parametrize("argv", [argv for _, example in table_rows()
                                  for argv in argv_of(example)], ids=" ".join)
def test_every_table_example_parses(argv, monkeypatch):
    """Each example goes through `jaxship`'s own parser (the command's work replaced by a
    recorder), and the vessel, manoeuvre and model it names exist."""
    seen = []
    for module in cli.COMMANDS:
        monkeypatch.setattr(module, "run", lambda args: seen.append(args) or 0)
    assert main(argv) == 0
    (args,) = seen
    assert args.command == argv[0]
    if getattr(args, "vessel", None):
        get_vessel(args.vessel)
    if getattr(args, "manoeuvre", None):
        TrialSpec.parse(args.manoeuvre)
    if args.command in ("identify", "discover"):
        assert args.model in MODELS, args.model


def test_the_manoeuvres_the_readme_names_parse():
    sentence = README.split("`--manoeuvre` takes", 1)[1].split("(", 1)[0]
    forms = re.findall(r"`([a-z0-9-]+(?::[-0-9/]+)?)`", sentence)
    assert len(forms) >= 5, sentence
    for form in forms:
        TrialSpec.parse(form)


def test_the_cheap_examples_run(tmp_path, capsys):
    assert main(["vessels"]) == 0
    (argv,) = argv_of(dict(table_rows())["simulate"])
    argv[argv.index("--out") + 1] = str(tmp_path / "zz")
    assert main(argv) == 0
    assert {"trial.csv", "indices.json", "trial.png"} <= {p.name for p in
                                                          (tmp_path / "zz").iterdir()}


def test_the_links_resolve():
    links = re.findall(r"\]\(([^)#]+)\)", README)
    assert {"docs/results.md", "docs/architecture.md", "notebooks/",
            "benchmarks/README.md"} <= set(links)
    for link in links:
        if "://" not in link:
            assert (ROOT / link).exists(), link
