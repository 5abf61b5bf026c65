"""The identification study of the thesis (Odegard 2009,
seed 000, chapter 4) on the built-in thesis vessel.

The experiment design of sec. 4.1 (turning circles at 5, 10, 20 and 40 deg, zig-zags
5/5 to 40/40 and the thesis manoeuvre, each at 200 and 500 rpm) is simulated with
`jaxship.get_vessel("thesis")`, measurement noise is added (`NOISE`), and three
response models are identified by prediction-error minimisation:

- `Nomoto1` (thesis eq. 3.2-3.3; K and T),
- `RossAutopilot` (thesis eq. 3.6-3.7 without roll; Ross' rudder moment
  $N_\\delta u^2\\delta$),
- `RossAutopilot` with speed-dependent rudder effectiveness (propeller race
  $n^2\\delta$ and stall $\\delta^3$ terms; `SPEED_RUDDER`),

from single experiments (the 40 deg trial of each family at 500 rpm, thesis sec. 4.2)
and from the merged experiments of each family at both rates (sec. 4.3). The score
is the thesis' fit % (eq. 3.23; MATLAB `compare`) of the yaw rate simulated from the
first sample with the recorded (simulated, noisy) rudder, u, v and n replayed (output
error), on the
40 deg / 500 rpm record of the family that the thesis' figures 4.8-4.30 show. The
fit % pooled over all records of the family is reported too.

Estimation: linear least-squares start (Nomoto1 ARX, `ross_initial_estimate`), then
Levenberg-Marquardt on the yaw-rate prediction error with a 10 s horizon
(`PredictionError(horizon=10.0)`), optionally refined on the output error
(`horizon=None`, `Settings(output_error=True)`); see `Settings` for why the two agree
here.
"""

import dataclasses
import math

import numpy as np

import jaxship as js

from .._workflow._trials import initial_state


DEG = math.pi / 180.0
RPMS = (200.0, 500.0)
FAMILIES = {
    "turning": ("turn:5", "turn:10", "turn:20", "turn:40"),
    "zigzag": ("zigzag:5/5", "zigzag:10/10", "zigzag:20/20", "zigzag:40/40"),
    "thesis": ("thesis",),
}
QUICK_FAMILIES = {
    "turning": ("turn:10", "turn:40"),
    "zigzag": ("zigzag:10/10", "zigzag:40/40"),
    "thesis": ("thesis",),
}
SHOWN = {"turning": "turn:40", "zigzag": "zigzag:40/40", "thesis": "thesis"}  # figs 4.8-4.30
MODELS = ("nomoto", "ross", "ross_speed_rudder")
# thesis fit % of the yaw rate (figs. 4.8-4.18 single, 4.20-4.30 merged)
THESIS_FIT = {
    "single": {"nomoto": {"turning": 83.93, "zigzag": 86.31, "thesis": 78.25},
               "ross": {"turning": 96.68, "zigzag": 96.91, "thesis": 97.63}},
    "merged": {"nomoto": {"turning": -98.11, "zigzag": 47.46, "thesis": 62.34},
               "ross": {"turning": 61.0, "zigzag": 75.75, "thesis": 81.12}},
}
# measurement noise, standard deviations (SI): a heading sensor, a rate gyro, speed
# through the water from a log / position fixes, and the rudder angle indicator
NOISE = {"psi": 0.1 * DEG, "r": 0.05 * DEG, "u": 0.005, "v": 0.005, "delta": 0.1 * DEG}


@dataclasses.dataclass(frozen=True)
class Settings:
    """Numbers of the study: sample interval `dt` [s] of the records (the simulation
    runs at `dt / 2`), the straight `approach` [s] before the rudder order, record
    lengths in units of L/U (`turn_length`, `zigzag_length`), the prediction
    `horizon` [s] of the first estimation stage, the RK4 `substeps` per sample of the
    models, the `span` [samples] of the least-squares start, the Levenberg-Marquardt
    `tolerance` (rtol = atol) and `max_steps`, whether to refine by `output_error`
    after the prediction-error stage, the `noise` and its `seed`.

    The thesis vessel's yaw response is fast (a fitted Nomoto T of 0.1-0.3 s against
    records of 100-1600 s), so the prediction of a 10 s window forgets its recorded
    start within a second: the 10 s prediction error is, to well under a percent of
    fit, the output error that the fit % measures, at a fraction of its cost (the
    windows run in parallel). `output_error=True` adds the output-error stage."""

    dt: float = 0.2
    approach: float = 10.0
    turn_length: float = 40.0
    zigzag_length: float = 45.0
    horizon: float = 10.0
    substeps: int = 2
    span: int = 5
    tolerance: float = 1e-6
    max_steps: int = 200
    output_error: bool = False
    noise: tuple = tuple(NOISE.items())
    seed: int = 0


def _manoeuvre(spec, vessel, x0, s: Settings):
    kind, _, rest = spec.partition(":")
    tau = float(vessel.length) / float(x0.u)
    dt = s.dt / 2
    if kind == "turn":
        return js.Turn(float(rest) * DEG, duration=s.approach + s.turn_length * tau, dt=dt,
                        execute=s.approach)
    if kind == "zigzag":
        a, h = (float(x) * DEG for x in rest.split("/"))
        return js.ZigZag(a, h, duration=s.approach + s.zigzag_length * tau, dt=dt,
                          execute=s.approach)
    if kind == "thesis":
        return js.thesis_manoeuvre(dt=dt)
    raise ValueError(f"unknown trial {spec!r}")


def reference_scales(vessel) -> dict:
    """Reference scales of `RossAutopilot` for `vessel`: $L_{pp}$ [m], the nominal
    speed [m/s] and propeller rate [rev/s]."""
    return dict(length=float(vessel.length), speed=float(vessel.nominal_speed),
                rate=float(vessel.nominal_n))


def record_name(spec, rpm) -> str:
    """The record name of trial `spec` at `rpm`, e.g. `"turn:40@500rpm"`."""
    return f"{spec}@{rpm:g}rpm"


def simulate_design(vessel=None, *, families=None, settings: Settings = Settings(),
                    progress=None) -> dict[str, tuple]:
    """Simulate the experiment design without noise: `{record name: (family, spec, rpm,
    manoeuvre, Trajectory)}` in the order of `families` (trials) and `RPMS`, at half the
    sample interval `settings.dt` (the trials of `jaxship reproduce`). `progress`: a
    callable taking the record name before each simulation, or None."""
    vessel = js.get_vessel("thesis") if vessel is None else vessel
    families = FAMILIES if families is None else families
    out = {}
    simulator = js.Simulator(substeps=2)
    for family, specs in families.items():
        for spec in specs:
            for rpm in RPMS:
                if progress is not None:
                    progress(record_name(spec, rpm))
                x0 = initial_state(vessel, rpm=rpm)
                manoeuvre = _manoeuvre(spec, vessel, x0, settings)
                traj = js.simulate(vessel, manoeuvre, x0, simulator=simulator)
                if not bool(traj.success):
                    raise RuntimeError(f"simulation of {spec} at {rpm:g} rpm failed")
                out[record_name(spec, rpm)] = (family, spec, rpm, manoeuvre, traj)
    return out


def noisy_records(design: dict, settings: Settings = Settings()) -> dict[str, js.Experiment]:
    """The records `{name: Experiment}` of a `simulate_design` result, sampled at
    `settings.dt` with the noise of `settings.noise` (seed `settings.seed`) added to psi,
    r, u, v and delta (n is exact)."""
    rng = np.random.default_rng(settings.seed)
    noise = dict(settings.noise)
    out = {}
    for name, (family, spec, rpm, _, traj) in design.items():
        exact = js.Experiment.from_trajectory(traj)
        keep = slice(None, None, 2)
        channels = {k: getattr(exact, k)[keep].copy() for k in
                    ("t", "delta", "psi", "r", "u", "v", "n")}
        for k, sigma in noise.items():
            channels[k] = channels[k] + sigma * rng.standard_normal(channels[k].shape)
        out[name] = js.Experiment(name=name, metadata=(("family", family), ("spec", spec),
                                                       ("rpm", rpm)), **channels)
    return out


def thesis_experiments(vessel=None, *, families=None, settings: Settings = Settings()
                       ) -> dict[str, js.Experiment]:
    """Simulate the experiment design and return noisy records `{name: Experiment}`
    (names `"turn:40@500rpm"`), sampled at `settings.dt` with the noise of
    `settings.noise` added to psi, r, u, v and delta (n is exact):
    `noisy_records(simulate_design(...))`."""
    return noisy_records(simulate_design(vessel, families=families, settings=settings),
                         settings)


def simulate_record(model, e: js.Experiment, substeps: int = 2) -> np.ndarray:
    """Yaw rate [rad/s] of `model` simulated over the record `e` from its first
    sample with its rudder, u, v and n replayed (no restarts: output error)."""
    tr = js.simulate(model, js.Replay(e.delta, dt=e.dt, delta_hold=js.strategies.FirstOrderHold()),
                     dataclasses.replace(js.straight_state(0.0, psi=e.psi[0]), r=e.r[0]),
                     aux=js.AuxInputs(u=e.u, v=e.v, n=e.n),
                     simulator=js.Simulator(max_step=math.inf, substeps=substeps))
    return np.asarray(tr.state.r)


def simulation_fit(model, records, substeps: int = 2) -> tuple[float, list[float]]:
    """(pooled fit %, per-record fit %) of the simulated yaw rate (thesis eq. 3.23),
    the first sample (a start value) excluded."""
    ys, yh = [], []
    for e in records:
        ys.append(e.r[1:])
        yh.append(simulate_record(model, e, substeps)[1:])
    per = [js.fit_percent(y, h) for y, h in zip(ys, yh)]
    n = max(len(y) for y in ys)
    pad = lambda a: np.concatenate([a, np.zeros(n - len(a))])
    mask = np.array([np.arange(n) < len(y) for y in ys])
    return js.fit_percent(np.stack([pad(y) for y in ys]), np.stack([pad(h) for h in yh]), mask), per


def nomoto_start(nomoto: js.Nomoto1, scales: dict) -> js.RossAutopilot:
    """A `RossAutopilot` that equals the fitted first-order Nomoto model at the
    reference speed ($u = U_0$): $\\dot r = (K\\delta - r)/T$ gives
    $a_{ur} = -L/(U_0T)$ and $a_\\delta = KL^2/(TU_0^2)$, all other terms zero. A
    stable start for the nonlinear fit when the data do not determine all terms
    (e.g. a single turning circle)."""
    L, U = scales["length"], scales["speed"]
    K, T = float(nomoto.K), float(nomoto.T)
    return js.RossAutopilot(**scales, n_ur=-L / (U * T), n_delta=K * L**2 / (T * U**2))


def _estimators(settings: Settings):
    solver = js.LevenbergMarquardt(rtol=settings.tolerance, atol=settings.tolerance)
    common = dict(channels=("r",), solver=solver,
                  simulator=js.Simulator(max_step=math.inf, substeps=settings.substeps),
                  max_steps=settings.max_steps)
    return (js.PredictionError(horizon=settings.horizon, **common),
            js.PredictionError(horizon=None, **common))


def _safe_fit(model, records, free, estimator):
    """`fit`, or None when the model diverges on the data (non-finite cost)."""
    try:
        with np.errstate(over="ignore", invalid="ignore"):  # residuals of a diverged model
            result = js.fit(model, records, free=free, estimator=estimator)
    except (ValueError, np.linalg.LinAlgError):  # NaN residuals of an unstable model
        return None
    return result if np.isfinite(result.cost) else None


def identify(model_name, records, vessel, *, settings: Settings = Settings(), nomoto=None,
             base=None):
    """Identify `model_name` (one of `MODELS`) from `records` (a list of
    experiments): start values, then prediction error on the yaw rate with
    `settings.horizon` (and output error if `settings.output_error`; see `Settings`).

    - `"nomoto"`: ARX least-squares start (`initial_estimate`).
    - `"ross"`: two starts, `ross_initial_estimate` and the Nomoto-equivalent
      `nomoto_start` (from `nomoto`, a fitted `Nomoto1`, fitted here if None); the
      least-squares start can be unstable off the data when the records do not
      excite all 13 terms. The output-error stage starts from the prediction-error
      estimate of lower cost (the other if that one diverges).
    - `"ross_speed_rudder"`: starts from `base` (a fitted `RossAutopilot`, e.g. the
      `"ross"` result; the extra rudder terms at 0), so that the larger model's
      output-error cost is at most the smaller one's, else as `"ross"`.

    Returns the `FitResult` of the last stage.
    """
    pe, oe = _estimators(settings)
    if nomoto is None or model_name == "nomoto":
        nomoto = js.LinearStart()(js.Nomoto1(K=0.1, T=5.0), records, None, "delta")
        nomoto = js.fit(nomoto, records, free=("K", "T"), estimator=pe).model
    if model_name == "nomoto":
        if not settings.output_error:
            return js.fit(nomoto, records, free=("K", "T"), estimator=pe)
        return js.fit(nomoto, records, free=("K", "T"), estimator=oe)
    free = js.default_free(js.RossAutopilot())  # Ross' hull terms and his rudder term
    if model_name != "ross":  # and the speed-dependent rudder (RossAutopilot's docstring)
        free += ("n_delta_nn", "n_delta3", "n_delta3_nn")
    scales = reference_scales(vessel)
    if model_name == "ross_speed_rudder" and base is not None:
        starts = [base]
    else:
        starts = [nomoto_start(nomoto, scales)]
        try:
            starts.append(js.LinearStart(span=settings.span)(js.RossAutopilot(**scales),
                                                             records, free, "delta"))
        except ValueError:  # singular regression: the Nomoto start only
            pass
    stages = [r for r in (_safe_fit(m, records, free, pe) for m in starts) if r is not None]
    for stage in sorted(stages, key=lambda r: r.cost):
        if not settings.output_error:
            return stage
        result = _safe_fit(stage.model, records, free, oe)
        if result is not None:
            return result
    raise RuntimeError(f"every start of the {model_name} fit diverged")


def identification_study(vessel=None, *, quick=False, settings: Settings = Settings(),
                         experiments=None, progress=None, families=None,
                         models=MODELS, cases=("single", "merged")) -> dict:
    """Run the study; returns a JSON-ready dict with `table` rows
    `{case, model, family, fit, fit_family, per_record, thesis}` (simulation fit % of
    the yaw rate on the family's 40 deg / 500 rpm record, pooled over all records of
    the family at both rates (None where the model diverges), and the thesis'
    number; a fit that fails has `success` False and its `error`, and the others go
    on), the fitted `parameters` per `"case/model/family"` (`parameter_entries`:
    value, std, std_robust and unit of each; None where it failed), the
    `noise`,
    the `settings` and the experiment `records`.

    `quick`: two trials per family instead of four (turn 10 and 40 deg, zig-zag
    10/10 and 40/40); `experiments`: records from `thesis_experiments` (simulated
    if None); `progress`: a callable taking a message string, or None; `families`
    {family: trial specs} (default `FAMILIES`, or `QUICK_FAMILIES` if `quick`) and
    `models` (a subset of `MODELS`, in order; "ross_speed_rudder" starts from "ross")
    and `cases` ("single", "merged") narrow the study (`jaxship reproduce --quick`).
    """
    vessel = js.get_vessel("thesis") if vessel is None else vessel
    if families is None:
        families = QUICK_FAMILIES if quick else FAMILIES
    if experiments is None:
        experiments = thesis_experiments(vessel, families=families, settings=settings)
    say = progress or (lambda msg: None)
    names, (rows, params, models) = tuple(models), ([], {}, {})
    for case in cases:
        for family, specs in families.items():
            shown = experiments[record_name(SHOWN[family], 500.0)]
            family_records = [experiments[record_name(s, rpm)] for s in specs for rpm in RPMS]
            train = [shown] if case == "single" else family_records
            fitted = {}
            for model_name in names:
                say(f"{case} {family}: {model_name}")
                key = f"{case}/{model_name}/{family}"
                thesis_fit = THESIS_FIT[case].get(model_name, {}).get(family)
                try:
                    result = identify(model_name, train, vessel, settings=settings,
                                      nomoto=fitted.get("nomoto"), base=fitted.get("ross"))
                except (RuntimeError, ValueError) as error:  # the other fits go on
                    say(f"{case} {family}: {model_name} failed: {error}")
                    rows.append(dict(case=case, model=model_name, family=family, fit=None,
                                     fit_family=None, thesis=thesis_fit, success=False,
                                     per_record={e.name: None for e in family_records},
                                     error=str(error)))
                    params[key], models[key] = None, None
                    continue
                fitted[model_name] = result.model
                fit_shown, _ = simulation_fit(result.model, [shown], settings.substeps)
                fit_family, per = simulation_fit(result.model, family_records,
                                                 settings.substeps)
                rows.append(dict(
                    case=case, model=model_name, family=family, fit=_finite(fit_shown),
                    fit_family=_finite(fit_family), thesis=thesis_fit,
                    per_record={e.name: _finite(f) for e, f in zip(family_records, per)},
                    success=result.success,
                ))
                params[key] = parameter_entries(result)
                models[key] = result.model
    return {"table": rows, "parameters": params, "models": models,
            "noise": dict(settings.noise),
            "settings": dataclasses.asdict(settings) | {"noise": dict(settings.noise)},
            "records": sorted(experiments), "quick": bool(quick)}


def _finite(x):
    return float(x) if np.isfinite(x) else None


def _plain(x):  # JSON: None for NaN (not computed), "inf" for an undetermined estimate
    x = float(x)
    return x if np.isfinite(x) else (None if np.isnan(x) else "inf")


def parameter_entries(result) -> dict:
    """`{name: {value, std, std_robust, unit}}` of the free parameters of a `FitResult`:
    the estimate, its white-noise standard error, the one that does not assume white
    residuals (`ParameterReport.std_robust`, clustered by window or Newey-West; None
    where not computed) and the parameter's unit."""
    p = result.parameters
    robust = getattr(p, "std_robust", None)
    robust = np.full(len(p.names), np.nan) if robust is None else np.asarray(robust)
    return {n: {"value": float(v), "std": _plain(s), "std_robust": _plain(r), "unit": u}
            for n, v, s, r, u in zip(p.names, p.values, p.std, robust, p.units)}


def quoted_std(entry) -> float:
    """The standard error to quote for a `parameter_entries` entry: the robust one where
    computed, else the white-noise one (inf where undetermined)."""
    for key in ("std_robust", "std"):
        s = entry.get(key)
        if s is not None:
            return math.inf if s == "inf" else float(s)
    return math.nan


def to_json(study: dict) -> dict:
    """The study without the model objects, for `json.dumps`."""
    return {k: v for k, v in study.items() if k != "models"}


def markdown_table(study: dict) -> str:
    """The study as a markdown table: fit % of the yaw rate, ours vs the thesis'."""
    names = {"nomoto": "Nomoto 1st order", "ross": "Ross autopilot",
             "ross_speed_rudder": "Ross + speed-dependent rudder"}
    lines = ["| experiments | model | family | fit % (40 deg, 500 rpm) | fit % (family) | "
             "thesis fit % |", "|---|---|---|---|---|---|"]
    for row in study["table"]:
        cell = lambda x: "diverges" if x is None else f"{x:.2f}"
        thesis = "" if row["thesis"] is None else f"{row['thesis']:.2f}"
        lines.append(f"| {row['case']} | {names[row['model']]} | {row['family']} | "
                     f"{cell(row['fit'])} | {cell(row['fit_family'])} | {thesis} |")
    return "\n".join(lines) + "\n"


def sign_flips(parameters: dict) -> list[dict]:
    """The coefficients whose estimated sign differs between the fits of one model
    (`parameters`: `{"case/model/family": thesis.parameter_entries(...) or None}`):
    one dict per coefficient, `{model, parameter, unit, estimates: [{fit, value, std}],
    determined}`, `std` the quoted one (`thesis.quoted_std`). `determined`: a positive
    and a negative estimate both lie more than 2 std from zero (their 95 % intervals
    exclude zero on opposite sides), so the flip is not within the uncertainty."""
    by = {}
    for key, entries in parameters.items():
        if not entries:
            continue
        model = key.split("/")[1]
        for name, e in entries.items():
            by.setdefault((model, name), []).append(
                {"fit": key, "value": e["value"], "std": quoted_std(e),
                 "unit": e.get("unit")})
    out = []
    for (model, name), estimates in by.items():
        signs = {np.sign(e["value"]) for e in estimates if e["value"] != 0}
        if signs != {-1.0, 1.0}:
            continue
        sure = lambda sign: any(np.sign(e["value"]) == sign and abs(e["value"]) > 2 * e["std"]
                                for e in estimates)
        out.append({"model": model, "parameter": name, "unit": estimates[0]["unit"],
                    "estimates": [{k: e[k] for k in ("fit", "value", "std")} | {
                        "std": None if not np.isfinite(e["std"]) else e["std"]}
                        for e in estimates],
                    "determined": bool(sure(1.0) and sure(-1.0))})
    return out
