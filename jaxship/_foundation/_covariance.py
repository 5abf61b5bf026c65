"""Parameter uncertainty of least-squares estimates: covariances
(`least_squares_covariance`, the Newey-West HAC sandwich `hac_covariance`,
`hac_from_windows`, `cluster_from_windows`) and a prior's share of it
(`effective_parameters`, `information_share`); the verdict on them is
`_parameter_report.py`'s. Host-side NumPy (float64), following Ljung (1999), *System
Identification*, 2nd ed., ch. 9 and 16.
"""

import math

import numpy as np


# ---------------------------------------------------------------------------------------
# parameter uncertainty


def _normalised_inverse(jac, rcond):
    """`(pinv, scale, undetermined, null)` of a Jacobian (N, d): `pinv` is
    $(J_n^TJ_n)^+$ of the column-normalised $J_n = J/\\mathrm{scale}$, directions
    with a singular value below `rcond` times the largest dropped; `null` the unit
    vectors (d,) spanning them and `undetermined` the parameters taking part."""
    d = jac.shape[1]
    norms = np.sqrt(np.sum(jac**2, axis=0))
    safe = np.where(norms > 0, norms, 1.0)
    jn = jac / safe
    _, s, vt = np.linalg.svd(jn, full_matrices=False)
    tol = rcond * (s[0] if s.size and s[0] > 0 else 1.0)
    good = (s > tol) & (s > 0)
    null = [vt[i] for i in range(len(s)) if not good[i]]
    for i in np.nonzero(norms == 0)[0]:  # zero columns: already in `null` via SVD, but be sure
        if not any(abs(v[i]) > 0.5 for v in null):
            unit = np.zeros(d)
            unit[i] = 1.0
            null.append(unit)
    pinv_a = (vt[good].T / s[good] ** 2) @ vt[good]  # (Jn^T Jn)^+
    undetermined = np.zeros(d, dtype=bool)
    for v in null:
        undetermined |= np.abs(v) > 1e-3
    return pinv_a, safe, undetermined, null


def least_squares_covariance(jacobian, residuals, groups=None, *, num_params=None,
                             rcond: float = 1e-10, prior_precision=None):
    """Covariance of a least-squares estimate from the Jacobian at the optimum.

    With one group (all residuals equally weighted) this is
    $\\hat\\sigma^2 (J^TJ)^{-1}$, $\\hat\\sigma^2 = \\sum\\varepsilon^2/(N - d)$
    (Ljung 1999, eq. 9.18). With several groups (e.g. heading and yaw-rate residuals
    with fixed weights) each group g gets its own variance
    $\\hat\\sigma_g^2 = \\sum_g\\varepsilon^2 N/(N_g(N - d))$ and the covariance is the
    sandwich $A^{-1}(\\sum_g\\hat\\sigma_g^2 J_g^TJ_g)A^{-1}$, $A = J^TJ$, which is
    right for any fixed weights when the residuals are white within a group and
    independent between groups. For correlated residuals see `hac_covariance`.

    The computation is done on the column-normalised Jacobian (scale invariant);
    directions whose singular value is below `rcond` times the largest are not
    determined by the data: the parameters taking part in them get infinite
    variance.

    **Arguments:** `jacobian` (N, d) of the (weighted) residuals with respect to
    the physical parameters; `residuals` (N,); `groups` (N,) integer labels or None.

    **Prior.** `prior_precision` (d,): the diagonal of a Gaussian prior's precision $P$ in
    the residuals' scale (0 where a parameter has none; see `jaxship/_estimate/_prior.py`):
    the posterior covariance $A^{-1}(\\sum_g\\hat\\sigma_g^2 J_g^TJ_g + \\hat\\sigma^2 P)
    A^{-1}$, $A = J^TJ + P$ (the prior's rows a group of the pooled variance
    $\\hat\\sigma^2$; with one group $\\hat\\sigma^2 A^{-1}$), and the degrees of freedom
    $N - d_\\text{eff}$ (`effective_parameters`).

    **Returns:** `(covariance (d, d), null_directions)`, the second a list of unit
    vectors (d,) spanning the undetermined directions (empty if none).
    """
    jac = np.asarray(jacobian, dtype=np.float64)
    res = np.asarray(residuals, dtype=np.float64).reshape(-1)
    num, d = jac.shape
    if res.shape[0] != num:
        raise ValueError(f"`residuals` has {res.shape[0]} entries, `jacobian` {num} rows.")
    groups = np.zeros(num, dtype=int) if groups is None else np.asarray(groups).reshape(-1)
    if prior_precision is not None:
        return _posterior_covariance(jac, res, groups, prior_precision, rcond)
    pinv_a, safe, undetermined, null = _normalised_inverse(jac, rcond)
    jn = jac / safe
    dof = max(num - d, 1)
    middle = np.zeros((d, d))
    for g in np.unique(groups):
        sel = groups == g
        num_g = int(sel.sum())
        sigma2 = float(np.sum(res[sel] ** 2)) * num / (num_g * dof)
        middle += sigma2 * jn[sel].T @ jn[sel]
    cov_n = pinv_a @ middle @ pinv_a
    cov = cov_n / safe[:, None] / safe[None, :]
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return cov, null


def _with_prior(rows, prior, rcond):
    """`_normalised_inverse` of `rows` (N, d) with the rows $\\sqrt{P}$ of a prior below
    and the prior's term $\\hat\\sigma^2 P$ of the sandwich's middle (normalised), for
    `prior = (precision (d,), variance)`; without a prior (None) the rows' own and 0."""
    if prior is None:
        return _normalised_inverse(rows, rcond), 0.0
    precision, variance = np.asarray(prior[0], dtype=np.float64), float(prior[1])
    out = _normalised_inverse(np.vstack([rows, np.diag(np.sqrt(precision))]), rcond)
    return out, variance * np.diag(precision / out[1] ** 2)


def effective_parameters(jacobian, prior_precision) -> float:
    """The effective number of parameters of a regularised least-squares fit, the trace
    of its hat matrix $d_\\text{eff} = \\mathrm{tr}\\,J(J^TJ + P)^{-1}J^T$ (Hastie,
    Tibshirani & Friedman 2009, eq. 3.50), for `jacobian` (N, d) and the diagonal
    `prior_precision` (d,) in the residuals' scale: d without a prior (P = 0, J of full
    rank), 0 for an infinitely strong one."""
    jac = np.asarray(jacobian, dtype=np.float64)
    (pinv_a, safe, _, _), _ = _with_prior(jac, (prior_precision, 0.0), 1e-10)
    jn = jac / safe
    return float(np.trace(pinv_a @ (jn.T @ jn)))


def information_share(jacobian, prior_precision) -> np.ndarray:
    """The data's share of each parameter's information in a fit with a Gaussian prior of
    diagonal precision `prior_precision` (d,), one minus the posterior over the prior
    variance, $1 - [(J^TJ + P)^{-1}]_{ii}P_{ii}$: in [0, 1] since $(J^TJ + P)^{-1} \\preceq
    P^{-1}$; 1 where a parameter has no prior."""
    jac = np.asarray(jacobian, dtype=np.float64)
    precision = np.asarray(prior_precision, dtype=np.float64)
    (pinv_a, safe, _, _), _ = _with_prior(jac, (precision, 0.0), 1e-10)
    return 1.0 - np.diag(pinv_a) * precision / safe**2


def _posterior_covariance(jac, res, groups, precision, rcond):
    """`least_squares_covariance` with a prior (its docstring)."""
    num, d = jac.shape
    d_eff = effective_parameters(jac, precision)
    dof = max(num - d_eff, 1.0)
    pooled = float(np.sum(res**2)) / dof
    (pinv_a, safe, undetermined, null), middle = _with_prior(jac, (precision, pooled), rcond)
    jn = jac / safe
    for g in np.unique(groups):
        sel = groups == g
        sigma2 = float(np.sum(res[sel] ** 2)) * num / (int(sel.sum()) * dof)
        middle = middle + sigma2 * jn[sel].T @ jn[sel]
    cov = pinv_a @ middle @ pinv_a / safe[:, None] / safe[None, :]
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return cov, null


def _auto_lags(scores, valid) -> int:
    """The automatic Bartlett bandwidth of Andrews (1991, eq. 6.2 and 6.4, AR(1)
    plug-in) for scores `(E, N, k)` (zero at invalid samples): each column,
    normalised to unit variance, gets an AR(1) fit $\\hat\\rho_a$ (pairs within one
    experiment), $\\hat\\alpha(1) = \\sum_a 4\\hat\\rho_a^2\\hat\\sigma_a^4 /
    ((1 - \\hat\\rho_a)^6(1 + \\hat\\rho_a)^2) \\,/\\, \\sum_a \\hat\\sigma_a^4 /
    (1 - \\hat\\rho_a)^4$ and the bandwidth is
    $S_T = 1.1447(\\hat\\alpha(1) T)^{1/3}$, T the number of valid samples; the lag
    count is $\\lfloor S_T \\rfloor$ ($\\hat\\rho$ clipped to $\\pm 0.99$), at most the
    longest experiment's span minus one."""
    g = scores
    count = valid.sum()
    if count < 3 or g.shape[-1] == 0:
        return 0
    rms = np.sqrt(np.sum(g**2, axis=(0, 1)) / count)
    keep = rms > 0
    if not keep.any():
        return 0
    g = g[..., keep] / rms[keep]
    pair = (valid[:, 1:] & valid[:, :-1])[..., None]
    x, y = np.where(pair, g[:, 1:], 0.0), np.where(pair, g[:, :-1], 0.0)
    num_pairs = int(pair.sum())
    yy = np.sum(y**2, axis=(0, 1))
    if num_pairs < 2 or not (yy > 0).all():
        return 0
    rho = np.clip(np.sum(x * y, axis=(0, 1)) / yy, -0.99, 0.99)
    sigma4 = (np.sum((x - rho * y) ** 2, axis=(0, 1)) / num_pairs) ** 2
    alpha = (np.sum(4 * rho**2 * sigma4 / ((1 - rho) ** 6 * (1 + rho) ** 2))
             / np.sum(sigma4 / (1 - rho) ** 4))
    span = 0
    for row in valid:
        idx = np.nonzero(row)[0]
        if idx.size:
            span = max(span, int(idx[-1] - idx[0]))
    lags = int(math.floor(1.1447 * (alpha * float(count)) ** (1.0 / 3.0)))
    return max(0, min(lags, span - 1 if span > 0 else 0))


def bartlett_long_run(scores, lags: int) -> np.ndarray:
    """$S = \\Gamma_0 + \\sum_{l=1}^{L}(1 - \\frac{l}{L+1})(\\Gamma_l + \\Gamma_l^T)$,
    $\\Gamma_l = \\sum_e\\sum_t g_{e,t}g_{e,t-l}^T$, of scores `(E, N, k)` (zero where
    invalid), summed over experiments and never across them. Computed exactly as
    $\\frac{1}{L+1}\\sum_t B_tB_t^T$ with the moving sums
    $B_t = \\sum_{s=t-L}^{t} g_s$ over the zero-padded series (each pair s, s' is
    counted $L + 1 - |s - s'|$ times): one product instead of L."""
    g = np.asarray(scores, dtype=np.float64)
    if g.ndim == 2:
        g = g[None]
    lags = int(lags)
    num_e, num, k = g.shape
    csum = np.cumsum(np.concatenate([np.zeros((num_e, 1, k)), g, np.zeros((num_e, lags, k))],
                                    axis=1), axis=1)
    t = np.arange(num + lags)
    # B_t = csum[t + 1] - csum[t - L]; csum[0] = 0 stands for every start before the series
    blocks = csum[:, t + 1] - csum[:, np.maximum(t - lags, 0)]
    return np.einsum("etp,etq->pq", blocks, blocks) / (lags + 1)


def _hac(rows, scores, valid, lags, focus, rcond, prior=None):
    num, d = rows.shape
    if num == 0:
        raise ValueError("no valid residuals.")
    (pinv_a, safe, undetermined, _), prior_middle = _with_prior(rows, prior, rcond)
    g = scores / safe
    if lags is None:
        sel = g if focus is None else g[..., np.asarray(focus)]
        lags = _auto_lags(sel, valid)
    elif int(lags) != lags or lags < 0:
        raise ValueError(f"`lags` must be None or a non-negative integer, got {lags!r}.")
    lags = int(lags)
    middle = bartlett_long_run(g, lags)
    if prior is not None:  # the long-run variance of the data, the prior's beside it
        d_eff = float(np.trace(pinv_a @ ((rows / safe).T @ (rows / safe))))
        return _finish(pinv_a @ (middle * (num / max(num - d_eff, 1.0)) + prior_middle)
                       @ pinv_a, safe, undetermined), lags
    cov = pinv_a @ middle @ pinv_a * (num / max(num - d, 1))
    cov = cov / safe[:, None] / safe[None, :]
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return cov, lags


def hac_covariance(jacobian, residuals, mask=None, *, lags=None, focus=None,
                   rcond: float = 1e-10):
    """Covariance of a (nonlinear) least-squares estimate that stays right when the
    residuals are correlated in time and of unequal variance: the
    heteroscedasticity and autocorrelation consistent (HAC) sandwich of Newey &
    West (1987, *Econometrica* 55, 703-708, eq. 2-3), also White (1984, ch. 6):

    $$\\Sigma = \\frac{N}{N - d}(J^TJ)^{-1} S (J^TJ)^{-1},\\quad
    S = \\Gamma_0 + \\sum_{l=1}^{L} w_l(\\Gamma_l + \\Gamma_l^T),\\quad
    w_l = 1 - \\frac{l}{L+1},\\quad \\Gamma_l = \\sum_t g_t g_{t-l}^T,$$

    with the score of sample t, $g_t = \\sum_c J_{c,t}^T e_{c,t}$, summed over the
    output channels c at that sample (channels of one sample are correlated too).
    Lagged products are taken within one experiment only: the Gammas are summed over
    experiments, never across them. N is the number of residuals and d of columns;
    $N/(N - d)$ is the same small-sample factor as in `least_squares_covariance`, so
    with white residuals and `lags=0` both agree to sampling error (lag 0 alone is
    White's heteroscedasticity-robust covariance). The Bartlett weights keep S
    positive semi-definite. Scale invariant (computed on the column-normalised
    Jacobian); undetermined directions get infinite variance as in
    `least_squares_covariance`. The sign convention of J (residuals or predictions)
    does not matter.

    **Bandwidth.** `lags=None` chooses L by the AR(1) plug-in rule of Andrews
    (1991, *Econometrica* 59, 817-858, eq. 6.4 with the Bartlett constant 1.1447):
    $L = \\lfloor 1.1447(\\hat\\alpha(1)T)^{1/3}\\rfloor$, where $\\hat\\alpha(1)$ comes from
    AR(1) fits to the normalised score columns (`focus` selects the columns, e.g. the
    physical parameters when the Jacobian also has nuisance columns) and T is the
    number of valid samples. It grows with the correlation of the scores: for
    scores with $\\rho = 0.81$ and T = 2000 it gives 40 lags, for $\\rho = 0.98$
    about 200 (capped at the longest experiment's span). The common fixed rule
    $\\lfloor 4(T/100)^{2/9}\\rfloor$ (Newey & West 1994) ignores the correlation:
    it gives 6 lags for T = 1000 and, with AR(1) errors of $\\phi = 0.9$ and a
    regressor as correlated, standard errors still 30-50 % too small, against
    10-20 % too small with the rule used here (Bartlett's bias; measured in
    tests/test_validate.py). Pass `lags=` to override.

    **Arguments:**

    - `jacobian`: `(C, E, N, d)`, `(E, N, d)` or `(N, d)`: the Jacobian of the
      (weighted) residuals with respect to the parameters, samples in time order
      within each experiment (channels, experiments, samples, parameters).
    - `residuals`: `(C, E, N)`, `(E, N)` or `(N,)`, same scale as the Jacobian.
    - `mask`: valid samples, broadcastable to the residuals' shape (e.g. `(E, N)`);
      masked samples (padding) contribute nothing but still count as time steps.
    - `lags`: the number L of lags, or None for the automatic rule.
    - `focus`: column indices that choose the automatic bandwidth (default all).

    **Returns:** `(covariance (d, d), lags)`.
    """
    jac = np.asarray(jacobian, dtype=np.float64)
    res = np.asarray(residuals, dtype=np.float64)
    if res.ndim not in (1, 2, 3) or jac.ndim != res.ndim + 1 or jac.shape[:-1] != res.shape:
        raise ValueError(f"`residuals` must be (C, E, N), (E, N) or (N,) and `jacobian` the "
                         f"same plus (d,), got {res.shape} and {jac.shape}.")
    lead = (1,) * (3 - res.ndim)
    res, jac = res.reshape(lead + res.shape), jac.reshape(lead + jac.shape)
    if mask is None:
        valid = np.ones(res.shape, dtype=bool)
    else:
        mask = np.asarray(mask, dtype=bool)
        valid = np.broadcast_to(mask.reshape((1,) * (3 - mask.ndim) + mask.shape), res.shape)
    bad = valid & ~(np.isfinite(res) & np.isfinite(jac).all(axis=-1))
    if bad.any():
        raise ValueError(f"non-finite residuals or Jacobian at {int(bad.sum())} valid samples.")
    jac0 = np.where(valid[..., None], jac, 0.0)
    scores = np.einsum("cenp,cen->enp", jac0, np.where(valid, res, 0.0))
    return _hac(jac[valid], scores, valid.any(axis=0), lags, focus, rcond)


def _finish(cov_n, safe, undetermined):
    """A normalised covariance back in the parameters' units, undetermined ones inf."""
    cov = cov_n / safe[:, None] / safe[None, :]
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return cov


def hac_from_windows(jacobian, residuals, layout, *, num_samples=None, lags=None,
                     focus=None, rcond: float = 1e-10, prior=None):
    """`hac_covariance` of a windowed prediction-error fit: the Jacobian
    `(C, E, W, L, d)` and residuals `(C, E, W, L)` at the window samples are put in
    time order with `layout["target"]` (E, W, L) sample indices and `layout["mask"]`
    (as `jaxship._estimate._windows.to_timeline` does); scores of window samples that
    land on the same sample are added. `num_samples`: length of the timeline
    (default the largest target index + 1). `prior = (precision (d,), variance)`: a
    Gaussian prior's (see `least_squares_covariance`), whose information is added to
    $J^TJ$ and, times the variance, to the long-run variance. Returns `(covariance (d, d),
    lags)`."""
    jac = np.asarray(jacobian, dtype=np.float64)
    res = np.asarray(residuals, dtype=np.float64)
    mask = np.asarray(layout["mask"], dtype=bool)
    target = np.asarray(layout["target"])
    if res.ndim == mask.ndim:
        res, jac = res[None], jac[None]
    if res.shape[1:] != mask.shape or jac.shape[:-1] != res.shape:
        raise ValueError(f"window residuals {res.shape} and Jacobian {jac.shape} do not match "
                         f"the layout's mask {mask.shape}.")
    d = jac.shape[-1]
    rows = np.concatenate([jac[c][mask] for c in range(res.shape[0])])
    if not (np.isfinite(rows).all() and all(np.isfinite(r[mask]).all() for r in res)):
        raise ValueError("non-finite residuals or Jacobian at valid window samples.")
    jac0 = np.where(mask[None, ..., None], jac, 0.0)
    per_window = np.einsum("cewlp,cewl->ewlp", jac0, np.where(mask[None], res, 0.0))
    num = int(target[mask].max()) + 1 if num_samples is None else int(num_samples)
    e_idx = np.broadcast_to(np.arange(mask.shape[0])[:, None, None], mask.shape)
    scores = np.zeros((mask.shape[0], num, d))
    np.add.at(scores, (e_idx[mask], target[mask]), per_window[mask])
    valid = np.zeros((mask.shape[0], num), dtype=bool)
    valid[e_idx[mask], target[mask]] = True
    return _hac(rows, scores, valid, lags, focus, rcond, prior)


def cluster_from_windows(jacobian, residuals, mask, *, rcond: float = 1e-10, prior=None):
    """Cluster-robust covariance of a windowed prediction-error fit, each prediction
    window a cluster (Liang & Zeger 1986; Cameron & Miller 2015, *J. Human Resources*
    50, eq. 11):

    $$\\Sigma = \\frac{G}{G - 1}(J^TJ)^{-1}\\Big(\\sum_g s_gs_g^T\\Big)(J^TJ)^{-1},
    \\qquad s_g = \\sum_{t \\in g} J_t^Te_t.$$

    Within a window the prediction error grows from the measured start, so its
    residuals are strongly correlated; windows restart from measurements, so
    different windows are nearly independent: the sandwich allows any correlation
    inside a cluster. Needs many windows (G of 20 or more). `jacobian` (C, E, W, L, d),
    `residuals` (C, E, W, L), `mask` (E, W, L); `prior` as in `hac_from_windows`. Returns
    `(covariance, G)`."""
    jac = np.asarray(jacobian, dtype=np.float64)
    res = np.asarray(residuals, dtype=np.float64)
    mask = np.asarray(mask, dtype=bool)
    rows = np.concatenate([jac[c][mask] for c in range(res.shape[0])])
    (pinv_a, safe, undetermined, _), prior_middle = _with_prior(rows, prior, rcond)
    jac0 = np.where(mask[None, ..., None], jac, 0.0)
    scores = np.einsum("cewlp,cewl->ewp", jac0, np.where(mask[None], res, 0.0))
    used = mask.any(axis=-1)
    g = scores[used] / safe
    count = int(used.sum())
    if count < 2:
        raise ValueError("a cluster-robust covariance needs at least two windows.")
    if prior is not None:
        return _finish(pinv_a @ ((g.T @ g) * (count / (count - 1)) + prior_middle) @ pinv_a,
                       safe, undetermined), count
    cov = pinv_a @ (g.T @ g) @ pinv_a * (count / (count - 1))
    cov = cov / safe[:, None] / safe[None, :]
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return cov, count
