"""The README works as written: its two commands, its ten-line example (run), every example
of its command table (parsed by the `jaxship` parser, the names in it checked, the cheap
ones run) and its links."""

import json
import math
import os
import pathlib
import re
import shlex
import subprocess
import sys

import pytest

import jaxship as js
import jaxship.cli as cli
from jaxship._models._vessel.catalogue import get_vessel
from jaxship.cli import main
from jaxship.identification import MODELS


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


def test_the_example_runs_in_float32(tmp_path):
    """The example without its `jax_enable_x64` line (JAX's default float32): before,
    `fit` refused jaxship's own simulation as "sampling is not uniform" (a tolerance below
    float32's spacing of the time stamps); now it converges (issue 57)."""
    code = block("python", after="## Example")
    lines = [line for line in code.splitlines() if "jax_enable_x64" not in line]
    assert len(lines) == len(code.splitlines()) - 1
    env = os.environ | {"PYTHONPATH": os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    env.pop("JAX_ENABLE_X64", None)
    done = subprocess.run([sys.executable, "-c", "\n".join(lines)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "Nomoto1 fitted to 1 experiment(s)" in done.stdout, done.stdout
    assert ": successful," in done.stdout, done.stdout


def test_the_table_has_every_command():
    names = {command for command, _ in table_rows()}  # a command may have more rows
    assert names == {m.__name__.rsplit(".", 1)[1] for m in cli.COMMANDS}
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
    if getattr(args, "vessel", None) and not args.vessel.endswith(("result.json", ".toml")):
        get_vessel(args.vessel)
    if getattr(args, "manoeuvre", None) and args.manoeuvre != "imo":
        js.StandardTrial.parse(args.manoeuvre)
    if args.command in ("identify", "discover"):
        assert args.model in MODELS, args.model


def test_the_manoeuvres_the_readme_names_parse():
    sentence = README.split("`--manoeuvre` takes", 1)[1].split("(", 1)[0]
    forms = re.findall(r"`([a-z0-9-]+(?::[-0-9/]+)?)`", sentence)
    assert len(forms) >= 5, sentence
    for form in forms:
        js.StandardTrial.parse(form)


def test_the_cheap_examples_run(tmp_path, capsys):
    assert main(["vessels"]) == 0
    (argv,) = argv_of(next(e for c, e in table_rows() if c == "simulate"))
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


def exit_statuses() -> dict[int, str]:
    """{status: meaning} of the README's exit-status table."""
    text = README.split("## Exit statuses", 1)[1].split("\n## ", 1)[0]
    rows = (line.strip().strip("|").split("|", 1) for line in text.splitlines()
            if re.match(r"^\| \d+ \|", line))
    return {int(status): meaning.strip().rstrip("|").strip() for status, meaning in rows}


def test_the_exit_statuses_hold_as_written(tmp_path, capsys, monkeypatch):
    """Each row of the README's exit-status table, its own clauses checked through
    `main`: 2 (one line on stderr, nothing written), 3 (results written, the reason on
    stderr), 1 (a file system failure), 130 (earlier results left as they were), 0."""
    import jaxship as js

    table = exit_statuses()
    assert set(table) == {0, 1, 2, 3, 130}
    model = js.Nomoto1(K=0.05, T=10.0)
    zigzag = js.simulate(model, js.ZigZag(10 * math.pi / 180, 10 * math.pi / 180,
                                          duration=200.0, dt=1.0))
    record = tmp_path / "zigzag.csv"
    js.write_trial_csv(record, js.Experiment.from_trajectory(zigzag))
    identify = ["identify", str(record), "--model", "nomoto1", "--no-figures", "--quiet"]

    def run(args):
        code = main(args)
        return code, capsys.readouterr().err

    assert "one line on stderr" in table[2] and "nothing written" in table[2]
    code, err = run([*identify[:1], str(tmp_path / "missing.csv"), *identify[2:],
                     "--out", str(tmp_path / "bad")])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "missing.csv" in err
    assert not (tmp_path / "bad").exists()

    assert "did not converge" in table[3] and "results written, the reason on stderr" in table[3]
    code, err = run([*identify, "--max-steps", "1", "--out", str(tmp_path / "short")])
    assert code == 3 and "not a converged estimate" in err
    assert json.loads((tmp_path / "short" / "result.json").read_text())["fit"]["code"] != \
        "successful"

    assert table[0] == "done"
    earlier = tmp_path / "earlier"
    code, _ = run([*identify, "--out", str(earlier)])
    assert code == 0
    before = {p: p.read_bytes() for p in earlier.rglob("*") if p.is_file()}

    assert "earlier results left as they were" in table[130]
    monkeypatch.setattr("jaxship.cli.identify.identify",
                        lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt))
    code, err = run([*identify, "--out", str(earlier)])
    assert code == 130 and "interrupted" in err
    assert {p: p.read_bytes() for p in earlier.rglob("*") if p.is_file()} == before

    assert "the file system failed while writing" in table[1]
    monkeypatch.undo()
    monkeypatch.setattr("jaxship.cli.identify.staged_folder", _disk_full)
    code, err = run([*identify, "--out", str(earlier)])
    assert code == 1 and "No space left on device" in err
    assert {p: p.read_bytes() for p in earlier.rglob("*") if p.is_file()} == before


def _disk_full(*args, **kwargs):
    raise OSError(28, "No space left on device")
