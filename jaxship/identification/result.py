"""`IdentificationResult`: the report of `identify` (fitted model, start, assessments on
the training and held-out records, notes), as text (`summary`) and JSON (`to_json`)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

import jaxship as js

from .._foundation._validate import _to_plain
from .assessment import Assessment


@dataclasses.dataclass(frozen=True)
class IdentificationResult:
    """Result of `identify`.

    - `model_name`: the registry name; `description`: its line;
    - `fit`: the `FitResult` (fitted `model`, `parameters` report with standard
      errors, correlation and flags, optimiser result);
    - `start`: the start model; `start_method`: how its values were obtained;
    - `train`: `Assessment` of the fit criterion on the training records;
    - `train_simulation`: output-error `Assessment` on the training records;
    - `validation`: output-error `Assessment` on the held-out records, or None;
    - `options`: horizon [s], rudder, channels; `notes`, `warnings`: texts.
    """

    model_name: str
    description: str
    fit: js.FitResult
    start: js.AbstractSteeringModel
    start_method: str
    train: Assessment
    train_simulation: Assessment
    validation: Assessment | None
    options: dict
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def model(self) -> js.AbstractSteeringModel:
        """The fitted model."""
        return self.fit.model

    @property
    def flags(self) -> tuple[str, ...]:
        """Plain-language identifiability findings (empty: well determined)."""
        return tuple(self.fit.flags)

    @property
    def identifiable(self) -> bool:
        return not self.flags

    def summary(self) -> str:
        """A text report: parameters with standard errors, fit % per block, flags."""
        lines = [f"{self.model_name}: {type(self.model).__name__}, "
                 f"{'converged' if self.fit.success else 'NOT converged: ' + self.fit.message}"
                 f" in {self.fit.num_steps} steps",
                 self.fit.parameters.table()]
        for label, block in (("train (criterion)", self.train),
                             ("train (simulation)", self.train_simulation),
                             ("validation (simulation)", self.validation)):
            if block is None:
                continue
            parts = [f"{c} fit {m.fit_percent:.2f} %, FPE {m.fpe:.4g}"
                     for c, m in block.metrics.items()]
            lines.append(f"{label}: " + "; ".join(parts))
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready report (schema in the `identify` docstring)."""
        fitted = self.fit.to_dict()
        report = self.fit.parameters
        start = {n: _to_plain(float(getattr(self.start, n))) for n in report.names}
        parameters = {}
        for name, entry in fitted["parameters"].items():
            rel = report.relative_std[report.names.index(name)]
            parameters[name] = {**entry, "relative_std": _to_plain(float(rel)),
                                "start": start[name]}

        def records(block):
            if block is None:
                return []
            ds = block.data
            return [{"name": ds.names[i],
                     "file": dict(ds.experiment_metadata[i]).get("file"),
                     "samples": int(ds.lengths[i]),
                     "dt_s": float(ds.dt[i]),
                     "duration_s": float(ds.dt[i] * (ds.lengths[i] - 1)),
                     "channels": list(ds.experiment_channels[i])}
                    for i in range(ds.num_experiments)]

        return {
            "model": self.model_name,
            "model_class": type(self.model).__name__,
            "description": self.description,
            "options": _to_plain(self.options),
            "data": {"train": records(self.train), "validation": records(self.validation)},
            "start": {"method": self.start_method, "parameters": start},
            "parameters": parameters,
            "frozen": fitted["frozen"],
            "fit": {k: fitted[k] for k in ("success", "result", "num_steps", "cost",
                                          "window_samples", "weights")},
            "train": self.train.to_dict(),
            "train_simulation": self.train_simulation.to_dict(),
            "validation": None if self.validation is None else self.validation.to_dict(),
            "correlation": {"names": list(report.names),
                            "matrix": _to_plain(np.asarray(report.correlation))},
            "identifiability": {
                "identifiable": self.identifiable,
                "condition_number": _to_plain(report.condition_number),
                "flags": list(self.flags),
            },
            "notes": list(self.notes),
            "warnings": list(self.warnings),
        }

    def to_json(self, indent: int | None = 2) -> str:
        """`to_dict` as JSON text (non-finite numbers as "inf"/"-inf"/null)."""
        return json.dumps(self.to_dict(), indent=indent)
