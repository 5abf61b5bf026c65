"""The IMO check (`js.indices.check_imo`, what `jaxship simulate --manoeuvre imo` runs): the
IMO MSC.137(76) trials of a vessel (the 35 deg turn, the 10/10 and 20/20 zig-zags and,
with a propeller, the full-astern stop), each criterion met or not with its margin, and
the band of each index that the parameters' standard errors give (`simulate_batch` over
parameter draws)."""

import dataclasses

import equinox as eqx
import jax
import numpy as np

import jaxship as js

from .._simulation._integrate import RK4, stages_rolled_by_default
from ._identify.result import check_fields
from ._trials import (
    StandardTrial,
    _cut_at_stop,
    _size,
    check_operating_point,
    initial_state,
    length_over_speed,
)


DRAWS = 64  # parameter draws of the band
LEVEL = 0.9  # the band: the central 90 % of the draws' values
SEED = 0
# MSC.137(76), 4.2.1: the trials at a test speed of at least 90 % of the ship's speed at
# 85 % of its maximum engine output (taken as the vessel's nominal, service speed)
TEST_SPEED_SHARE = 0.9


@dataclasses.dataclass(frozen=True)
class ImoCheck:
    """The IMO check of `check_imo`: the criteria `rows` (`CriterionRow`: value, limit,
    met), the `runs` `{trial as written: (manoeuvre, trajectory, marks)}` and the band:
    `bands` `{criterion: (low, high)}`, `passed` `{criterion: fraction of the draws that
    meet it}`, `draws` (how many, how many ran, from what) and `notes` (e.g. an approach
    below the resolution's test speed). `str()` is `table()`."""

    rows: list
    runs: dict
    bands: dict
    passed: dict
    draws: dict
    notes: tuple = ()

    def to_dict(self) -> dict:
        rows = [row.to_dict() | {"margin": row.limit - row.value if np.isfinite(row.value)
                                 else None,
                                 "band": list(self.bands.get(row.criterion, ())) or None,
                                 "passed_in_draws": self.passed.get(row.criterion)}
                for row in self.rows]
        return {"imo_criteria": rows, "uncertainty": self.draws} | (
            {"notes": list(self.notes)} if self.notes else {})

    def table(self) -> str:
        """The criteria as a markdown table: value, limit, margin, band, met."""
        lines = [f"| criterion | value | limit | margin (limit - value) | {LEVEL:.0%} band "
                 "| met |", "|---|---:|---:|---:|---|:---:|"]
        for row in self.rows:
            lo, hi = self.bands.get(row.criterion, (None, None))
            band = "-" if lo is None else f"{lo:.2f} to {hi:.2f} {row.unit}"
            value, margin = (f"{row.value:.2f} {row.unit}", f"{row.limit - row.value:+.2f} "
                             f"{row.unit}") if np.isfinite(row.value) else ("-", "-")
            lines.append(f"| {row.criterion} | {value} | {row.limit:.2f} {row.unit} | {margin} "
                         f"| {band} | {'yes' if row.passed else 'NO'} |")
        return "\n".join(lines + [f"\n{row.criterion}: {row.note}." for row in self.rows
                                   if row.note]) + "\n"

    def __str__(self) -> str:
        return self.table()

    def to_markdown(self, title: str) -> str:
        """The check as `criteria.md` holds it: a heading with `title`, the table, and
        what the band was drawn from (no band: why)."""
        band = (f"Band: the central {self.draws['level']:.0%} of {self.draws['used']} of "
                f"{self.draws['draws']} parameter draws from {self.draws['from']}."
                if self.draws["draws"] else
                f"No band: {self.draws['from'].removeprefix('none: ')}.")
        return (f"# IMO MSC.137(76) criteria: {title}\n\n{self.table()}\n{band}\n"
                + "".join(f"\nNote: {n}\n" for n in self.notes))


def parameter_draws(report, rng) -> tuple[tuple, np.ndarray, str]:
    """`(names, (DRAWS, d) values, how)` of the fitted parameters of an identify
    `report`: from the covariance $D C D$ (std and correlation) where the correlation
    is stored, else independent normal draws from std; parameters with no finite
    standard error are held at their estimates (`how` says which)."""
    if not report or not isinstance(report.get("parameters"), dict):
        return (), np.zeros((DRAWS, 0)), "none: no standard errors (a preset or a vessel file)"
    check_fields(report)  # a damaged std or correlation: one line, before any trial
    entries = {k: e for k, e in report["parameters"].items() if isinstance(e, dict)}
    std = {k: _float(e.get("std")) for k, e in entries.items()}
    names = tuple(k for k, s in std.items() if np.isfinite(s) and s >= 0)
    held = [k for k in entries if k not in names]
    values = [float(entries[k]["value"]) for k in names]
    correlation = (report.get("correlation") or {})
    order = list(correlation.get("names") or [])
    matrix = np.asarray(correlation.get("matrix") or [], dtype=float) if order else None
    if matrix is not None and set(names) <= set(order) and np.all(np.isfinite(matrix)):
        index = [order.index(k) for k in names]
        corr, how = matrix[np.ix_(index, index)], "the covariance (std and correlation)"
    else:
        corr, how = None, "independent normal draws from std (no correlation stored)"
    # draws from N(theta, D C D): D the standard errors, C the correlation (or identity)
    sd = np.asarray([std[k] for k in names], np.float64)
    cov = (np.eye(len(names)) if corr is None else np.asarray(corr, np.float64)) * np.outer(sd, sd)
    draws = rng.multivariate_normal(np.asarray(values, np.float64), cov, size=DRAWS,
                                    method="eigh", check_valid="ignore")  # rounding: slightly < 0
    if held:
        how += f"; held at the estimate (no finite std): {', '.join(held)}"
    return names, draws, how


def _float(value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return np.inf


def check_imo(model, *, identification=None, speed=None, rpm=None) -> ImoCheck:
    """Run the IMO MSC.137(76) 5.3 trials of the vessel `model` (`StandardTrial.imo`,
    each sized by `StandardTrial.sized`) from the straight run at `speed` [m/s] and/or
    `rpm` (nominal if neither), check each criterion (`js.indices.imo_criteria`: value,
    limit, margin = limit - value, met), and with `identification` (an identification
    result, anything with `to_dict()`, or the dict of its `result.json`) give each
    criterion its band: the central 90 % of its values over 64 parameter draws from
    the fit's covariance $D C D$ (std and correlation; seed 0), each draw run through
    every trial at once (`js.simulate_batch`)."""
    report = identification.to_dict() if callable(getattr(identification, "to_dict", None)) \
        else identification
    names, draws, how = parameter_draws(report, np.random.default_rng(SEED))  # read first
    check_operating_point(model, speeds=[speed] if speed else [], rpms=[rpm] if rpm else [])
    runs, batch, rows = {}, {}, []
    x0 = initial_state(model, speed=speed, rpm=rpm)
    tau = length_over_speed(model, x0)
    approach, service = float(np.hypot(x0.u, x0.v)), float(model.nominal_speed)
    notes = () if approach >= TEST_SPEED_SHARE * service else (
        f"the approach speed {approach:.3g} m/s is {100 * approach / service:.0f} % of the "
        f"service speed {service:.3g} m/s; MSC.137(76) 4.2.1 tests at no less than "
        f"{100 * TEST_SPEED_SHARE:.0f} % of it, so these criteria are not the resolution's.",)
    for trial in StandardTrial.imo(model):
        manoeuvre, traj = _size(trial, model, x0, tau, duration=None, dt=None)
        traj = js.simulate(model, manoeuvre, x0, simulator=StandardTrial.simulator) \
            if traj is None else _cut_at_stop(traj) if trial.kind == "stop" else traj
        if not bool(traj.success):
            raise ValueError(f"the {trial.kind} trial failed (non-finite state).")
        marks = trial.marks(manoeuvre, traj)
        runs[str(trial)], batch[trial] = (manoeuvre, traj, marks), manoeuvre
        rows += trial.criteria(model, traj, marks)
    bands, passed, used = {}, {}, 0
    if names:
        values, used = _drawn_criteria(model, names, draws, batch, speed=speed, rpm=rpm)
        for criterion, (found, met) in values.items():
            if not found.size:
                continue
            bands[criterion] = tuple(float(q) for q in np.quantile(
                found, [(1 - LEVEL) / 2, (1 + LEVEL) / 2]))
            passed[criterion] = float(np.mean(met))
    info = {"draws": DRAWS if names else 0, "used": used, "level": LEVEL, "from": how,
            "parameters": list(names), "seed": SEED}
    if names:
        bands, passed, said = _trusted_bands(rows, bands, passed, used)
        notes += said
    return ImoCheck(rows, runs, bands, passed, info, notes)


def _within(value: float, low: float, high: float) -> bool:
    """`low <= value <= high` up to rounding (1e-9 of the value): the fitted value and
    the draws come from different compiled programs (one run, a batch), so a criterion
    the drawn parameters do not move has a band of zero width that the value may miss
    by its last digit."""
    slack = 1e-9 * max(abs(value), 1e-300)
    return low - slack <= value <= high + slack


def _trusted_bands(rows, bands, passed, used) -> tuple[dict, dict, tuple[str, ...]]:
    """`(bands, passed, notes)`: no band where fewer than half the draws ran every trial
    (those that ran are a biased half: the standard errors reach where the model blows
    up), and a note for draws left out and for a value outside its own band."""
    if used < DRAWS / 2:
        return {}, {}, (f"only {used} of {DRAWS} parameter draws ran every trial (the others "
                        "blew up): the standard errors reach where the model cannot run, so "
                        "no band is given; identify on records that determine the model.",)
    notes = (f"{DRAWS - used} of {DRAWS} parameter draws blew up in a trial and are left out "
             f"of the bands, drawn from the {used} that ran.",) if used < DRAWS else ()
    outside = [f"{row.criterion} ({row.value:.3g} {row.unit})" for row in rows
               if row.criterion in bands and np.isfinite(row.value)
               and not _within(row.value, *bands[row.criterion])]
    if outside:
        notes += (f"the fitted value lies outside its own {LEVEL:.0%} band for "
                  f"{', '.join(outside)}: the draws do not describe the fit there.",)
    return bands, passed, notes


def _drawn_criteria(vessel, names, draws, batch, *, speed, rpm):
    """`({criterion: (values, met or not)}, how many)` of the draws that ran every trial:
    each manoeuvre of `batch` `{trial: manoeuvre}` simulated at once for every parameter
    draw (`simulate_batch`; a stop for its whole duration)."""
    vessels = [vessel.with_parameters(dict(zip(names, row))) for row in draws]
    nominal = initial_state(vessel, speed=speed, rpm=rpm)
    starts, ran = [], np.ones(len(vessels), bool)
    for k, v in enumerate(vessels):  # a draw with no straight run is left out
        try:
            starts.append(initial_state(v, speed=speed, rpm=rpm))
        except ValueError:
            starts.append(nominal)
            ran[k] = False
    x0, stacked, found = js.stack(starts), js.stack(vessels), {}
    # the draws integrated as the fitted run is (`js.simulate`: RK4's stages rolled on the
    # CPU, written out on an accelerator), so that a criterion they do not move has the
    # fitted value for its band to the last digit, not a batch's other rounding
    as_one_run = eqx.tree_at(lambda s: s.solver, StandardTrial.simulator,
                             RK4(rolled=stages_rolled_by_default()))
    for trial, manoeuvre in batch.items():
        trajs = jax.tree.map(np.asarray, js.simulate_batch(
            stacked, manoeuvre, x0, in_axes=(0, None, 0, None), simulator=as_one_run))
        for k, v in enumerate(vessels):
            traj = jax.tree.map(lambda a, k=k: a[k], trajs)
            marks = trial.marks(manoeuvre, traj) if traj.success else None
            rows = trial.criteria(v, traj, marks)
            ran[k] &= bool(rows) and all(np.isfinite(row.value) for row in rows)
            for row in rows:
                found.setdefault(row.criterion, {})[k] = (row.value, row.passed)
    keep = [k for k in np.flatnonzero(ran)]
    return ({c: tuple(np.array([by[k][i] for k in keep if k in by]) for i in (0, 1))
             for c, by in found.items()}, len(keep))
