"""Write notebooks/published_splits.ipynb (run: python notebooks/make_published_splits.py,
then execute it with `jupyter nbconvert --to notebook --execute --inplace
notebooks/published_splits.ipynb`).

The notebook puts the lab's simulator for the Esso Osaka 3 m model (as published, and with
jaxship's wind loads) beside `jaxship identify --model esso_osaka` on Miyauchi et al.'s
Train-R. It scores both on every
test run of the two papers' published splits, and plots the measured and simulated tracks,
yaw rates and headings. The whole table over all training sets is
`benchmarks/published_splits.py`.
"""

import pathlib

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook


CELLS = [
    new_markdown_cell("""# Esso Osaka on the data owners' published splits: the lab's model against jaxship

Data: FRT-DS-ESSO, the Esso Osaka 3 m model sailed free in the Inukai pond of Osaka
University (2020), in `../shared/data/esso_osaka_frt` (licence CC BY-NC(-SA) 4.0, not part
of this repository). Its upstream README fixes the training and test runs of two papers by
the lab that recorded it:

* **Miyauchi et al. 2022** (*J. Mar. Sci. Technol.* 27:1065-1083, low-speed MMG model by
  CMA-ES): test runs random `16_24_25_3`, turn `14_50_41`, zig-zag `14_10_05` and two
  berthing runs;
* **Wakita et al. 2022** (*J. Mar. Sci. Technol.* 27:772-785, recurrent network): test runs
  random `16_24_25_3`, turn `15_06_53`, zig-zag `13_42_53` and three berthing runs.

The lists live in one place, `jaxship/studies/published_splits.py` (`SPLITS`).

* **The lab's simulator,** two ways: as published (`lab (Fujiwara wind)`: the lab's MMG
  coefficients, `reference/MMG_params_EssoOsaka3m.csv`, with Fujiwara et al.'s wind loads),
  and with jaxship's generic wind loads (`lab (jaxship wind)`). Every goal is judged
  against the stronger of the two on each run.
* **jaxship:** `jaxship identify --model esso_osaka` on Miyauchi's **Train-R** (random runs
  `_1`, `_4`, `_5`, `_6`) with no option. Its defaults (prediction horizon, sample interval,
  free coefficients, wind model) were chosen by `benchmarks/published_splits.py` by
  leave-one-run-out cross-validation on these four runs, without opening a test run.
* **Score:** a free simulation of each whole test run from its first measured state,
  replaying the logged rudder angle, propeller rate and true wind, at the logged 10 Hz
  (`free_run_score`): RMSE of r and psi, mean and final distance between the simulated and
  measured positions, and fit % of r.
* **One source:** the benchmark writes `benchmarks/results/published_splits.json`; this
  notebook recomputes the Train-R column and checks it against that file."""),
    new_code_cell("""import json
import os
import pathlib
import time

import jax
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import Markdown, display

import jaxship as js


jax.config.update("jax_enable_x64", True)
plt.rcParams["figure.dpi"] = 80  # eight wide figures: the notebook stays under 1 MB
from jaxship.studies import published_splits as protocol
from jaxship.studies.published_splits import SPLITS, free_run, run_score


data = js.shared_data_dir()
HAVE = data is not None and (data / "esso_osaka_frt").is_dir()
print("Esso Osaka data:", "found" if HAVE else "absent: the cells below do nothing")
if os.environ.get("CI") and not HAVE:
    raise FileNotFoundError("CI: ../shared/data must be beside the checkout")
# what benchmarks/published_splits.py recorded (in a checkout of the repository)
RECORDED = pathlib.Path.cwd().parent / "benchmarks" / "results" / "published_splits.json"
recorded = json.loads(RECORDED.read_text()) if RECORDED.is_file() else None
print("recorded results:", "../benchmarks/results/published_splits.json" if recorded
      else "absent (not a checkout)")"""),
    new_markdown_cell("## The splits"),
    new_code_cell("""rows = ["| paper | set | runs |", "|---|---|---|"]
for paper, split in SPLITS.items():
    for name, runs in split.items():
        rows.append(f"| {paper} | {name} | {len(runs)}: " + ", ".join(runs[:6])
                    + (", ..." if len(runs) > 6 else "") + " |")
display(Markdown("\\n".join(rows)))"""),
    new_markdown_cell("""## The choice, made on Train-R only

Each candidate was fitted on three of Train-R's runs and scored on the fourth, four times
over; the score is the held-out r RMSE as a share of the lab's coefficients' on that run.
The search starts from the command's settings and tries each factor in turn. (Recorded by
`benchmarks/published_splits.py`: about half an hour, so not rerun here.)"""),
    new_code_cell("""if recorded:
    display(Markdown(protocol.tables({"selection": recorded["selection"]})))
    print("chosen:", protocol.key(recorded["selection"]["chosen"]))
print("jaxship identify's defaults for esso_osaka:", js.VESSELS["esso_osaka"].fit_settings)"""),
    new_markdown_cell("## `js.identify(\"esso_osaka\", ...)` on Train-R, no option"),
    new_code_cell("""if HAVE:
    t0 = time.perf_counter()
    reader = protocol.Reader()
    fitted, code = protocol.identify(reader, SPLITS["Miyauchi 2022"]["Train-R"], None)
    print(f"exit {code}, {time.perf_counter() - t0:.0f} s")
    # exit 3: the optimiser converged, but by their robust (HAC) errors the training runs
    # leave some coefficients undetermined, which the fit now says (issue 72)
    assert code == 3"""),
    new_markdown_cell("""## Every test run of both papers, free simulation

The r cut is the reduction of the yaw-rate RMSE against the stronger lab column on that
run. Issue 58's goal is a cut of at least 40 % on each non-berthing run, and psi and
position errors no worse than the lab's."""),
    new_code_cell("""if HAVE:
    names = list(dict.fromkeys(SPLITS["Miyauchi 2022"]["Test"] + SPLITS["Wakita 2022"]["Test"]))
    test = reader.runs(names)
    models = {**{k: protocol.lab(w) for k, w in protocol.LABS.items()},
              "jaxship, Train-R": fitted}
    sims = {k: [free_run(m, run) for run in test] for k, m in models.items()}
    scores = {k: [run_score(run, sim) for run, sim in zip(test, sims[k])] for k in models}
    rows = ["| test run | in | model | r RMSE [deg/s] | r cut | psi RMSE [deg] | "
            "position error mean / final [m] | r fit % |", "|---|---|---|---|---|---|---|---|"]
    for i, run in enumerate(test):
        papers = " + ".join(p.split()[0] for p, s in SPLITS.items() if run.name in s["Test"])
        lab = min(scores[k][i].rmse["r"] for k in protocol.LABS)
        for k in models:
            s = scores[k][i]
            cut = "" if k in protocol.LABS else f"{100 * (1 - s.rmse['r'] / lab):.0f} %"
            rows.append(f"| {run.name} | {papers} | {k} | {np.degrees(s.rmse['r']):.3f} | {cut} | "
                        f"{np.degrees(s.rmse['psi']):.1f} | {s.position_mean:.1f} / "
                        f"{s.position_final:.1f} | {s.fit_percent['r']:.1f} |")
    display(Markdown("\\n".join(rows)))"""),
    new_markdown_cell("""The slow test tier runs this notebook. It checks that the user's command gives the
numbers the results file (and so the documentation) carries, run for run, and states the
goal with the measured figures."""),
    new_code_cell("""if HAVE and recorded:
    block = recorded["headline"]["Miyauchi 2022"]
    mine = {s.run: s for s in scores["jaxship, Train-R"]}
    for row in block["columns"]["Train-R"]:
        measured = mine[row["run"]].rmse["r"]
        assert abs(measured / row["r"] - 1) < 0.02, (row["run"], measured, row["r"])
    goal = block["goals"]["Train-R"]
    cuts = ", ".join(f"{100 * c:.0f} %" for c in goal["r_cut"])
    print(f"r RMSE cut on Miyauchi's three non-berthing test runs: {cuts}; goal (>= 40 % "
          f"on each): {'met' if goal['r_cut_met'] else 'NOT met'}")
    worse = {m: r for m, r in goal["worse_than_lab"].items() if r}
    print("psi and mean position no worse than the lab's on any: "
          + ("met" if not worse else f"NOT met ({worse})"))
    assert goal["r_cut_met"] == (min(goal["r_cut"]) >= protocol.GOAL_CUT)"""),
    new_markdown_cell("""## Measured and simulated, every test run

Track (north against east), yaw rate and heading. Both models start from the first
measured state and see only the logged rudder, propeller and wind from then on."""),
    new_code_cell("""def plot_run(i):
    run = test[i]
    fig, (track, rate, heading) = plt.subplots(1, 3, figsize=(14, 3.8), layout="constrained",
                                               gridspec_kw={"width_ratios": [1.1, 1.6, 1.6]})
    track.plot(run.y, run.x, "k", lw=1.2, label="measured")
    rate.plot(run.t, np.degrees(run.r), "k", lw=0.8, label="measured")
    heading.plot(run.t, np.degrees(run.psi), "k", lw=1.2, label="measured")
    for k, colour in zip(models, ("C1", "C3", "C0")):
        sim, s = sims[k][i], scores[k][i]
        label = f"{k} (r RMSE {np.degrees(s.rmse['r']):.2f} deg/s)"
        track.plot(sim["y"], sim["x"], colour, lw=1.0, label=k)
        rate.plot(sim["t"], np.degrees(sim["r"]), colour, lw=0.8, alpha=0.85, label=label)
        heading.plot(sim["t"], np.degrees(sim["psi"]), colour, lw=1.0, label=k)
    track.plot(run.y[0], run.x[0], "ko", ms=4)
    track.set(xlabel="east [m]", ylabel="north [m]", title="track")
    track.set_aspect("equal", adjustable="datalim")
    rate.set(xlabel="time [s]", ylabel="r [deg/s]", title="yaw rate")
    heading.set(xlabel="time [s]", ylabel="psi [deg]", title="heading")
    fig.legend(*rate.get_legend_handles_labels(), loc="outside lower center", ncol=3,
               fontsize=8, frameon=False)
    fig.suptitle(run.name, fontsize=10)

if HAVE:
    for i in range(len(test)):
        plot_run(i)"""),
    new_markdown_cell("""## The berthing runs

The berthing runs were sailed with the bow and stern thrusters, whose commands are not in
the logs. Every model here, the lab's included, is fed only the rudder, the propeller and
the wind, so in these runs it misses a side force and a yaw moment that the operator used
to push the ship sideways at almost no speed: their errors measure what the thrusters did,
not the hull model. They are reported as measured and left out of the goal."""),
]


def main():
    nb = new_notebook(cells=CELLS, metadata={
        "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
        "language_info": {"name": "python"},
    })
    path = pathlib.Path(__file__).with_name("published_splits.ipynb")
    nbformat.write(nb, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
