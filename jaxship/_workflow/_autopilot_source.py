"""What an autopilot is designed from (issue 68, point 4): a model, an identification
(an object with `.model` and `.selection`, e.g. `identify`'s result) or the parsed
`result.json` of `jaxship identify`. From an `identify --model auto` result the PID's poles
sit on the linear candidate of its selection (issue 61: pole placement needs a linear yaw
equation; the chosen Norrbin model's tangent at r = 0 is an extrapolation), the
feed-forward inverts the chosen model or, with the steady-turn trial, the nearer of the
two (`nearest_steady_turn`)."""

from typing import NamedTuple

import jaxship as js

from ._identify.result import model_from_report
from ._identify.selection import linear_candidate


class DesignModels(NamedTuple):
    """`evaluate`'s two models where they differ (a chosen Norrbin model and the linear
    candidate of `identify --model auto`, `selection.linear_candidate`): the one the
    feed-forward inverts and the one the PID's poles are placed on. With the steady-turn
    trial the feed-forward inverts whichever turns steadily nearer the vessel at the
    step's peak rate (`nearest_steady_turn`)."""

    feedforward: object
    feedback: object


class Source(NamedTuple):
    """A resolved design source: the `models` (`DesignModels`), the `report` (the
    result.json form, or None for a bare model) and its `selection` (or None)."""

    models: DesignModels
    report: dict | None
    selection: dict | None

    def describe(self) -> dict:
        """autopilot.json's "model" (without the file): the model's name, class, the fit's
        code, the selection, the model the poles sit on, the parameters."""
        model, report = self.models.feedforward, self.report
        linear = linear_candidate(self.selection)
        if report is None:  # a model: its name is its class, its parameters its own
            name = type(model).__name__
            parameters = {k: float(model.get_parameter(k)) for k in model.parameter_names()}
            code = None
        else:
            name = report["model"]
            parameters = {k: float(e["value"] if isinstance(e, dict) else e)
                          for k, e in report["parameters"].items()}
            fit = report.get("fit")  # none: parameters written by hand
            code = fit.get("code") if isinstance(fit, dict) else None
        return {"name": name, "class": type(model).__name__, "fit_code": code,
                "selection": self.selection,
                "feedback": name if linear is None else linear["model"],
                "parameters": parameters}


def resolve(source) -> Source:
    """`Source` of `source`: a `DesignModels` pair, a model, an identification (`.model`,
    `.selection`; its `to_dict()` is the report where it has one) or a parsed result.json
    (`model_from_report`). **Raises** `ValueError` where the selection's linear candidate
    cannot be rebuilt."""
    if isinstance(source, DesignModels):
        return Source(source, None, None)
    if isinstance(source, dict):
        model, report = model_from_report(source), source
        selection = report.get("selection")
    elif isinstance(source, js.AbstractModel):
        return Source(DesignModels(source, source), None, None)
    else:  # an identification
        model, selection = source.model, getattr(source, "selection", None)
        report = source.to_dict() if callable(getattr(source, "to_dict", None)) else None
    linear = linear_candidate(selection)
    if linear is None:
        return Source(DesignModels(model, model), report, selection)
    try:
        return Source(DesignModels(model, model_from_report(linear)), report, selection)
    except ValueError as error:
        raise ValueError(f"the linear candidate of its selection: {error}") from None


def chosen_text(selection) -> str:
    """How `identify --model auto` chose the model (its `selection`); "" for a model
    named by hand."""
    if not isinstance(selection, dict) or "candidates" not in selection:
        return ""
    number = lambda x: f"{x:.6g}" if isinstance(x, (int, float)) else str(x)  # "inf"
    scores = "; ".join(f"{name} {number(c['bic'])}" if "bic" in c else f"{name} not fitted"
                       for name, c in selection["candidates"].items())
    text = (f" `identify --model auto` chose {selection.get('chosen')} by the least BIC on "
            f"its training records ({scores}).")
    linear = linear_candidate(selection)
    if linear is not None:
        values = ", ".join(f"{k} = {float(e['value']):.4g}"
                           for k, e in linear["parameters"].items())
        text += (f" The PID's poles are placed on its linear candidate {linear['model']} "
                 f"({values}), fitted to the same records: pole placement needs a linear "
                 "yaw equation; this one is fitted over the records' yaw rates, while the "
                 "chosen model's tangent at r = 0 is an extrapolation.")
    return text
