"""Write notebooks/esso_osaka_identification.ipynb (run: python notebooks/make_esso_osaka_identification.py).

The notebook identifies the Esso Osaka 3-DOF model and Nomoto models on the FRT-DS-ESSO
random runs and validates them on held-out runs, then Nomoto models on the HSVA KVLCC2
zig-zags; the pipeline is `jaxship/studies/real_data.py`. Every cell after the first skips when
the measured data are absent.
"""

import pathlib

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook


CELLS = [
    new_markdown_cell("""# Esso Osaka: 3-DOF and Nomoto models identified on measured free-running data

Data: FRT-DS-ESSO, the Esso Osaka 3 m model sailed in the Inukai pond of Osaka University
(2020; Wakita et al. 2022, *J. Mar. Sci. Technol.* 27:772-785, doi:10.1007/s00773-021-00867-1;
licence CC BY-NC(-SA) 4.0), in `../shared/data/esso_osaka_frt` (not part of this repository;
the cells below do nothing when it is absent).

* **Training:** the "random" runs (operator-chosen rudder and propeller sequences, including
  astern propeller), except `random_06-Aug-2020_16_24_25_3`.
* **Held out** (Wakita et al.'s test runs that are manoeuvres): `random_06-Aug-2020_16_24_25_3`,
  `turn_14-Oct-2020_15_06_53`, `zigzag_31-Jul-2020_13_42_53`.
* **Models:** the `esso_osaka` preset (low-speed MMG model of the NAOE lab, coefficients of
  `NAOE-5thLab/mmg-1p1r-simulator`) with 11 free coefficients (hull linear derivatives and
  cross-flow drag, resistance ahead, rudder inflow and flow straightening), fitted by
  prediction error with a 20 s horizon on psi, r, u, v, replaying the measured rudder angle,
  propeller rate and true wind; Nomoto 1 (ARX start, then prediction error) and Nomoto 2
  (started from Nomoto 1) on psi and r.
* **Validation:** fit % per channel on the held-out runs, $100(1 - \\|y - \\hat y\\| /
  \\|y - \\bar y\\|)$, for the 20 s-ahead predictor and for free simulation of each whole run.

The records are decimated to 2 Hz (every 5th sample) to keep the notebook fast."""),
    new_code_cell("""import os
import time

import jax
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import Markdown, display

import jaxship as js


jax.config.update("jax_enable_x64", True)
from jaxship.studies.real_data import identify_esso_osaka, identify_kvlcc2_hsva


data = js.shared_data_dir()
HAVE_ESSO = data is not None and (data / "esso_osaka_frt").is_dir()
HAVE_HSVA = data is not None and (data / "kvlcc2_simman2008_hsva").is_dir()
print("Esso Osaka data:", "found" if HAVE_ESSO else "absent: its cells are skipped")
print("HSVA KVLCC2 data:", "found" if HAVE_HSVA else "absent: its cells are skipped")
if os.environ.get("CI") and not (HAVE_ESSO and HAVE_HSVA):
    raise FileNotFoundError("CI: ../shared/data must be beside the checkout")"""),
    new_markdown_cell("## Identification (3-DOF model, Nomoto 1 and 2)"),
    new_code_cell("""if HAVE_ESSO:
    t0 = time.perf_counter()
    esso = identify_esso_osaka()
    print(f"identified and validated in {time.perf_counter() - t0:.0f} s")
    for m in esso.models:
        print(m.result.summary(), end="\\n\\n")"""),
    new_markdown_cell("""## Fit % on the held-out runs

"preset (not fitted)" is the `esso_osaka` preset with the upstream coefficients, for
reference. The heading fit % of a free simulation is dominated by the heading drift of a
long run."""),
    new_code_cell("""if HAVE_ESSO:
    display(Markdown(esso.table()))
    # the slow test tier runs this notebook, and this is its test of the 3-DOF fit: it
    # simulates the held-out runs better than the preset in every channel and predicts
    # them 20 s ahead better in psi, r and v (not in u: the fit trades surge accuracy
    # over short windows for the steering channels, 78.7 % against the preset's 87.8 %)
    fitted = esso.models[0]
    # the optimiser converged, but by their robust (HAC) errors these runs leave y_r (61 %)
    # and gamma_p (110 %) undetermined: the fit says so, poorly_determined (issue 72)
    assert fitted.result.result == js.RESULTS.poorly_determined, fitted.result.message
    assert [f.split(" ")[0] for f in fitted.result.parameters.undetermined] == ["y_r",
                                                                                 "gamma_p"]
    for key, channels in (("simulation", ("psi", "r", "u", "v")),
                          ("T_p = 20 s", ("psi", "r", "v"))):
        for c in channels:
            assert (fitted.validation[key].metrics[c].fit_percent
                    > esso.baseline[key].metrics[c].fit_percent), (key, c)"""),
    new_markdown_cell("## Measured and predicted, held-out runs (3-DOF model)"),
    new_code_cell("""UNITS = {"psi": ("deg", np.rad2deg), "r": ("deg/s", np.rad2deg), "u": ("m/s", lambda a: a),
         "v": ("m/s", lambda a: a)}

def plot_runs(report, label, channels, predictors):
    model = next(m for m in report.models if m.label == label)
    first = model.validation[predictors[0]]
    runs = first.experiment_names
    fig, axes = plt.subplots(len(channels), len(runs), figsize=(5 * len(runs), 2.2 * len(channels)),
                             squeeze=False, sharex="col")
    for j, run in enumerate(runs):
        for i, c in enumerate(channels):
            ax = axes[i, j]
            unit, f = UNITS[c]
            for predictor in predictors:
                pred = model.validation[predictor]
                hit = pred.predicted[j]
                y = pred.predictions[c][j]
                ax.plot(np.flatnonzero(hit), f(y[hit]), lw=0.9, label=f"{label}, {predictor}")
            ax.set_ylabel(f"{c} [{unit}]")
            if i == 0:
                ax.set_title(run, fontsize=9)
    return fig, axes

def add_measured(axes, runs, channels):
    for j, e in enumerate(runs):
        for i, c in enumerate(channels):
            unit, f = UNITS[c]
            axes[i, j].plot(np.arange(e.num_samples), f(getattr(e, c)), "k", lw=0.6, alpha=0.6,
                            label="measured", zorder=0)
            axes[-1, j].set_xlabel("sample")
    axes[0, 0].legend(fontsize=7)

if HAVE_ESSO:
    from jaxship.studies.real_data import esso_osaka_split
    _, test = esso_osaka_split()
    fig, axes = plot_runs(esso, "3-DOF esso_osaka", ("psi", "r", "u", "v"),
                          ("T_p = 20 s", "simulation"))
    add_measured(axes, test, ("psi", "r", "u", "v"))
    fig.tight_layout()"""),
    new_markdown_cell("## Measured and predicted, held-out runs (Nomoto 2)"),
    new_code_cell("""if HAVE_ESSO:
    fig, axes = plot_runs(esso, "Nomoto2", ("psi", "r"), ("T_p = 20 s", "simulation"))
    add_measured(axes, test, ("psi", "r"))
    fig.tight_layout()"""),
    new_markdown_cell("""## KVLCC2 (HSVA zig-zags, SIMMAN 2008): Nomoto 1 and 2

Output error (free simulation) on the 10/10 and 20/10 port-first and 15/5 zig-zags,
validated by simulating the starboard-first 10/10 and 20/10 and the 10/5 and 20/5 zig-zags
(model scale, decimated to 5 Hz)."""),
    new_code_cell("""if HAVE_HSVA:
    kv = identify_kvlcc2_hsva()
    for m in kv.models:
        print(m.result.summary(), end="\\n\\n")
    display(Markdown(kv.table()))
    from jaxship.studies.real_data import hsva_split
    _, kv_test = hsva_split()
    fig, axes = plot_runs(kv, "Nomoto2", ("psi", "r"), ("simulation",))
    add_measured(axes, kv_test, ("psi", "r"))
    fig.tight_layout()"""),
]


def main():
    nb = new_notebook(cells=CELLS, metadata={
        "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
        "language_info": {"name": "python"},
    })
    path = pathlib.Path(__file__).with_name("esso_osaka_identification.ipynb")
    nbformat.write(nb, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
