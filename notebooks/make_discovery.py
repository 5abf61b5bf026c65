"""Write notebooks/discovery.ipynb (run: python notebooks/make_discovery.py, then execute
it with `jupyter nbconvert --to notebook --execute --inplace notebooks/discovery.ipynb`)."""

import pathlib

import nbformat as nbf


HERE = pathlib.Path(__file__).parent
SETUP = """import jax
jax.config.update("jax_enable_x64", True)
import matplotlib.pyplot as plt
import numpy as np
import jaxship as js
from jaxship.studies.discovery import hidden_effect_records

DEG = np.pi / 180
"""

RESIDUALS = """def residual_plot(report, records, title):
    est = js.PredictionError(horizon=None)
    before = js.predict(report.model_before, records, estimator=est)
    after = js.predict(report.model_after, records, estimator=est)
    fig, axes = plt.subplots(1, len(records), figsize=(11, 3), sharey=True)
    for i, (ax, e) in enumerate(zip(np.atleast_1d(axes), records)):
        for label, p, colour in (("before", before, "C3"), ("after", after, "C2")):
            hit = p.predicted[i, :e.t.size]
            fit = p.metrics["psi"].fit_per_experiment[i]
            ax.plot(e.t[hit], np.rad2deg(e.psi - p.predictions["psi"][i, :e.t.size])[hit],
                    colour, lw=1, label=f"{label} (psi fit {fit:.1f} %)")
        ax.set_title(e.name, fontsize=9)
        ax.set_xlabel("time [s]")
        ax.legend(fontsize=8, frameon=False)
    np.atleast_1d(axes)[0].set_ylabel("heading residual [deg]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
"""

nb = nbf.v4.new_notebook()
nb.cells = [
    nbf.v4.new_markdown_cell(
        "# Find, name and add the missing effect\n\n"
        "`js.discover(model, train, holdout)` fits the model, scores every physically named "
        "effect of its catalogue at the fit (robust score tests from one forward-mode "
        "Jacobian), refits the best candidates, accepts one only if it passes calibrated "
        "tests and improves held-out predictions, and repeats until nothing passes. Here it "
        "runs on data where the truth is known: a Nomoto model with an effect hidden in it, "
        "integrated more finely than any fit, with the rudder logged at 2 Hz; trained on "
        "10/10 and 20/20 zig-zags to both sides and checked on +-20 deg turning circles."),
    nbf.v4.new_code_cell(SETUP + "\n" + RESIDUALS),
    nbf.v4.new_markdown_cell("## The catalogue"),
    nbf.v4.new_code_cell("for c in js.DISCOVERY_CATALOGUE:\n"
                         "    print(f'{c.id:24s} {c.name}')"),
    nbf.v4.new_markdown_cell(
        "## A hidden cubic yaw damping\n\nThe truth is $T\\dot r + r + \\beta r^3 = K\\delta$ "
        "with K = 0.06 1/s, T = 25 s, beta = 300 s^2/rad^2; the base model has no r^3 term."),
    nbf.v4.new_code_cell(
        "truth = js.augment(js.Nomoto1(K=0.06, T=25.0), js.YawCubicDamping(beta=300.0))\n"
        "train, holdout = hidden_effect_records(truth, seed=4)\n"
        "report = js.discover(js.Nomoto1(K=0.05, T=20.0), train, holdout)\n"
        "print(report.to_markdown())"),
    nbf.v4.new_code_cell("residual_plot(report, holdout, 'held-out turning circles')"),
    nbf.v4.new_markdown_cell(
        "## A rudder offset: named with the effect it cannot be told from\n\n"
        "At one speed a rudder offset and a constant yaw moment are the same column of the "
        "Jacobian; the report names the class and the experiment that would separate them."),
    nbf.v4.new_code_cell(
        "truth = js.augment(js.Nomoto1(K=0.06, T=25.0), js.RudderOffset(delta0=0.5 * DEG))\n"
        "train, holdout = hidden_effect_records(truth, seed=3)\n"
        "report = js.discover(js.Nomoto1(K=0.05, T=20.0), train, holdout)\n"
        "for e in report.effects:\n"
        "    print(e['id'], e['parameters'], 'cannot be told from', e['equivalent_to'])"),
    nbf.v4.new_markdown_cell(
        "## Nothing missing, also under a slowly varying disturbance\n\n"
        "A yaw moment that is not in any log (an Ornstein-Uhlenbeck equivalent rudder angle, "
        "1 deg, 20 s) colours the residuals. A score test that assumes white residuals "
        "would call several effects significant; the robust statistics do not."),
    nbf.v4.new_code_cell(
        "train, holdout = hidden_effect_records(js.Nomoto1(K=0.06, T=25.0), seed=2,\n"
        "                                       disturbance_std=1.0 * DEG)\n"
        "report = js.discover(js.Nomoto1(K=0.05, T=20.0), train, holdout)\n"
        "print(report.verdict)\n"
        "for k, s in sorted(report.scores.items(), key=lambda kv: -kv[1]['score_naive']):\n"
        "    print(f\"{k:24s} naive {s['score_naive']:8.2f}   robust {s['score']:6.2f}   \"\n"
        "          f\"threshold {s['threshold']:.2f}\")"),
    nbf.v4.new_markdown_cell(
        "The Monte-Carlo rates over seeds and effect sizes are printed by "
        "`python benchmarks/discovery.py --seeds 20` (see `benchmarks/README.md`)."),
]
nbf.write(nb, HERE / "discovery.ipynb")
