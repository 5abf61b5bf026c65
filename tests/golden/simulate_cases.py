"""The cases of `tests/golden/simulate.json`: `jaxship simulate` runs whose key numbers
(every value of `indices.json`, the text of `criteria.md`, the SHA-256 of `trial.csv`)
must stay the same (issue 68: the command a shell over the library, same numbers).

Written at commit 91cbe21 (before the trials moved into the library) with
`python tests/golden/simulate_cases.py tests/golden/simulate.json`, run from a checkout
of that commit (`git worktree add /tmp/base 91cbe21`; this file copied there; the
temporary folder in the heading of the band case's `criteria.md` then written `TMP`);
`tests/test_simulate_golden.py` reruns the cases and compares.
"""

import hashlib
import json
import pathlib
import sys
import tempfile


# a result.json of the thesis vessel with standard errors and a correlation: the IMO
# check's band (its parameter draws from the covariance D C D)
THESIS_RESULT = {
    "model": "thesis",
    "parameters": {"n_ur": {"value": None, "std": None}, "y_uv": {"value": None, "std": None}},
    "correlation": {"names": ["n_ur", "y_uv"], "matrix": [[1.0, 0.3], [0.3, 1.0]]},
}
CASES = {
    "thesis imo": ["--vessel", "thesis", "--manoeuvre", "imo"],
    "thesis imo band": ["--vessel", "RESULT", "--manoeuvre", "imo"],
    "mariner imo": ["--vessel", "mariner", "--manoeuvre", "imo"],
    "thesis turn:35": ["--vessel", "thesis", "--manoeuvre", "turn:35"],
    "thesis zigzag:20/20": ["--vessel", "thesis", "--manoeuvre", "zigzag:20/20"],
    "thesis spiral": ["--vessel", "thesis", "--manoeuvre", "spiral"],
    "thesis stop": ["--vessel", "thesis", "--manoeuvre", "stop"],
    "mariner zigzag:10/10": ["--vessel", "mariner", "--manoeuvre", "zigzag:10/10"],
}


def thesis_result(folder) -> str:
    """`THESIS_RESULT` with the preset's values and standard errors of 2 % written out."""
    import jaxship as js

    vessel = js.get_vessel("thesis")
    report = json.loads(json.dumps(THESIS_RESULT))
    for name, entry in report["parameters"].items():
        value = float(getattr(vessel, name))
        entry.update(value=value, std=0.02 * abs(value))
    path = pathlib.Path(folder) / "result.json"
    path.write_text(json.dumps(report))
    return str(path)


def run_case(argv, folder) -> dict:
    """The key numbers of `jaxship simulate argv --out folder`."""
    from jaxship.cli import main

    out = pathlib.Path(folder) / "out"
    argv = [thesis_result(folder) if a == "RESULT" else a for a in argv]
    code = main(["simulate", *argv, "--out", str(out)])
    found = {"exit": code, "indices": json.loads((out / "indices.json").read_text())}
    if (out / "criteria.md").exists():  # its heading names the result file: its folder out
        found["criteria_md"] = (out / "criteria.md").read_text().replace(str(folder), "TMP")
    if (out / "trial.csv").exists():
        found["trial_csv_sha256"] = hashlib.sha256((out / "trial.csv").read_bytes()).hexdigest()
    return found


def run_all() -> dict:
    found = {}
    for name, argv in CASES.items():
        with tempfile.TemporaryDirectory() as folder:
            found[name] = run_case(argv, folder)
    return found


if __name__ == "__main__":
    import subprocess

    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                            check=True).stdout.strip()
    import importlib.metadata

    golden = {"how": __doc__.strip(), "commit": commit,
              "jaxlib": importlib.metadata.version("jaxlib"), "cases": run_all()}
    pathlib.Path(sys.argv[1]).write_text(json.dumps(golden, indent=1) + "\n")
