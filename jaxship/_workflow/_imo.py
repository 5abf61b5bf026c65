"""`jaxship simulate --manoeuvre imo`: the IMO MSC.137(76) trials of a vessel (the 35 deg
turn, the 10/10 and 20/20 zig-zags and, with a propeller, the full-astern stop), each
criterion met or not with its margin, and the band of each index that the parameters'
standard errors give (`simulate_batch` over parameter draws)."""

import dataclasses

import jax
import numpy as np

import jaxship as js

from .._models._vessel._base import surge_force
from ._trials import (
    TrialSpec,
    initial_state,
    run_spec,
    spec_text,
    trial_criteria,
    trial_marks,
)


DRAWS = 64  # parameter draws of the band
LEVEL = 0.9  # the band: the central 90 % of the draws' values
SEED = 0
SIMULATOR = js.Simulator(substeps=2)  # as `run_spec`'s


def imo_specs(vessel) -> tuple[TrialSpec, ...]:
    """The trials of MSC.137(76) 5.3 for `vessel`: the stop only where it has a
    propeller model (astern thrust differs from ahead)."""
    specs = [TrialSpec.parse(s) for s in ("turn:35", "zigzag:10/10", "zigzag:20/20")]
    u, n = float(vessel.nominal_speed), float(vessel.nominal_n)
    if n and float(surge_force(vessel, u, n) - surge_force(vessel, u, -n)) != 0.0:
        specs.append(TrialSpec.parse("stop"))
    return tuple(specs)


@dataclasses.dataclass(frozen=True)
class ImoCheck:
    """The criteria rows (`CriterionRow`), the runs `{spec text: (manoeuvre, trajectory,
    marks)}` and the band: `bands` `{criterion: (low, high)}`, `passed` `{criterion:
    fraction of the draws that meet it}`, `draws` (how many, from what)."""

    rows: list
    runs: dict
    bands: dict
    passed: dict
    draws: dict

    def to_dict(self) -> dict:
        rows = [row.to_dict() | {"margin": row.limit - row.value,
                                 "band": list(self.bands.get(row.criterion, ())) or None,
                                 "passed_in_draws": self.passed.get(row.criterion)}
                for row in self.rows]
        return {"imo_criteria": rows, "uncertainty": self.draws}

    def table(self) -> str:
        """The criteria as a markdown table: value, limit, margin, band, met."""
        lines = [f"| criterion | value | limit | margin (limit - value) | {LEVEL:.0%} band "
                 "| met |", "|---|---:|---:|---:|---|:---:|"]
        for row in self.rows:
            lo, hi = self.bands.get(row.criterion, (None, None))
            band = "-" if lo is None else f"{lo:.2f} to {hi:.2f} {row.unit}"
            lines.append(f"| {row.criterion} | {row.value:.2f} {row.unit} | {row.limit:.2f} "
                         f"{row.unit} | {row.limit - row.value:+.2f} {row.unit} | {band} | "
                         f"{'yes' if row.passed else 'NO'} |")
        return "\n".join(lines) + "\n"


def parameter_draws(report, rng) -> tuple[tuple, np.ndarray, str]:
    """`(names, (DRAWS, d) values, how)` of the fitted parameters of an identify
    `report`: from the covariance $D C D$ (std and correlation) where the correlation
    is stored, else independent normal draws from std; parameters with no finite
    standard error are held at their estimates (`how` says which)."""
    if not report or not isinstance(report.get("parameters"), dict):
        return (), np.zeros((DRAWS, 0)), "none: no standard errors (a preset or a vessel file)"
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


def check_imo(vessel, *, report=None, speed=None, rpm=None) -> ImoCheck:
    """Run the IMO trials of `vessel` (`imo_specs`), check the criteria, and with the
    identify `report` propagate its standard errors to a band on each criterion."""
    runs, rows = {}, []
    for spec in imo_specs(vessel):
        manoeuvre, traj = run_spec(vessel, spec, speed=speed, rpm=rpm)
        if not bool(traj.success):
            raise ValueError(f"the {spec.kind} trial failed (non-finite state).")
        marks = trial_marks(spec, manoeuvre, traj)
        runs[spec] = (manoeuvre, traj, marks)
        rows += trial_criteria(spec, vessel, traj, marks)
    names, draws, how = parameter_draws(report, np.random.default_rng(SEED))
    bands, passed, used = {}, {}, 0
    if names:
        values, used = _drawn_criteria(vessel, names, draws, runs, speed=speed, rpm=rpm)
        for criterion, (found, met) in values.items():
            if not found.size:
                continue
            bands[criterion] = tuple(float(q) for q in np.quantile(
                found, [(1 - LEVEL) / 2, (1 + LEVEL) / 2]))
            passed[criterion] = float(np.mean(met))
    info = {"draws": DRAWS if names else 0, "used": used, "level": LEVEL, "from": how,
            "parameters": list(names), "seed": SEED}
    return ImoCheck(rows, {spec_text(s): r for s, r in runs.items()}, bands, passed, info)


def _drawn_criteria(vessel, names, draws, runs, *, speed, rpm):
    """`({criterion: (values, met or not)}, how many)` of the draws that ran every trial:
    each trial of `runs` simulated at once for every parameter draw (`simulate_batch`)."""
    vessels = [vessel.with_parameters(dict(zip(names, row))) for row in draws]
    nominal = initial_state(vessel, speed=speed, rpm=rpm)
    starts, ran = [], np.ones(len(vessels), bool)
    for k, v in enumerate(vessels):  # a draw with no straight run is left out
        try:
            starts.append(initial_state(v, speed=speed, rpm=rpm))
        except ValueError:
            starts.append(nominal)
            ran[k] = False
    x0, batch, found = js.stack(starts), js.stack(vessels), {}
    for spec, (manoeuvre, _, _) in runs.items():
        trajs = jax.tree.map(np.asarray, js.simulate_batch(
            batch, manoeuvre, x0, in_axes=(0, None, 0, None), simulator=SIMULATOR))
        for k, v in enumerate(vessels):
            traj = jax.tree.map(lambda a, k=k: a[k], trajs)
            marks = trial_marks(spec, manoeuvre, traj) if traj.success else None
            rows = trial_criteria(spec, v, traj, marks)
            ran[k] &= bool(rows)
            for row in rows:
                found.setdefault(row.criterion, {})[k] = (row.value, row.passed)
    keep = [k for k in np.flatnonzero(ran)]
    return ({c: tuple(np.array([by[k][i] for k in keep if k in by]) for i in (0, 1))
             for c, by in found.items()}, len(keep))
