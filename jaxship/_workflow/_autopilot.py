"""The heading autopilot designed from an identified model and evaluated in closed loop
on a vessel: the backend of `jaxship autopilot`, and of each run of the thesis' chapter 5
(Odegard 2009, seed 000; `autopilot_thesis` compares them with its tables).

**Chapter 5.** The steering models of chapter 4 identified from the merged experiments
(200 + 500 rpm) of each family (turning circles, zig-zags, the thesis manoeuvre;
`jaxship.cli.reproduction.thesis`) each give a PID autopilot by pole placement (eq. 5.3-5.5)
and a reference feed-forward (eq. 5.2 for Nomoto, eq. 5.6 for Ross), driven by the
third-order reference model of Table 5.1 (45 deg step at 100 s, damping 1.0,
natural frequency 0.2 rad/s). Each autopilot steers the *true* thesis vessel
(`jaxship.get_vessel("thesis")`, rudder 45 deg and 15 deg/s through its servo) at 300
and 400 rpm, with feed-forward (`"pid+ff"`, the thesis' controller) and without
(`"pid"`). The score is the thesis' closed-loop residual, eq. 3.19,
$\\sum_k|\\psi_d(t_k) - \\psi(t_k)|$ in degrees, **sampled every 1 s over 100-200 s**
(the thesis states neither unit nor sampling: its Tables 5.2-5.7 are compared by
ordering and ratios, not by absolute size).

**The controller's own natural frequency and damping** are not in the thesis (only
the reference model's, Table 5.1). `AutopilotDesign` uses $\\omega_n$ = 0.5 rad/s, 2.5 times
the reference's 0.2 rad/s (the error stays small while $\\psi_d$ moves) and half the
bandwidth of the rudder servo it does not model (1 s), and $\\zeta$ = 1 as the
reference (no overshoot). $K_d$ is Fossen's $2\\zeta\\omega_n m - d$ (exact pole
placement), not the thesis' printed $2\\zeta\\omega_n m$ (which damps more by
$d/(2m\\omega_n)$). The gains are designed once, at the mean operating point of the
runs, and kept for every run; the feed-forward uses the simulated vessel's $u$, $v$, $n$
(noise-free, as an ideal sensor would give them).
"""

import dataclasses
import math

import numpy as np

import jaxship as js

from .._analysis._autopilot import design_autopilot as design_pid
from ._autopilot_reference import (
    RUDDER_SHARE as RUDDER_SHARE,
    ordered_error_deg,
    tune_autopilot,
)
from ._autopilot_source import DesignModels as DesignModels, resolve
from ._autopilot_steady_turn import (
    feedforward_at_step as feedforward_at_step,
    feedforward_gain_text as feedforward_gain_text,
    nearest_steady_turn as nearest_steady_turn,
    operating_point as operating_point,
    peak_reference_rate as peak_reference_rate,
    steady_turn_trial as steady_turn_trial,
    vessel_steady_rudder as vessel_steady_rudder,
)


DEG = math.pi / 180.0
# the thesis design's proportions (Table 5.1 with omega_n = 0.5 rad/s): reference model
# at 0.4 omega_n, the heading step at 50 / omega_n (100 s), the run twice as long; and
# its omega_n times the yaw time constant of its Nomoto model (2.6 s at 350 rpm: 1.3)
REFERENCE_RATIO = 0.4
STEP_TIME_RATIO = 50.0
BANDWIDTH_TIMES_T = 1.25
CONTROLLERS = ("pid+ff", "pid")  # with and without the reference feed-forward
# the columns of a run (`Evaluation.rows`, `autopilot.json` "runs")
RUN_KEYS = ("controller", "rpm", "speed", "sum_abs_error_deg", "rms_error_deg",
            "max_overshoot_deg", "settling_time_s", "mean_abs_rudder_deg",
            "rudder_travel_deg", "time_rate_limited_s")


# the most output samples of one closed-loop run (`AutopilotDesign.check`): 10^6 at 0.1 s is 28 h;
# a model with a yaw time constant of years (a fit the data did not determine) would
# otherwise ask for petabytes
MAX_SAMPLES = 1e6


@dataclasses.dataclass(frozen=True)
class AutopilotDesign:
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

    `AutopilotDesign.scaled(omega_n)` keeps the thesis' proportions for any ship: the reference at
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
    def scaled(cls, natural_frequency: float, *, basis: str = "", **kwargs) -> "AutopilotDesign":
        """The thesis' proportions about `natural_frequency` [rad/s] (class text)."""
        w = float(natural_frequency)
        step_time = float(f"{STEP_TIME_RATIO / w:.2g}")  # two digits: 100 s, 840 s
        return cls(natural_frequency=w, reference_frequency=REFERENCE_RATIO * w,
                   step_time=step_time, duration=2 * step_time,
                   basis=basis or f"omega_n = {w:.4g} rad/s as given, the reference and "
                   "timing in the thesis' proportions", **kwargs)

    @classmethod
    def auto(cls, source, plant, *, rpm=None, speeds=None, step: float = 45.0,
             damping: float = 1.0, **kwargs) -> "AutopilotDesign":
        """The design `jaxship autopilot` takes by default: `scaled` about omega_n of
        `natural_frequency_for` (1.25 / T, at most half the servo bandwidth and what keeps
        the feed-forward of the `step` [deg] within half the rudder's limits) from the
        model the poles are placed on (`source`: a model, an identification or a parsed
        result.json; from `--model auto` its linear candidate), about the straight run of
        the vessel `plant` at the mean of `rpm` or `speeds` [m/s]."""
        if (rpm is None) == (speeds is None):
            raise ValueError("give exactly one of rpm and speeds.")
        key, values = ("rpm", rpm) if rpm is not None else ("speed", speeds)
        values = [float(x) for x in values]
        u0, n0 = operating_point(plant, **{key: sum(values) / len(values)})
        omega, basis = natural_frequency_for(resolve(source).models.feedback, plant,
                                             speed=u0, n=n0, step=step)
        return cls.scaled(omega, step=step, damping=damping, basis=basis, **kwargs)

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
        if self.duration / self.dt > MAX_SAMPLES:
            raise ValueError(f"the run would be {self.duration:.3g} s long, "
                             f"{self.duration / self.dt:.3g} samples of {self.dt:g} s (at "
                             f"most {MAX_SAMPLES:.0e}): omega_n = {self.natural_frequency:.3g} "
                             "rad/s is too slow; a model with so long a yaw time constant "
                             "barely steers (give --natural-frequency).")
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
    and the `design`; `feedforward_at_step` (`steady_turn_trial`, or None); `feedback`:
    the model the PID's poles were placed on (None: `model`).
    """

    model: object
    plant: object
    design: AutopilotDesign
    design_speed: float
    design_rpm: float
    controllers: dict
    runs: dict
    rpm: list
    speed: list
    rows: list
    tuning: dict | None = None
    feedforward_at_step: dict | None = None
    feedback: object = None

    def gains(self) -> dict:
        """{controller: {kp, ki, kd, reference_frequency, feedforward[, ff_gain,
        ff_steady_gain]}}: kp [rad/rad], ki [1/s], kd [s], the reference model's bandwidth
        [rad/s], the class of the model the poles were placed on ("feedback"), of the
        inverted model ("feedforward"; None: feedback only) and the
        feed-forward's gains; "tuned" also has the tuning summary (`tune_on_vessel`)."""
        out = {}
        for name, a in self.controllers.items():
            ff = a.feedforward
            out[name] = {"kp": float(a.kp), "ki": float(a.ki), "kd": float(a.kd),
                         "reference_frequency": float(a.reference.natural_frequency),
                         "feedback": type(self.model if self.feedback is None
                                          else self.feedback).__name__,
                         "feedforward": None if ff is None else type(ff.model).__name__}
            if ff is not None:  # its acceleration and steady-turn gains (`Feedforward`)
                out[name] |= {"ff_gain": float(ff.gain),
                              "ff_steady_gain": float(ff.steady_gain)}
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
    "over {start:g}-{end:g} s (psi_d: the reference model's output); "
    "sum_abs_error_ordered_deg: the same sum against the ordered heading psi_ref (the step) in "
    "place of psi_d, which compares designs with different reference models; rms_error_deg: "
    "the RMS of the psi_d samples; max_overshoot_deg: the heading past the ordered heading "
    "after the step; settling_time_s: from the step until the heading stays within 2 % of the step "
    "(null: never); mean_abs_rudder_deg, rudder_travel_deg: mean |delta| and sum |d delta| "
    "of the actual rudder over the window; time_rate_limited_s: time the command moved at "
    "the rudder rate limit.")


def reference_rudder_frequency(m: float, d: float, step: float, max_angle: float,
                               max_rate: float, share: float = RUDDER_SHARE) -> float:
    """The largest reference frequency $\\omega$ [rad/s] whose feed-forward rudder
    for a heading step of `step` [rad] stays within `share` of the rudder's angle and
    rate limits [rad, rad/s]. The reference model at damping 1 is $\\omega^3/(s+\\omega)^3$
    (eq. 5.7): with $x = \\omega t$, $\\dot\\psi_d = A\\omega\\,\\tfrac{x^2}{2}e^{-x}$,
    $\\ddot\\psi_d = A\\omega^2(x - \\tfrac{x^2}{2})e^{-x}$ and
    $\\dddot\\psi_d = A\\omega^3(1 - 2x + \\tfrac{x^2}{2})e^{-x}$; the feed-forward of
    $m\\dot r + d r = \\delta$ is $\\delta = m\\ddot\\psi_d + d\\dot\\psi_d$, its rate
    $m\\dddot\\psi_d + d\\ddot\\psi_d$; both peaks grow with $\\omega$ (bisection)."""
    x = np.linspace(0.0, 30.0, 3001)
    g1, g2 = x * x / 2 * np.exp(-x), (x - x * x / 2) * np.exp(-x)
    g3 = (1 - 2 * x + x * x / 2) * np.exp(-x)
    a, m, d = abs(step), abs(m), abs(d)

    def demand(w):  # the larger of the two peaks, as shares of their limits
        angle = np.max(np.abs(m * w * w * g2 + d * w * g1)) * a / max_angle
        rate = np.max(np.abs(m * w**3 * g3 + d * w * w * g2)) * a / max_rate
        return max(angle, rate) / share

    low, high = 1e-9, 1e3
    for _ in range(200):  # on a log scale: 1e-9 to 1e3 to 1e-12 relative
        mid = math.sqrt(low * high)
        low, high = (mid, high) if demand(mid) <= 1.0 else (low, mid)
    return low


def steered_inertia(model, *, speed: float, n: float) -> tuple[float, float]:
    """`(m, d)` of `jaxship.yaw_inertia`; `ValueError` where m <= 0: the model turns the
    ship against its rudder (K < 0 for Nomoto's), and no design can steer it."""
    m, d = (float(x) for x in js.yaw_inertia(model, speed=speed, n=n))
    if not m > 0:
        raise ValueError(f"the {type(model).__name__} model turns the ship against its rudder "
                         f"at {speed:.3g} m/s (yaw inertia m = {m:.3g}; K < 0 for Nomoto's): "
                         "no autopilot design. Is the rudder of its records signed the other "
                         "way (positive to port)?")
    return m, d


def natural_frequency_for(model, plant, *, speed: float, n: float,
                          step: float = 45.0) -> tuple[float, str]:
    """`(omega_n, basis)`: the controller's natural frequency [rad/s] from the model's
    yaw time constant $T = m/|d|$ (`jaxship.yaw_inertia` about the straight run at
    `speed`, `n`), $\\omega_n = 1.25/T$ as the thesis design, at most half the rudder
    servo's bandwidth $0.5/T_s$ of the vessel `plant` (which the controller does not
    model) and at most what keeps the reference's feed-forward rudder for the `step`
    [deg] within half the rudder's angle and rate limits (`reference_rudder_frequency`,
    the reference at 0.4 omega_n), with the sentence saying which bound holds."""
    m, d = steered_inertia(model, speed=speed, n=n)
    if not (d != 0 and math.isfinite(m / d)):
        raise ValueError(f"the {type(model).__name__} model has no yaw time constant at "
                         f"{speed:.3g} m/s (m = {m:.3g}, d = {d:.3g}); give "
                         "--natural-frequency.")
    T = abs(m / d)
    servo = float(plant.rudder.time_constant)
    rudder = reference_rudder_frequency(
        m, d, step * DEG, float(plant.rudder.max_angle),
        float(plant.rudder.max_rate)) / REFERENCE_RATIO
    bounds = {"1.25 / T": BANDWIDTH_TIMES_T / T, "half the servo bandwidth": 0.5 / servo,
              f"the feed-forward of the {step:g} deg step within half the rudder's limits "
              f"({math.degrees(float(plant.rudder.max_angle)):.3g} deg, "
              f"{math.degrees(float(plant.rudder.max_rate)):.3g} deg/s)": rudder}
    limited, w = min(bounds.items(), key=lambda item: item[1])
    if w < 1e-3 * bounds["1.25 / T"]:  # the rudder bound, a thousand times below 1.25 / T
        raise ValueError(f"the {type(model).__name__} model barely answers its rudder: its "
                         f"steady yaw rate per radian of rudder, 1/d = {1 / d:.3g} 1/s at "
                         f"{speed:.3g} m/s, keeps the feed-forward of the {step:g} deg step "
                         f"within half the rudder's limits only at omega_n = {w:.3g} rad/s, "
                         f"against 1.25 / T = {BANDWIDTH_TIMES_T / T:.3g} rad/s from its yaw "
                         f"time constant T = {T:.3g} s. Check the model's gain K (its units?), "
                         "or give --natural-frequency.")
    return w, (f"omega_n = {w:.4g} rad/s from the model's yaw time constant T = {T:.4g} s at "
               f"{speed:.3g} m/s ({limited}; at most 0.5 / T_servo = {0.5 / servo:.3g} "
               f"rad/s and {rudder:.3g} rad/s for the rudder), the reference and timing in "
               "the thesis' proportions")


def design_controllers(model, plant, design: AutopilotDesign = AutopilotDesign(), *, speed: float,
                       n: float, steady_gain: float = 1.0, feedback=None) -> dict:
    """{"pid+ff": ..., "pid": ...}: `HeadingAutopilot`s for `model` (a steering model
    or vessel) by pole placement about the straight run at `speed` [m/s] and `n`
    [rev/s], with the reference model and step of `design` and the rudder limits of
    the vessel `plant`; "pid+ff" inverts `model` for the reference feed-forward, its
    steady-turn part weighted by `steady_gain` (`Feedforward`; 1: the model's own).
    `feedback`: the model the poles are placed on, when not `model` (the linear Nomoto 1
    beside a chosen Norrbin model, `selection.linear_candidate`)."""
    feedback = model if feedback is None else feedback
    steps = js.HeadingSteps(times=(design.step_time,), headings=(design.step * DEG,))
    reference = js.ReferenceModel(natural_frequency=design.reference_frequency,
                                  damping=design.reference_damping)
    kw = dict(natural_frequency=design.natural_frequency, damping=design.damping,
              reference=reference, steps=steps, max_angle=float(plant.rudder.max_angle),
              max_rate=float(plant.rudder.max_rate), interval=design.interval, speed=speed,
              n=n, subtract_damping=design.subtract_damping)
    for each in (model, feedback):
        steered_inertia(each, speed=speed, n=n)
    inverse = js.Feedforward(model, steady_gain=steady_gain)
    return {"pid+ff": design_pid(feedback, feedforward=inverse, **kw),
            "pid": design_pid(feedback, feedforward=False, **kw)}


def cell(x, digits=2) -> str:  # a table cell: "-" for None
    return "-" if x is None else f"{x:.{digits}f}"


def _finite(x):
    x = float(x)
    return x if math.isfinite(x) else None


# a run whose rudder sits at its limit for more than this share of the window says
# little about the controller (its code is "rudder_saturated")
SATURATED_SHARE = 0.5
# a run settled when its heading error |psi_ref - psi| (unwrapped: a ship that circles
# is as far off as it turned) stays within SETTLED_BAND of the step over the last
# SETTLED_TAIL of the window; else its code is "not_settled" (`RESULTS.not_settled`).
# 5 % is the wider of the two customary settling bands (2 % and 5 % of the final value:
# Ogata, Modern Control Engineering, 5th ed., sec. 5-3); the 2 % band times the
# settling (`settling_time_s`), which a loop may reach late in the window, while a loop
# outside 5 % at its end has not settled at all (issue 72: 18 deg off a 45 deg step)
SETTLED_BAND = 0.05
SETTLED_TAIL = 0.1


def run_rows(name: str, run, design: AutopilotDesign, rpm, speed, max_angle: float) -> list[dict]:
    """The rows (`RUN_KEYS`, `success`, `time_saturated_s`, `end_error_deg` (the largest
    heading error over the window's last tenth) and the run's `code`: "successful",
    "blew_up", "not_settled" (`SETTLED_BAND`) or "rudder_saturated", the rudder command
    within 1 % of its limit `max_angle` [rad] for more than half the window) of the
    closed-loop `run` of controller `name` at the operating points `rpm`, `speed`."""
    metrics = js.closed_loop_metrics(run, design.sample_interval, window=design.window)
    m = metrics.to_dict_deg()
    ordered = ordered_error_deg(run, design.sample_interval, design.window)
    t = np.asarray(run.t)
    inside = (t >= design.window[0]) & (t <= design.window[1])
    at_limit = np.abs(np.asarray(run.delta_c)[0]) >= 0.99 * max_angle  # the command
    start, end = design.window
    tail = inside & (t >= end - SETTLED_TAIL * (end - start))
    end_error = np.degrees(np.max(np.abs(np.asarray(run.psi_ref)[0][:, tail]
                                         - np.asarray(run.psi)[0][:, tail]), axis=-1))
    rows = []
    for j in range(len(rpm)):
        ok = bool(np.asarray(run.success)[0, j])
        saturated = float(np.mean(at_limit[j][inside])) if ok else math.nan
        code = ("blew_up" if not ok else
                "not_settled" if not end_error[j] <= SETTLED_BAND * abs(design.step) else
                "rudder_saturated" if saturated > SATURATED_SHARE else "successful")
        rows.append({
            "controller": name, "rpm": float(rpm[j]), "speed": float(speed[j]),
            "sum_abs_error_deg": _finite(m["residual_sum_deg"][0][j]),
            "sum_abs_error_ordered_deg": _finite(ordered[0, j]),
            "rms_error_deg": _finite(m["rms_error_deg"][0][j]),
            "max_overshoot_deg": _finite(m["overshoot_deg"][0][j]),
            "settling_time_s": _finite(m["settling_time_s"][0][j]),
            "mean_abs_rudder_deg": _finite(m["mean_abs_rudder_deg"][0][j]),
            "rudder_travel_deg": _finite(m["rudder_travel_deg"][0][j]),
            "time_rate_limited_s": _finite(m["time_at_rate_limit_s"][0][j]),
            "time_saturated_s": _finite(saturated * (design.window[1] - design.window[0])),
            "end_error_deg": _finite(end_error[j]),
            "success": ok, "code": code,
        })
    return rows


def tune_on_vessel(model, plant, design: AutopilotDesign, controllers: dict, *, speed: float,
                   n: float, run_kw: dict, say) -> tuple:
    """`(tuned autopilot, summary)`: `tune_autopilot` with its reference bandwidth
    (`reference_bandwidth=True`) on `plant` at the operating points `run_kw` from the
    "pid+ff" gains of `controllers` (if its $K_d \\le 0$, from the thesis' $K_d =
    2\\zeta\\omega_n m$, designed about `speed`, `n`), with the design's run length,
    output interval, rudder weight and step limit. `say`: the progress callable.
    `model`: the one the poles are placed on (`design_controllers`' `feedback`); the
    feed-forward keeps its own."""
    start = controllers["pid+ff"]
    if not float(start.kd) > 0:
        start = design_controllers(start.feedforward.model, plant, dataclasses.replace(
            design, subtract_damping=False), speed=speed, n=n,
            steady_gain=start.feedforward.steady_gain, feedback=model)["pid+ff"]
    tuned = tune_autopilot(plant, start, duration=design.duration, dt=design.tune_dt,
                           rudder_weight=design.rudder_weight, max_steps=design.tune_steps,
                           reference_bandwidth=True, progress=say, **run_kw)
    return tuned.autopilot, {"objective_before": float(tuned.objective_before),
                             "objective_after": float(tuned.objective_after),
                             "steps": int(tuned.num_steps), "converged": bool(tuned.success),
                             **tuned.reference}


def operating_points(plant, *, rpm=None, speeds=None) -> tuple:
    """`(key, values, points, (u0, n0))` of the runs at `rpm` or `speeds` [m/s] (exactly
    one of them, positive): "rpm" or "speed", the values, each one's straight run `(u, n)`
    and the design's, at their mean. **Raises** `ValueError` (one line) where the vessel
    has no straight run there, or no propeller model for `rpm`."""
    if (rpm is None) == (speeds is None):
        raise ValueError("give exactly one of rpm and speeds.")
    values = [float(x) for x in (rpm if rpm is not None else speeds)]
    if not values or not all(math.isfinite(x) and x > 0 for x in values):
        raise ValueError(f"{'rpm' if rpm is not None else 'speeds'} must be positive numbers, "
                         f"got {values}.")
    key = "rpm" if rpm is not None else "speed"
    js.check_operating_point(plant, **{f"{key}s": values})
    points = [operating_point(plant, **{key: x}) for x in values]
    mean = float(np.mean(values))
    u0, n0 = operating_point(plant, **{key: mean})
    if not all(math.isfinite(u) and u > 0 and math.isfinite(n) for u, n in points + [(u0, n0)]):
        raise ValueError(f"no straight run of the vessel at {key} {values}"
                         + (" (has it a propeller model? give speeds)" if key == "rpm" else ""))
    if key == "rpm" and operating_point(plant, rpm=1.25 * mean)[0] == u0:
        raise ValueError(f"the {type(plant).__name__} has no propeller model (its speed does "
                         "not depend on the rpm): give speeds (--speed) instead.")
    return key, values, points, (u0, n0)


def design_on_vessel(models: DesignModels, plant, design: AutopilotDesign, *, at: dict,
                     u0: float, n0: float, steady_turn: str = "model", say=None) -> tuple:
    """`(controllers, model, at_step)`: `design_controllers` of `models` about the straight
    run `u0`, `n0`; with `steady_turn="trial"` the feed-forward inverts the model nearer the
    vessel's steady turn at the step's peak rate, its steady-turn part scaled to it
    (`nearest_steady_turn` at the operating point `at`, {"rpm" or "speed": the mean});
    `model`: the one the
    feed-forward inverts; `at_step`: the trial (None for "model")."""
    model, feedback = models
    controllers = design_controllers(model, plant, design, speed=u0, n=n0, feedback=feedback)
    at_step = None
    if steady_turn == "trial":
        (say or (lambda message: None))("the vessel's steady turn at the step's peak rate")
        model, at_step = nearest_steady_turn((model, feedback), plant, design,
                                             controllers["pid"], **at)
        controllers = design_controllers(model, plant, design, speed=u0, n=n0,
                                         steady_gain=at_step["steady_gain"], feedback=feedback)
    elif steady_turn != "model":
        raise ValueError(f"steady_turn is 'trial' or 'model', got {steady_turn!r}.")
    return controllers, model, at_step


def evaluate(model, plant, *, rpm=None, speeds=None,
             design: AutopilotDesign = AutopilotDesign(), tune: bool = False, progress=None,
             steady_turn: str = "model") -> Evaluation:
    """Design the autopilots of `model` (`design_controllers`, about the mean operating
    point of the runs) and run each on the vessel `plant` from straight runs at each
    of `rpm` or `speeds` [m/s] (exactly one of them, a sequence). `tune`: also a
    `"tuned"` controller, its gains and reference bandwidth tuned on `plant` at the same
    operating points (`tune_on_vessel`). `progress`: a callable taking a message, or None.
    `steady_turn`: "model" (the feed-forward inverts the model as it is; the thesis'
    eq. 5.2/5.6) or "trial" (its steady-turn part scaled to the vessel's own rudder at
    the step's peak rate, `steady_turn_trial`). `model` may be a `DesignModels` pair: the
    PID's poles are placed on its `feedback`, the feed-forward inverts its `feedforward`
    (with the trial: the nearer of the two, `nearest_steady_turn`)."""
    models = model if isinstance(model, DesignModels) else DesignModels(model, model)
    if (rpm is None) == (speeds is None):
        raise ValueError("give exactly one of rpm and speeds.")
    design.check()
    key, values, points, (u0, n0) = operating_points(plant, rpm=rpm, speeds=speeds)
    say = progress or (lambda message: None)
    controllers, model, at_step = design_on_vessel(
        models, plant, design, at={key: float(np.mean(values))}, u0=u0, n0=n0,
        steady_turn=steady_turn, say=say)
    run_kw = {"rpm": values} if key == "rpm" else {"speeds": values}
    tuning = None
    if tune:
        controllers["tuned"], tuning = tune_on_vessel(models.feedback, plant, design,
                                                      controllers, speed=u0, n=n0,
                                                      run_kw=run_kw, say=say)
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
                      speed=speeds_, rows=rows, tuning=tuning, feedforward_at_step=at_step,
                      feedback=models.feedback)
