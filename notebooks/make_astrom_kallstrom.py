"""Write notebooks/astrom_kallstrom.ipynb (run: python notebooks/make_astrom_kallstrom.py)."""

import pathlib

import nbformat as nbf


HERE = pathlib.Path(__file__).parent

nb = nbf.v4.new_notebook()
nb.cells = [
    nbf.v4.new_markdown_cell(
        "# Astrom & Kallstrom (1979): Sea Stratus, prediction error against output error\n\n"
        "Reproduction 2 of issue 3. The Norrbin cross-flow model of Sea Stratus (their Table 3, "
        "nonlinear column, C = 0.63) is simulated through 5/5 and 20/20 zig-zags with a random "
        "yaw moment (process noise) and measurement noise (`jaxship/studies/astrom.py`). The six "
        "derivatives and C are identified from Table 3's initial estimates by output error and "
        "by prediction error with a 60 s horizon, on each zig-zag and on both. Their finding: "
        "under process noise a horizon of tens of seconds is essential, output error drifts.\n\n"
        "Columns: estimate with its standard error `fit` reports [and the window-robust one]; "
        "the largest |estimate - truth| in standard errors; fit % of psi."),
    nbf.v4.new_code_cell(
        "import jax\njax.config.update('jax_enable_x64', True)\n"
        "import matplotlib.pyplot as plt\nimport numpy as np\n"
        "from IPython.display import Markdown, display\n"
        "from jaxship.studies import astrom\n\n"
        "study = astrom.astrom_kallstrom()\ndisplay(Markdown(astrom.table(study)))"),
    nbf.v4.new_markdown_cell("## The records"),
    nbf.v4.new_code_cell(
        "fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)\n"
        "for e in list(study['data'].values())[:2]:\n"
        "    t = np.asarray(e.t) / 60\n"
        "    axes[0].plot(t, np.rad2deg(np.asarray(e.psi)), label=e.name)\n"
        "    axes[1].plot(t, np.rad2deg(np.asarray(e.delta)), label=e.name)\n"
        "axes[0].set_ylabel('heading [deg]'); axes[1].set_ylabel('rudder [deg]')\n"
        "axes[1].set_xlabel('time [min]'); axes[0].legend(); fig.tight_layout()"),
    nbf.v4.new_markdown_cell("## Parameter errors in standard errors, per fit"),
    nbf.v4.new_code_cell(
        "names = list(study['truth'])\n"
        "fig, ax = plt.subplots(figsize=(10, 4))\n"
        "for i, row in enumerate(study['rows']):\n"
        "    z = row.z_robust if np.all(np.isfinite(row.z_robust)) else row.z\n"
        "    ax.plot(names, z, 'o-', label=f'{row.data}, {row.method}')\n"
        "ax.axhspan(-2, 2, color='0.9'); ax.set_ylabel('(estimate - truth) / std')\n"
        "ax.legend(fontsize=8); fig.tight_layout()"),
]
nbf.write(nb, HERE / "astrom_kallstrom.ipynb")
