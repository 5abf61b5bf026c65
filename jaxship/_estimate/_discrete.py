"""The four discrete response models of Lu & Zhao (2008; seed 002), fitted by linear
least squares or by epsilon-support-vector regression, and converted back to the
continuous manoeuvring indices.

The continuous models (Lu & Zhao eqs. 1-4; $\\delta_r$ the rudder offset):

- `"linear1"`: eq. (1) $T\\dot r + r = K(\\delta + \\delta_r)$; discrete eq. (7)
  $r_k = a_1r_{k-1} + a_2\\delta_{k-1} + b_0$.
- `"nonlinear1"`: eq. (2) $\\dot r + \\alpha_1r + \\beta_1r^3 = \\alpha_2(\\delta + \\delta_r)$;
  eq. (8) $r_k = a_1r_{k-1} + a_2r_{k-1}^3 + a_3\\delta_{k-1} + b_0$.
- `"linear2"`: eq. (3) $T_1T_2\\ddot r + (T_1 + T_2)\\dot r + r = K(\\delta + \\delta_r) +
  KT_3\\dot\\delta$; eq. (9) $r_k = a_1r_{k-1} + a_2r_{k-2} + b_1\\delta_{k-1} +
  b_2\\delta_{k-2} + c_0$.
- `"nonlinear2"`: eq. (4), (3) with $\\alpha_1r + \\beta_1r^3$ for $r$; eq. (10), (9)
  $+\\,c_1r_{k-1}^3$.

with $\\alpha_2 = K/T$ in (2) (their Table 2) and $\\alpha_1 = 1$ in (4) (fixed, as
they do, for identifiability). The paper does not say how it discretised; here:

- `discretisation=ExactDiscretisation()` (default for the linear models): the exact zero-order-hold
  sampling (the rudder held over each sample interval, as recorded and replayed
  data are). (7): $a_1 = e^{-h/T}$, $a_2 = K(1 - a_1)$, $b_0 = a_2\\delta_r$; (9): the
  zero-order-hold transfer function of $K(1 + T_3s)/((1 + T_1s)(1 + T_2s))$
  (`scipy.signal.cont2discrete`), $c_0 = (b_1 + b_2)\\delta_r$. Exact on noise-free
  data of the continuous model.
- `discretisation=EulerDiscretisation()` (the only one for the nonlinear models, which have no
  exact sampled form): finite differences at sample $k-1$,
  $\\dot r \\approx (r_k - r_{k-1})/h$ for (8), and
  $\\ddot r \\approx (r_k - 2r_{k-1} + r_{k-2})/h^2$,
  $\\dot r \\approx (r_{k-1} - r_{k-2})/h$,
  $\\dot\\delta \\approx (\\delta_{k-1} - \\delta_{k-2})/h$
  for (10). First-order accurate in $h$: choose $h$ well below the time constants.

All four are linear in their coefficients: least squares (`method="ls"`) or
epsilon-SVR with a linear kernel (`method="svr"`, scikit-learn `LinearSVR`; Lu & Zhao
use a linear kernel and $C = 10^{10}$, sec. 2.1). Both are equation-error
estimates: biased when the measured r is noisy (errors in variables); they are
start values and quick looks, `fit` (prediction error) gives the final estimates.
"""

import cmath
import dataclasses
import math
import warnings
from collections.abc import Sequence

import equinox as eqx
import numpy as np
import scipy  # scipy.linalg loads on first use (an import-time saving)

from .._models._effects import nonlinear_nomoto2
from .._models._steering.nomoto import Nomoto1, Nomoto2, NonlinearNomoto
from .._simulation._data import Experiment


STRUCTURES = ("linear1", "nonlinear1", "linear2", "nonlinear2")
# the coefficient names of Lu & Zhao eqs. 7-10, in regression order
COEFFICIENTS = {
    "linear1": ("a1", "a2", "b0"),
    "nonlinear1": ("a1", "a2", "a3", "b0"),
    "linear2": ("a1", "a2", "b1", "b2", "c0"),
    "nonlinear2": ("a1", "a2", "b1", "b2", "c1", "c0"),
}
_ORDER = {"linear1": 1, "nonlinear1": 1, "linear2": 2, "nonlinear2": 2}


class ExactDiscretisation(eqx.Module):
    """`discretisation=ExactDiscretisation()`: the exact zero-order-hold sampling of the
    linear models (module docstring); the default for them."""

    name = "zoh"  # the label of `DiscreteResponseFit.discretisation`

    def check(self, structure: str) -> None:
        if structure.startswith("nonlinear"):
            raise ValueError(f"the nonlinear structure {structure!r} has no exact "
                             "zero-order-hold form; use EulerDiscretisation().")

    def pole(self, T: float, h: float) -> float:
        """$a_1 = e^{-h/T}$ of eq. (7)."""
        return math.exp(-h / T)

    def time_constant(self, a1: float, h: float) -> float:
        """$T$ from $a_1$ of eq. (7) (NaN where no positive real pole gives it)."""
        return -h / math.log(a1) if a1 > 0 and a1 != 1.0 else math.nan

    def second_order(self, structure, p, K, P, S, T3, dr, h) -> dict:
        """The coefficients of eq. (9) (`_zoh2_ps`), $c_0 = (b_1 + b_2)\\delta_r$."""
        a1, a2, b1, b2 = _zoh2_ps(K, P, S, T3, h)
        return {"a1": a1, "a2": a2, "b1": b1, "b2": b2, "c0": (b1 + b2) * dr}

    def second_order_inverse(self, structure, c, h, alpha1, out) -> tuple:
        """`(P, S, K, T3)` from the coefficients of eq. (9): the poles by the matrix
        logarithm of the sampled ones, $T_3$ by least squares on $b_1, b_2$."""
        a1, a2, b1, b2 = c["a1"], c["a2"], c["b1"], c["b2"]
        z = np.roots([1.0, -a1, -a2]).astype(complex)
        if np.any(np.abs(z) == 0):
            raise ValueError(f"{structure}: a pole at z = 0 has no continuous counterpart.")
        s = [cmath.log(zi) / h for zi in z]
        prod, total = s[0] * s[1], s[0] + s[1]
        ok = abs(prod.imag) <= 1e-9 * abs(prod) and abs(total.imag) <= 1e-9 * abs(total) + 1e-300
        P = 1.0 / prod.real if ok else math.nan
        S = -total.real / prod.real if ok else math.nan
        K = (b1 + b2) / (1.0 - a1 - a2)
        if not ok:
            return P, S, K, math.nan
        # b1, b2 are affine in T3 for given K, P, S: least squares for T3
        _, _, u1, u2 = _zoh2_ps(K, P, S, 0.0, h)
        _, _, v1, v2 = _zoh2_ps(K, P, S, 1.0, h)
        d = np.array([v1 - u1, v2 - u2])
        return P, S, K, float(d @ np.array([b1 - u1, b2 - u2]) / (d @ d))


class EulerDiscretisation(eqx.Module):
    """`discretisation=EulerDiscretisation()`: finite differences at sample $k-1$ (module
    docstring); the only one for the nonlinear models."""

    name = "euler"  # the label of `DiscreteResponseFit.discretisation`

    def check(self, structure: str) -> None:
        """Every structure has an Euler form."""

    def pole(self, T: float, h: float) -> float:
        """$a_1 = 1 - h/T$."""
        return 1.0 - h / T

    def time_constant(self, a1: float, h: float) -> float:
        return h / (1.0 - a1)

    def second_order(self, structure, p, K, P, S, T3, dr, h) -> dict:
        """The coefficients of eqs. (9), (10) by finite differences."""
        al1 = float(p.get("alpha1", 1.0))
        be1 = float(p.get("beta1", 0.0))
        out = {"a1": 2.0 - h * S / P - h * h * al1 / P, "a2": -1.0 + h * S / P,
               "b1": h * h * K / P + h * K * T3 / P, "b2": -h * K * T3 / P}
        if structure == "nonlinear2":
            out["c1"] = -h * h * be1 / P
        elif be1 != 0.0:
            raise ValueError("`beta1` is not a parameter of 'linear2'; use 'nonlinear2'.")
        out["c0"] = h * h * K * dr / P
        return out

    def second_order_inverse(self, structure, c, h, alpha1, out) -> tuple:
        """`(P, S, K, T3)` from the finite-difference coefficients; for `nonlinear2`
        `alpha1` and `beta1` join `out`."""
        al1 = float(alpha1) if structure == "nonlinear2" else 1.0
        P = h * h * al1 / (1.0 - c["a1"] - c["a2"])
        S = P * (1.0 + c["a2"]) / h
        K = (c["b1"] + c["b2"]) * P / (h * h)
        if structure == "nonlinear2":
            out["alpha1"] = al1
            out["beta1"] = -c["c1"] * P / (h * h)
        return P, S, K, -c["b2"] * P / (h * K)


DISCRETISATIONS = (ExactDiscretisation, EulerDiscretisation)
Discretisation = ExactDiscretisation | EulerDiscretisation


def _check_structure(structure, discretisation=None):
    """The discretisation of `structure`: `discretisation`, or by default the exact one
    for the linear models and Euler's for the nonlinear ones."""
    if structure not in STRUCTURES:
        raise ValueError(f"`structure` must be one of {STRUCTURES}, got {structure!r}.")
    if discretisation is None:
        linear = structure.startswith("linear")
        return ExactDiscretisation() if linear else EulerDiscretisation()
    if not isinstance(discretisation, DISCRETISATIONS):
        raise ValueError(f"`discretisation` must be ExactDiscretisation() or "
                         f"EulerDiscretisation(), got {discretisation!r}.")
    discretisation.check(structure)
    return discretisation


def regressors(structure: str, r, delta) -> tuple[np.ndarray, np.ndarray]:
    """The regression of one record: `(X, y)` with `y = r[k]` and the rows of `X`
    the regressors of Lu & Zhao eqs. 7-10 (columns in the order of
    `COEFFICIENTS[structure]`), for k = order..N-1."""
    _check_structure(structure)
    r = np.asarray(r, dtype=np.float64)
    d = np.asarray(delta, dtype=np.float64)
    if r.ndim != 1 or r.shape != d.shape:
        raise ValueError(f"`r` and `delta` must be 1-D arrays of one length, got shapes "
                         f"{r.shape} and {d.shape}.")
    p = _ORDER[structure]
    if r.size < p + 2:
        raise ValueError(f"{structure}: needs at least {p + 2} samples, got {r.size}.")
    r1, d1, one = r[p - 1:-1], d[p - 1:-1], np.ones(r.size - p)
    if structure == "linear1":
        cols = [r1, d1, one]
    elif structure == "nonlinear1":
        cols = [r1, r1**3, d1, one]
    else:
        r2, d2 = r[:-2], d[:-2]
        cols = [r1, r2, d1, d2] + ([r1**3] if structure == "nonlinear2" else []) + [one]
    return np.stack(cols, axis=1), r[p:]


# ---------------------------------------------------------------------------------------
# continuous <-> discrete


def _zoh2_ps(K, P, S, T3, h):
    """(a1, a2, b1, b2) of the zero-order-hold sampling of
    $K(1 + T_3s)/(Ps^2 + Ss + 1)$ at interval h, by the matrix exponential of the
    controllable realisation $\\dot x_1 = x_2$, $P\\dot x_2 = -x_1 - Sx_2 + \\delta$,
    $r = K(x_1 + T_3x_2)$ (Astrom & Wittenmark, Computer-Controlled Systems, ch. 2)."""
    m = np.zeros((3, 3))
    m[0, 1] = 1.0
    m[1, :] = [-1.0 / P, -S / P, 1.0 / P]
    e = scipy.linalg.expm(m * h)
    phi, gamma = e[:2, :2], e[:2, 2]
    c = np.array([K, K * T3])
    adj = np.array([[-phi[1, 1], phi[0, 1]], [phi[1, 0], -phi[0, 0]]])
    # r_k = tr(phi) r_{k-1} - det(phi) r_{k-2} + c.gamma d_{k-1} + c.adj.gamma d_{k-2}
    return (float(np.trace(phi)), float(-np.linalg.det(phi)), float(c @ gamma),
            float(c @ adj @ gamma))


def discretise(structure: str, parameters: dict, dt: float, *,
               discretisation: Discretisation | None = None) -> dict[str, float]:
    """The coefficients of the discrete model (Lu & Zhao eqs. 7-10) sampled from the
    continuous one (eqs. 1-4) at interval `dt` [s] (see the module docstring).

    `parameters`: `linear1` `K, T, delta_r`; `nonlinear1` `alpha1, beta1, alpha2,
    delta_r`; `linear2` `K, T1, T2, T3, delta_r`; `nonlinear2` the same plus `beta1`
    (and optional `alpha1`, default 1). `delta_r` defaults to 0.
    """
    how = _check_structure(structure, discretisation)
    h = float(dt)
    if not h > 0:
        raise ValueError(f"`dt` must be positive, got {dt}.")
    p = dict(parameters)
    dr = float(p.get("delta_r", 0.0))
    if structure == "linear1":
        K, T = float(p["K"]), float(p["T"])
        a1 = how.pole(T, h)
        a2 = K * (1.0 - a1)
        return {"a1": a1, "a2": a2, "b0": a2 * dr}
    if structure == "nonlinear1":
        al1, be1, al2 = float(p["alpha1"]), float(p["beta1"]), float(p["alpha2"])
        return {"a1": 1.0 - h * al1, "a2": -h * be1, "a3": h * al2, "b0": h * al2 * dr}
    K, T1, T2, T3 = (float(p[k]) for k in ("K", "T1", "T2", "T3"))
    return how.second_order(structure, p, K, T1 * T2, T1 + T2, T3, dr, h)


def _time_constants(P, S):
    """T1 >= T2 from T1 T2 = P and T1 + T2 = S; NaN when they are complex."""
    disc = S * S - 4.0 * P
    if not disc >= 0:
        return math.nan, math.nan
    root = math.sqrt(disc)
    return 0.5 * (S + root), 0.5 * (S - root)


def continuous_parameters(structure: str, coefficients: dict, dt: float, *,
                          discretisation: Discretisation | None = None, alpha1: float = 1.0
                          ) -> dict[str, float]:
    """Invert `discretise`: the manoeuvring indices of Lu & Zhao eqs. 1-4 from the
    discrete coefficients (eqs. 7-10), plus the combinations of their Tables 2-4.

    **Returns** a dict with, per structure:

    - `linear1`: `K` [1/s], `T` [s], `delta_r` [rad], `K_over_T` [1/s^2] ($\\alpha_2$ of Table 2).
    - `nonlinear1`: `alpha1` [1/s], `beta1` [s/rad^2], `alpha2` [1/s^2], `delta_r`, and the
      equivalent `K = alpha2/|alpha1|`, `T = 1/|alpha1|`.
    - `linear2`, `nonlinear2`: `K`, `T1` >= `T2`, `T3` [s], `delta_r`, (nonlinear2:
      `alpha1` (fixed), `beta1` [s/rad^2]), the Table 4 combinations
      `S_over_P` $= (T_1 + T_2)/(T_1T_2)$ [1/s], `K_over_P` $= K/(T_1T_2)$ [1/s^3],
      `KT3_over_P` $= KT_3/(T_1T_2)$ [1/s^2], and `T` $= T_1 + T_2 - T_3$ (Nomoto's
      first-order approximation, Astrom & Kallstrom 1979 eq. 6; Lu & Zhao's eq. 14
      drops $T_3$). `T1`, `T2` are NaN when the poles are complex (or, for ZOH, not
      on the positive real axis); `S_over_P` etc. stay defined where possible.

    `alpha1`: the fixed linear coefficient of `nonlinear2` (Lu & Zhao set it to 1).
    """
    how = _check_structure(structure, discretisation)
    h = float(dt)
    c = {k: float(coefficients[k]) for k in COEFFICIENTS[structure]}
    if structure == "linear1":
        a1, a2, b0 = c["a1"], c["a2"], c["b0"]
        T = how.time_constant(a1, h)
        K = a2 / (1.0 - a1)
        return {"K": K, "T": T, "delta_r": b0 / a2, "K_over_T": K / T}
    if structure == "nonlinear1":
        al1, be1, al2 = (1.0 - c["a1"]) / h, -c["a2"] / h, c["a3"] / h
        return {"alpha1": al1, "beta1": be1, "alpha2": al2, "delta_r": c["b0"] / c["a3"],
                "K": al2 / abs(al1), "T": 1.0 / abs(al1)}
    out = {}
    P, S, K, T3 = how.second_order_inverse(structure, c, h, alpha1, out)
    c0, gain = c["c0"], c["b1"] + c["b2"]
    T1, T2 = _time_constants(P, S)
    out.update({"K": K, "T1": T1, "T2": T2, "T3": T3, "delta_r": c0 / gain,
                "S_over_P": S / P, "K_over_P": K / P, "KT3_over_P": K * T3 / P,
                "T": S - T3})
    return out


# ---------------------------------------------------------------------------------------
# fitting


def _records(data, rudder):
    if isinstance(data, Experiment):
        data = [data]
    if not isinstance(data, Sequence) or not data:
        raise ValueError("`data` must be a jaxship Experiment or a non-empty list of them, got "
                         f"{type(data).__name__}.")
    if rudder not in ("delta", "delta_c"):
        raise ValueError(f"`rudder` must be 'delta' or 'delta_c', got {rudder!r}.")
    steps = []
    for i, e in enumerate(data):
        if not isinstance(e, Experiment):
            raise ValueError(f"`data[{i}]` is a {type(e).__name__}, not a jaxship.Experiment.")
        if not e.is_uniform():
            raise ValueError(f"experiment {e.name!r} is not uniformly sampled; the discrete "
                             "models need one sample interval (resample it).")
        steps.append(e.dt)
    if max(steps) - min(steps) > 1e-6 * max(steps):
        raise ValueError(f"the experiments have different sample intervals {sorted(set(steps))}; "
                         "the discrete models need one.")
    return list(data), float(np.mean(steps))


class LeastSquaresRegression(eqx.Module):
    """`DiscreteResponse(method=LeastSquaresRegression())` (the default): the discrete
    coefficients by linear least squares (`numpy.linalg.lstsq` on the columns scaled to
    unit norm)."""

    name = "ls"  # the label of `FitResult.criterion`

    def coefficients(self, x, y) -> tuple[np.ndarray, bool]:
        """`(coefficients, converged)` of $y \\approx X c$."""
        norms = np.sqrt(np.sum(x**2, axis=0))
        return np.linalg.lstsq(x / norms, y, rcond=None)[0] / norms, True

    def covariance(self, x, rms: float) -> np.ndarray:
        """$\\hat\\sigma^2(X^TX)^{-1}$, $\\hat\\sigma^2 = \\mathrm{RSS}/(N - p)$, from the
        equation-error RMS `rms`."""
        rows, count = x.shape
        sigma2 = rms**2 * rows / max(rows - count, 1)
        return sigma2 * np.linalg.inv(x.T @ x)


class SupportVectorRegression(eqx.Module):
    """`DiscreteResponse(method=SupportVectorRegression(C, epsilon))`: the discrete
    coefficients by epsilon-SVR with a linear kernel (scikit-learn `LinearSVR`; Lu & Zhao
    2008), regulariser `C`, insensitivity `epsilon` [rad/s], liblinear's tolerance `tol`
    and iteration limit `max_iter` (needs `pip install scikit-learn`)."""

    C: float = 1e10
    epsilon: float = 0.0
    tol: float = 1e-8
    max_iter: int = 20_000

    name = "svr"  # the label of `FitResult.criterion`

    def coefficients(self, x, y) -> tuple[np.ndarray, bool]:
        """`(coefficients, converged)` of $y \\approx X c$ (`_svr`)."""
        return _svr(x, y, self.C, self.epsilon, self.tol, self.max_iter)

    def covariance(self, x, rms: float) -> np.ndarray:
        """Not known for the epsilon-insensitive loss: NaN."""
        return np.full((x.shape[1],) * 2, np.nan)


def _svr(x, y, C, epsilon, tol, max_iter):
    try:
        from sklearn.exceptions import ConvergenceWarning as LiblinearWarning
        from sklearn.svm import LinearSVR
    except ImportError as err:  # pragma: no cover - depends on the environment
        raise ImportError("SupportVectorRegression() needs scikit-learn: pip install "
                          "'jaxship[svm]'.") from err
    # Precondition: regress on orthonormal features q = x R^-1 (x = QR) scaled to unit
    # RMS, then map back w = R^-1 w_q. The epsilon-insensitive loss depends on x w
    # only, so this changes nothing but the regulariser, ||w_q||^2 instead of ||w||^2,
    # which C = 1e10 (Lu & Zhao) makes negligible either way; it turns the badly
    # conditioned lagged regressors (r_{k-1}, r_{k-2} nearly equal) into a problem
    # that liblinear's dual coordinate descent solves in a few hundred sweeps instead
    # of not converging. The intercept is the column of ones (fit_intercept=False).
    n = x.shape[0]
    q, rmat = np.linalg.qr(x)
    ys = float(np.sqrt(np.mean(y**2))) or 1.0
    reg = LinearSVR(C=C, epsilon=epsilon / ys, loss="epsilon_insensitive", fit_intercept=False,
                    dual=True, tol=tol, max_iter=max_iter)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        reg.fit(q * math.sqrt(n), y / ys)
    converged = not any(issubclass(w.category, LiblinearWarning) for w in caught)
    coef = np.linalg.solve(rmat, reg.coef_ * math.sqrt(n)) * ys
    return coef, converged


@dataclasses.dataclass(frozen=True)
class DiscreteResponseFit:
    """Result of `DiscreteResponse.regress`: the discrete coefficients (Lu & Zhao eqs.
    7-10), the continuous indices (`continuous_parameters`), the sample interval `dt`
    [s], the estimation `method` (`LeastSquaresRegression` or `SupportVectorRegression`),
    whether the solver `converged`,
    the equation-error RMS `rms` [rad/s] and the number of regression rows `num_rows`."""

    structure: str
    method: eqx.Module
    discretisation: Discretisation
    dt: float
    coefficients: dict
    parameters: dict
    rms: float
    num_rows: int
    converged: bool = True

    def one_step(self, r, delta) -> np.ndarray:
        """One-step predictions of r [rad/s] for samples order..N-1 of a record."""
        x, _ = regressors(self.structure, r, delta)
        return x @ np.array([self.coefficients[k] for k in COEFFICIENTS[self.structure]])

    def simulate(self, delta, r0: float = 0.0) -> np.ndarray:
        """Run the difference equation on the rudder `delta` [rad] (held from each
        sample), shape `(N,)`, from `r[0] = r0` with, before sample 0, the yaw rate
        `r0` and zero rudder (from rest when `r0 = 0`, as `simulate` starts a steering model)."""
        d = np.concatenate([[0.0], np.asarray(delta, dtype=np.float64)])
        c = self.coefficients
        r = np.full(d.shape, float(r0))
        for k in range(2, d.size):
            if self.structure in ("linear1", "nonlinear1"):
                nl = c["a2"] * r[k - 1] ** 3 if self.structure == "nonlinear1" else 0.0
                lin = c["a3" if self.structure == "nonlinear1" else "a2"] * d[k - 1]
                r[k] = c["a1"] * r[k - 1] + nl + lin + c["b0"]
            else:
                nl = c["c1"] * r[k - 1] ** 3 if self.structure == "nonlinear2" else 0.0
                r[k] = (c["a1"] * r[k - 1] + c["a2"] * r[k - 2] + c["b1"] * d[k - 1]
                        + c["b2"] * d[k - 2] + nl + c["c0"])
        return r[1:]

    def to_steering(self):
        """The continuous model (Lu & Zhao eqs. 1-4) as a jaxship steering model:
        `Nomoto1`, `NonlinearNomoto` (with $n_1 = \\mathrm{sign}\\,\\alpha_1$,
        $n_3 = \\beta_1/|\\alpha_1|$, $n_0 = -K\\delta_r$), `Nomoto2` or
        `nonlinear_nomoto2` (`Nomoto2` with `YawCubicDamping`); the offset is
        `delta0`. Raises `ValueError` when the second-order time constants are complex
        or not positive."""
        p = self.parameters
        if self.structure == "linear1":
            return Nomoto1(K=p["K"], T=p["T"], delta0=p["delta_r"])
        if self.structure == "nonlinear1":
            return NonlinearNomoto(K=p["K"], T=p["T"], n3=p["beta1"] / abs(p["alpha1"]),
                                   n2=0.0, n1=float(np.sign(p["alpha1"])),
                                   n0=-p["K"] * p["delta_r"])
        if not (p["T1"] > 0 and p["T2"] > 0):
            raise ValueError(f"{self.structure}: T1 = {p['T1']}, T2 = {p['T2']} are not both "
                             "real and positive; no Nomoto2 realisation (use the discrete "
                             "model, `simulate`).")
        if self.structure == "linear2":
            return Nomoto2(K=p["K"], T1=p["T1"], T2=p["T2"], T3=p["T3"], delta0=p["delta_r"])
        if p["alpha1"] != 1.0:
            raise ValueError(f"nonlinear2 with alpha1 = {p['alpha1']} (not 1) has no "
                             "Nomoto2 realisation here; fit it with alpha1=1.")
        return nonlinear_nomoto2(K=p["K"], T1=p["T1"], T2=p["T2"], T3=p["T3"],
                                 beta1=p["beta1"], delta0=p["delta_r"])


def regress(structure: str, data, *,
            method: LeastSquaresRegression | SupportVectorRegression = LeastSquaresRegression(),
            discretisation: Discretisation | None = None, rudder: str = "delta",
            alpha1: float = 1.0) -> DiscreteResponseFit:
    """Regress one of Lu & Zhao's discrete response models (eqs. 7-10) on measured yaw
    rate and rudder and convert it to the continuous indices (eqs. 1-4): the step of
    `DiscreteResponse` (`jaxship.fit`'s estimator, and its `regress` method).

    **Arguments:**

    - `structure`: `"linear1"`, `"nonlinear1"`, `"linear2"` or `"nonlinear2"`.
    - `data`: an `Experiment` or a list of them (one sample interval); regressions
      never reach across records.
    - `method`: `LeastSquaresRegression()` (default) or `SupportVectorRegression(C,
      epsilon, tol, max_iter)`: the strategy that computes the coefficients.
    - `discretisation`: `ExactDiscretisation()` (linear models, default) or
      `EulerDiscretisation()`.
    - `rudder`: `"delta"` (actual) or `"delta_c"` (commanded).
    - `alpha1`: fixed linear coefficient of `nonlinear2` (1 as in Lu & Zhao).

    **Raises:** `ValueError` for bad arguments or data that do not excite the
    coefficients (singular regression).
    """
    how = _check_structure(structure, discretisation)
    if not isinstance(method, (LeastSquaresRegression, SupportVectorRegression)):
        raise ValueError(f"`method` must be LeastSquaresRegression() or "
                         f"SupportVectorRegression(), got {method!r}.")
    records, dt = _records(data, rudder)
    parts = [regressors(structure, e.r, getattr(e, rudder)) for e in records]
    x = np.concatenate([p[0] for p in parts])
    y = np.concatenate([p[1] for p in parts])
    names = COEFFICIENTS[structure]
    norms = np.sqrt(np.sum(x**2, axis=0))
    if np.any(norms == 0):
        raise ValueError(f"{structure}: the regressor of {names[int(np.argmin(norms))]} is zero "
                         "in the data (no excitation).")
    sv = np.linalg.svd(x / norms, compute_uv=False)
    if sv[-1] < 1e-12 * sv[0]:
        raise ValueError(f"{structure}: the regression is singular (condition number "
                         f"{sv[0] / max(sv[-1], 1e-300):.3g}); the data do not excite all of "
                         f"{', '.join(names)}.")
    coef, converged = method.coefficients(x, y)
    coefficients = dict(zip(names, map(float, coef)))
    params = continuous_parameters(structure, coefficients, dt, discretisation=how,
                                   alpha1=alpha1)
    rms = float(np.sqrt(np.mean((y - x @ coef) ** 2)))
    return DiscreteResponseFit(structure, method, how, dt, coefficients, params, rms,
                               int(y.size), converged)
