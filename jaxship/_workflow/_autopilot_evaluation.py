"""The autopilot of an identification, designed and evaluated on a vessel as `jaxship
autopilot` does (issue 68, point 4): `design_autopilot` (the command's design rules),
`evaluate_autopilot` (what autopilot.json holds) and its `AutopilotEvaluation`."""

import dataclasses

import numpy as np

from .._analysis._autopilot import design_autopilot as design_pid
from ._autopilot import (
    AutopilotDesign,
    Evaluation,
    design_on_vessel,
    evaluate,
    operating_points,
    steady_turn_trial as measure_steady_turn,
)
from ._autopilot_source import chosen_text, resolve
from ._autopilot_steady_turn import feedforward_gain_text
from ._autopilot_text import (
    evaluation_report,
    gains_table,
    problems,
    runs_table,
    tuning_text,
)
from ._trials import check_operating_point


def design_autopilot(model, *, plant=None, rpm=None, speeds=None,
                     design: AutopilotDesign | None = None, steady_turn_trial: bool = True,
                     feedforward=True, **options):
    """A `HeadingAutopilot` by pole placement (thesis eq. 5.3-5.5; Fossen 2011, sec.
    12.2): $K_p = m\\omega_n^2$, $K_d = 2\\zeta\\omega_n m - d$, $K_i = \\omega_n K_p/10$
    with $(m, d)$ of the linearised yaw equation $m\\dot r + d r = \\delta$ (`yaw_inertia`),
    and the reference feed-forward inverting a model (eq. 5.2/5.6).

    - `model`: a steering model or vessel, an identification (`.model`, `.selection`)
      or a parsed `result.json`. From an `identify --model auto` result the poles sit on
      the linear candidate of its selection and the feed-forward inverts the chosen
      model.
    - Without `plant`: the `options` of the pole placement (`bandwidth` or
      `natural_frequency`, `damping`, `reference`, `steps`, `max_angle`, `max_rate`,
      `interval`, `speed`, `n`, `subtract_damping`, `anti_windup`, `wave_filter`; see
      `jaxship._analysis`' `design_autopilot`, unchanged). `feedforward`: True (invert
      the model), False/None, or a model or `Feedforward` to invert.
    - With the vessel `plant` and `rpm` or `speeds` [m/s]: `jaxship autopilot`'s rules,
      no `options`: the `design` (default `AutopilotDesign.auto`: omega_n = 1.25 / T
      within the servo's and the rudder's bounds, the reference at 0.4 omega_n), about the
      straight run at the mean operating point, the vessel's rudder limits; with
      `steady_turn="trial"` the feed-forward inverts the candidate that turns steadily
      nearer the vessel at the step's peak yaw rate, its steady-turn part scaled to the
      vessel's (`nearest_steady_turn`). `feedforward`: True ("pid+ff") or False ("pid").
    """
    source = resolve(model)
    inverse, feedback = source.models
    if plant is None:
        return design_pid(feedback, feedforward=inverse if feedforward is True else feedforward,
                          **options)
    if options:
        raise ValueError(f"with a `plant` the numbers come from `design` (an "
                         f"AutopilotDesign), not {', '.join(sorted(options))}.")
    if design is None:
        design = AutopilotDesign.auto(source.models, plant, rpm=rpm, speeds=speeds)
    design.check()
    key, values, _, (u0, n0) = operating_points(plant, rpm=rpm, speeds=speeds)
    controllers, _, _ = design_on_vessel(source.models, plant, design,
                                         at={key: float(np.mean(values))}, u0=u0, n0=n0,
                                         steady_turn="trial" if steady_turn_trial else "model")
    return controllers["pid+ff" if feedforward else "pid"]


@dataclasses.dataclass
class AutopilotEvaluation(Evaluation):
    """What `evaluate_autopilot` returns: the `Evaluation` (the design, the controllers
    "pid+ff", "pid" and with tuning "tuned", their closed-loop runs and the rows of their
    metrics) with `source`, the model it was designed from (autopilot.json's "model": name,
    class, the fit's code, the selection, the model of the poles, the parameters), and
    `chosen`, how `identify --model auto` chose it in words (None otherwise).
    `feedforward_at_step` is always measured (with the model's own steady turn too).
    `to_dict()` is autopilot.json without the command's own entries (the model file, the
    vessel's name, the figures); `summary()` the text the command prints, `report()` the
    page it writes."""

    source: dict | None = None
    chosen: str | None = None

    def to_dict(self) -> dict:
        """JSON-ready: "model" (`source`), "feedforward_at_step", "design", "gains",
        "runs"."""
        return {"model": self.source, "feedforward_at_step": self.feedforward_at_step,
                **super().to_dict()}

    def inverse_text(self) -> str:
        """The model the feed-forward inverts and its steady turn where the step steers,
        then how the model was chosen, in words."""
        return feedforward_gain_text(self.feedforward_at_step) + (self.chosen or "")

    def problems(self) -> tuple[str, str]:
        """`(failure, saturation)`: the sentences on runs that blew up or did not settle
        (code not_settled) and on runs whose rudder sat on its limit for more than half
        the window; "" where none."""
        start, end = self.design.window
        return problems(self.rows, end - start)

    def summary(self) -> str:
        """The gains and runs as tables, the inverse's sentence and the tuning."""
        texts = (gains_table(self.gains()), runs_table(self.rows), self.inverse_text(),
                 tuning_text(self.tuning))
        return "\n".join(text for text in texts if text)

    def report(self, *, vessel: str | None = None, file: str | None = None, figures=(),
               unconverged: str | None = None) -> str:
        """The markdown page (report.md): its title names the model and the `vessel`, the
        model's line its `file`; the sentences on saturated or blown-up runs and
        `unconverged` (a fit that did not converge) first, in bold; `figures` (paths
        relative to the page) last."""
        source = self.source
        name = f"Heading autopilot: {source['name']}" + (f" on {vessel}" if vessel else "")
        parameters = ", ".join(f"{k} = {float(v):.4g}" for k, v in source["parameters"].items())
        page = evaluation_report(
            self, title=name, figures=figures,
            model_text=f"Model: {source['name']} ({source['class']})"
            + (f" from `{file}`" if file else "") + f": {parameters}. {self.inverse_text()}")
        failure, saturation = self.problems()
        for sentence in (saturation, failure, unconverged):  # first, under the title
            if sentence:
                title, _, rest = page.partition("\n")
                page = f"{title}\n\n**{sentence}**\n{rest}"
        return page


def evaluate_autopilot(source, plant, *, rpm=None, speeds=None,
                       design: AutopilotDesign | None = None, tune: bool = False,
                       steady_turn_trial: bool = True, progress=None) -> AutopilotEvaluation:
    """`jaxship autopilot` as a verb: design the autopilots of `source` (a model, an
    identification or a parsed result.json; `design_autopilot`'s rules, `design` default
    `AutopilotDesign.auto`) and run each on the vessel `plant` from straight runs at each
    of `rpm` or `speeds` [m/s]: "pid+ff" (PID and the reference feed-forward), "pid"
    (feedback only) and with `tune` "tuned" (its gains, then its reference bandwidth,
    tuned on `plant`: `tune_autopilot(..., reference_bandwidth=True)`). The metrics of
    each run: thesis eq. 3.19 sampled over the design's window, RMS error, overshoot,
    settling time, rudder use (`closed_loop_metrics`). `steady_turn_trial`: True (the
    feed-forward's steady-turn part scaled to the vessel's at the step's peak yaw rate;
    `--steady-turn trial`) or False (the model's own, thesis eq. 5.2/5.6). `progress`: a
    callable taking a message (each stage), or None."""
    resolved = resolve(source)
    check_operating_point(plant, rpms=() if rpm is None else rpm,  # before any work
                          speeds=() if speeds is None else speeds)
    if design is None:
        design = AutopilotDesign.auto(resolved.models, plant, rpm=rpm, speeds=speeds)
    evaluation = evaluate(resolved.models, plant, rpm=rpm, speeds=speeds, design=design,
                          tune=tune, progress=progress,
                          steady_turn="trial" if steady_turn_trial else "model")
    at_step = evaluation.feedforward_at_step
    if at_step is None:  # the model's own steady turn: the trial's numbers for the report
        (progress or (lambda message: None))("the vessel's steady turn at the step's peak rate")
        key, values = ("rpm", rpm) if rpm is not None else ("speed", speeds)
        values = [float(x) for x in values]
        at_step = measure_steady_turn(evaluation.model, plant, design,
                                    evaluation.controllers["pid"],
                                    **{key: sum(values) / len(values)})
        del at_step["steady_gain"]
        at_step.pop("trial_failed", None)  # not measured: the report says nothing of it
    fields = {f.name: getattr(evaluation, f.name) for f in dataclasses.fields(evaluation)}
    return AutopilotEvaluation(**fields | {"feedforward_at_step": at_step},
                               source=resolved.describe(), chosen=chosen_text(resolved.selection))
