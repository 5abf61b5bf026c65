"""`jaxship reproduce`: the thesis pipeline (chapter 4) end to end on the built-in vessel.

Simulates the experiment design of the thesis (section 4.1): turning circles at 5, 10,
20 and 40 deg, zig-zags 5/5 to 40/40 and the thesis manoeuvre, each at 200 and 500
rpm, writes every trial as a trial CSV with its indices, a summary table, and the
figures that correspond to the thesis' figs. 4.2-4.7; then identifies the Nomoto and
Ross steering models from noisy records of the same design (sections 4.2-4.3,
`jaxship.studies.thesis`) and writes their fit % next to the thesis' numbers
(`identification.json`, and a table in `summary.md`).
"""

import json
import pathlib

import matplotlib.pyplot as plt
import numpy as np
from tqdm.auto import tqdm

import jaxship as js
from jaxship.plotting import plot_trajectory
from jaxship.studies.thesis import identification_study, markdown_table, to_json


TRIALS = [
    "turn:5",
    "turn:10",
    "turn:20",
    "turn:40",
    "zigzag:5/5",
    "zigzag:10/10",
    "zigzag:20/20",
    "zigzag:40/40",
    "thesis",
]
QUICK_TRIALS = ["turn:40", "zigzag:40/40", "thesis"]
RPMS = (200.0, 500.0)
# thesis figures reproduced: (trial, rpm, figure name, thesis figure)
FIGURES = [
    ("turn:40", 500.0, "turn40_500rpm", "figs. 4.2-4.3"),
    ("zigzag:40/40", 500.0, "zigzag40_500rpm", "figs. 4.4-4.5"),
    ("thesis", 500.0, "thesis_manoeuvre_500rpm", "figs. 4.6-4.7"),
    ("thesis", 200.0, "thesis_manoeuvre_200rpm", "fig. A.3x"),
]


def _file_name(spec, rpm):
    return f"{spec.replace(':', '').replace('/', '-')}_{rpm:.0f}rpm"


def reproduce(out, *, quick=False, progress=False, identification=True) -> dict:
    """Run the pipeline into the folder `out`; returns the summary {file name: indices}.

    `identification`: also run the identification study (`quick`: its reduced design,
    two trials per family)."""
    out = pathlib.Path(out)
    (out / "trials").mkdir(parents=True, exist_ok=True)
    (out / "figures").mkdir(exist_ok=True)
    vessel = js.vessel("thesis")
    jobs = [(spec, rpm) for rpm in RPMS for spec in (QUICK_TRIALS if quick else TRIALS)]
    summary, runs = {}, {}
    for spec, rpm in tqdm(jobs, desc="thesis trials", disable=not progress, unit="trial"):
        manoeuvre, traj = js.run_trial(vessel, spec, rpm=rpm, dt=0.1)
        if not bool(traj.success):
            raise RuntimeError(f"simulation of {spec} at {rpm:g} rpm failed")
        name = _file_name(spec, rpm)
        js.write_trial_csv(out / "trials" / f"{name}.csv", traj)
        summary[name] = _finite(js.trial_indices(spec, manoeuvre, traj))
        runs[(spec, rpm)] = traj
    for spec, rpm, name, thesis_figure in FIGURES:
        if (spec, rpm) in runs:
            fig = plot_trajectory(
                runs[(spec, rpm)],
                title=f"{spec} at {rpm:g} rpm (thesis {thesis_figure})",
                labels=[f"jaxship {spec}, {rpm:g} rpm"],
            )
            fig.savefig(out / "figures" / f"{name}.png", dpi=110)
            plt.close(fig)
    (out / "indices.json").write_text(json.dumps(summary, indent=2) + "\n")
    text = summary_table(summary)
    if identification:
        bar = tqdm(desc="identification", disable=not progress, unit="fit",
                   total=2 * 3 * 3)
        study = identification_study(vessel, quick=quick, progress=lambda msg: (
            bar.set_postfix_str(msg), bar.update()))
        bar.close()
        (out / "identification.json").write_text(json.dumps(to_json(study), indent=2) + "\n")
        text += ("\n## Steering models identified (thesis chapter 4)\n\nSimulation fit % of "
                 "the yaw rate (thesis eq. 3.23) on the 40 deg, 500 rpm record of each family "
                 "and pooled over the family's records; noise (SI): "
                 + ", ".join(f"{k} {v:.3g}" for k, v in study["noise"].items())
                 + ("; quick design (2 trials per family)" if quick else "") + ".\n\n"
                 + markdown_table(study))
    (out / "summary.md").write_text(text)
    if progress:
        print(text)
        print(
            f"wrote {out}/trials/*.csv, {out}/indices.json, {out}/summary.md, {out}/figures/*.png"
            + (f", {out}/identification.json" if identification else "")
        )
    return summary


def _finite(d):
    return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in d.items()}


def summary_table(summary) -> str:
    """Markdown table of the main indices of each trial."""
    cols = [
        ("max_yaw_rate_deg_s", "max r [deg/s]"),
        ("min_speed_m_s", "min U [m/s]"),
        ("max_speed_m_s", "max U [m/s]"),
        ("tactical_diameter_m", "tactical diam. [m]"),
        ("advance_m", "advance [m]"),
        ("overshoot_1_deg", "1st overshoot [deg]"),
        ("overshoot_2_deg", "2nd overshoot [deg]"),
    ]
    lines = ["| trial | " + " | ".join(c[1] for c in cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for name, ind in summary.items():
        cells = [f"{ind[k]:.2f}" if isinstance(ind.get(k), float) else "" for k, _ in cols]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
