"""Linear least squares (equation error) start values for the nonlinear fits.

Models that are linear in their parameters once the yaw acceleration is known are
fitted in one linear regression on the measured yaw rate and rudder (Ljung 1999,
sec. 7.3; the discrete response models of Lu & Zhao 2008, eqs. 7-8):

- `Nomoto1`: the exact zero-order-hold discretisation
  $r_{k+1} = a r_k + b\\delta_k + c$, $a = e^{-dt/T}$, $b = K(1 - a)$,
  $c = b\\delta_0$ (an ARX model; exact on noise-free data of the model) when all
  experiments share one sample interval, else the midpoint regression below.
- `NonlinearNomoto` (and `Nomoto1` with mixed sample intervals): the midpoint
  regression $T\\frac{r_{k+1} - r_k}{dt} + H_N(\\bar r_k) = K\\delta_k$ with
  $\\bar r_k = (r_k + r_{k+1})/2$, linear in $T, K, n_i$, second-order accurate.

With measurement noise on r these regressions are biased (errors in variables): they
give start values, not final estimates.
"""

import math

import numpy as np

from .._steering.nomoto import Nomoto1, NonlinearNomoto
from .._steering.ross import RossAutopilot, ross_initial_estimate
from ._params import resolve_free
from ._windows import as_dataset, check_data


def _pairs(ds, rudder):
    """(r_k, r_{k+1}, delta_k, dt, experiment index) over the valid samples."""
    r0, r1, d0, dt, which = [], [], [], [], []
    for i, n in enumerate(ds.lengths):
        r = np.asarray(ds.r, dtype=np.float64)[i, :n]
        d = np.asarray(getattr(ds, rudder), dtype=np.float64)[i, :n]
        r0.append(r[:-1])
        r1.append(r[1:])
        d0.append(d[:-1])
        dt.append(np.full(n - 1, float(np.asarray(ds.dt)[i])))
        which.append(np.full(n - 1, i))
    cat = np.concatenate
    return cat(r0), cat(r1), cat(d0), cat(dt), cat(which)


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


def initial_estimate(model, dataset, *, free=None, rudder: str = "delta"):
    """Equation-error least-squares start values for `model`'s free parameters
    (`free` as in `fit`); frozen parameters keep their values and enter the
    regression as known. Supported: `Nomoto1`, `NonlinearNomoto`, `RossAutopilot`
    (`jaxship._steering.ross.ross_initial_estimate`, one-interval span).

    **Returns:** a model of the same type with the estimates.

    **Raises:** `ValueError` for unsupported models, bad data (as `fit`) or data
    that do not excite the parameters.
    """
    ds = as_dataset(dataset)
    check_data(ds, rudder, ("r",))
    names = tuple(s.name for s in resolve_free(model, free))
    if isinstance(model, Nomoto1):
        return _nomoto1(model, ds, names, rudder)
    if isinstance(model, NonlinearNomoto):
        return _midpoint(model, ds, names, rudder)
    if isinstance(model, RossAutopilot):
        return ross_initial_estimate(model, ds, free=free, rudder=rudder)
    raise ValueError(f"no linear least-squares start for {type(model).__name__}; supported: "
                     "Nomoto1, NonlinearNomoto, RossAutopilot (start Nomoto2 from a fitted "
                     "Nomoto1).")


def _nomoto1(model, ds, names, rudder):
    r0, r1, d0, dt, _ = _pairs(ds, rudder)
    if np.ptp(np.asarray(ds.dt)) > 1e-9 * float(np.max(ds.dt)):
        as_nonlinear = NonlinearNomoto(K=model.K, T=model.T, n3=0.0, n2=0.0, n1=1.0,
                                       n0=-model.K * model.delta0)
        free = tuple(n for n in names if n in ("K", "T")) + (("n0",) if "delta0" in names else ())
        fitted = _midpoint(as_nonlinear, ds, free, rudder)
        values = {"K": fitted.K, "T": fitted.T,
                  "delta0": -fitted.n0 / fitted.K if "delta0" in names else model.delta0}
    else:
        step = float(dt[0])
        if "delta0" in names:
            columns, labels = [r0, d0, np.ones_like(r0)], ("a", "b", "c")
        else:
            columns, labels = [r0, d0 + model.delta0], ("a", "b")
        coef = _lstsq(np.stack(columns, axis=1), r1, labels, "Nomoto1 ARX start")
        a, b = coef[0], coef[1]
        if not 0.0 < a < 1.0:
            raise ValueError(f"Nomoto1 ARX start: the pole a = {a:.6g} is not in (0, 1), so the "
                             "data do not show a stable first-order response; give start "
                             "values by hand.")
        values = {"K": b / (1.0 - a), "T": -step / math.log(a),
                  "delta0": coef[2] / b if "delta0" in names else model.delta0}
    return _replace(model, {n: values[n] for n in names})


def _midpoint(model, ds, names, rudder):
    r0, r1, d0, dt, _ = _pairs(ds, rudder)
    rdot = (r1 - r0) / dt
    rm = 0.5 * (r0 + r1)
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
    import equinox as eqx

    if not values:
        return model
    names = tuple(values)
    return eqx.tree_at(lambda m: tuple(getattr(m, n) for n in names), model,
                       tuple(float(values[n]) for n in names))
