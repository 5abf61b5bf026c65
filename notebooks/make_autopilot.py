"""Write notebooks/autopilot.ipynb.

Run: python notebooks/make_autopilot.py (then execute it, e.g. `jupyter nbconvert --to
notebook --execute --inplace notebooks/autopilot.ipynb`).

The notebook reproduces the heading-autopilot study of the thesis (Odegard 2009, chapter
5) on the built-in thesis vessel: the merged chapter-4 models (Nomoto and Ross, from
turning circles, zig-zags and the thesis manoeuvre) each give a PID with reference
feed-forward that steers the true vessel at 300 and 400 rpm; the residuals next to the
thesis' Tables 5.2-5.7 and the closed-loop figures (thesis figs. 5.1-5.6). The pipeline
is `jaxship/thesis/autopilot.py` (`jaxship.thesis.autopilot`).
"""

import pathlib

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook


CELLS = [
    new_markdown_cell("""# Heading autopilot on the thesis vessel (thesis chapter 5)

The thesis (Odegard 2009, chapter 5) puts its identified steering models to work: each gives a
PID heading autopilot with a reference feed-forward (eq. 5.1),

$$\\delta_c = \\delta_{ff}(r_d, \\dot r_d) + K_p\\tilde\\psi + K_d\\tilde r
+ K_i\\int\\tilde\\psi\\,dt,$$

with gains by pole placement, $K_p = m\\omega_n^2$, $K_d = 2\\zeta\\omega_n m - d$,
$K_i = \\omega_n K_p/10$ (eq. 5.3-5.5, $m$ and $d$ of the model's linearised yaw equation
$m\\dot r + dr = \\delta$), the feed-forward by inverting the model along the reference
(eq. 5.2 for Nomoto, $\\delta_{ff} = (T\\dot r_d + r_d)/K$; eq. 5.6 for Ross), and the
third-order reference model of Table 5.1 (a 45 deg step at 100 s, damping 1.0, natural
frequency 0.2 rad/s). The models are those identified from the **merged** experiments at 200
and 500 rpm (chapter 4, sec. 4.3); the closed loop runs at **300 and 400 rpm**, speeds not
used for the fits.

Here the same chain runs on `js.get_vessel("thesis")` (the true vessel steered, rudder 45 deg and
15 deg/s through its servo; not the thesis' own coefficients, which are unpublished), with the
models of `jaxship/thesis/identification.py` (the chapter-4 pipeline).

* **Controller frequency.** The thesis gives the reference model's $\\omega$ and $\\zeta$ but
  not the controller's. We use $\\omega_n$ = 0.5 rad/s and $\\zeta$ = 1: faster than the
  reference it tracks (2.5 times), slower than the rudder servo it does not model (1 s time
  constant, 15 deg/s), and critically damped like the reference. The gains are designed once,
  about the straight run at 350 rpm, and kept at both speeds.
* **Score.** The thesis' closed-loop residual, eq. 3.19: $\\sum_k|\\psi_d(t_k) - \\psi(t_k)|$
  in **degrees, sampled every 1 s over 100-200 s**. The thesis states neither the unit nor the
  sampling, so its Tables 5.2-5.7 compare by ordering and ratios, not absolute size.
* **Controllers.** `pid+ff` is the thesis' controller; `pid` the same gains without the
  feed-forward; "the vessel itself" designs on the true vessel's yaw equation (what a
  perfect identification would give)."""),
    new_code_cell("""import time

import jax
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import Markdown, display

import jaxship as js
from jaxship.plotting import plot_autopilot
from jaxship.thesis import autopilot as ap


jax.config.update("jax_enable_x64", True)
vessel = js.get_vessel("thesis")
design = js.AutopilotDesign()
print(f"controller: omega_n = {design.natural_frequency} rad/s, zeta = {design.damping}; "
      f"reference: omega = {design.reference_frequency} rad/s, zeta = "
      f"{design.reference_damping}; step {design.step} deg at {design.step_time} s")
print(f"rudder limits: {np.rad2deg(vessel.rudder.max_angle):.0f} deg, "
      f"{np.rad2deg(vessel.rudder.max_rate):.0f} deg/s")
t0 = time.time()
study = ap.autopilot_study(vessel, design=design)
print(f"identified 6 models and ran {len(study['table']) + len(study['reference'])} closed "
      f"loops in {time.time() - t0:.0f} s")"""),
    new_markdown_cell("""## Tables 5.2-5.7: closed-loop residuals, ours next to the thesis'

`ours` and `thesis`: the residual of the thesis' controller (PID + feed-forward) at 300 and
400 rpm; `pid`: the same gains without feed-forward; `ch. 4 fit %`: the simulation fit of the
yaw rate pooled over the family's records (thesis eq. 3.23)."""),
    new_code_cell("""display(Markdown(ap.comparison_table(study)))
display(Markdown(ap.comparison_text(study)))"""),
    new_markdown_cell("""## The closed loop at 300 rpm (thesis figs. 5.1-5.6)

Desired and actual heading, the error and the rudder with its limits, for the thesis'
controller (`pid+ff`) and the same gains without feed-forward (`pid`)."""),
    new_code_cell("""for name in study["models"]:
    for family in ap.FAMILIES:
        ev = study["evaluations"][f"{name}/{family}"]
        fig = plot_autopilot(ev.runs["pid+ff"], index=0, others=[ev.runs["pid"]],
                             labels=["pid+ff", "pid"], max_angle=vessel.rudder.max_angle,
                             window=(90.0, 200.0),
                             title=f"Table {ap.THESIS_TABLES[name, family]}: "
                             f"{ap.MODEL_NAMES[name]} from the merged "
                             f"{ap.FAMILY_NAMES[family]}, 300 rpm")
        fig.set_size_inches(9, 6)
        plt.show()"""),
    new_markdown_cell("""## Gains

$K_p$ [rad/rad], $K_i$ [1/s], $K_d$ [s] of each model's design. A Nomoto model whose time
constant is far too long (the merged turning circles determine $T$ poorly) has a large
$m = T/K$, hence large gains and a large feed-forward; the rate-limited rudder then
chatters, which the `rate-limited` column of the runs shows."""),
    new_code_cell("""rows = []
for key, gains in study["gains"].items():
    g = gains["pid+ff"]
    runs = [r for r in study["table"] if f"{r['model']}/{r['family']}" == key
            and r["controller"] == "pid+ff"] or [r for r in study["reference"]
                                                  if r["controller"] == "pid+ff"]
    limited = ", ".join(f"{r['time_rate_limited_s']:.0f}" for r in runs)
    rows.append(f"| {key} | {g['kp']:.3g} | {g['ki']:.3g} | {g['kd']:.3g} | {limited} |")
display(Markdown("| model | K_p | K_i | K_d | pid+ff rate-limited at 300, 400 rpm [s] |\\n"
                 "|---|---|---|---|---|\\n" + "\\n".join(rows)))"""),
    new_markdown_cell("""## The goals

1. Feed-forward from the best identified model (highest chapter-4 fit) beats feedback only at
   both speeds.
2. On informative data (zig-zags, the thesis manoeuvre), Ross' model gives the better
   autopilot than Nomoto's."""),
    new_code_cell("""g = study["goals"]
f = g["feedforward"]
print(f"1. best identified model {f['best_model']} (fit {f['fit_family']:.1f} %): pid+ff",
      [round(x, 2) for x in f["pid+ff"]], "vs pid", [round(x, 2) for x in f["pid"]],
      "->", "met" if f["met"] else "NOT met")
print("   feed-forward helps for:", ", ".join(f["met_by"]) or "none")
r = g["ross_vs_nomoto"]
for family, v in r["families"].items():
    print(f"2. {family:8s} Ross", [round(x, 2) for x in v["ross"]], "Nomoto",
          [round(x, 2) for x in v["nomoto"]], "-> Ross better" if v["ross_better"] else "")
print("   on the informative data:", "met" if r["met"] else "NOT met")"""),
]


def main():
    nb = new_notebook(cells=CELLS, metadata={"kernelspec": {
        "display_name": "Python 3", "language": "python", "name": "python3"}})
    path = pathlib.Path(__file__).with_name("autopilot.ipynb")
    nbformat.write(nb, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
