"""Write notebooks/thesis_identification.ipynb.

Run: python notebooks/make_thesis_identification.py.

The notebook reproduces the identification study of the thesis (Odegard 2009, chapter 4)
on the built-in thesis vessel: Nomoto and Ross' autopilot model identified from single
and merged experiments, fit % next to the thesis' numbers. The pipeline is
`jaxship/thesis/identification.py` (`jaxship.thesis.identification`).
"""

import pathlib

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook


CELLS = [
    new_markdown_cell("""# Identification of steering models on the thesis vessel (thesis chapter 4)

Reproduction 1 of issue 3. The thesis (Odegard 2009, *Identification of Manoeuvring
Characteristics*, chapter 4) simulates turning circles at 5, 10, 20 and 40 deg, zig-zags 5/5 to
40/40 and its suggested manoeuvre, each at 200 and 500 rpm, and identifies the first-order
Nomoto model (eq. 3.2-3.3) and the autopilot model of Ross (eq. 3.6-3.7) by prediction-error
minimisation, first from single experiments (the 40 deg trial at 500 rpm, sec. 4.2), then from
the merged experiments of each family at both rates (sec. 4.3).

Here the same design is simulated with `js.get_vessel("thesis")` (the Ross-type 3-DOF model of
the 4 m DTMB 5415 model, `docs/thesis_vessel.md`; **not** the thesis' own coefficients, which
are unpublished), measurement noise is added, and three models are identified:

* **Nomoto 1** ($K$, $T$);
* **Ross** (`RossAutopilot`, eq. 3.6 without roll: 12 hull terms in $u, v, r$ with the measured
  $u$ and $v$, and Ross' rudder moment $N_\\delta u^2\\delta$; 13 parameters);
* **Ross + speed-dependent rudder** (the same plus $n^2\\delta$ for the propeller race and
  $u^2\\delta^3$, $n^2\\delta^3$ for stall; 16 parameters).

**Score.** The thesis' fit % (eq. 3.23, MATLAB `compare`): $100(1 - \\|y - \\hat y\\| /
\\|y - \\bar y\\|)$ of the **yaw rate** (the channel of figs. 4.8-4.30), $\\hat y$ simulated
from the first sample with the measured rudder (and $u$, $v$, $n$) replayed, on the 40 deg /
500 rpm record of each family, which is the record the thesis' figures show for merged fits
too. The pooled fit over all records of a family is given as well.

**Estimation.** Least-squares start, prediction error with a 10 s horizon, then output error
on $r$ (Levenberg-Marquardt, forward-mode Jacobians through RK4)."""),
    new_code_cell("""import time
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import matplotlib.pyplot as plt
from IPython.display import Markdown, display
import jaxship as js
from jaxship.thesis import identification as ti

DEG = np.pi / 180
vessel = js.get_vessel("thesis")
settings = ti.Settings()
print("records sampled at", settings.dt, "s; noise (standard deviations):")
for k, sigma in ti.NOISE.items():
    print(f"  {k:5s} {np.rad2deg(sigma) if k in ('psi', 'r', 'delta') else sigma:.3g}",
          "deg" if k in ("psi", "delta") else "deg/s" if k == "r" else "m/s")
t0 = time.time()
experiments = ti.thesis_experiments(vessel, settings=settings)
print(f"{len(experiments)} records simulated in {time.time() - t0:.0f} s")"""),
    new_code_cell("""t0 = time.time()
study = ti.identification_study(vessel, settings=settings, experiments=experiments)
print(f"identified {len(study['table'])} models in {time.time() - t0:.0f} s")
display(Markdown(ti.markdown_table(study)))"""),
    new_markdown_cell("""Measured (noisy) yaw rate and the three identified models on the record the
thesis shows (40 deg trial at 500 rpm), from single experiments (top, thesis figs.
4.8-4.18) and merged experiments (bottom, figs. 4.20-4.30)."""),
    new_code_cell("""labels = {"nomoto": "Nomoto", "ross": "Ross",
          "ross_speed_rudder": "Ross + speed rudder"}
rows = {(r["case"], r["model"], r["family"]): r for r in study["table"]}
fig, axes = plt.subplots(2, 3, figsize=(15, 7.5))
for i, case in enumerate(("single", "merged")):
    for j, family in enumerate(ti.FAMILIES):
        ax = axes[i, j]
        e = experiments[ti.record_name(ti.SHOWN[family], 500.0)]
        ax.plot(e.t, np.rad2deg(e.r), color="0.6", lw=1.0, label="measured")
        for name in ti.MODELS:
            model = study["models"][f"{case}/{name}/{family}"]
            f = rows[case, name, family]["fit"]
            r = ti.simulate_record(model, e, settings.substeps)
            text = "diverges" if f is None else f"{f:.2f} %"
            ax.plot(e.t, np.rad2deg(r), lw=1.2, label=f"{labels[name]}; fit {text}")
        thesis = ti.THESIS_FIT[case]
        ax.set_title(f"{case}, {family} (thesis: Nomoto {thesis['nomoto'][family]:.2f} %, "
                     f"Ross {thesis['ross'][family]:.2f} %)", fontsize=9)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("yaw rate (deg/s)")
        ax.legend(fontsize=7, loc="lower left")
fig.tight_layout()"""),
    new_markdown_cell("""Estimates of the merged fits (scaled coefficients of `RossAutopilot`:
$u' = u/U_0$, $v' = v/U_0$, $r' = rL/U_0$, $n' = n/n_0$ with $L = 4.002$ m,
$U_0 = 1.543$ m/s, $n_0$ = 500 rpm)."""),
    new_code_cell("""for family in ti.FAMILIES:
    for name in ("ross", "ross_speed_rudder"):
        p = study["parameters"][f"merged/{name}/{family}"]
        print(f"{family:8s} {name:18s}", "  ".join(
            f"{k}={e['value']:.3g} +- {ti.quoted_std(e):.2g}" for k, e in p.items()))"""),
    new_code_cell("""merged = [r for r in study["table"] if r["case"] == "merged"]
for name in ("ross", "ross_speed_rudder"):
    fits = {r["family"]: r["fit"] for r in merged if r["model"] == name}
    ok = all(f is not None and f >= 90.0 for f in fits.values())
    print(f"merged {labels[name]}: " + ", ".join(f"{k} {v:.2f} %" for k, v in fits.items()),
          "-> at least 90 % on every family" if ok else "-> below 90 % on some family")"""),
]


def main():
    nb = new_notebook(cells=CELLS, metadata={"kernelspec": {
        "display_name": "Python 3", "language": "python", "name": "python3"}})
    path = pathlib.Path(__file__).with_name("thesis_identification.ipynb")
    nbformat.write(nb, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
