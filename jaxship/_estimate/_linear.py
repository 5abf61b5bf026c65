"""Linear least squares (equation error) start values for the nonlinear fits.

Models that are linear in their parameters once the yaw acceleration is known are
fitted in one linear regression on the measured yaw rate and rudder (Ljung 1999,
sec. 7.3; the discrete response models of Lu & Zhao 2008, eqs. 7-8):

- `Nomoto1`: the exact discretisation $r_{k+1} = a r_k + b\\delta_k + c$ of a
  rudder held over each interval (zero-order hold), $a = e^{-dt/T}$, $b = K(1 - a)$,
  $c = b\\delta_0$, or $r_{k+1} = a r_k + b_0\\delta_k + b_1\\delta_{k+1} + c$ of a
  rudder linear between samples (first-order hold), $b_0 + b_1 = K(1 - a)$ (ARX
  models; exact on noise-free data of the model) when all experiments share one
  sample interval, else the midpoint regression below.
- `NonlinearNomoto` (and `Nomoto1` with mixed sample intervals): the midpoint
  regression $T\\frac{r_{k+1} - r_k}{dt} + H_N(\\bar r_k) = K\\bar\\delta_k$ with
  $\\bar r_k = (r_k + r_{k+1})/2$ and $\\bar\\delta_k$ the mean rudder over the
  interval, linear in $T, K, n_i$, second-order accurate.

With measurement noise on r these regressions are biased (errors in variables): they
give start values, not final estimates.
"""

import math

import equinox as eqx
import numpy as np

from .._foundation._params import as_arrays, resolve_free
from .._models._holds import FirstOrderHold, ZeroOrderHold
from .._models._steering._base import AuxInputs
from .._models._steering.nomoto import Nomoto1, NonlinearNomoto
from .._models._steering.ross import HULL_TERMS, RUDDER_TERMS, RossAutopilot
from ._windows import as_dataset, check_data, resolve_holds


def _pairs(ds, rudder):
    """(r_k, r_{k+1}, delta_k, delta_{k+1}, dt, experiment index) over the valid samples."""
    r0, r1, d0, d1, dt, which = [], [], [], [], [], []
    for i, n in enumerate(ds.lengths):
        r = np.asarray(ds.r, dtype=np.float64)[i, :n]
        d = np.asarray(getattr(ds, rudder), dtype=np.float64)[i, :n]
        r0.append(r[:-1])
        r1.append(r[1:])
        d0.append(d[:-1])
        d1.append(d[1:])
        dt.append(np.full(n - 1, float(np.asarray(ds.dt)[i])))
        which.append(np.full(n - 1, i))
    cat = np.concatenate
    return cat(r0), cat(r1), cat(d0), cat(d1), cat(dt), cat(which)


def _lstsq(x, y, names, what):
    x = np.asarray(x, dtype=np.float64)
    norms = np.sqrt(np.sum(x**2, axis=0))
    if np.any(norms == 0):
        raise ValueError(f"{what}: the regressor of {names[int(np.argmin(norms))]} is zero in "
                         "the data (no excitation); cannot compute start values.")
    coef, _, rank, s = np.linalg.lstsq(x / norms, y, rcond=None)
    if rank < x.shape[1] or s[-1] < 1e-10 * s[0]:
        raise ValueError(f"{what}: the regression is singular (condition number "
                         f"{s[0] / max(s[-1], 1e-300):.3g}); the data do not excite all of "
                         f"{', '.join(names)}.")
    return coef / norms


class LinearStart(eqx.Module):
    """The start-value strategy of `PredictionError(start=LinearStart())`: before the
    optimiser runs, the free parameters get their equation-error least-squares
    estimates (`initial_estimate`; frozen ones enter as known). `span`: sample
    intervals per regression row of `RossAutopilot` (longer averages the noise on r);
    `hold` as `PredictionError(hold=...)`. `fit(model, data, estimator=
    PredictionError(start=LinearStart(), max_steps=0)).model` is the start itself."""

    span: int = 1
    hold: ZeroOrderHold | FirstOrderHold | dict | None = None

    def __call__(self, model, dataset, free, rudder: str):
        return initial_estimate(model, dataset, free=free, rudder=rudder, hold=self.hold,
                                span=self.span)


def initial_estimate(model, dataset, *, free=None, rudder: str = "delta", hold=None,
                     span: int = 1):
    """Equation-error least-squares start values for `model`'s free parameters
    (`free` as in `fit`); frozen parameters keep their values and enter the
    regression as known. Supported: `Nomoto1`, `NonlinearNomoto`, `RossAutopilot`
    (`_ross`, over `span` sample intervals). `hold`: the rudder between samples, as
    `PredictionError(hold=...)` (default: linear for the measured angle `delta`, held
    for the command `delta_c`).

    **Returns:** a model of the same type with the estimates.

    **Raises:** `ValueError` for unsupported models, bad data (as `fit`) or data
    that do not excite the parameters.
    """
    ds = as_dataset(dataset)
    check_data(ds, rudder, ("r",))
    names = tuple(s.name for s in resolve_free(model, free))
    held = dict(resolve_holds(rudder, hold, ("delta",)))["delta"]
    if isinstance(model, Nomoto1):
        return _nomoto1(model, ds, names, rudder, held)
    if isinstance(model, NonlinearNomoto):
        return _midpoint(model, ds, names, rudder, held)
    if isinstance(model, RossAutopilot):
        return _ross(model, ds, free=free, rudder=rudder, hold=hold, span=span)
    raise ValueError(f"no linear least-squares start for {type(model).__name__}; supported: "
                     "Nomoto1, NonlinearNomoto, RossAutopilot (start Nomoto2 from a fitted "
                     "Nomoto1).")


def _nomoto1(model, ds, names, rudder, held):
    r0, r1, d0, d1, dt, _ = _pairs(ds, rudder)
    if np.ptp(np.asarray(ds.dt)) > 1e-9 * float(np.max(ds.dt)):
        as_nonlinear = NonlinearNomoto(K=model.K, T=model.T, n3=0.0, n2=0.0, n1=1.0,
                                       n0=-model.K * model.delta0)
        free = tuple(n for n in names if n in ("K", "T")) + (("n0",) if "delta0" in names else ())
        fitted = _midpoint(as_nonlinear, ds, free, rudder, held)
        values = {"K": fitted.K, "T": fitted.T,
                  "delta0": -fitted.n0 / fitted.K if "delta0" in names else model.delta0}
    else:
        step = float(dt[0])
        rudders = held.interval_samples(d0, d1)
        if "delta0" in names:
            columns = [r0, *rudders, np.ones_like(r0)]
        else:
            columns = [r0, *(d + model.delta0 for d in rudders)]
        labels = ("a", "b0", "b1")[: 1 + len(rudders)] + (("c",) if "delta0" in names else ())
        coef = _lstsq(np.stack(columns, axis=1), r1, labels, "Nomoto1 ARX start")
        a, b = coef[0], float(np.sum(coef[1: 1 + len(rudders)]))
        if not 0.0 < a < 1.0:
            raise ValueError(f"Nomoto1 ARX start: the pole a = {a:.6g} is not in (0, 1), so the "
                             "data do not show a stable first-order response; give start "
                             "values by hand.")
        values = {"K": b / (1.0 - a), "T": -step / math.log(a),
                  "delta0": coef[-1] / b if "delta0" in names else model.delta0}
    return _replace(model, {n: values[n] for n in names})


def _midpoint(model, ds, names, rudder, held):
    r0, r1, d0, d1, dt, _ = _pairs(ds, rudder)
    rdot = (r1 - r0) / dt
    rm = 0.5 * (r0 + r1)
    d0 = held.interval_mean(d0, d1)  # the mean rudder over the interval
    # T rdot + n3 rm^3 + n2 rm^2 + n1 rm + n0 - K delta = 0
    terms = {"T": rdot, "n3": rm**3, "n2": rm**2, "n1": rm, "n0": np.ones_like(rm), "K": -d0}
    known = sum(float(getattr(model, n)) * x for n, x in terms.items() if n not in names)
    if np.all(np.asarray(known) == 0.0):
        raise ValueError("NonlinearNomoto start: at least one of T, K, n_i must be frozen at a "
                         "nonzero value (n1 = 1 by default) to fix the scale.")
    coef = _lstsq(np.stack([terms[n] for n in names], axis=1), -known, names,
                  f"{type(model).__name__} start")
    values = dict(zip(names, coef))
    if "T" in values and not values["T"] > 0:
        raise ValueError(f"{type(model).__name__} start: the regression gives T = "
                         f"{values['T']:.4g} <= 0; give start values by hand.")
    return _replace(model, values)


def _replace(model, values):
    if not values:
        return model
    names = tuple(values)
    return eqx.tree_at(lambda m: tuple(getattr(m, n) for n in names), model,
                       tuple(float(values[n]) for n in names))


def _ross(model: RossAutopilot, dataset, *, free=None, rudder: str = "delta", span: int = 1,
          hold=None) -> RossAutopilot:
    """Equation-error least-squares start values of `RossAutopilot` (`free` as in
    `fit`; frozen parameters enter as known).

    The model is linear in its coefficients, $\\dot r = (U_0/L)^2\\phi(r, \\delta, u, v,
    n)\\cdot a$. Integrated over `span` sample intervals with the trapezoid rule for
    r and the inputs held (or, with a first-order `hold`, at the interval midpoints),

    $$r_{k+m} - r_k = \\frac{U_0^2}{L^2}\\sum_{j=k}^{k+m-1} dt\\,
    \\phi\\big(\\tfrac12(r_j + r_{j+1}), \\delta_j, u_j, v_j, n_j\\big)\\cdot a,$$

    one linear regression over all (non-overlapping) spans of all experiments. A
    longer span averages measurement noise on r (the regressand is a difference of
    noisy samples) at the price of discretisation error. Like every equation-error
    estimate it is biased by noise in the regressors; it gives start values for
    `fit`, not final estimates.

    **Raises:** `ValueError` for bad data (as `fit`) or data that do not excite the
    free parameters (singular regression).
    """
    if not isinstance(model, RossAutopilot):
        raise ValueError(f"`model` must be a RossAutopilot, got {type(model).__name__}.")
    span = int(span)
    if span < 1:
        raise ValueError(f"`span` must be a positive number of samples, got {span}.")
    ds = as_dataset(dataset)
    check_data(ds, rudder, ("r",))
    names = tuple(s.name for s in resolve_free(model, free))
    held = dict(resolve_holds(rudder, hold, ("delta",)))["delta"]
    order = tuple(h for h, _ in HULL_TERMS) + RUDDER_TERMS
    gain = (float(model.speed) / float(model.length)) ** 2
    # the inputs over each interval: held, or (first-order hold) at its midpoint; every
    # record's intervals in one evaluation of the regressors (one program, not op by op)
    lengths = [int(num) for num in ds.lengths]
    get = lambda key: [np.asarray(getattr(ds, key), dtype=np.float64)[i, :num]
                       for i, num in enumerate(lengths)]
    over = lambda rows: np.concatenate([held.interval_mean(a[:-1], a[1:]) for a in rows])
    records = get("r")
    aux = AuxInputs(u=over(get("u")), v=over(get("v")), n=over(get("n")))
    r_mid = np.concatenate([0.5 * (r[:-1] + r[1:]) for r in records])
    phi_all = np.asarray(_regressors(as_arrays(model), r_mid, over(get(rudder)), aux),
                         np.float64)
    rows, targets = [], []
    for i, (num, r, phi) in enumerate(zip(lengths, records, np.split(
            phi_all, np.cumsum([num - 1 for num in lengths])[:-1]))):
        count = (num - 1) // span
        if count == 0:
            continue
        dt = float(np.asarray(ds.dt)[i])
        rows.append(phi[: count * span].reshape(count, span, -1).sum(axis=1) * dt * gain)
        targets.append(r[span: count * span + 1: span] - r[: count * span: span])
    if not rows:
        raise ValueError(f"RossAutopilot start: no experiment has more than `span` = {span} "
                         "samples.")
    phi, y = np.concatenate(rows), np.concatenate(targets)
    columns = [order.index(n) for n in names]
    frozen = [k for k, n in enumerate(order) if n not in names]
    a = np.asarray(model.coefficients(), dtype=np.float64)
    known = phi[:, frozen] @ a[frozen] if frozen else 0.0
    coef = _lstsq(phi[:, columns], y - known, names, "RossAutopilot start")
    return _replace(model, dict(zip(names, coef)))


@eqx.filter_jit
def _regressors(model, r, delta, aux):
    """`model.regressors(r, delta, aux)` as one compiled program."""
    return model.regressors(r, delta, aux)
