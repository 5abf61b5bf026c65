"""Write notebooks/svm_response_models.ipynb and notebooks/experiment_design.ipynb
(run: python notebooks/make_svm_design_notebooks.py)."""

import pathlib

import nbformat as nbf


HERE = pathlib.Path(__file__).parent
SETUP = "import jax\njax.config.update('jax_enable_x64', True)\nimport numpy as np\n"

svm = nbf.v4.new_notebook()
svm.cells = [
    nbf.v4.new_markdown_cell(
        "# Lu & Zhao (2008): four discrete response models, LS and SVR\n\n"
        "The four models of their eqs. 7-10 (continuous eqs. 1-4) fitted to a simulated "
        "20/20 zig-zag of the Mariner (`svm_response_study` in `jaxship/studies/svm.py`); overshoots "
        "in the form of their Table 1, indices in the form of Tables 2-4, and prediction of "
        "an untrained 10/10 zig-zag and a 20 deg turning circle (sec. 3.2)."),
    nbf.v4.new_code_cell(SETUP + "from jaxship.studies.svm import svm_response_study\n"
                         "study = svm_response_study('mariner', dt=0.5)"),
    nbf.v4.new_markdown_cell("## Table 1: first and second overshoot [deg]"),
    nbf.v4.new_code_cell("for name, o1, o2 in study['table1']:\n"
                         "    print(f'{name:22s} {o1:8.2f} {o2:8.2f}')"),
    nbf.v4.new_markdown_cell("## Tables 2-4: indices of the four models (LS and SVR)"),
    nbf.v4.new_code_cell(
        "keys = ['K', 'T', 'K_over_T', 'alpha1', 'beta1', 'alpha2', 'T1', 'T2', 'T3', "
        "'S_over_P', 'K_over_P', 'KT3_over_P', 'delta_r']\n"
        "for (s, m), p in study['consistency'].items():\n"
        "    print(s, m, {k: float(f'{p[k]:.4g}') for k in keys if k in p})"),
    nbf.v4.new_markdown_cell("## Generalisation: fit % of r, models simulated open loop"),
    nbf.v4.new_code_cell("for key, g in study['generalisation'].items():\n"
                         "    print(key, {k: round(v, 1) for k, v in g.items()})\n"
                         "for key, f in study['fits'].items():\n"
                         "    print(key, 'converged' if f.converged else 'NOT converged', "
                         "f'rms {f.rms:.3g}')"),
]
nbf.write(svm, HERE / "svm_response_models.ipynb")

design = nbf.v4.new_notebook()
design.cells = [
    nbf.v4.new_markdown_cell(
        "# Experiment design: Cramer-Rao bounds of standard manoeuvres\n\n"
        "Nomoto 1 and 2 models of the thesis vessel at 500 rpm (least-squares fits to a "
        "noise-free simulation), a rate gyro with 0.05 deg/s white noise, every manoeuvre "
        "run for the same duration as the thesis manoeuvre (thesis sec. 3.3.2). "
        "`design_study` in `jaxship/studies/svm.py`, `jaxship.fisher_information`."),
    nbf.v4.new_code_cell(SETUP + "from jaxship.studies.svm import design_study\n"
                         "from jaxship import excitation_order\n"
                         "d = design_study('thesis', rpm=500.0)\nprint(d['nominal'])\n"
                         "print('duration', d['duration'], 's')"),
    nbf.v4.new_code_cell(
        "for (model, name), rep in d['reports'].items():\n"
        "    rel = ', '.join(f'{n} {s:.3%}' for n, s in zip(rep.names, rep.relative_std))\n"
        "    print(f'{model} {name:14s} logdet {rep.log_det:8.2f} '\n"
        "          f'PE order {excitation_order(rep.delta, max_order=40):3d}  CRB rel. std: {rel}')"),
]
nbf.write(design, HERE / "experiment_design.ipynb")
