"""`DiscoveryReport`: what `jaxship.discover` found, as data (typed outcomes; `to_dict`,
the JSON of `jaxship discover`) and as a page (`to_markdown`)."""

import dataclasses
import math

import equinox as eqx
import jax
import numpy as np


class CandidateScore(eqx.Module):
    """A candidate's robust score test at the base fit: the `score` statistic, the
    `score_naive` one (white residuals assumed), its degrees of freedom `dof`, the
    Bonferroni `threshold` it must pass and the cost decrease it predicts."""

    score: float
    score_naive: float
    dof: int
    threshold: float
    predicted_decrease: float


# an estimate's interval: the value within this many standard errors (issue 60: a case
# is right only where the truth lies inside)
INTERVAL_SE = 3.0


class EffectParameter(eqx.Module):
    """A fitted effect parameter: `value`, robust standard error `std`, `unit`, and
    `interval` `(value - 3 std, value + 3 std)` (`INTERVAL_SE`)."""

    value: float
    std: float
    unit: str
    interval: tuple[float, float] = (math.nan, math.nan)

    @classmethod
    def with_interval(cls, value: float, std: float, unit: str) -> "EffectParameter":
        return cls(value, std, unit, (value - INTERVAL_SE * std, value + INTERVAL_SE * std))

    def covers(self, truth: float) -> bool:
        """Whether `truth` lies within the interval."""
        return self.interval[0] <= truth <= self.interval[1]


class Equivalent(eqx.Module):
    """A candidate these data cannot tell apart from another (canonical correlation of
    their sensitivities above the threshold), and the experiment that would separate
    them (`separate`)."""

    id: str
    separate: str


class CandidateOutcome(eqx.Module):
    """What became of one candidate (or of a joint set, `id`s joined by "+") in an
    iteration of `discover`: accepted where `why` is empty, else rejected for the
    reasons in `why`. A candidate rejected by its score alone was never refitted and
    has no refit fields (None, empty)."""

    id: str
    name: str
    iteration: int
    score: float
    why: tuple[str, ...] = ()
    parameters: dict[str, EffectParameter] = eqx.field(default_factory=dict)
    score_naive: float | None = None
    likelihood_ratio: float | None = None  # robust (divided by the score's inflation)
    p_value: float | None = None
    delta_bic: float | None = None
    holdout_cost: float | None = None
    # the rudder angle [deg] whose loads match the effect's (family units only); per
    # member for a rejected joint set
    rudder_equivalent_deg: float | dict | None = None
    equivalent_to: tuple[Equivalent, ...] = ()
    jointly_with: tuple[str, ...] = ()  # the others accepted with it by the joint step
    # the start of its refit (issue 71): "warm" (the path's fit, the new terms at their
    # probe values) or "staged" (the new terms fitted alone first); None: not refitted
    start: str | None = None

    @property
    def accepted(self) -> bool:
        return not self.why


class Verdict(eqx.Enumeration):
    """The outcome code of `discover` (`DiscoveryReport.verdict`)."""

    missing_effect = ("the model misses effects the data show: candidates passed the score, "
                      "likelihood-ratio, held-out and plausibility tests (see `effects`)")
    nothing_missing = ("no candidate of the catalogue passed the tests: nothing it holds is "
                       "missing from the model (see `rejected` and `scores`)")
    cannot_judge = ("the training records cannot judge whether an effect is missing: too "
                    "short, or the base model does not describe them (see `why`); no "
                    "candidate was scored")


class DiscoveryReport(eqx.Module):
    """The outcome of `discover`.

    - `verdict`: the `Verdict` code, `Verdict.missing_effect`, `Verdict.nothing_missing`
      or `Verdict.cannot_judge` (`verdict_name`: its name, as in the JSON), and `why`:
      the sentence saying why the records cannot judge (empty otherwise);
    - `effects`: the accepted effects in order (`CandidateOutcome`s with empty `why`);
    - `rejected`: candidates refitted or scored that did not pass (`CandidateOutcome`s
      with their reasons in `why`; a joint step's set as one entry, its ids joined by
      "+");
    - `scores`: every candidate's score test at the base fit (`{id: CandidateScore}`);
    - `model_before`, `model_after`: the fitted base and augmented models;
    - `train_cost_*`, `holdout_cost_*` (half the sum of squared normalised
      residuals), `holdout_fit_percent_*` per channel, `holdout_indices` per
      held-out record `{index: {measured, before, after}}`;
    - `alpha`: the family-wise false-alarm rate; `channels`: the fitted outputs;
    - `disagreement`: where the simulated training records depart from the measured
      ones, `{"before": ..., "after": ...}` (`locate_disagreement`: by
      record, time window, state region, turning side and correlated signal; for a
      vessel also the loads it lacks).
    """

    verdict: "Verdict"
    effects: tuple[CandidateOutcome, ...]
    rejected: tuple[CandidateOutcome, ...]
    scores: dict[str, CandidateScore]
    model_before: eqx.Module
    model_after: eqx.Module
    train_cost_before: float
    train_cost_after: float
    holdout_cost_before: float | None
    holdout_cost_after: float | None
    holdout_fit_percent_before: dict | None
    holdout_fit_percent_after: dict | None
    holdout_indices: dict
    alpha: float
    channels: tuple
    disagreement: dict
    why: str | None = None

    @property
    def verdict_name(self) -> str:
        """`"missing_effect"`, `"nothing_missing"` or `"cannot_judge"`."""
        return next(name for name in ("missing_effect", "nothing_missing", "cannot_judge")
                    if self.verdict == getattr(Verdict, name))

    @property
    def not_judged(self) -> tuple[str, ...]:
        """The ids of candidates whose refit failed numerically from every start and
        that were not named later (issue 71): the verdict does not cover them."""
        ids = [r.id for r in self.rejected if r.why and r.why[0].startswith("not judged: ")]
        return tuple(dict.fromkeys(k for k in ids if k not in self.named))

    @property
    def named(self) -> tuple[str, ...]:
        """The ids of the accepted effects, in order."""
        return tuple(e.id for e in self.effects)

    def names_or_classes(self) -> list[set]:
        """Per accepted effect, the set of its id and the ids it cannot be told from."""
        return [{e.id, *(q.id for q in e.equivalent_to)} for e in self.effects]

    def to_dict(self) -> dict:
        """The JSON of `jaxship discover` (plain Python numbers and strings)."""
        keys = ("verdict", "effects", "rejected", "scores", "train_cost_before",
                "train_cost_after", "holdout_cost_before", "holdout_cost_after",
                "holdout_fit_percent_before", "holdout_fit_percent_after",
                "holdout_indices", "alpha", "disagreement", "why")
        plain = {k: getattr(self, k) for k in keys} | {"verdict": self.verdict_name,
                                                       "not_judged": list(self.not_judged)}
        return _plain(plain | {"channels": list(self.channels)})

    def to_markdown(self) -> str:
        """The story in a page: verdict, effects, rejected candidates, the gap."""
        lines = ["# Discovery report", ""] + self._base_does_not_describe()
        if self.effects:
            lines += [f"**Verdict: missing effect(s): {', '.join(self.named)}** (family-wise "
                      f"false-alarm rate {self.alpha:g}).", ""]
            lines += ["| effect | parameter | value | std | interval (+-3 std) | unit | score | "
                      "LR | p | dBIC | cannot be told from |",
                      "|---|---|---|---|---|---|---|---|---|---|---|"]
            for e in self.effects:
                twins = "; ".join(f"{q.id} ({q.separate})" for q in e.equivalent_to)
                twins = twins.replace("|", "\\|")  # r|r| inside a table cell
                for name, p in e.parameters.items():
                    unit = p.unit.replace("|", "or")
                    lines.append(f"| {e.name} | `{name}` | {p.value:.4g} | {p.std:.2g} | "
                                 f"{p.interval[0]:.4g} to {p.interval[1]:.4g} | {unit} | "
                                 f"{e.score:.3g} | {e.likelihood_ratio:.3g} | "
                                 f"{e.p_value:.2g} | {e.delta_bic:.1f} | {twins or '-'} |")
            staged = [e.id for e in self.effects if e.start == "staged"]
            if staged:
                lines += ["", f"Refitted from the staged start (their own parameters first, "
                              f"the warm start having failed numerically): {', '.join(staged)}."]
        elif self.why:
            lines.append(f"**Verdict: cannot judge.** {self.why[:1].upper()}{self.why[1:]}")
        else:
            best = max(self.scores.items(), key=lambda kv: kv[1].score, default=None)
            lines.append("**Verdict: nothing missing.** No candidate passed the calibrated "
                         f"tests (family-wise false-alarm rate {self.alpha:g}).")
            if best:
                lines.append(f"The largest robust score was {best[1].score:.3g} "
                             f"({best[0]}), against a threshold of {best[1].threshold:.3g}.")
        if self.not_judged:
            lines += ["", f"**Not judged: {', '.join(self.not_judged)}.** Their refits failed "
                      "numerically from every start (see Rejected): the verdict does not say "
                      "whether they are missing."]
        if self.disagreement:
            lines += _where(self.disagreement["before"], self.disagreement["after"])
        if self.scores:
            lines += ["", "## Candidates at the base fit", "", "| candidate | robust score | "
                      "naive score | threshold |", "|---|---|---|---|"]
        for k, s in sorted(self.scores.items(), key=lambda kv: -kv[1].score):
            lines.append(f"| {k} | {s.score:.3g} | {s.score_naive:.3g} | {s.threshold:.3g} |")
        if self.rejected:
            lines += ["", "## Rejected", ""]
            lines += [f"- iteration {r.iteration}, {r.id}: {'; '.join(r.why)}"
                      + (f" (held-out cost with it {r.holdout_cost:.4g})"
                         if r.holdout_cost is not None else "")
                      + (f" (refit from the {r.start} start)" if r.start else "")
                      for r in self.rejected]
        lines += ["", "## The gap", "",
                  f"Training cost {self.train_cost_before:.5g} -> {self.train_cost_after:.5g}."]
        if self.holdout_cost_before is not None:
            track = "; positions over the fit's windows" if "x" in self.channels else ""
            lines.append(f"Held-out cost (output error{track}) {self.holdout_cost_before:.5g} "
                         f"-> {self.holdout_cost_after:.5g}.")
            lines += ["", "| channel | held-out fit % before | after |", "|---|---|---|"]
            for c in self.channels:
                lines.append(f"| {c} | {self.holdout_fit_percent_before[c]:.1f} | "
                             f"{self.holdout_fit_percent_after[c]:.1f} |")
        rows = [(r, k, v) for r, idx in self.holdout_indices.items() for k, v in idx.items()]
        if rows:
            lines += ["", "| record | index | measured | before | after |",
                      "|---|---|---|---|---|"]
            fmt = lambda x: "-" if x is None else f"{x:.2f}"
            lines += [f"| {r} | {k} | {fmt(v['measured'])} | {fmt(v['before'])} | "
                      f"{fmt(v['after'])} |" for r, k, v in rows]
        return "\n".join(lines) + "\n"


    def _base_does_not_describe(self) -> list[str]:
        """The first sentence where the base model predicts a held-out channel worse than
        its mean (fit below 0 %): any effect named is then relative to a model that
        does not describe the records."""
        before = self.holdout_fit_percent_before or {}
        poor = [c for c in self.channels if before.get(c, 0.0) < 0.0]
        if not poor:
            return []
        after = self.holdout_fit_percent_after
        fits = ", ".join(f"{c} {before[c]:.0f} %" + (f" ({after[c]:.0f} % after)" if
                                                    self.effects else "") for c in poor)
        return [f"**The base model does not describe these records:** its held-out fit is "
                f"below 0 % (worse than each record's mean) on {fits}. What follows is "
                "relative to a model that is wrong beyond any one effect; fix the model (or "
                "its start values) before reading the effects as the missing physics.", ""]


def _where(before: dict, after: dict) -> list[str]:
    """The disagreement section: records, windows, regions, sides, correlations."""
    lines = ["", "## Where the base model disagrees (training records, simulated)", "",
             "Residuals in standard deviations of each measured channel; descriptive "
             "(the tests below decide).", "",
             "| record | channel | fit % before | after | worst 60 s window | its RMS / "
             "record's |", "|---|---|---|---|---|---|"]
    for name, per in before["records"].items():
        w = before["windows"][name]
        span = f"{w['start_s']:.0f}-{w['end_s']:.0f} s" if w else "-"
        ratio = f"{w['rms'] / w['record_rms']:.2f}" if w and w["record_rms"] else "-"
        for c, m in per.items():
            lines.append(f"| {name} | {c} | {m['fit_percent']:.1f} | "
                         f"{after['records'][name][c]['fit_percent']:.1f} | {span} | {ratio} |")
    lines += ["", "| state region | samples % | squared residual % | ratio |",
              "|---|---|---|---|"]
    for k, v in before["regions"].items():
        ratio = "-" if v["ratio"] is None else f"{v['ratio']:.2f}"
        lines.append(f"| {k} ({before['regions_defined'][k]}) | {100 * v['fraction']:.0f} | "
                     f"{100 * v['share']:.0f} | {ratio} |")
    if before["sides"]:
        lines += ["", "| channel | mean residual, starboard turning | port | symmetric "
                  "(bias) | antisymmetric (odd in r) |", "|---|---|---|---|---|"]
        for c, v in before["sides"].items():
            lines.append(f"| {c} | {v['starboard']:+.2f} | {v['port']:+.2f} | "
                         f"{v['symmetric']:+.2f} | {v['antisymmetric']:+.2f} |")
    if before.get("forces"):
        lines += ["", "Loads the model lacks, from the measured u, v, r and their smoothed "
                  "derivatives (M dnu/dt - tau):", "",
                  "| load | mean | RMS | mean, starboard turning | port | follows |",
                  "|---|---|---|---|---|---|"]
        fmt = lambda x: "-" if x is None else f"{x:.3g}"
        for name, v in before["forces"].items():
            top = sorted(v["correlations"].items(), key=lambda kv: -kv[1])[:2]
            lines.append(f"| {name} [{v['unit']}] | {fmt(v['mean'])} | {fmt(v['rms'])} | "
                         f"{fmt(v['starboard'])} | {fmt(v['port'])} | "
                         + ", ".join(f"{k} {c:.2f}" for k, c in top) + " |")
    lines += ["", f"Signals the residuals follow (largest |correlation| over lags; 95 % band "
              f"of independent series {before['band']:.3f}):", ""]
    for c, corr in before["correlations"].items():
        top = sorted(corr.items(), key=lambda kv: -kv[1])[:3]
        lines.append(f"- {c}: " + ", ".join(f"{k} {v:.2f}" for k, v in top)
                     + f"; autocorrelations outside the band: "
                     f"{100 * before['whiteness'][c]:.0f} % before, "
                     f"{100 * after['whiteness'][c]:.0f} % after")
    return lines


def _plain(x):
    """Python floats, lists and dicts for JSON (a typed outcome as the dict of its
    fields)."""
    if isinstance(x, eqx.Module):
        return {f.name: _plain(getattr(x, f.name)) for f in dataclasses.fields(x)}
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, (np.generic, np.ndarray, jax.Array)) and np.ndim(x) == 0:
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):  # e.g. a candidate never scored
        return None
    return x
