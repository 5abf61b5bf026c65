"""The final result code of a fit, from what the estimator's optimiser reported and what
the estimates and the data say: an estimate on a bound (`at_bound`), a fit of noise
(`undetermined`), a combination the data do not determine (`poorly_determined`)."""

import dataclasses
import math
import statistics

import numpy as np

from .._foundation._params import resolve_free
from ._lm import RESULTS
from ._result import FitResult


# the optimiser's codes that an estimate on a bound explains: it crawls towards the
# bound (softplus transform) until it settles or meets the step limit
_BOUND_EXPLAINS = (RESULTS.successful, RESULTS.nonlinear_max_steps_reached,
                   RESULTS.max_steps_reached)

# `RESULTS.undetermined`: a fit whose best channel explains less than NOISE_FIT_PERCENT of
# the measured variation (fit %, `validate`) explains almost nothing; a parameter of such a
# fit whose 95 % interval (value +- 1.96 standard errors) includes zero is not determined
# by the data. Issue 59 proposed the 68 % interval (one standard error); on pure noise an
# estimate is about N(0, sigma), so that interval misses zero a third of the time per
# parameter (Nomoto 1 fitted by output error to white noise: K 1.6 standard errors from
# zero, fit -0.6 %, "successful"); the 95 % one misses it 5 % of the time. White noise
# fitted by a p-parameter model over N samples explains by chance about 50 p / N % (fit % =
# 100 (1 - sqrt(1 - R^2)), R^2 ~ p / N: 0.3 % for p = 2, N = 300); a record with a rudder
# response worth the name explains tens of percent.
NOISE_LEVEL = 0.95
NOISE_FIT_PERCENT = 5.0


def optimiser_verdict(result, specs, p, rows, jac, pred, targets, mask) -> RESULTS:
    """The optimiser's code, unless the fit blew up (predictions not finite, or a
    thousand times the measured range of a channel) or stopped as converged without
    moving from a start where the cost is not stationary: the largest cosine between
    the residuals and a Jacobian column (the scaled gradient) above 1e-3. "Not moved":
    within 1e-10 of the start, or a few roundings of the float type of the estimates `p`
    (float32 stores a start of 1e-12 as 9.99999996e-13)."""
    values = np.asarray(p, dtype=np.float64)
    eps = float(np.finfo(np.asarray(p).dtype).eps)
    size = [np.max(np.abs(t[mask])) + np.std(t[mask]) for t in targets]
    blown = [np.max(np.abs(np.where(mask, p, 0.0))) > 1e3 * (s + 1e-9)
             for p, s in zip(pred, size)]
    if not np.all(np.isfinite(rows)) or not np.all(np.isfinite(jac)) or any(blown):
        return RESULTS.simulation_blew_up
    start = np.array([s.start for s in specs], dtype=np.float64)
    unmoved = np.all(np.abs(values - start) <= max(1e-10, 4 * eps) * np.abs(start))
    if result == RESULTS.successful and unmoved and rows.size:  # stopped as if converged
        norms = np.linalg.norm(jac, axis=0) * np.linalg.norm(rows)
        cosine = np.abs(rows @ jac) / np.where(norms > 0, norms, np.inf)
        if np.max(cosine, initial=0.0) > 1e-3:
            return RESULTS.did_not_move
    return result


def final_verdict(out: FitResult, model, free) -> FitResult:
    """`at_bound` when an estimate ended within 1e-4 of its bound span (or scale) from a
    bound, the optimiser having converged or crawled to its step limit; for a converged
    fit `undetermined` when it explains almost nothing and a parameter's 95 % interval
    includes zero (`noise_flags`), else `poorly_determined` when the data leave a
    combination of the parameters undetermined; the sentences join the parameter flags.
    Any other code stands as the estimator gave it."""
    if out.code not in _BOUND_EXPLAINS:
        return out
    report = out.parameters
    hits = bound_flags(out, model, free)
    if hits:
        report = dataclasses.replace(report, flags=report.flags + hits, bound_flags=hits)
        return dataclasses.replace(out, parameters=report, result=RESULTS.at_bound)
    if out.code != RESULTS.successful:
        return out
    noise = noise_flags(out)
    if noise:
        report = dataclasses.replace(report, flags=report.flags + noise,
                                     undetermined=report.undetermined + noise)
        return dataclasses.replace(out, parameters=report, result=RESULTS.undetermined)
    if report.undetermined:
        return dataclasses.replace(out, result=RESULTS.poorly_determined)
    return out


def bound_flags(out: FitResult, model, free) -> tuple[str, ...]:
    """A sentence for each estimate of `out` within 1e-4 of its bound span (or scale)
    from a bound of its `Free` spec."""
    values = dict(zip(out.names, np.asarray(out.values, dtype=np.float64)))
    hits = []
    for spec in resolve_free(model, free):
        value = values.get(spec.name)
        if value is None:
            continue
        span = spec.upper - spec.lower if math.isfinite(spec.upper - spec.lower) else spec.scale
        tol = 1e-4 * (span if span > 0 else 1.0)
        for side, bound in (("lower", spec.lower), ("upper", spec.upper)):
            if math.isfinite(bound) and abs(value - bound) <= tol:
                unit = f" {spec.unit}" if spec.unit and spec.unit != "-" else ""
                hits.append(f"{spec.name} = {value:.4g}{unit} ended on its {side} bound "
                            f"{bound:g}{unit}: the data pull it beyond the bound, so the fit "
                            "is not a proper optimum and its standard error means nothing.")
    return tuple(hits)


def noise_flags(out: FitResult) -> tuple[str, ...]:
    """The rule of `RESULTS.undetermined`: when no fitted channel's fit % (on the fitted
    data) reaches `NOISE_FIT_PERCENT`, a sentence for each free parameter $\\theta$ whose
    `NOISE_LEVEL` (95 %) interval includes zero, $|\\hat\\theta| \\le 1.96\\,
    \\sigma_\\theta$, with $\\sigma_\\theta$ the larger of the white-noise and the robust
    (HAC) standard error. Nothing otherwise."""
    fits = [m.fit_percent for m in out.metrics.values()]
    best = max((f for f in fits if math.isfinite(f)), default=-math.inf)
    if best >= NOISE_FIT_PERCENT:
        return ()
    report = out.parameters
    std = np.asarray(report.std, dtype=np.float64)
    if report.std_robust is not None:
        std = np.fmax(std, np.asarray(report.std_robust, dtype=np.float64))
    z = statistics.NormalDist().inv_cdf(0.5 + NOISE_LEVEL / 2)
    explained = ", ".join(f"{c} {m.fit_percent:.2f} %" for c, m in out.metrics.items())
    return tuple(
        f"{name} = {value:.4g} +- {s:.2g}: its {NOISE_LEVEL * 100:g} % interval includes zero on a "
        f"fit that explains almost nothing (fit {explained}, below {NOISE_FIT_PERCENT:g} %): "
        f"the data do not determine {name}."
        for name, value, s in zip(report.names, np.asarray(report.values, dtype=np.float64),
                                  std)
        if not abs(value) > z * s)
