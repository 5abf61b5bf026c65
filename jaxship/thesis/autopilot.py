"""The heading-autopilot study of the thesis (Odegard 2009, seed 000, chapter 5) on the
built-in thesis vessel: the chapter-4 models identified from the merged experiments of
each family, their autopilots (`jaxship.AutopilotDesign`, `autopilot.evaluate`) on the true
thesis vessel at 300 and 400 rpm, and their comparison with the thesis' Tables 5.2-5.7
(the goals, the ordering by Spearman rank correlation, the best run)."""

import itertools
import math

import numpy as np
import scipy  # scipy.stats loads on first use (an import-time saving)

import jaxship as js

from .._workflow._autopilot import CONTROLLERS, _finite, cell, evaluate
from . import identification as thesis


RPMS = (300.0, 400.0)  # thesis sec. 5.4: simulated at 300 and 400 rpm
FAMILIES = ("turning", "zigzag", "thesis")
MODELS = ("nomoto", "ross")
MODEL_NAMES = {"nomoto": "Nomoto", "ross": "Ross", "ross_speed_rudder": "Ross + speed rudder"}
FAMILY_NAMES = {"turning": "turning circles", "zigzag": "zig-zags",
                "thesis": "thesis manoeuvre"}
# thesis Tables 5.2-5.7: closed-loop residuals (eq. 3.19) at (300, 400) rpm
THESIS_RESIDUALS = {
    "nomoto": {"turning": (80.4113, 44.7822), "zigzag": (108.0843, 17.3626),
               "thesis": (179.6080, 69.0153)},
    "ross": {"turning": (110.0642, 185.0572), "zigzag": (125.1633, 145.2591),
             "thesis": (78.7259, 31.0921)},
}
THESIS_TABLES = {("nomoto", "turning"): "5.2", ("nomoto", "zigzag"): "5.3",
                 ("nomoto", "thesis"): "5.4", ("ross", "turning"): "5.5",
                 ("ross", "zigzag"): "5.6", ("ross", "thesis"): "5.7"}


def merged_models(vessel=None, *, quick: bool = False,
                  settings: thesis.Settings = thesis.Settings(), models=MODELS,
                  experiments=None, progress=None) -> dict:
    """The chapter-4 models identified from the merged experiments of each family,
    with the chapter-4 pipeline's own calls (`thesis.thesis_experiments`,
    `thesis.identify`, the Ross fit started from the family's Nomoto fit, as in
    `thesis.identification_study`) but without its single-experiment fits: a dict
    like that study's (`models` keyed `"merged/<model>/<family>"`, `table` rows with
    the pooled simulation fit % `fit_family`)."""
    vessel = js.get_vessel("thesis") if vessel is None else vessel
    families = thesis.QUICK_FAMILIES if quick else thesis.FAMILIES
    if experiments is None:
        experiments = thesis.thesis_experiments(vessel, families=families, settings=settings)
    say = progress or (lambda message: None)
    out, rows = {}, []
    for family, specs in families.items():
        records = [experiments[thesis.record_name(s, rpm)] for s in specs for rpm in thesis.RPMS]
        fitted = {}
        for name in ("nomoto", *[m for m in models if m != "nomoto"]):
            say(f"identifying {name} on the merged {family}")
            result = thesis.identify(name, records, vessel, settings=settings,
                                     nomoto=fitted.get("nomoto"), base=fitted.get("ross"))
            fitted[name] = result.model
            out[f"merged/{name}/{family}"] = result.model
            fit, _ = thesis.simulation_fit(result.model, records, settings.substeps)
            rows.append(dict(case="merged", model=name, family=family,
                             fit_family=_finite(fit)))
    return {"models": out, "table": rows, "quick": bool(quick)}


def autopilot_study(vessel=None, *, identification=None, quick: bool = False,
                    settings: thesis.Settings = thesis.Settings(),
                    design: js.AutopilotDesign = js.AutopilotDesign(),
                    rpms=RPMS, models=MODELS, progress=None) -> dict:
    """Thesis chapter 5 on `vessel` (default `jaxship.get_vessel("thesis")`).

    - `identification`: the chapter-4 study (`thesis.identification_study`, e.g. from
      `jaxship reproduce`) whose merged models are reused; None: `merged_models`
      (`quick`: its reduced design, two trials per family).
    - `design`: `jaxship.AutopilotDesign`; `rpms`: the closed-loop propeller rates; `models`: which
      identified models (`"nomoto"`, `"ross"`, `"ross_speed_rudder"`).

    Returns a dict: `table` (one row per model, family, controller and rpm: the run
    keys of `evaluate`, `model`, `family`, `thesis` (the thesis' residual, pid+ff rows)
    and `fit_family` (chapter-4 pooled fit %)), `reference` (the same for the vessel's
    own yaw equation: the gains and feed-forward of a perfect model), `gains`
    {"<model>/<family>": gains}, `goals`, `design`, `rpms`, and `evaluations` (the
    `Evaluation` objects, with the closed-loop runs; not JSON: see `to_json`).
    """
    vessel = js.get_vessel("thesis") if vessel is None else vessel
    say = progress or (lambda message: None)
    if identification is None:
        identification = merged_models(vessel, quick=quick, settings=settings, models=models,
                                       progress=say)
    fits = {(r["model"], r["family"]): r.get("fit_family")
            for r in identification["table"] if r["case"] == "merged"}
    table, gains, evaluations = [], {}, {}
    for name in models:
        for family in FAMILIES:
            model = identification["models"].get(f"merged/{name}/{family}")
            say(f"closed loop: {name} from the merged {family}" if model is not None else
                f"closed loop: no {name} model from the merged {family}")
            if model is None:  # not identified, or its identification failed
                continue
            ev = evaluate(model, vessel, rpm=rpms, design=design)
            evaluations[f"{name}/{family}"] = ev
            gains[f"{name}/{family}"] = ev.gains()
            thesis_values = THESIS_RESIDUALS.get(name, {}).get(family)
            for i, row in enumerate(ev.rows):
                paper = (thesis_values[i % 2] if thesis_values and row["controller"] == "pid+ff"
                         and list(rpms) == list(RPMS) else None)
                table.append(dict(model=name, family=family, **row, thesis=paper,
                                  fit_family=fits.get((name, family))))
    say("closed loop: the vessel's own yaw equation")
    reference = evaluate(vessel, vessel, rpm=rpms, design=design)
    evaluations["vessel"] = reference
    gains["vessel"] = reference.gains()
    study = {"table": table, "reference": reference.rows, "gains": gains,
             "design": reference.to_dict()["design"], "rpms": [float(r) for r in rpms],
             "models": list(models), "quick": bool(identification.get("quick", quick)),
             "evaluations": evaluations}
    study["goals"] = goals(study)
    return study


def _residuals(study, model, family, controller):
    return [r["sum_abs_error_deg"] for r in study["table"] if r["model"] == model
            and r["family"] == family and r["controller"] == controller]


def _beats(a, b):
    return all(x is not None and y is not None and x < y for x, y in zip(a, b))


# the thesis' ordering of its six autopilots counts as reproduced when our ordering's
# Spearman rank correlation with it is positive at this one-sided significance level
ORDERING_ALPHA = 0.05


def spearman_exact(x, y) -> tuple[float, float]:
    """(rho, p): Spearman's rank correlation of `x` and `y` (`scipy.stats.spearmanr`) and
    its one-sided p-value $P(\\rho' \\ge \\rho)$ over all $n!$ orderings of `x` (exact;
    the t approximation misstates it for the six autopilots). NaN for constant input."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan, math.nan
    rho = float(scipy.stats.spearmanr(x, y)[0])
    if len(x) > 8:  # 9! orderings and more: the t approximation
        return rho, float(scipy.stats.spearmanr(x, y, alternative="greater")[1])
    ry = scipy.stats.rankdata(y)
    every = [np.corrcoef(scipy.stats.rankdata(x[list(p)]), ry)[0, 1]
             for p in itertools.permutations(range(len(x)))]
    return rho, float(np.mean(np.asarray(every) >= rho - 1e-12))


def _thesis_keys(study):
    """(model, family) of the autopilots that have a thesis table and a pid+ff run."""
    return [(m, f) for m in ("nomoto", "ross") for f in FAMILIES
            if _residuals(study, m, f, "pid+ff") and m in THESIS_RESIDUALS
            and None not in _residuals(study, m, f, "pid+ff")]


def goals(study: dict) -> dict:
    """The goals of the study, with their numbers:

    - `thesis_ordering` (all six autopilots at the thesis' 300 and 400 rpm): our
      ordering of the mean pid+ff residual against the thesis' Tables 5.2-5.7, Spearman
      rank correlation with its one-sided p-value (`scipy.stats.spearmanr`); met when
      positive at `ORDERING_ALPHA`;

    - `feedforward`: the reference feed-forward of the best identified model (highest
      chapter-4 pooled fit % among the merged fits) lowers the residual below that
      model's feedback-only PID at every rpm; and the same for every model;
    - `ross_vs_nomoto`: on the informative data (zig-zags and the thesis manoeuvre,
      which excite the yaw dynamics; the turning circles are mostly steady turns),
      the Ross model's autopilot (its gains and feed-forward) beats Nomoto's at every
      rpm."""
    present = {(r["model"], r["family"]) for r in study["table"]}
    fits = {(r["model"], r["family"]): r["fit_family"] for r in study["table"]}
    ranked = sorted((k for k in present if fits.get(k) is not None), key=lambda k: -fits[k])
    out = {}
    if ranked:
        best = ranked[0]
        ff, fb = (_residuals(study, *best, c) for c in ("pid+ff", "pid"))
        out["feedforward"] = {
            "best_model": f"{best[0]}/{best[1]}", "fit_family": fits[best],
            "pid+ff": ff, "pid": fb, "met": _beats(ff, fb),
            "met_by": sorted(f"{m}/{f}" for m, f in present
                             if _beats(_residuals(study, m, f, "pid+ff"),
                                       _residuals(study, m, f, "pid"))),
        }
    keys = _thesis_keys(study)
    if len(keys) == 6 and len(study["rpms"]) == 2 and list(study["rpms"]) == list(RPMS):
        ours = [float(np.mean(_residuals(study, m, f, "pid+ff"))) for m, f in keys]
        paper = [float(np.mean(THESIS_RESIDUALS[m][f])) for m, f in keys]
        rho, p = spearman_exact(ours, paper)
        out["thesis_ordering"] = {
            "autopilots": [f"{m}/{f}" for m, f in keys], "ours": ours, "thesis": paper,
            "spearman": float(rho), "p_value": float(p), "alpha": ORDERING_ALPHA,
            "met": bool(rho > 0 and p < ORDERING_ALPHA)}  # False for NaN
    if {"nomoto", "ross"} <= {m for m, _ in present}:
        per = {}
        for family in FAMILIES:
            if ("ross", family) in present and ("nomoto", family) in present:
                ross, nomoto = (_residuals(study, m, family, "pid+ff") for m in ("ross", "nomoto"))
                per[family] = {"ross": ross, "nomoto": nomoto, "ross_better": _beats(ross, nomoto)}
        informative = [f for f in ("zigzag", "thesis") if f in per]
        out["ross_vs_nomoto"] = {"families": per, "informative": informative,
                                 "met": bool(informative) and all(per[f]["ross_better"]
                                                                  for f in informative)}
    return out


def to_json(study: dict) -> dict:
    """The study without the `Evaluation` objects, for `json.dumps`."""
    return {k: v for k, v in study.items() if k != "evaluations"}


def comparison_table(study: dict) -> str:
    """Markdown: our Tables 5.2-5.7 (pid+ff residual at each rpm) next to the thesis',
    with the feedback-only residual and the chapter-4 fit %."""
    rpms = study["rpms"]
    head = " | ".join(f"ours {r:.0f} | thesis {r:.0f}" for r in rpms)
    fb = " | ".join(f"pid {r:.0f}" for r in rpms)
    lines = [f"| table | model | identified from | {head} | {fb} | ch. 4 fit % |",
             "|---" * (4 + 3 * len(rpms)) + "|"]
    for name in study["models"]:
        for family in FAMILIES:
            ff = _residuals(study, name, family, "pid+ff")
            pid = _residuals(study, name, family, "pid")
            if not ff:
                continue
            row = [r for r in study["table"] if r["model"] == name and r["family"] == family
                   and r["controller"] == "pid+ff"]
            pairs = " | ".join(f"{cell(a)} | {cell(r['thesis'])}" for a, r in zip(ff, row))
            fit = row[0]["fit_family"]
            lines.append(f"| {THESIS_TABLES.get((name, family), '-')} | "
                         f"{MODEL_NAMES.get(name, name)} | {FAMILY_NAMES[family]} (merged) | "
                         f"{pairs} | {' | '.join(cell(x) for x in pid)} | {cell(fit)} |")
    ref = study["reference"]
    by = {c: [r["sum_abs_error_deg"] for r in ref if r["controller"] == c] for c in CONTROLLERS}
    lines.append("| - | the vessel itself | (true yaw equation) | "
                 + " | ".join(f"{cell(a)} | -" for a in by["pid+ff"]) + " | "
                 + " | ".join(cell(x) for x in by["pid"]) + " | - |")
    return "\n".join(lines) + "\n"


def comparison_text(study: dict) -> str:
    """Sentences on orderings and ratios, ours against the thesis' (Spearman rank
    correlation), the best run of the table, and the goals, each with its numbers."""
    keys = _thesis_keys(study)
    g = study["goals"]
    text = []
    name = lambda k: f"{MODEL_NAMES[k[0]]}/{k[1]}"
    if "thesis_ordering" in g:
        o = g["thesis_ordering"]
        ours, paper = o["ours"], o["thesis"]
        order = lambda v: ", ".join(name(keys[i]) for i in np.argsort(v))
        ratio_ours = [a / b for a, b in (_residuals(study, m, f, "pid+ff") for m, f in keys)
                      if a and b]
        ratio_paper = [THESIS_RESIDUALS[m][f][0] / THESIS_RESIDUALS[m][f][1] for m, f in keys]
        cells = [a / b for m, f in keys
                 for a, b in zip(_residuals(study, m, f, "pid+ff"), THESIS_RESIDUALS[m][f])
                 if a is not None]
        text.append(
            f"Ordered by the mean residual of the two speeds (best first), the thesis has "
            f"{order(paper)}; we have {order(ours)}. Reproducing the thesis' ordering: "
            f"{'met' if o['met'] else 'NOT met'} (Spearman rank correlation "
            f"{o['spearman']:+.2f}, one-sided p = {o['p_value']:.2g} with {len(keys)} "
            f"autopilots; met when positive at p < {o['alpha']:g}). "
            f"The ratio of the 300 rpm to the 400 rpm residual is "
            f"{', '.join(f'{x:.2f}' for x in ratio_paper)} in the thesis and "
            f"{', '.join(f'{x:.2f}' for x in ratio_ours)} here (same order of rows). "
            f"Cell by cell ours are {np.median(cells):.2g} times the thesis' (median; range "
            f"{min(cells):.2g}-{max(cells):.2g}): the thesis states neither the unit nor the "
            f"sampling of its residual, so only orderings and ratios compare.")
    best = best_run_text(study)
    if best:
        text.append(best)
    if "feedforward" in g:
        f = g["feedforward"]
        diffs = [None if a is None or b is None else a - b for a, b in zip(f["pid+ff"], f["pid"])]
        text.append(
            f"Goal 1 (ours; the thesis runs no autopilot without feed-forward), feed-forward "
            f"from the best identified model ({f['best_model']}, chapter-4 fit "
            f"{cell(f['fit_family'])} %) beats feedback only at every speed: "
            f"{'met' if f['met'] else 'NOT met'} (pid+ff "
            f"{', '.join(cell(x) for x in f['pid+ff'])} against pid "
            f"{', '.join(cell(x) for x in f['pid'])} deg, differences "
            f"{', '.join('-' if x is None else f'{x:+.2f}' for x in diffs)} deg at "
            f"{', '.join(f'{r:.0f}' for r in study['rpms'])} rpm); feed-forward helps for "
            f"{len(f['met_by'])} of {len({(r['model'], r['family']) for r in study['table']})}"
            f" models ({', '.join(f['met_by']) or 'none'}).")
    if "ross_vs_nomoto" in g:
        r = g["ross_vs_nomoto"]
        parts = [f"{FAMILY_NAMES[k]}: Ross {', '.join(cell(x) for x in v['ross'])} vs "
                 f"Nomoto {', '.join(cell(x) for x in v['nomoto'])}"
                 for k, v in r["families"].items()]
        paper = []
        for k in r["informative"]:
            ross, nomoto = THESIS_RESIDUALS["ross"][k], THESIS_RESIDUALS["nomoto"][k]
            paper.append(f"{FAMILY_NAMES[k]}: Ross {', '.join(f'{x:.1f}' for x in ross)} vs "
                         f"Nomoto {', '.join(f'{x:.1f}' for x in nomoto)} (Ross better at "
                         f"{sum(x < y for x, y in zip(ross, nomoto))} of {len(ross)} speeds)")
        text.append(
            f"Goal 2, Ross beats Nomoto when fitted on informative data (zig-zags, thesis "
            f"manoeuvre): {'met' if r['met'] else 'NOT met'} ({'; '.join(parts)} deg; each "
            f"model brings its own gains and feed-forward). The thesis' tables give "
            f"{'; '.join(paper)}.")
    return "\n\n".join(text) + "\n"


def best_run_text(study: dict) -> str:
    """A sentence on the run of lowest residual in the table (any model, family,
    controller and rpm), against the thesis' number for it where the thesis has one."""
    rows = [r for r in study["table"] if r["sum_abs_error_deg"] is not None]
    if not rows:
        return ""
    b = min(rows, key=lambda r: r["sum_abs_error_deg"])
    controller = ("pid+ff (the thesis' controller)" if b["controller"] == "pid+ff"
                  else "pid (feedback only)")
    what = (f"{controller} with the {MODEL_NAMES.get(b['model'], b['model'])} model from "
            f"the merged {FAMILY_NAMES[b['family']]} at {b['rpm']:.0f} rpm")
    text = (f"The best run of the table is {what}: residual {b['sum_abs_error_deg']:.2f} deg "
            f"(RMS {cell(b['rms_error_deg'])} deg)")
    rpms = list(study["rpms"])
    paper = THESIS_RESIDUALS.get(b["model"], {}).get(b["family"])
    if paper is not None and rpms == list(RPMS):
        thesis_value = paper[rpms.index(b["rpm"])]
        table = THESIS_TABLES[(b["model"], b["family"])]
        ff = _residuals(study, b["model"], b["family"], "pid+ff")[rpms.index(b["rpm"])]
        if b["controller"] == "pid+ff":
            text += (f"; the thesis' Table {table} gives {thesis_value:.2f} for it (ours "
                     f"{b['sum_abs_error_deg'] / thesis_value:.2g} times that)")
        else:
            text += (f". The thesis has no feedback-only run; with feed-forward the same "
                     f"model gives {cell(ff)} deg here (difference "
                     + ("-" if ff is None else f"{ff - b['sum_abs_error_deg']:+.2f}")
                     + f" deg) and {thesis_value:.2f} in the thesis' Table {table}")
        best_paper = min(((m, f, i) for m, f in keys_of(THESIS_RESIDUALS) for i in range(2)),
                         key=lambda k: THESIS_RESIDUALS[k[0]][k[1]][k[2]])
        m, f, i = best_paper
        ours = _residuals(study, m, f, "pid+ff")
        text += (f". The thesis' best is {MODEL_NAMES[m]} from the {FAMILY_NAMES[f]} at "
                 f"{RPMS[i]:.0f} rpm ({THESIS_RESIDUALS[m][f][i]:.2f}, Table "
                 f"{THESIS_TABLES[(m, f)]}); ours there "
                 + (f"{cell(ours[i])} deg" if len(ours) == 2 else "not run"))
    return text + "."


def keys_of(table: dict) -> list:
    """(model, family) pairs of a {model: {family: ...}} table."""
    return [(m, f) for m, families in table.items() for f in families]


def report_section(study: dict, *, level: int = 2) -> str:
    """A markdown section for a report (`report.md`, `jaxship reproduce`'s summary):
    the set-up, our Tables 5.2-5.7 next to the thesis', orderings and the goals."""
    d = study["design"]
    h = "#" * level
    quick = " (quick identification design: 2 trials per family)" if study["quick"] else ""
    return (
        f"{h} Heading autopilot (thesis chapter 5)\n\n"
        f"The merged chapter-4 models{quick} each give a PID by pole placement (omega_n = "
        f"{d['natural_frequency']:g} rad/s, zeta = {d['damping']:g}, about the straight run at "
        f"{d['design_rpm']:.0f} rpm) and a reference feed-forward; reference model omega = "
        f"{d['reference_frequency']:g} rad/s, zeta = {d['reference_damping']:g}, "
        f"{d['step']:g} deg step at {d['step_time']:g} s; the true thesis vessel is steered "
        f"at {', '.join(f'{r:.0f}' for r in study['rpms'])} rpm (rudder "
        f"{d['max_rudder_deg']:.0f} deg, {d['max_rudder_rate_deg_s']:.0f} deg/s). Residual: "
        f"thesis eq. 3.19, sum of |psi_d - psi| in degrees sampled every "
        f"{d['sample_interval']:g} s over {d['window_s'][0]:g}-{d['window_s'][1]:g} s; pid+ff "
        f"is the thesis' controller, pid the same gains without feed-forward.\n\n"
        + comparison_table(study) + "\n" + comparison_text(study)
    )
