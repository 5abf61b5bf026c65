"""The search of `discover` (design: ../shared/reference/discovery-design.md, sec. 4).

A path is a set of named effects with its fit. One forward step from a path:

1. every applicable catalogue effect is added at zero and scored at the path's fit
   with one forward-mode Jacobian (`score_tests`: robust score statistics);
2. candidates the data cannot tell apart (canonical correlation of their projected
   sensitivities above `equivalence`) form a class; the best-scoring member of each
   of the `top` best classes is refitted with Levenberg-Marquardt from the path's
   fit (warm start);
3. a candidate is accepted only if all of these hold: its robust score and its
   likelihood ratio (divided by the score's inflation by correlated residuals)
   exceed the chi-square quantile at `alpha / ((m + 1) K)` (Bonferroni over the m
   candidates, one joint test and K = `max_effects` iterations); its robust
   confidence interval at the same level excludes zero; its estimate lies in the
   parameter's plausible range (for parameters with family units: its loads as a
   rudder angle, `rudder_equivalent`, within the entry's `rudder_range`), and the
   refit pushes no base parameter onto the edge of its range; and the held-out cost
   does not rise beyond the spread a disturbance gives it (`heldout_rise`). The
   held-out check vetoes but does not choose: no candidate is accepted while a rival
   that lowers the training cost more fails on the held-out runs alone;
4. where no single candidate passes, effects too weak alone may pass together: a
   forward search on the conditional scores (`forward_path`) picks up to `top`, and
   their union is refitted and judged by the same gates, its threshold simulated
   with the search (`joint_null`), each member's interval excluding zero;
5. a backward step follows each addition (`eliminate`): every effect named so far is
   refitted with the others and tested for removal by its robust Wald statistic at
   the same level, and for plausibility (its size as in 3, and no sign flip beyond
   3 standard errors since it joined: an offset taking the place of a current it
   aliased); the weakest that fails leaves (and is not offered again on that path),
   the rest are refitted, until all hold.

Every candidate that passes a step makes a child path; `beam` paths go on, the best
first (`rank`): those whose every estimate is plausible, by held-out cost (training
cost without held-out records). A child whose training cost the data cannot tell
from the best child's (likelihood ratio between the two below the threshold) is kept
as a rival path; others are not (one clear winner costs one path). Effects sit in the
model in the catalogue's order (after the start model's own), whatever the order they
joined in.
"""

import dataclasses

import equinox as eqx
import numpy as np
import scipy  # scipy.stats loads on first use (an import-time saving)

from ..._estimate._fit import fit
from ..._estimate._lm import RESULTS, LevenbergMarquardt
from ..._estimate._sensitivity import sensitivities
from ..._foundation._contract import parameter_fields
from ..._foundation._validate import NonFiniteError
from ..._models._effects import augment
from ._catalogue import applicable
from ._plumbing import (
    at_edge,
    delta_bic,
    free_names,
    parameters,
    points_outside,
    rudder_size,
    set_value,
    split,
)
from ._report import CandidateOutcome, CandidateScore, Equivalent
from ._score import (
    canonical_correlation,
    forward_path,
    joint_null,
    joint_scores,
    null_scores,
    score_tests,
)


# warm-started refits converged in 12-57 LM steps on the Monte-Carlo, KVLCC2 and Esso data;
# one that needs more is not converging (Esso's r|r|: 256 steps, 100 s) and is rejected
REFIT_STEPS = 100
# a refit starts from the current fit with the new terms at zero (a warm start): its first
# step is damped lightly (`LevenbergMarquardt.damping`), not at 1 as a fit from afar is
REFIT_DAMPING = 1e-3
# a named estimate whose sign flips by more than this many standard errors once another
# effect joins was standing in for that effect (issue 60: an offset for a current)
FLIP_Z = 3.0
# refit outcomes the gates judge themselves (a bound: the edge gate; an undetermined
# combination: the confidence-interval gate)
_JUDGED_BY_GATES = (RESULTS.successful, RESULTS.at_bound, RESULTS.poorly_determined)
# refits that failed numerically (issue 71: stopped at their step limit, diverged, blew
# up): tried again from the next start
_NUMERICAL = (RESULTS.max_steps_reached, RESULTS.nonlinear_max_steps_reached,
              RESULTS.nonlinear_divergence, RESULTS.nonfinite, RESULTS.simulation_blew_up)
# the starts a candidate's refit is tried from, in order, until one does not fail
# numerically (issue 71): "warm", the path's fit with the new terms at their probe
# values; "staged", the new terms' own parameters fitted first with every other held at
# the path's fit (their size as the data suggest it: a current from the drift of the
# track against the through-water prediction, an offset from the rudder at which the
# ship holds its course), then all together from there
STARTS = ("warm", "staged")
# the reason of a candidate whose refit failed numerically from every start: not judged
NOT_JUDGED = "not judged: "


@dataclasses.dataclass(frozen=True)
class Path:
    """A set of named effects: its `fit`, `names` `{id: fitted parameter names}`, the
    `accepted` outcomes, its held-out check `held` (None without held-out records),
    `barred` ids removed by a backward step, and `joined` `{parameter: estimate when
    its effect joined}` (the sign-flip check)."""

    fit: object
    names: dict
    accepted: tuple = ()
    held: dict | None = None
    barred: frozenset = frozenset()
    joined: dict = dataclasses.field(default_factory=dict)
    rejected: tuple = ()


@dataclasses.dataclass(frozen=True)
class _Scored:
    """One path's candidates scored at its fit (what `Search.forward` needs)."""

    sens: object
    scored: object
    scores: dict
    names: dict
    entry: dict
    classes: dict
    theta: tuple
    level: float
    sigma2: float

    def threshold(self, dof):
        return float(scipy.stats.chi2.isf(self.level, dof))


class Search:
    """The fixed context of one `discover` run and its steps (module text). `setup`:
    the `discover` set-up (`free`, `data`, `train`, `holdout`, `catalogue`, `estimator`,
    `loss`, `check`, `heldout_rise`, `options`, `say`, `order` `{id: place in the model}`,
    `entries` `{id: Candidate}`, `before` the base model's held-out check). Collects
    `rejected` outcomes and the base fit's `first_scores`."""

    def __init__(self, setup):
        self.__dict__.update(setup)
        self.rejected, self.first_scores = [], None

    def ordered(self, effects):
        return tuple(sorted(effects, key=lambda e: self.order[e.id]))

    def refit(self, start, free):
        """A warm-started fit of `start` (`REFIT_STEPS`, `REFIT_DAMPING`)."""
        refit = dataclasses.replace(self.loss(start), max_steps=min(self.estimator.max_steps,
                                                                    REFIT_STEPS))
        if isinstance(refit.solver, LevenbergMarquardt):
            refit = dataclasses.replace(refit, solver=eqx.tree_at(
                lambda solver: solver.search.damping, refit.solver, REFIT_DAMPING))
        return fit(start, self.train, estimator=refit, free=free)

    def theta(self, path):
        return self.free + sum(path.names.values(), ())

    def score(self, path, iteration) -> _Scored | None:
        """The candidates of a forward step scored at `path`'s fit, or None where none
        can be (rejecting those that cannot, with the reason)."""
        base, effects = split(path.fit.model)
        done = {e.id for e in effects} | set(getattr(base, "built_in_effects", ())) | path.barred
        candidates = applicable(base, self.data, self.catalogue, exclude=done)
        if not candidates:
            return None
        theta = self.theta(path)
        names = {c.id: free_names(c, e) for c, e, _ in candidates}
        probes = {f"{c.id}.{k}": v for c, _, pr in candidates for k, v in pr.items()}
        scored = augment(base, *self.ordered(effects + tuple(e for _, e, _ in candidates)))
        self.say(f"iteration {iteration}: scoring {len(candidates)} candidates")
        every = self.free + sum(((path.names | names).get(e.id, ()) for e in scored.effects),
                                ())
        sens = sensitivities(scored, self.train, self.loss(scored), every, probes,
                             start_offsets=path.fit.start_offsets)
        nuisance = tuple(n for n in sens.names if n.startswith("start["))
        entry = {c.id: (c, e, pr) for c, e, pr in candidates}
        # a candidate whose sensitivities are not finite (the model with it blows up on
        # these records) is rejected, not the run; where the residuals or the base
        # sensitivities are not finite, or the scores fail numerically, none is scored
        finite = dict(zip(sens.names, np.isfinite(sens.jacobian).all(axis=0)))
        unscored = [k for k in names if not all(finite[n] for n in names[k])]
        self.rejected.extend(CandidateOutcome(
            k, entry[k][0].name, iteration, float("nan"),
            ("not scored: its sensitivities at the current fit are not finite (the model "
             "with it blows up on these records)",)) for k in unscored)
        names = {k: v for k, v in names.items() if k not in unscored}
        failure = None
        if not (np.isfinite(sens.residuals).all() and all(finite[n] for n in theta + nuisance)):
            failure = "the residuals or the base model's sensitivities are not finite"
        elif names:
            try:
                scores = score_tests(sens, theta + nuisance, names)
            except np.linalg.LinAlgError as error:  # e.g. an SVD that does not converge
                failure = f"the scores failed numerically ({error})"
        if failure:
            self.rejected.extend(CandidateOutcome(k, entry[k][0].name, iteration, float("nan"),
                                                  (f"not scored: {failure}",)) for k in names)
        if failure or not names:
            return None
        # one test per candidate and one joint test per iteration (Bonferroni)
        level = self.options.alpha / ((len(candidates) + 1) * self.options.max_effects)
        ranked = sorted(scores, key=lambda k: -scores[k].statistic)
        classes = {k: [j for j in ranked if j != k and canonical_correlation(
            scores[k], scores[j]) > self.options.equivalence] for k in ranked}
        sigma2 = 2 * sens.cost / max(sens.residuals.size - len(theta) - len(nuisance), 1)
        self.level, self.sigma2 = level, sigma2  # the backward step's and the beam's
        out = _Scored(sens, scored, {k: scores[k] for k in ranked}, names, entry, classes,
                      theta + nuisance, level, sigma2)
        if self.first_scores is None:
            self.first_scores = {k: CandidateScore(s.statistic, s.naive, s.dof,
                                                   out.threshold(s.dof), s.predicted_decrease)
                                 for k, s in out.scores.items()}
        return out

    def forward(self, path, iteration) -> list:
        """The child paths of `path`: one per candidate (or joint set) passing the gates
        (module text), each after its backward step."""
        sc = self.score(path, iteration)
        if sc is None:
            return []
        chosen = []
        for k in sc.scores:
            if len(chosen) < self.options.top and not any(k in sc.classes[c] for c in chosen):
                chosen.append(k)
        passed, vetoed = [], []  # vetoed: (id, cost) of refits failing only the held-out check
        for k in chosen:
            s, limit = sc.scores[k], sc.threshold(sc.scores[k].dof)
            if s.statistic <= limit or points_outside(sc.scored, sc.names[k], s.step):
                why = (f"score {s.statistic:.3g} below the threshold {limit:.3g}"
                       if s.statistic <= limit else
                       "its score points out of the plausible range (a negative lag, rate "
                       "or area)")
                self.rejected.append(CandidateOutcome(k, sc.entry[k][0].name, iteration,
                                                      s.statistic, (why,)))
                continue
            self.say(f"iteration {iteration}: refitting with {k}")
            records, trial, after, veto = self.judge(path, sc, (k,), s, limit, iteration)
            if veto:
                vetoed.append((k, trial.cost))
            if records[0].why:
                self.rejected.extend(records)
            else:
                passed.append((records, trial, after))
        # the held-out check vetoes, it does not choose: where a rival explains the training
        # data better and fails only on the held-out runs, these data do not say which
        # (if either) is missing
        rival = min(vetoed, key=lambda pair: pair[1], default=None)
        if rival and passed and rival[1] < min(row[1].cost for row in passed):
            # the rival's whole class is named: its members tie on these data (a rudder
            # offset and a yaw-moment bias on a Nomoto model)
            rivals = " or ".join(sorted([rival[0], *sc.classes[rival[0]]]))
            why = (f"{rivals} explains the training data better but fails on the held-out "
                   "runs",)
            for records, _, _ in passed:
                self.rejected.extend(dataclasses.replace(r, why=why) for r in records)
            return []
        size = min(self.options.top, self.options.max_effects - len(path.names))
        if not passed and size > 1:
            passed = self.joint(path, sc, size, iteration)
        return [self.eliminate(self.child(path, *row, sc), iteration)
                for row in self.unless_outscored(passed, sc)]

    def unless_outscored(self, passed, sc) -> list:
        """`passed` less the sets that a candidate not judged this step (`NOT_JUDGED`)
        outscores (issue 71): a candidate that would explain more was never judged, so
        a lesser one may be standing in for it. Their records are rejected, saying so."""
        unjudged = {r.id: sc.scores[r.id].statistic for r in self.rejected
                    if r.why and r.why[0].startswith(NOT_JUDGED) and r.id in sc.scores}
        kept = []
        for records, trial, after in passed:
            ids = {r.id for r in records}
            above = sorted(k for k, score in unjudged.items()
                           if k not in ids and score > max(r.score for r in records))
            if not above:
                kept.append((records, trial, after))
                continue
            why = (f"not named while {', '.join(above)}, which scores higher, could not be "
                   "judged (its refit failed numerically from every start)",)
            self.rejected.extend(dataclasses.replace(r, why=why) for r in records)
        return kept

    def child(self, path, records, trial, after, sc) -> Path:
        self.say(f"accepted {' + '.join(r.id for r in records)}")
        names = path.names | {r.id: sc.names[r.id] for r in records}
        joined = path.joined | {n: p.value for r in records for n, p in r.parameters.items()}
        return Path(trial, names, path.accepted + tuple(records), after, path.barred, joined,
                    path.rejected + tuple(self.rejected))

    def step(self, paths, iteration) -> tuple[list, list]:
        """`(the paths that go on, those that end)`: a forward step from every path of the
        beam; a path ends where nothing passes or it names `max_effects`."""
        going, ended = [], []
        for path in paths:
            self.rejected = []
            more = len(path.names) < self.options.max_effects
            children = self.forward(path, iteration) if more else []
            if not children:
                ended.append(dataclasses.replace(path, rejected=path.rejected
                                                 + tuple(self.rejected)))
            going += children
        return self.keep(going), ended

    def rank(self, path):
        """Held-out cost (training cost without held-out records): lower is better."""
        return path.held["cost"] if self.holdout else path.fit.cost

    def keep(self, children) -> list:
        """The `beam` best distinct children (`rank`), the best and those whose training
        cost the data cannot tell from its (module text)."""
        unique = {}
        for c in sorted(children, key=self.rank):
            unique.setdefault(frozenset(c.names), c)
        ranked = list(unique.values())
        if not ranked:
            return []
        cheapest = min(c.fit.cost for c in ranked)
        limit = float(scipy.stats.chi2.isf(self.level, 1))
        close = [c for c in ranked if 2 * (c.fit.cost - cheapest) / self.sigma2 <= limit]
        return close[:self.options.beam]

    def eliminate(self, path, iteration) -> Path:
        """The backward step (module text, step 5): `path` less the effects that fail it,
        each removal refitted."""
        while len(path.names) > 1:
            weakest = self.weakest(path)
            if weakest is None:
                return path
            k, why = weakest
            self.say(f"iteration {iteration}: removing {k}")
            base, effects = split(path.fit.model)
            names = {j: v for j, v in path.names.items() if j != k}
            try:
                trial = self.refit(augment(base, *(e for e in effects if e.id != k)),
                                   self.free + sum(names.values(), ()))
                after = self.check(trial.model) if self.holdout else None
            except (np.linalg.LinAlgError, OverflowError, FloatingPointError, NonFiniteError):
                return path  # the set without it cannot be judged: it stays
            removed = next(r for r in path.accepted if r.id == k)
            removed = dataclasses.replace(removed, iteration=iteration, why=(why,),
                                          jointly_with=())
            path = Path(trial, names, tuple(r for r in path.accepted if r.id != k), after,
                        path.barred | {k}, {n: v for n, v in path.joined.items()
                                            if n.split(".")[0] != k}, path.rejected + (removed,))
        return path

    def weakest(self, path):
        """`(id, why)` of the named effect that fails the backward step (implausible
        first, then the smallest robust Wald statistic below its threshold), or None.
        The robust covariance of an effect's estimates: their robust standard errors
        with the fit's correlation."""
        fit, p = path.fit, path.fit.parameters
        index = {n: i for i, n in enumerate(fit.names)}
        robust = np.asarray(p.std_robust if p.std_robust is not None else p.std, float)
        std = np.where(np.isfinite(robust), robust, np.asarray(p.std, float))
        failing = []
        for k, names in path.names.items():
            i = [index[n] for n in names]
            b = np.asarray(fit.values, float)[i]
            flips = [n for n, j in zip(names, i) if path.joined[n] * fit.values[j] < 0
                     and abs(fit.values[j] - path.joined[n]) > FLIP_Z * std[j]]
            size = rudder_size(fit, self.entries[k], names, self.data, self.loss(fit.model).wind)
            why = self.implausible(fit, names, (), fit, {k: size})
            if flips:
                why.append(f"its sign flipped once others joined ({', '.join(flips)})")
            if why:
                failing.append((-np.inf, k, f"removed: {'; '.join(why)}"))
                continue
            cov = std[i][:, None] * np.asarray(p.correlation)[np.ix_(i, i)] * std[i][None, :]
            wald = float(b @ np.linalg.pinv(cov, rcond=1e-12) @ b)
            limit = float(scipy.stats.chi2.isf(self.level, len(i)))
            if not wald > limit:
                failing.append((wald / limit, k, f"removed: robust Wald statistic {wald:.3g} "
                                                 f"below the threshold {limit:.3g} with "
                                                 f"{', '.join(j for j in path.names if j != k)}"))
        return min(failing)[1:] if failing else None

    def joint(self, path, sc, size, iteration) -> list:
        """The joint step (module text, step 4): `[(records, fit, held-out check)]` of
        the union the forward search picks, where it passes; else []."""
        keys = list(sc.scores)
        equivalent = np.array([[j in sc.classes[k] for j in keys] for k in keys])
        fields = parameter_fields(sc.scored)
        lower = np.array([fields[n].lower == 0.0 for k in keys for n in sc.names[k]])
        g, v, gram, blocks = joint_scores(sc.sens, sc.theta, {k: sc.names[k] for k in keys})
        picks = forward_path(g[None], v, gram, blocks, equivalent, lower, size)[0]
        union = tuple(keys[i] for i in np.flatnonzero(picks))
        if len(union) < 2:
            return []
        null = joint_null(null_scores(v), v, gram, blocks, equivalent, lower, size)
        s = next(iter(score_tests(sc.sens, sc.theta, {"+".join(union): sum(
            (sc.names[k] for k in union), ())}).values()))
        limit = float(np.quantile(null, 1 - sc.level))
        group = dict(id="+".join(union), iteration=iteration,
                     name="jointly: " + ", ".join(sc.entry[k][0].name for k in union))
        if s.statistic <= limit:
            self.rejected.append(CandidateOutcome(
                **group, score=s.statistic, why=(f"joint score {s.statistic:.3g} below the "
                                                 f"threshold {limit:.3g} (simulated with the "
                                                 "search)",)))
            return []
        self.say(f"iteration {iteration}: refitting with {' + '.join(union)}")
        records, trial, after, _ = self.judge(path, sc, union, s, limit, iteration,
                                              p_value=float(np.mean(null >= s.statistic)))
        if not records[0].why:
            return [(records, trial, after)]
        self.rejected.append(dataclasses.replace(  # one entry for the set
            records[0], **group, equivalent_to=(), jointly_with=(),
            parameters={n: p for r in records for n, p in r.parameters.items()},
            rudder_equivalent_deg={r.id: r.rudder_equivalent_deg for r in records}))
        return []

    def judge(self, path, sc, keys, s, limit, iteration, p_value=None):
        """Refit `path` with the candidates `keys` (one, or a joint union) and apply the
        gates (module text) against the score threshold `limit`. Returns (one record per
        candidate, with `why` where the refit fails a gate; the fit; its held-out check;
        whether that check alone failed). A refit that fails numerically (an error, a
        prediction that is not finite, or a stop at its step limit) is tried again from
        the next of `STARTS` before it is judged; one that fails from every start is
        "not judged" (`NOT_JUDGED`), not rejected by a gate, and rejects neither the run
        nor the candidate's effect. Each record says which start its refit used."""
        for start in STARTS:
            try:
                records, trial, after, veto = self.attempt(path, sc, keys, s, limit,
                                                           iteration, p_value, start)
            except (np.linalg.LinAlgError, OverflowError, FloatingPointError) as error:
                why = f"the refit failed numerically ({type(error).__name__}: {error})"
            except NonFiniteError as error:
                why = f"a prediction with it is not finite ({error})"
            else:
                if trial.code not in _NUMERICAL:
                    return records, trial, after, veto
                why = f"the refit did not converge ({trial.message})"
            self.say(f"iteration {iteration}: {' + '.join(keys)} from the {start} start: "
                     f"{why}")
        why = (f"{NOT_JUDGED}{why}, from every start ({', '.join(STARTS)})",)
        return [CandidateOutcome(k, sc.entry[k][0].name, iteration, s.statistic, why,
                                 start=start) for k in keys], None, None, False

    def attempt(self, path, sc, keys, s, limit, iteration, p_value, how="warm"):
        base, effects = split(path.fit.model)
        start = augment(base, *self.ordered(effects + tuple(sc.entry[k][1] for k in keys)))
        for k in keys:
            for field, value in sc.entry[k][2].items():
                start = set_value(start, f"{k}.{field}", value)
        free = sum((sc.names[k] for k in keys), ())
        theta = self.theta(path)
        if how == "staged":  # the new terms' own size from the data first, the rest held
            start = self.refit(start, free).model
        trial = self.refit(start, theta + free)
        lr = 2 * (path.fit.cost - trial.cost) / sc.sigma2 / max(s.inflation, 1.0)
        z = float(scipy.stats.norm.isf(sc.level / 2))
        params = {k: parameters(trial, sc.names[k]) for k in keys}
        why = []
        if trial.code not in _JUDGED_BY_GATES:
            why.append(f"the refit did not converge ({trial.message})")
        if lr <= limit:
            why.append(f"likelihood ratio {lr:.3g} (robust) below the threshold {limit:.3g}")
        # an effect with several parameters (added mass in sway and yaw) needs one away from
        # zero; the likelihood ratio tests them jointly
        for k in keys:
            if not any(abs(p.value) > z * p.std for p in params[k].values()):
                why.append(f"the confidence interval of {k} includes zero")
        sizes = {k: rudder_size(trial, sc.entry[k][0], sc.names[k], self.data,
                                self.loss(trial.model).wind) for k in keys}
        why += self.implausible(trial, free, theta, path.fit, sizes)
        after = self.check(trial.model) if self.holdout else None
        others = len(why)
        if self.holdout:
            reason = self.heldout_rise(after, path.held, self.before)
            if reason:
                why.append(reason)
        shared = dict(
            iteration=iteration, score=s.statistic, why=tuple(why), score_naive=s.naive,
            likelihood_ratio=lr,
            p_value=float(scipy.stats.chi2.sf(lr, s.dof)) if p_value is None else p_value,
            delta_bic=delta_bic(path.fit.cost, trial.cost, sc.sens.residuals.size, s.dof),
            holdout_cost=after["cost"] if self.holdout else None)
        records = [CandidateOutcome(
            id=k, name=sc.entry[k][0].name, parameters=params[k], **shared,
            rudder_equivalent_deg=float(np.degrees(sizes[k][0])) if sizes[k] else None,
            equivalent_to=tuple(Equivalent(j, sc.entry[j][0].separate) for j in sc.classes[k]),
            jointly_with=tuple(j for j in keys if j != k), start=how) for k in keys]
        return records, trial, after, others == 0 and len(why) == 1

    @staticmethod
    def implausible(trial, free, theta, before, sizes) -> list:
        """Why the estimates of `trial` are implausible in size: the parameters `free`, and
        base ones of `theta` the refit pushes onto a bound that `before` did not (the new
        terms then distort the base model rather than add to it), at the edge of their
        ranges; loads beyond their rudder-equivalent range (`sizes` `{id: (angle, limit)}`)."""
        why = []
        edge = at_edge(trial, free + tuple(n for n in theta if not at_edge(before, (n,))))
        if edge:
            why.append(f"at or beyond the edge of the plausible range: {', '.join(edge)}")
        for k, size in sizes.items():
            if size and size[0] > size[1]:
                why.append(f"{k}'s loads equal {np.degrees(size[0]):.1f} deg of rudder, "
                           f"beyond the plausible {np.degrees(size[1]):.1f} deg")
        return why
