"""`identify --model auto`: the steering model chosen from the training records alone.

Each candidate of `CANDIDATES` (the first-order steering models the autopilot's feed-forward
inverts: Nomoto 1 and Norrbin's nonlinear Nomoto 1 of either course stability, issue 61) is
fitted to the training records as `identify` fits it, and the one with the least Bayesian
information criterion of its fit criterion on those records is chosen:

$$\\mathrm{BIC} = N\\log\\det\\hat\\Lambda + d\\log N,$$

$\\hat\\Lambda$ the residual covariance of the fitted channels (its diagonal here: the
channels' losses $V_c$), $d$ the number of estimated parameters and $N$ the samples per
channel (Schwarz 1978; Ljung 1999, sec. 16.4). Akaike's FPE, $\\det\\hat\\Lambda\\,(1 +
d/N)/(1 - d/N)$ (thesis eq. 3.21 for one channel), is reported beside it but does not
choose: it charges an extra parameter about $2/N$ of the loss, and the output-error
residuals of a steering fit are correlated in time (fewer independent samples than $N$),
so on a linear Nomoto 1 truth it took Norrbin's cubic term on one of three noise draws
(loss 0.5 % lower, penalty 0.3 %; issue 61). BIC's $\\log N$ per parameter keeps the
simpler model unless the extra term buys more than that (parsimony; consistent as $N$
grows). Held-out records (`--validate`) are assessed for every candidate but never enter
the choice.

Every candidate's fitted model is kept in the selection (`fitted`). Where the choice is
Norrbin's model, `autopilot` places the PID's poles on the linear Nomoto 1 fitted to the
same records (`linear_candidate`): pole placement needs a linear yaw equation, and the
least-squares linear model of the records is a better one than the cubic's tangent at
r = 0, an extrapolation into a spiral loop where the 10-20 deg zig-zags never turn
steadily. Its feed-forward inverts whichever of the two turns steadily nearer the vessel
at the step's yaw rate (issue 61).
"""

from __future__ import annotations

import dataclasses
import math


CANDIDATES = ("nomoto1", "nomoto1-norrbin")
LINEAR = "nomoto1"  # the linear candidate: the autopilot's feedback design model
AUTO = "auto"  # the `--model` that chooses among `CANDIDATES`
CRITERION = ("BIC of the fit criterion on the training records: N times the sum of the log "
             "losses of the fitted channels plus d log N, d estimated parameters, N samples "
             "per channel (Schwarz 1978; Ljung 1999, sec. 16.4); Akaike's FPE (the product "
             "of the losses times (1 + d/N) / (1 - d/N)) reported beside it")


def is_auto(model) -> bool:
    """Whether `model` (a `--model` text) asks for the choice."""
    return isinstance(model, str) and model.strip().lower() == AUTO


def criterion(result) -> dict:
    """The choice's figures of one candidate's `Identification`, from its
    `train` assessment only (the fit criterion on the training records): `bic` and `fpe`
    (module text; inf for a fit that did not converge, or non-positive or non-finite
    losses), `losses` per channel, `num_params` d, `num_samples` N, `fit_code`."""
    metrics = result.train.metrics
    losses = {c: float(m.loss) for c, m in metrics.items()}
    d = len(result.fit.names) if result.fit.effective_params is None else \
        result.fit.effective_params  # with a prior: the effective number
    n = min(int(m.num_samples) for m in metrics.values())
    usable = (bool(result.fit.success) and d < n
              and all(math.isfinite(v) and v > 0 for v in losses.values()))
    if not usable:
        return {"bic": math.inf, "fpe": math.inf, "losses": losses, "num_params": d,
                "num_samples": n, "fit_code": result.fit.code_name}
    log_det = sum(math.log(v) for v in losses.values())
    return {"bic": n * log_det + d * math.log(n),
            "fpe": math.exp(log_det) * (1 + d / n) / (1 - d / n), "losses": losses,
            "num_params": d, "num_samples": n, "fit_code": result.fit.code_name}


def choose(results: dict, failed: dict) -> tuple[str, dict]:
    """`(name, selection)`: the candidate of `results` {name: Identification} with the
    least BIC (`criterion`; the first listed on a tie: the simpler); `failed` {name: why} are
    the candidates whose fit diverged. `selection` (JSON-ready): `criterion` (in words),
    `chosen`, `candidates` {name: `criterion`, or {"failed": why}}."""
    if not results:
        raise ValueError("--model auto: no candidate could be fitted ("
                         + "; ".join(f"{n}: {why}" for n, why in failed.items()) + ").")
    figures = {name: criterion(r) | {"fitted": fitted(r)} for name, r in results.items()}
    name = min(figures, key=lambda n: (figures[n]["bic"], list(figures).index(n)))
    candidates = {n: figures.get(n) or {"failed": failed[n]} for n in (*results, *failed)}
    return name, {"criterion": CRITERION, "chosen": name, "candidates": candidates}


def fitted(result) -> dict:
    """The fitted model of a candidate's `Identification` in the report's own form
    (`model`, `model_class`, `parameters`, `frozen`, `constants`: what `model_from_report`
    rebuilds), so that `autopilot` can design its feedback on the linear candidate."""
    report = result.to_dict()
    return {k: report[k] for k in ("model", "model_class", "parameters", "frozen", "constants")
            if k in report}


def linear_candidate(selection) -> dict | None:
    """The fitted linear Nomoto 1 (`fitted`) of a `selection` (a report's, or None) whose
    chosen model is another candidate: the model `autopilot` designs its feedback on.
    None where the choice was the linear model, there is no choice, or the linear fit
    did not succeed (not fitted, or a code other than successful: its T and K may be
    anything)."""
    if not isinstance(selection, dict) or selection.get("chosen") == LINEAR:
        return None
    entry = (selection.get("candidates") or {}).get(LINEAR)
    if not isinstance(entry, dict) or entry.get("fit_code") != "successful":
        return None
    return entry.get("fitted")


def selection_text(selection: dict) -> str:
    """The choice in one paragraph (the printed report and `summary`)."""
    parts = []
    for name, c in selection["candidates"].items():
        if "failed" in c:
            parts.append(f"{name}: not fitted ({c['failed']})")
        else:
            parts.append(f"{name}: BIC {c['bic']:.6g}, FPE {c['fpe']:.6g} (d = "
                         f"{c['num_params']}, N = {c['num_samples']}, {c['fit_code']})")
    return (f"model chosen: {selection['chosen']}, the least BIC on the training records "
            f"({'; '.join(parts)})")


def with_selection(result, selection: dict):
    """`result` (the chosen candidate's) carrying `selection`, with a note saying so."""
    return dataclasses.replace(result, selection=selection,
                               notes=result.notes + (selection_text(selection) + ".",))
