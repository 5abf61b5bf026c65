"""Score (Lagrange-multiplier) tests of candidate effects at the current fit.

For candidate k with parameters $\\beta_k$ (zero: absent) and the fitted parameters
$\\theta$, let $e$ be the weighted residuals at the fit and $J_\\theta$, $J_k$ their
sensitivities. Projecting out what the fitted parameters can already do,
$\\tilde J_k = (I - QQ^T)J_k$ with $Q$ an orthonormal basis of $J_\\theta$'s columns,
the score is $g_k = \\tilde J_k^Te$ and (Rao 1948; for least squares e.g. Seber & Wild
1989, sec. 5.9)

$$S_k = g_k^T(\\hat\\sigma^2\\tilde J_k^T\\tilde J_k)^{-1}g_k \\sim \\chi^2_{\\dim\\beta_k},
\\qquad \\hat\\sigma^2 = e^Te/(N - p),$$

when nothing is missing and the residuals are white; $\\frac12 g_k^T(\\tilde J_k^T
\\tilde J_k)^{-1}g_k$ is the cost decrease one Gauss-Newton step in $\\beta_k$ predicts.
Residuals coloured by waves or gusts make $S_k$ far too large, so the decision uses
the robust form $S_k^{rob} = g_k^TV_k^{-1}g_k$ with $V_k$ the variance of the score
sum that allows correlated residuals, computed from the residuals after one
Gauss-Newton step in $\beta_k$, $e - \tilde J_k(\tilde J_k^T\tilde J_k)^{-1}g_k$ (under the
null the step is small and nothing changes; under the alternative the effect's own
signal would otherwise count as noise, and the statistic could not grow with the
effect's size): clustered by prediction window when there are
at least `MIN_CLUSTERS` windows (Liang & Zeger 1986; windows restart from
measurements, so they are nearly independent), else the Bartlett (Newey-West) long-run
variance of the per-sample scores in time with Andrews' bandwidth (as
`jaxship.hac_covariance`).

Candidates that the data cannot tell apart have (nearly) the same projected column
space: their largest canonical correlation (cosine of the smallest principal angle,
Bjorck & Golub 1973) is near 1.

Effects that are each too weak alone can be strong together, and one may only show
once another is in. `forward_path` picks a set by forward selection on the linearised
conditional scores; the set is chosen after looking at the data, so its joint score is
not $\\chi^2$ under the null: `joint_null` simulates it, selection included, from the
scores' joint normal law $g \\sim N(0, V)$ (V the window-clustered variance of all
candidates' scores; a Gaussian multiplier bootstrap, Chernozhukov, Chetverikov & Kato
2013).
"""

import dataclasses

import numpy as np
import scipy  # scipy.stats and scipy.special load on first use (an import-time saving)

from ..._foundation._covariance import _auto_lags, bartlett_long_run


MIN_CLUSTERS = 20  # prediction windows needed for the window-clustered score variance


@dataclasses.dataclass(frozen=True)
class Score:
    """A candidate's score test: `statistic` (robust, the one decisions use),
    `naive` (assuming white residuals), `dof` (its number of parameters),
    `predicted_decrease` (cost decrease of one Gauss-Newton step), `step` that
    Gauss-Newton step in the candidate's parameters, `basis` (N, dof)
    an orthonormal basis of its projected sensitivities (for the equivalence test)
    and `inflation` = naive / robust (how much correlated residuals inflate the
    naive statistic; 1 for white residuals)."""

    statistic: float
    naive: float
    dof: int
    predicted_decrease: float
    step: np.ndarray
    basis: np.ndarray
    inflation: float


def _orthonormal(a, rtol=1e-10):
    """An orthonormal basis of the columns of `a` (dropping dependent ones)."""
    if a.shape[1] == 0:
        return a
    u, s, _ = np.linalg.svd(a, full_matrices=False)
    return u[:, s > rtol * max(s[0], 1e-300)]


def _score_variance(contributions, sens):
    """Variance of the score sum under correlated residuals (see the module text),
    from scores centred on their mean: a missing effect adds the same systematic
    score to every window, which would otherwise count as variance and hide it."""
    windows = np.unique(sens.window)
    if windows.size >= MIN_CLUSTERS:
        _, cluster = np.unique(sens.window, return_inverse=True)
        sums = np.zeros((windows.size, contributions.shape[1]))
        np.add.at(sums, cluster, contributions)
        sums -= sums.mean(axis=0)
        return sums.T @ sums * windows.size / (windows.size - 1)
    num_e = int(sens.experiment.max()) + 1
    series = np.zeros((num_e, sens.num_samples, contributions.shape[1]))
    np.add.at(series, (sens.experiment, sens.sample), contributions)
    valid = np.zeros((num_e, sens.num_samples), bool)
    valid[sens.experiment, sens.sample] = True
    series = np.where(valid[..., None], series - series[valid].mean(axis=0), 0.0)
    return bartlett_long_run(series, _auto_lags(series, valid))


def _projector(sens, fitted):
    """(the columns of `sens` for given names projected against those of `fitted`:
    $(I - QQ^T)J_k$, the number of independent fitted columns)."""
    column = {n: i for i, n in enumerate(sens.names)}
    q = _orthonormal(sens.jacobian[:, [column[n] for n in fitted]])

    def project(names):
        jk = sens.jacobian[:, [column[n] for n in names]]
        return jk - q @ (q.T @ jk)

    return project, q.shape[1]


def score_tests(sens, fitted, candidates) -> dict:
    """`Score` of every candidate. `sens`: `Sensitivities` with columns for the fitted
    parameter names `fitted` and for each candidate's names; `candidates`: `{id:
    (names, ...)}`."""
    e = sens.residuals
    project, rank = _projector(sens, fitted)
    sigma2 = float(e @ e) / max(e.size - rank, 1)
    out = {}
    for key, names in candidates.items():
        jt = project(names)
        g = jt.T @ e
        a = jt.T @ jt
        a_inv = np.linalg.pinv(a, rcond=1e-12)
        decrease = 0.5 * float(g @ a_inv @ g)
        naive = 2.0 * decrease / sigma2
        v = _score_variance(jt * (e - jt @ (a_inv @ g))[:, None], sens)
        robust = float(g @ np.linalg.pinv(v, rcond=1e-12) @ g)
        out[key] = Score(statistic=robust, naive=naive, dof=len(names),
                         predicted_decrease=decrease, step=-(a_inv @ g),
                         basis=_orthonormal(jt),
                         inflation=naive / robust if robust > 0 else 1.0)
    return out


def canonical_correlation(a: Score, b: Score) -> float:
    """The largest canonical correlation of two candidates' projected sensitivities
    (1: one can mimic the other on these data)."""
    if a.basis.shape[1] == 0 or b.basis.shape[1] == 0:
        return 0.0
    return float(np.linalg.svd(a.basis.T @ b.basis, compute_uv=False)[0])



def _groups(labels):
    """(label index, rows) for each distinct label."""
    order = np.argsort(labels, kind="stable")
    cuts = np.cumsum(np.bincount(labels))[:-1]
    return enumerate(np.split(order, cuts))


def forward_path(g, v, gram, blocks, equivalent, lower, top, enter=0.05):
    """Which candidates a forward search picks for each row of `g` (draws, p): one at a
    time, the one whose robust score conditional on those picked before is the most
    significant (linearised: its sensitivities projected against theirs), never one
    equivalent to a pick or whose conditional step leaves the plausible range, only
    while that score's p-value is below `enter`, and at most `top`. `v`, `gram`
    (p, p): the scores' variance and the projected sensitivities' Gram matrix;
    `blocks`: each candidate's columns; `equivalent` (m, m) bool; `lower` (p,) bool:
    parameters that may not go negative. Returns (draws, m) bool."""
    draws, m = g.shape[0], len(blocks)
    chosen = np.zeros((draws, m), bool)
    for _ in range(top):
        best, best_p = np.full(draws, -1), np.full(draws, np.log(enter))
        sets, label = np.unique(chosen, axis=0, return_inverse=True)
        for i, rows in _groups(label.ravel()):
            picked = np.flatnonzero(sets[i])
            a = np.concatenate([blocks[j] for j in picked]) if picked.size else np.arange(0)
            for k in range(m):
                if sets[i, k] or equivalent[k, picked].any():
                    continue
                b = blocks[k]
                coef = gram[np.ix_(b, a)] @ np.linalg.pinv(gram[np.ix_(a, a)], rcond=1e-12)
                gk = g[np.ix_(rows, b)] - g[np.ix_(rows, a)] @ coef.T
                lk = np.hstack([np.eye(b.size), -coef])
                vk = lk @ v[np.ix_(np.r_[b, a], np.r_[b, a])] @ lk.T
                stat = np.einsum("di,ij,dj->d", gk, np.linalg.pinv(vk, rcond=1e-12), gk)
                step = -gk @ np.linalg.pinv(gram[np.ix_(b, b)] - coef @ gram[np.ix_(a, b)],
                                            rcond=1e-12)
                # log of the chi2 tail, as `scipy.stats.chi2.logsf` computes it above the
                # median (below it the p-value is over 0.5: never entered); the special
                # function skips the distribution's per-call checks (a third of the time)
                with np.errstate(divide="ignore"):
                    tail = np.log(scipy.special.chdtrc(b.size, stat))
                logp = np.where((lower[b] & (step < 0)).any(axis=1), 0.0, tail)
                better = logp < best_p[rows]
                best[rows[better]], best_p[rows[better]] = k, logp[better]
        took = best >= 0
        chosen[np.flatnonzero(took), best[took]] = True
    return chosen


def joint_scores(sens, fitted, candidates):
    """(g (p,), v (p, p), gram (p, p), blocks) of all `candidates` `{id: names}` at the
    fit: their projected scores, the scores' variance and Gram matrix."""
    names = [n for k in candidates for n in candidates[k]]
    span = np.cumsum([0] + [len(c) for c in candidates.values()])
    blocks = [np.arange(span[i], span[i + 1]) for i in range(len(candidates))]
    jt = _projector(sens, fitted)[0](names)
    v = _score_variance(jt * sens.residuals[:, None], sens)
    return jt.T @ sens.residuals, v, jt.T @ jt, blocks


def null_scores(v, draws=100_000, seed=0):
    """`draws` draws (rows) of the score vector under the null, $g \\sim N(0, V)$."""
    w, u = np.linalg.eigh(v)
    g = np.random.default_rng(seed).standard_normal((draws, v.shape[0]))
    return g @ (u * np.sqrt(np.clip(w, 0.0, None))).T


def joint_null(g, v, gram, blocks, equivalent, lower, top, enter=0.05):
    """The null law of the robust joint score of `forward_path`'s picks (module text),
    sorted, from the null score draws `g` (`null_scores`); 0 where it picks fewer than
    two."""
    draws = g.shape[0]
    chosen = forward_path(g, v, gram, blocks, equivalent, lower, top, enter)
    joint = np.zeros(draws)
    sets, label = np.unique(chosen, axis=0, return_inverse=True)
    for i, rows in _groups(label.ravel()):
        if sets[i].sum() < 2:
            continue  # one pick is the single-candidate test
        cols = np.concatenate([blocks[j] for j in np.flatnonzero(sets[i])])
        gc = g[np.ix_(rows, cols)]
        joint[rows] = np.einsum("di,ij,dj->d", gc, np.linalg.pinv(v[np.ix_(cols, cols)]), gc)
    return np.sort(joint)
