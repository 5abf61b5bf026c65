"""Write notebooks/quick_start.ipynb: a turning circle and a zig-zag of the Mariner with
their indices, figures and the IMO MSC.137(76) check, then a steering model identified from
the zig-zags, validated, saved, loaded and steered by an autopilot designed from it, through
the public API (`IDENTIFY`: the workflow of `jaxship identify` and `jaxship autopilot` in
at most 25 lines, tests/test_notebooks.py).

Run: python notebooks/make_quick_start.py (then execute the notebook).
"""

import pathlib

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook


IDENTIFY = """import pathlib
import tempfile


records = [js.Experiment.from_trajectory(zigzag)]  # the 20/20 zig-zag above
held_out = [js.Experiment.from_trajectory(zigzag10)]  # the 10/10 one, held out
fit = js.identify("nomoto1", records, validate=held_out)
print(fit.summary())  # K and T with standard errors, fit % and FPE per channel

path = pathlib.Path(tempfile.mkdtemp()) / "result.json"
fit.save(path)  # the file `jaxship identify` writes
model = js.load_model(path)  # the fitted Nomoto1 again
print(model)

autopilot = js.design_autopilot(fit, plant=ship, speeds=[U])  # the command's rules
print(f"K_p = {float(autopilot.kp):.3g}, K_i = {float(autopilot.ki):.3g} 1/s, "
      f"K_d = {float(autopilot.kd):.3g} s")
evaluation = js.evaluate_autopilot(fit, ship, speeds=[U])  # PID +- feed-forward, closed loop
display(Markdown(evaluation.summary()))"""

CELLS = [
    new_markdown_cell("""# Quick start: a turning circle and a zig-zag

`jaxship` simulates a 3-DOF (surge, sway, yaw) vessel as pure JAX functions. Here the Mariner
class cargo ship (Chislett & Strom-Tejsen 1965, as in Fossen's MSS `mariner.m`; `js.get_vessel`
lists the presets) sails the two trials every manoeuvring booklet has, a 35 deg turning
circle and a 20/20 zig-zag, and the IMO MSC.137(76) criteria are checked on them.

SI units and radians inside, degrees only at the edges; positive rudder turns the ship to
starboard."""),
    new_code_cell("""import jax
import numpy as np
from IPython.display import Markdown, display

import jaxship as js
from jaxship.plotting import plot_imo_criteria, plot_trajectory


jax.config.update("jax_enable_x64", True)  # our choice here; jaxship never changes it

ship = js.get_vessel("mariner")
L, U = float(ship.length), float(ship.nominal_speed)
print(f"Mariner: L = {L:.1f} m, approach speed U = {U:.2f} m/s ({U / 0.5144:.1f} kn)")"""),
    new_markdown_cell("""## Turning circle, 35 deg to starboard

A trial is a manoeuvre (`js.Turn`, `js.ZigZag`, ...): `js.simulate` runs it from the
straight run at the approach speed, here for 60 ship lengths' time L/U (past the 540 deg of
heading change ITTC asks for), with an output every second and two RK4 steps per sample, as
`jaxship simulate --manoeuvre turn:35` does. `js.indices.turning_indices` gives advance, transfer
and tactical diameter."""),
    new_code_cell("""tau = L / U  # the ship's time scale [s]
x0 = js.straight_run(ship)  # the approach at the nominal speed
fine = js.Simulator(substeps=2)
turn = js.simulate(ship, js.Turn(np.deg2rad(35), duration=60 * tau, dt=1.0), x0, simulator=fine)
turning = js.indices.turning_indices(turn)
tactical = turning.tactical_diameter
print(f"advance {turning.advance:.0f} m = {turning.advance / L:.2f} L, "
      f"transfer {turning.transfer:.0f} m, "
      f"tactical diameter {tactical:.0f} m = {tactical / L:.2f} L")
fig = plot_trajectory(turn, length=L, indices=turning, title="Mariner, 35 deg turning circle")"""),
    new_markdown_cell("""## Zig-zag 20/20

The rudder goes to 20 deg and is reversed each time the heading has changed by 20 deg; the
overshoots are how far the heading swings past that before it turns back."""),
    new_code_cell("""zigzag = js.simulate(ship, js.ZigZag(np.deg2rad(20), np.deg2rad(20), duration=35 * tau, dt=1.0),
                     x0, simulator=fine)
zz20 = js.indices.zigzag_indices(zigzag, np.deg2rad(20))
print("overshoots [deg]:", np.round(np.rad2deg(zz20.overshoots), 2))
fig = plot_trajectory(zigzag, length=L, indices=zz20, title="Mariner, 20/20 zig-zag")"""),
    new_markdown_cell("""## IMO criteria

MSC.137(76) limits the 35 deg turn (advance 4.5 L, tactical diameter 5 L) and the zig-zag
overshoots (the 10/10 limits depend on L/V)."""),
    new_code_cell("""zigzag10 = js.simulate(ship, js.ZigZag(np.deg2rad(10), np.deg2rad(10), duration=35 * tau,
                                        dt=1.0), x0, simulator=fine)
zz10 = js.indices.zigzag_indices(zigzag10, np.deg2rad(10))
rows = js.indices.imo_criteria(L, U, turning35=turning, zigzag10=zz10, zigzag20=zz20)
display(Markdown(js.indices.format_table(rows)))
fig = plot_imo_criteria(rows)"""),
    new_markdown_cell("""The same from a shell: `jaxship simulate --vessel mariner --manoeuvre turn:35 --out
out/turn35` writes the trial's CSV, its indices as JSON and these figures.

## Identify, validate, save, load, steer

What `jaxship identify` and `jaxship autopilot` do, as library verbs: `js.identify` fits
Nomoto's first-order model to the 20/20 zig-zag (start values, the fit, the assessment with
fit %, FPE and residual tests on the training and the held-out records), `save` writes the
`result.json` the command writes and `js.load_model` reads it back; `js.design_autopilot`
applies the command's design rules (omega_n = 1.25 / T, the reference at 0.4 omega_n, the
rudder's share) and `js.evaluate_autopilot` runs the PID with and without the reference
feed-forward on the Mariner itself. The Mariner turns nonlinearly, so a linear model
simulated over a whole zig-zag drifts in heading (the psi fit of the simulation): the
autopilot's feedback corrects what the model misses."""),
    new_code_cell(IDENTIFY),
    new_markdown_cell("""Next: identification from measured records (`esso_osaka_identification.ipynb`),
the thesis' study (`thesis_identification.ipynb`), the heading autopilot in depth
(`autopilot.ipynb`) and what a model is missing (`discovery.ipynb`)."""),
]


def main():
    path = pathlib.Path(__file__).with_name("quick_start.ipynb")
    nb = new_notebook(cells=CELLS, metadata={"kernelspec": {"name": "python3",
                                                            "display_name": "Python 3"}})
    nbformat.write(nb, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
