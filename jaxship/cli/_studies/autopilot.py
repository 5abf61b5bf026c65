"""The heading-autopilot study of the thesis (Odegard 2009, seed 000, chapter 5) on the
built-in thesis vessel, and the evaluation of one identified model behind
`jaxship autopilot`.

**Chapter 5.** The steering models of chapter 4 identified from the merged experiments
(200 + 500 rpm) of each family (turning circles, zig-zags, the thesis manoeuvre;
`jaxship.cli._studies.thesis`) each give a PID autopilot by pole placement (eq. 5.3-5.5)
and a reference feed-forward (eq. 5.2 for Nomoto, eq. 5.6 for Ross), driven by the
third-order reference model of Table 5.1 (45 deg step at 100 s, damping 1.0,
natural frequency 0.2 rad/s). Each autopilot steers the *true* thesis vessel
(`jaxship.vessel("thesis")`, rudder 45 deg and 15 deg/s through its servo) at 300
and 400 rpm, with feed-forward (`"pid+ff"`, the thesis' controller) and without
(`"pid"`). The score is the thesis' closed-loop residual, eq. 3.19,
$\\sum_k|\\psi_d(t_k) - \\psi(t_k)|$ in degrees, **sampled every 1 s over 100-200 s**
(the thesis states neither unit nor sampling: its Tables 5.2-5.7 are compared by
ordering and ratios, not by absolute size).

**The controller's own natural frequency and damping** are not in the thesis (only
the reference model's, Table 5.1). `Design` uses $\\omega_n$ = 0.5 rad/s, 2.5 times
the reference's 0.2 rad/s (the error stays small while $\\psi_d$ moves) and half the
bandwidth of the rudder servo it does not model (1 s), and $\\zeta$ = 1 as the
reference (no overshoot). $K_d$ is Fossen's $2\\zeta\\omega_n m - d$ (exact pole
placement), not the thesis' printed $2\\zeta\\omega_n m$ (which damps more by
$d/(2m\\omega_n)$). The gains are designed once, at the mean operating point of the
runs, and kept for every run; the feed-forward uses the simulated vessel's $u$, $v$, $n$
(noise-free, as an ideal sensor would give them).
"""

import dataclasses
import itertools
import math

import numpy as np
import scipy.stats

import jaxship as js

from . import thesis


DEG = math.pi / 180.0
# the thesis design's proportions (Table 5.1 with omega_n = 0.5 rad/s): reference model
# at 0.4 omega_n, the heading step at 50 / omega_n (100 s), the run twice as long; and
# its omega_n times the yaw time constant of its Nomoto model (2.6 s at 350 rpm: 1.3)
REFERENCE_RATIO = 0.4
STEP_TIME_RATIO = 50.0
BANDWIDTH_TIMES_T = 1.25
RPMS = (300.0, 400.0)  # thesis sec. 5.4: simulated at 300 and 400 rpm
FAMILIES = ("turning", "zigzag", "thesis")
MODELS = ("nomoto", "ross")
MODEL_NAMES = {"nomoto": "Nomoto", "ross": "Ross", "ross_speed_rudder": "Ross + speed rudder"}
FAMILY_NAMES = {"turning": "turning circles", "zigzag": "zig-zags",
                "thesis": "thesis manoeuvre"}
# thesis Tables 5.2-5.7: closed-loop residuals (eq. 3.19) at (300, 400) rpm
THESIS_RESIDUALS = {
    "nomoto": {"turning": (80.4113, 44.7822), "zigzag": (108.0843, 17.3626),
               "thesis": (179.6080, 69.0153)},
    "ross": {"turning": (110.0642, 185.0572), "zigzag": (125.1633, 145.2591),
             "thesis": (78.7259, 31.0921)},
}
THESIS_TABLES = {("nomoto", "turning"): "5.2", ("nomoto", "zigzag"): "5.3",
                 ("nomoto", "thesis"): "5.4", ("ross", "turning"): "5.5",
                 ("ross", "zigzag"): "5.6", ("ross", "thesis"): "5.7"}
CONTROLLERS = ("pid+ff", "pid")  # with and without the reference feed-forward
# the columns of a run (`Evaluation.rows`, `autopilot.json` "runs")
RUN_KEYS = ("controller", "rpm", "speed", "sum_abs_error_deg", "rms_error_deg",
            "max_overshoot_deg", "settling_time_s", "mean_abs_rudder_deg",
            "rudder_travel_deg", "time_rate_limited_s")


@dataclasses.dataclass(frozen=True)
class Design:
    """Numbers of the autopilot design and of the closed-loop runs.

    - `natural_frequency` $\\omega_n$ [rad/s], `damping` $\\zeta$ [-]: the PID's pole
      placement (eq. 5.3-5.5; the module docstring says why); `subtract_damping`:
      Fossen's $K_d = 2\\zeta\\omega_n m - d$ (True) or the thesis' $2\\zeta\\omega_n m$;
    - `reference_frequency` [rad/s], `reference_damping` [-]: the reference model and
      `step` [deg] at `step_time` [s], relative to the initial heading (Table 5.1: 0.2
      rad/s, 1.0, 45 deg at 100 s); `duration` [s] of each run;
    - `dt` [s]: output interval; `interval` [s]: the controller's update interval;
    - `sample_interval` [s]: sampling of the residual eq. 3.19 and the RMS error over
      `step_time` to `duration`;
    - `tune_dt` [s], `tune_steps`, `rudder_weight`: `tune_autopilot`'s output
      interval, step limit and rudder weight (`--tune`);
    - `basis`: how the numbers were chosen, in one sentence (`scaled`).

    `Design.scaled(omega_n)` keeps the thesis' proportions for any ship: the reference at
    0.4 omega_n, the step at 50 / omega_n (two digits) and the run twice as long (Table 5.1's 0.2
    rad/s, 100 s and 200 s for 0.5 rad/s); `natural_frequency_for` derives omega_n from
    the model's own yaw time constant.
    """

    natural_frequency: float = 0.5
    damping: float = 1.0
    subtract_damping: bool = True
    reference_frequency: float = 0.2
    reference_damping: float = 1.0
    step: float = 45.0
    step_time: float = 100.0
    duration: float = 200.0
    dt: float = 0.1
    interval: float = 0.1
    sample_interval: float = 1.0
    tune_dt: float = 1.0
    tune_steps: int = 20
    rudder_weight: float = 0.1
    basis: str = "the thesis' numbers (Table 5.1) and omega_n = 0.5 rad/s"

    @classmethod
    def scaled(cls, natural_frequency: float, *, basis: str = "", **kwargs) -> "Design":
        """The thesis' proportions about `natural_frequency` [rad/s] (class text)."""
        w = float(natural_frequency)
        step_time = float(f"{STEP_TIME_RATIO / w:.2g}")  # two digits: 100 s, 840 s
        return cls(natural_frequency=w, reference_frequency=REFERENCE_RATIO * w,
                   step_time=step_time, duration=2 * step_time,
                   basis=basis or f"omega_n = {w:.4g} rad/s as given, the reference and "
                   "timing in the thesis' proportions", **kwargs)

    @property
    def window(self) -> tuple[float, float]:
        """(start, end) [s] of the metrics: from the step to the end of the run."""
        return (self.step_time, self.duration)

    def check(self):
        """`ValueError` (one line) for numbers the runs cannot use."""
        positive = ("natural_frequency", "damping", "reference_frequency",
                    "reference_damping", "duration", "dt", "interval", "sample_interval")
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"the {name.replace('_', ' ')} must be a positive number, "
                                 f"got {value}.")
        if not (math.isfinite(self.step) and 0 < abs(self.step) <= 180):
            raise ValueError(f"the heading step must be non-zero and at most 180 deg, got "
                             f"{self.step}.")
        if not 0 <= self.step_time < self.duration:
            raise ValueError(f"the step time ({self.step_time} s) must lie within the run "
                             f"(0 to {self.duration} s).")
        every = self.sample_interval / self.dt
        if abs(every - round(every)) > 1e-9 * every:
            raise ValueError(f"the sample interval ({self.sample_interval} s) must be a "
                             f"multiple of the output interval ({self.dt} s).")


@dataclasses.dataclass
class Evaluation:
    """What `evaluate` returns: the `model` designed on, the `plant` steered, the
    operating point of the design (`design_speed` [m/s], `design_rpm`), the
    `controllers` {name: HeadingAutopilot}, their closed-loop `runs` {name:
    ClosedLoop} (axes: 1 autopilot x operating points x samples), the operating points
    `rpm` and `speed` of the runs, the `rows` (one dict per controller and
    operating point, keys `RUN_KEYS` and `success`), the `tuning` summary (or None)
    and the `design`."""

    model: object
    plant: object
    design: Design
    design_speed: float
    design_rpm: float
    controllers: dict
    runs: dict
    rpm: list
    speed: list
    rows: list
    tuning: dict | None = None

    def gains(self) -> dict:
        """{controller: {kp, ki, kd, feedforward}}: kp [rad/rad], ki [1/s], kd [s] and
        the class of the inverted model (None: feedback only)."""
        out = {}
        for name, a in self.controllers.items():
            ff = a.feedforward
            out[name] = {"kp": float(a.kp), "ki": float(a.ki), "kd": float(a.kd),
                         "feedforward": None if ff is None else type(ff.model).__name__}
        if self.tuning is not None and "tuned" in out:
            out["tuned"] |= self.tuning
        return out

    def to_dict(self) -> dict:
        """JSON-ready: `design` (numbers, operating point, rudder limits, metric
        definition), `gains` and `runs`."""
        d = self.design
        return {
            "design": dataclasses.asdict(d) | {
                "window_s": list(d.window),
                "design_speed_m_s": self.design_speed, "design_rpm": self.design_rpm,
                "max_rudder_deg": round(float(np.degrees(self.controllers["pid"].max_angle)), 9),
                "max_rudder_rate_deg_s": round(float(np.degrees(
                    self.controllers["pid"].max_rate)), 9),
                "metrics": METRICS_TEXT.format(dt=d.sample_interval, start=d.window[0],
                                               end=d.window[1]),
            },
            "gains": self.gains(),
            "runs": self.rows,
        }


METRICS_TEXT = (
    "sum_abs_error_deg: thesis eq. 3.19, the sum of |psi_d - psi| [deg] sampled every {dt:g} s "
    "over {start:g}-{end:g} s (psi_d: the reference model's output); rms_error_deg: the RMS "
    "of the same samples; max_overshoot_deg: the heading past the ordered heading after the "
    "step; settling_time_s: from the step until the heading stays within 2 % of the step "
    "(null: never); mean_abs_rudder_deg, rudder_travel_deg: mean |delta| and sum |d delta| "
    "of the actual rudder over the window; time_rate_limited_s: time the command moved at "
    "the rudder rate limit.")


def operating_point(plant, *, rpm=None, speed=None) -> tuple[float, float]:
    """(u [m/s], n [rev/s]) of the straight run of the vessel `plant` at `rpm` or
    `speed` (one number)."""
    if rpm is not None:
        state = js.straight_run(plant, n=float(rpm) / 60.0)
    else:
        state = js.straight_run(plant, speed=float(speed))
    return float(state.u), float(state.n)


def natural_frequency_for(model, plant, *, speed: float, n: float) -> tuple[float, str]:
    """`(omega_n, basis)`: the controller's natural frequency [rad/s] from the model's
    yaw time constant $T = m/|d|$ (`jaxship.yaw_inertia` about the straight run at
    `speed`, `n`), $\\omega_n = 1.25/T$ as the thesis design, at most half the rudder
    servo's bandwidth $0.5/T_s$ of the vessel `plant` (which the controller does not
    model), with the sentence saying so."""
    m, d = (float(x) for x in js.yaw_inertia(model, speed=speed, n=n))
    if not (m > 0 and d != 0 and math.isfinite(m / d)):
        raise ValueError(f"the {type(model).__name__} model has no yaw time constant at "
                         f"{speed:.3g} m/s (m = {m:.3g}, d = {d:.3g}); give "
                         "--natural-frequency.")
    T = abs(m / d)
    servo = float(plant.rudder.time_constant)
    w = min(BANDWIDTH_TIMES_T / T, 0.5 / servo)
    limited = "half the servo bandwidth" if w < BANDWIDTH_TIMES_T / T else "1.25 / T"
    return w, (f"omega_n = {w:.4g} rad/s from the model's yaw time constant T = {T:.4g} s at "
               f"{speed:.3g} m/s ({limited}; at most 0.5 / T_servo = {0.5 / servo:.3g} "
               "rad/s), the reference and timing in the thesis' proportions")


def design_controllers(model, plant, design: Design = Design(), *, speed: float,
                       n: float) -> dict:
    """{"pid+ff": ..., "pid": ...}: `HeadingAutopilot`s for `model` (a steering model
    or vessel) by pole placement about the straight run at `speed` [m/s] and `n`
    [rev/s], with the reference model and step of `design` and the rudder limits of
    the vessel `plant`; "pid+ff" inverts `model` for the reference feed-forward."""
    steps = js.HeadingSteps(times=(design.step_time,), headings=(design.step * DEG,))
    reference = js.ReferenceModel(natural_frequency=design.reference_frequency,
                                  damping=design.reference_damping)
    kw = dict(natural_frequency=design.natural_frequency, damping=design.damping,
              reference=reference, steps=steps, max_angle=float(plant.rudder.max_angle),
              max_rate=float(plant.rudder.max_rate), interval=design.interval, speed=speed,
              n=n, subtract_damping=design.subtract_damping)
    m = float(js.yaw_inertia(model, speed=speed, n=n)[0])
    if not m > 0:
        raise ValueError(f"the {type(model).__name__} model turns the ship against its rudder "
                         f"at {speed:.3g} m/s (yaw inertia m = {m:.3g}): no autopilot design.")
    return {"pid+ff": js.design_autopilot(model, feedforward=True, **kw),
            "pid": js.design_autopilot(model, feedforward=False, **kw)}


def cell(x, digits=2) -> str:  # a table cell: "-" for None
    return "-" if x is None else f"{x:.{digits}f}"


def _finite(x):
    x = float(x)
    return x if math.isfinite(x) else None


# a run whose rudder sits at its limit for more than this share of the window says
# little about the controller (its code is "rudder_saturated")
SATURATED_SHARE = 0.5


def run_rows(name: str, run, design: Design, rpm, speed, max_angle: float) -> list[dict]:
    """The rows (`RUN_KEYS`, `success`, `time_saturated_s` and the run's `code`:
    "successful", "blew_up" or "rudder_saturated", the rudder command within 1 % of its
    limit `max_angle` [rad] for more than half the window) of the closed-loop `run` of
    controller `name` at the operating points `rpm`, `speed`."""
    metrics = js.closed_loop_metrics(run, design.sample_interval, window=design.window)
    m = metrics.to_dict_deg()
    t = np.asarray(run.t)
    inside = (t >= design.window[0]) & (t <= design.window[1])
    at_limit = np.abs(np.asarray(run.delta_c)[0]) >= 0.99 * max_angle  # the command
    rows = []
    for j in range(len(rpm)):
        ok = bool(np.asarray(run.success)[0, j])
        saturated = float(np.mean(at_limit[j][inside])) if ok else math.nan
        code = ("blew_up" if not ok else "rudder_saturated" if saturated > SATURATED_SHARE
                else "successful")
        rows.append({
            "controller": name, "rpm": float(rpm[j]), "speed": float(speed[j]),
            "sum_abs_error_deg": _finite(m["residual_sum_deg"][0][j]),
            "rms_error_deg": _finite(m["rms_error_deg"][0][j]),
            "max_overshoot_deg": _finite(m["overshoot_deg"][0][j]),
            "settling_time_s": _finite(m["settling_time_s"][0][j]),
            "mean_abs_rudder_deg": _finite(m["mean_abs_rudder_deg"][0][j]),
            "rudder_travel_deg": _finite(m["rudder_travel_deg"][0][j]),
            "time_rate_limited_s": _finite(m["time_at_rate_limit_s"][0][j]),
            "time_saturated_s": _finite(saturated * (design.window[1] - design.window[0])),
            "success": ok, "code": code,
        })
    return rows


def evaluate(model, plant, *, rpm=None, speeds=None, design: Design = Design(),
             tune: bool = False, progress=None) -> Evaluation:
    """Design the autopilots of `model` (`design_controllers`, about the mean operating
    point of the runs) and run each on the vessel `plant` from straight runs at each
    of `rpm` or `speeds` [m/s] (exactly one of them, a sequence). `tune`: also a
    `"tuned"` controller, `tune_autopilot` on `plant` at the same operating points
    from the "pid+ff" gains (if its $K_d \\le 0$, from the thesis' $K_d =
    2\\zeta\\omega_n m$). `progress`: a callable taking a message, or None."""
    if (rpm is None) == (speeds is None):
        raise ValueError("give exactly one of rpm and speeds.")
    design.check()
    values = [float(x) for x in (rpm if rpm is not None else speeds)]
    if not values or not all(math.isfinite(x) and x > 0 for x in values):
        raise ValueError(f"{'rpm' if rpm is not None else 'speeds'} must be positive numbers, "
                         f"got {values}.")
    say = progress or (lambda message: None)
    key = "rpm" if rpm is not None else "speed"
    points = [operating_point(plant, **{key: x}) for x in values]
    mean = float(np.mean(values))
    u0, n0 = operating_point(plant, **{key: mean})
    if not all(math.isfinite(u) and u > 0 and math.isfinite(n) for u, n in points + [(u0, n0)]):
        raise ValueError(f"no straight run of the vessel at {key} {values}"
                         + (" (has it a propeller model? give speeds)" if key == "rpm" else ""))
    if key == "rpm" and operating_point(plant, rpm=1.25 * mean)[0] == u0:
        raise ValueError(f"the {type(plant).__name__} has no propeller model (its speed does "
                         "not depend on the rpm): give speeds (--speed) instead.")
    controllers = design_controllers(model, plant, design, speed=u0, n=n0)
    run_kw = {"rpm": values} if key == "rpm" else {"speeds": values}
    tuning = None
    if tune:
        start = controllers["pid+ff"]
        if not float(start.kd) > 0:
            start = design_controllers(model, plant, dataclasses.replace(
                design, subtract_damping=False), speed=u0, n=n0)["pid+ff"]
        say("tuning the gains on the vessel")
        tuned = js.tune_autopilot(plant, start, duration=design.duration, dt=design.tune_dt,
                                  rudder_weight=design.rudder_weight,
                                  max_steps=design.tune_steps, **run_kw)
        controllers["tuned"] = tuned.autopilot
        tuning = {"objective_before": float(tuned.objective_before),
                  "objective_after": float(tuned.objective_after),
                  "steps": int(tuned.num_steps), "converged": bool(tuned.success)}
    runs, rows = {}, []
    rpms = values if key == "rpm" else [60.0 * n for _, n in points]
    speeds_ = values if key == "speed" else [u for u, _ in points]
    for name, autopilot in controllers.items():
        say(f"closed loop: {name}")
        runs[name] = js.closed_loop(plant, autopilot, duration=design.duration, dt=design.dt,
                                    **run_kw)
        rows += run_rows(name, runs[name], design, rpms, speeds_,
                         float(plant.rudder.max_angle))
    return Evaluation(model=model, plant=plant, design=design, design_speed=u0,
                      design_rpm=60.0 * n0, controllers=controllers, runs=runs, rpm=rpms,
                      speed=speeds_, rows=rows, tuning=tuning)


# ----------------------------------------------------------------------------- chapter 5


def merged_models(vessel=None, *, quick: bool = False,
                  settings: thesis.Settings = thesis.Settings(), models=MODELS,
                  experiments=None, progress=None) -> dict:
    """The chapter-4 models identified from the merged experiments of each family,
    with the chapter-4 pipeline's own calls (`thesis.thesis_experiments`,
    `thesis.identify`, the Ross fit started from the family's Nomoto fit, as in
    `thesis.identification_study`) but without its single-experiment fits: a dict
    like that study's (`models` keyed `"merged/<model>/<family>"`, `table` rows with
    the pooled simulation fit % `fit_family`)."""
    vessel = js.vessel("thesis") if vessel is None else vessel
    families = thesis.QUICK_FAMILIES if quick else thesis.FAMILIES
    if experiments is None:
        experiments = thesis.thesis_experiments(vessel, families=families, settings=settings)
    say = progress or (lambda message: None)
    out, rows = {}, []
    for family, specs in families.items():
        records = [experiments[thesis.record_name(s, rpm)] for s in specs for rpm in thesis.RPMS]
        fitted = {}
        for name in ("nomoto", *[m for m in models if m != "nomoto"]):
            say(f"identifying {name} on the merged {family}")
            result = thesis.identify(name, records, vessel, settings=settings,
                                     nomoto=fitted.get("nomoto"), base=fitted.get("ross"))
            fitted[name] = result.model
            out[f"merged/{name}/{family}"] = result.model
            fit, _ = thesis.simulation_fit(result.model, records, settings.substeps)
            rows.append(dict(case="merged", model=name, family=family,
                             fit_family=_finite(fit)))
    return {"models": out, "table": rows, "quick": bool(quick)}


def autopilot_study(vessel=None, *, identification=None, quick: bool = False,
                    settings: thesis.Settings = thesis.Settings(), design: Design = Design(),
                    rpms=RPMS, models=MODELS, progress=None) -> dict:
    """Thesis chapter 5 on `vessel` (default `jaxship.vessel("thesis")`).

    - `identification`: the chapter-4 study (`thesis.identification_study`, e.g. from
      `jaxship reproduce`) whose merged models are reused; None: `merged_models`
      (`quick`: its reduced design, two trials per family).
    - `design`: `Design`; `rpms`: the closed-loop propeller rates; `models`: which
      identified models (`"nomoto"`, `"ross"`, `"ross_speed_rudder"`).

    Returns a dict: `table` (one row per model, family, controller and rpm: the run
    keys of `evaluate`, `model`, `family`, `thesis` (the thesis' residual, pid+ff rows)
    and `fit_family` (chapter-4 pooled fit %)), `reference` (the same for the vessel's
    own yaw equation: the gains and feed-forward of a perfect model), `gains`
    {"<model>/<family>": gains}, `goals`, `design`, `rpms`, and `evaluations` (the
    `Evaluation` objects, with the closed-loop runs; not JSON: see `to_json`).
    """
    vessel = js.vessel("thesis") if vessel is None else vessel
    say = progress or (lambda message: None)
    if identification is None:
        identification = merged_models(vessel, quick=quick, settings=settings, models=models,
                                       progress=say)
    fits = {(r["model"], r["family"]): r.get("fit_family")
            for r in identification["table"] if r["case"] == "merged"}
    table, gains, evaluations = [], {}, {}
    for name in models:
        for family in FAMILIES:
            model = identification["models"].get(f"merged/{name}/{family}")
            say(f"closed loop: {name} from the merged {family}" if model is not None else
                f"closed loop: no {name} model from the merged {family}")
            if model is None:  # not identified, or its identification failed
                continue
            ev = evaluate(model, vessel, rpm=rpms, design=design)
            evaluations[f"{name}/{family}"] = ev
            gains[f"{name}/{family}"] = ev.gains()
            thesis_values = THESIS_RESIDUALS.get(name, {}).get(family)
            for i, row in enumerate(ev.rows):
                paper = (thesis_values[i % 2] if thesis_values and row["controller"] == "pid+ff"
                         and list(rpms) == list(RPMS) else None)
                table.append(dict(model=name, family=family, **row, thesis=paper,
                                  fit_family=fits.get((name, family))))
    say("closed loop: the vessel's own yaw equation")
    reference = evaluate(vessel, vessel, rpm=rpms, design=design)
    evaluations["vessel"] = reference
    gains["vessel"] = reference.gains()
    study = {"table": table, "reference": reference.rows, "gains": gains,
             "design": reference.to_dict()["design"], "rpms": [float(r) for r in rpms],
             "models": list(models), "quick": bool(identification.get("quick", quick)),
             "evaluations": evaluations}
    study["goals"] = goals(study)
    return study


def _residuals(study, model, family, controller):
    return [r["sum_abs_error_deg"] for r in study["table"] if r["model"] == model
            and r["family"] == family and r["controller"] == controller]


def _beats(a, b):
    return all(x is not None and y is not None and x < y for x, y in zip(a, b))


# the thesis' ordering of its six autopilots counts as reproduced when our ordering's
# Spearman rank correlation with it is positive at this one-sided significance level
ORDERING_ALPHA = 0.05


def spearman_exact(x, y) -> tuple[float, float]:
    """(rho, p): Spearman's rank correlation of `x` and `y` (`scipy.stats.spearmanr`) and
    its one-sided p-value $P(\\rho' \\ge \\rho)$ over all $n!$ orderings of `x` (exact;
    the t approximation misstates it for the six autopilots). NaN for constant input."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan, math.nan
    rho = float(scipy.stats.spearmanr(x, y)[0])
    if len(x) > 8:  # 9! orderings and more: the t approximation
        return rho, float(scipy.stats.spearmanr(x, y, alternative="greater")[1])
    ry = scipy.stats.rankdata(y)
    every = [np.corrcoef(scipy.stats.rankdata(x[list(p)]), ry)[0, 1]
             for p in itertools.permutations(range(len(x)))]
    return rho, float(np.mean(np.asarray(every) >= rho - 1e-12))


def _thesis_keys(study):
    """(model, family) of the autopilots that have a thesis table and a pid+ff run."""
    return [(m, f) for m in ("nomoto", "ross") for f in FAMILIES
            if _residuals(study, m, f, "pid+ff") and m in THESIS_RESIDUALS
            and None not in _residuals(study, m, f, "pid+ff")]


def goals(study: dict) -> dict:
    """The goals of the study, with their numbers:

    - `thesis_ordering` (all six autopilots at the thesis' 300 and 400 rpm): our
      ordering of the mean pid+ff residual against the thesis' Tables 5.2-5.7, Spearman
      rank correlation with its one-sided p-value (`scipy.stats.spearmanr`); met when
      positive at `ORDERING_ALPHA`;

    - `feedforward`: the reference feed-forward of the best identified model (highest
      chapter-4 pooled fit % among the merged fits) lowers the residual below that
      model's feedback-only PID at every rpm; and the same for every model;
    - `ross_vs_nomoto`: on the informative data (zig-zags and the thesis manoeuvre,
      which excite the yaw dynamics; the turning circles are mostly steady turns),
      the Ross model's autopilot (its gains and feed-forward) beats Nomoto's at every
      rpm."""
    present = {(r["model"], r["family"]) for r in study["table"]}
    fits = {(r["model"], r["family"]): r["fit_family"] for r in study["table"]}
    ranked = sorted((k for k in present if fits.get(k) is not None), key=lambda k: -fits[k])
    out = {}
    if ranked:
        best = ranked[0]
        ff, fb = (_residuals(study, *best, c) for c in ("pid+ff", "pid"))
        out["feedforward"] = {
            "best_model": f"{best[0]}/{best[1]}", "fit_family": fits[best],
            "pid+ff": ff, "pid": fb, "met": _beats(ff, fb),
            "met_by": sorted(f"{m}/{f}" for m, f in present
                             if _beats(_residuals(study, m, f, "pid+ff"),
                                       _residuals(study, m, f, "pid"))),
        }
    keys = _thesis_keys(study)
    if len(keys) == 6 and len(study["rpms"]) == 2 and list(study["rpms"]) == list(RPMS):
        ours = [float(np.mean(_residuals(study, m, f, "pid+ff"))) for m, f in keys]
        paper = [float(np.mean(THESIS_RESIDUALS[m][f])) for m, f in keys]
        rho, p = spearman_exact(ours, paper)
        out["thesis_ordering"] = {
            "autopilots": [f"{m}/{f}" for m, f in keys], "ours": ours, "thesis": paper,
            "spearman": float(rho), "p_value": float(p), "alpha": ORDERING_ALPHA,
            "met": bool(rho > 0 and p < ORDERING_ALPHA)}  # False for NaN
    if {"nomoto", "ross"} <= {m for m, _ in present}:
        per = {}
        for family in FAMILIES:
            if ("ross", family) in present and ("nomoto", family) in present:
                ross, nomoto = (_residuals(study, m, family, "pid+ff") for m in ("ross", "nomoto"))
                per[family] = {"ross": ross, "nomoto": nomoto, "ross_better": _beats(ross, nomoto)}
        informative = [f for f in ("zigzag", "thesis") if f in per]
        out["ross_vs_nomoto"] = {"families": per, "informative": informative,
                                 "met": bool(informative) and all(per[f]["ross_better"]
                                                                  for f in informative)}
    return out


def to_json(study: dict) -> dict:
    """The study without the `Evaluation` objects, for `json.dumps`."""
    return {k: v for k, v in study.items() if k != "evaluations"}


def comparison_table(study: dict) -> str:
    """Markdown: our Tables 5.2-5.7 (pid+ff residual at each rpm) next to the thesis',
    with the feedback-only residual and the chapter-4 fit %."""
    rpms = study["rpms"]
    head = " | ".join(f"ours {r:.0f} | thesis {r:.0f}" for r in rpms)
    fb = " | ".join(f"pid {r:.0f}" for r in rpms)
    lines = [f"| table | model | identified from | {head} | {fb} | ch. 4 fit % |",
             "|---" * (4 + 3 * len(rpms)) + "|"]
    for name in study["models"]:
        for family in FAMILIES:
            ff = _residuals(study, name, family, "pid+ff")
            pid = _residuals(study, name, family, "pid")
            if not ff:
                continue
            row = [r for r in study["table"] if r["model"] == name and r["family"] == family
                   and r["controller"] == "pid+ff"]
            pairs = " | ".join(f"{cell(a)} | {cell(r['thesis'])}" for a, r in zip(ff, row))
            fit = row[0]["fit_family"]
            lines.append(f"| {THESIS_TABLES.get((name, family), '-')} | "
                         f"{MODEL_NAMES.get(name, name)} | {FAMILY_NAMES[family]} (merged) | "
                         f"{pairs} | {' | '.join(cell(x) for x in pid)} | {cell(fit)} |")
    ref = study["reference"]
    by = {c: [r["sum_abs_error_deg"] for r in ref if r["controller"] == c] for c in CONTROLLERS}
    lines.append("| - | the vessel itself | (true yaw equation) | "
                 + " | ".join(f"{cell(a)} | -" for a in by["pid+ff"]) + " | "
                 + " | ".join(cell(x) for x in by["pid"]) + " | - |")
    return "\n".join(lines) + "\n"


def comparison_text(study: dict) -> str:
    """Sentences on orderings and ratios, ours against the thesis' (Spearman rank
    correlation), the best run of the table, and the goals, each with its numbers."""
    keys = _thesis_keys(study)
    g = study["goals"]
    text = []
    name = lambda k: f"{MODEL_NAMES[k[0]]}/{k[1]}"
    if "thesis_ordering" in g:
        o = g["thesis_ordering"]
        ours, paper = o["ours"], o["thesis"]
        order = lambda v: ", ".join(name(keys[i]) for i in np.argsort(v))
        ratio_ours = [a / b for a, b in (_residuals(study, m, f, "pid+ff") for m, f in keys)
                      if a and b]
        ratio_paper = [THESIS_RESIDUALS[m][f][0] / THESIS_RESIDUALS[m][f][1] for m, f in keys]
        cells = [a / b for m, f in keys
                 for a, b in zip(_residuals(study, m, f, "pid+ff"), THESIS_RESIDUALS[m][f])
                 if a is not None]
        text.append(
            f"Ordered by the mean residual of the two speeds (best first), the thesis has "
            f"{order(paper)}; we have {order(ours)}. Reproducing the thesis' ordering: "
            f"{'met' if o['met'] else 'NOT met'} (Spearman rank correlation "
            f"{o['spearman']:+.2f}, one-sided p = {o['p_value']:.2g} with {len(keys)} "
            f"autopilots; met when positive at p < {o['alpha']:g}). "
            f"The ratio of the 300 rpm to the 400 rpm residual is "
            f"{', '.join(f'{x:.2f}' for x in ratio_paper)} in the thesis and "
            f"{', '.join(f'{x:.2f}' for x in ratio_ours)} here (same order of rows). "
            f"Cell by cell ours are {np.median(cells):.2g} times the thesis' (median; range "
            f"{min(cells):.2g}-{max(cells):.2g}): the thesis states neither the unit nor the "
            f"sampling of its residual, so only orderings and ratios compare.")
    best = best_run_text(study)
    if best:
        text.append(best)
    if "feedforward" in g:
        f = g["feedforward"]
        diffs = [None if a is None or b is None else a - b for a, b in zip(f["pid+ff"], f["pid"])]
        text.append(
            f"Goal 1 (ours; the thesis runs no autopilot without feed-forward), feed-forward "
            f"from the best identified model ({f['best_model']}, chapter-4 fit "
            f"{cell(f['fit_family'])} %) beats feedback only at every speed: "
            f"{'met' if f['met'] else 'NOT met'} (pid+ff "
            f"{', '.join(cell(x) for x in f['pid+ff'])} against pid "
            f"{', '.join(cell(x) for x in f['pid'])} deg, differences "
            f"{', '.join('-' if x is None else f'{x:+.2f}' for x in diffs)} deg at "
            f"{', '.join(f'{r:.0f}' for r in study['rpms'])} rpm); feed-forward helps for "
            f"{len(f['met_by'])} of {len({(r['model'], r['family']) for r in study['table']})}"
            f" models ({', '.join(f['met_by']) or 'none'}).")
    if "ross_vs_nomoto" in g:
        r = g["ross_vs_nomoto"]
        parts = [f"{FAMILY_NAMES[k]}: Ross {', '.join(cell(x) for x in v['ross'])} vs "
                 f"Nomoto {', '.join(cell(x) for x in v['nomoto'])}"
                 for k, v in r["families"].items()]
        paper = []
        for k in r["informative"]:
            ross, nomoto = THESIS_RESIDUALS["ross"][k], THESIS_RESIDUALS["nomoto"][k]
            paper.append(f"{FAMILY_NAMES[k]}: Ross {', '.join(f'{x:.1f}' for x in ross)} vs "
                         f"Nomoto {', '.join(f'{x:.1f}' for x in nomoto)} (Ross better at "
                         f"{sum(x < y for x, y in zip(ross, nomoto))} of {len(ross)} speeds)")
        text.append(
            f"Goal 2, Ross beats Nomoto when fitted on informative data (zig-zags, thesis "
            f"manoeuvre): {'met' if r['met'] else 'NOT met'} ({'; '.join(parts)} deg; each "
            f"model brings its own gains and feed-forward). The thesis' tables give "
            f"{'; '.join(paper)}.")
    return "\n\n".join(text) + "\n"


def best_run_text(study: dict) -> str:
    """A sentence on the run of lowest residual in the table (any model, family,
    controller and rpm), against the thesis' number for it where the thesis has one."""
    rows = [r for r in study["table"] if r["sum_abs_error_deg"] is not None]
    if not rows:
        return ""
    b = min(rows, key=lambda r: r["sum_abs_error_deg"])
    controller = ("pid+ff (the thesis' controller)" if b["controller"] == "pid+ff"
                  else "pid (feedback only)")
    what = (f"{controller} with the {MODEL_NAMES.get(b['model'], b['model'])} model from "
            f"the merged {FAMILY_NAMES[b['family']]} at {b['rpm']:.0f} rpm")
    text = (f"The best run of the table is {what}: residual {b['sum_abs_error_deg']:.2f} deg "
            f"(RMS {cell(b['rms_error_deg'])} deg)")
    rpms = list(study["rpms"])
    paper = THESIS_RESIDUALS.get(b["model"], {}).get(b["family"])
    if paper is not None and rpms == list(RPMS):
        thesis_value = paper[rpms.index(b["rpm"])]
        table = THESIS_TABLES[(b["model"], b["family"])]
        ff = _residuals(study, b["model"], b["family"], "pid+ff")[rpms.index(b["rpm"])]
        if b["controller"] == "pid+ff":
            text += (f"; the thesis' Table {table} gives {thesis_value:.2f} for it (ours "
                     f"{b['sum_abs_error_deg'] / thesis_value:.2g} times that)")
        else:
            text += (f". The thesis has no feedback-only run; with feed-forward the same "
                     f"model gives {cell(ff)} deg here (difference "
                     + ("-" if ff is None else f"{ff - b['sum_abs_error_deg']:+.2f}")
                     + f" deg) and {thesis_value:.2f} in the thesis' Table {table}")
        best_paper = min(((m, f, i) for m, f in keys_of(THESIS_RESIDUALS) for i in range(2)),
                         key=lambda k: THESIS_RESIDUALS[k[0]][k[1]][k[2]])
        m, f, i = best_paper
        ours = _residuals(study, m, f, "pid+ff")
        text += (f". The thesis' best is {MODEL_NAMES[m]} from the {FAMILY_NAMES[f]} at "
                 f"{RPMS[i]:.0f} rpm ({THESIS_RESIDUALS[m][f][i]:.2f}, Table "
                 f"{THESIS_TABLES[(m, f)]}); ours there "
                 + (f"{cell(ours[i])} deg" if len(ours) == 2 else "not run"))
    return text + "."


def keys_of(table: dict) -> list:
    """(model, family) pairs of a {model: {family: ...}} table."""
    return [(m, f) for m, families in table.items() for f in families]


def report_section(study: dict, *, level: int = 2) -> str:
    """A markdown section for a report (`report.md`, `jaxship reproduce`'s summary):
    the set-up, our Tables 5.2-5.7 next to the thesis', orderings and the goals."""
    d = study["design"]
    h = "#" * level
    quick = " (quick identification design: 2 trials per family)" if study["quick"] else ""
    return (
        f"{h} Heading autopilot (thesis chapter 5)\n\n"
        f"The merged chapter-4 models{quick} each give a PID by pole placement (omega_n = "
        f"{d['natural_frequency']:g} rad/s, zeta = {d['damping']:g}, about the straight run at "
        f"{d['design_rpm']:.0f} rpm) and a reference feed-forward; reference model omega = "
        f"{d['reference_frequency']:g} rad/s, zeta = {d['reference_damping']:g}, "
        f"{d['step']:g} deg step at {d['step_time']:g} s; the true thesis vessel is steered "
        f"at {', '.join(f'{r:.0f}' for r in study['rpms'])} rpm (rudder "
        f"{d['max_rudder_deg']:.0f} deg, {d['max_rudder_rate_deg_s']:.0f} deg/s). Residual: "
        f"thesis eq. 3.19, sum of |psi_d - psi| in degrees sampled every "
        f"{d['sample_interval']:g} s over {d['window_s'][0]:g}-{d['window_s'][1]:g} s; pid+ff "
        f"is the thesis' controller, pid the same gains without feed-forward.\n\n"
        + comparison_table(study) + "\n" + comparison_text(study)
    )
