"""`Identification`: the report of `identify` (fitted model, start, assessments on
the training and held-out records, notes), as text (`summary`) and JSON (`to_json`);
`model_from_report` and `read_result` rebuild the fitted model from that JSON."""

from __future__ import annotations

import dataclasses
import json
import math
import pathlib
import re
import tomllib

import jax
import numpy as np

import jaxship as js

from ..._foundation._schema import Field, check, read_text
from ..._models._vessel.file import vessel_to_dict
from .assessment import Assessment
from .registry import model_key


@dataclasses.dataclass(frozen=True)
class Identification:
    """Result of `identify`: the fitted model and how it was found and assessed. It prints
    as text (`summary`), converts to the JSON of `jaxship identify`'s `result.json`
    (`to_dict`, `to_json`) and saves to it (`save`), which `load_model` reads back.

    - `model_name`: the registry name; `description`: its line;
    - `fit`: the `FitResult` (fitted `model`, `parameters` report with standard
      errors, correlation and flags, optimiser result);
    - `start`: the start model; `start_method`: how its values were obtained;
    - `train`: `Assessment` of the fit criterion on the training records;
    - `train_simulation`: output-error `Assessment` on the training records;
    - `validation`: output-error `Assessment` on the held-out records, or None;
    - `options`: horizon [s], rudder, channels; `notes`, `warnings`: texts;
    - `selection`: with `--model auto`, how the model was chosen (`selection.choose`:
      the criterion, the chosen name, each candidate's figures); None otherwise.
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
    selection: dict | None = None

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
        if self.fit.prior is not None:
            lines.insert(2, self.fit.prior_table())
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready report (schema in the `identify` docstring)."""
        fitted = self.fit.to_dict()
        report = self.fit.parameters
        value = (self.start.get_parameter if isinstance(self.start, js.AbstractModel)
                 else lambda n: getattr(self.start, n))  # ARMAX: its polynomials' fields
        start = {n: float(value(n)) for n in report.names}
        parameters = {name: {**entry, "start": start[name]}
                      for name, entry in fitted["parameters"].items()}

        def records(block):
            if block is None:
                return []
            ds = block.data
            return [{"name": ds.names[i],
                     "file": dict(ds.experiment_metadata[i]).get("file"),
                     "samples": int(ds.lengths[i]),
                     "dt_s": float(ds.dt[i]),
                     "duration_s": float(ds.dt[i] * (ds.lengths[i] - 1)),
                     "channels": list(ds.experiment_channels[i]),
                     "velocities": "over ground" if ds.over_ground[i] else "through the water",
                     # the reader's columns it could not check against each other, and why
                     **{k: v for k, v in dict(ds.experiment_metadata[i]).items()
                        if k == "unchecked"}}
                    for i in range(ds.num_experiments)]

        return _json_floats({
            "model": self.model_name,
            "model_class": type(self.model).__name__,
            "description": self.description,
            "options": self.options,
            "data": {"train": records(self.train), "validation": records(self.validation)},
            "start": {"method": self.start_method, "parameters": start},
            "parameters": parameters,
            "frozen": fitted["frozen"],
            "constants": _constants(self.model),
            **_structure(self.model),
            "fit": {k: fitted[k] for k in ("success", "code", "result", "num_steps", "cost",
                                          "window_samples", "weights", "prior",
                                          "effective_params") if k in fitted},
            "train": self.train.to_dict(),
            "train_simulation": self.train_simulation.to_dict(),
            "validation": None if self.validation is None else self.validation.to_dict(),
            "correlation": {"names": list(report.names),
                            "matrix": fitted["correlation"]},
            "identifiability": {
                "identifiable": self.identifiable,
                "condition_number": fitted["condition_number"],
                "flags": list(self.flags),
            },
            "notes": list(self.notes),
            "warnings": list(self.warnings),
            **({} if self.selection is None else {"selection": self.selection}),
        })

    def to_json(self, indent: int | None = 2) -> str:
        """`to_dict` as JSON text (non-finite numbers as "inf"/"-inf"/null)."""
        return json.dumps(self.to_dict(), indent=indent)

    def save(self, path) -> pathlib.Path:
        """Write `to_json()` to the file `path` (the `result.json` that `jaxship identify`
        writes; `load_model(path)` gives the fitted model back), after `checked_json`:
        a result that loading would refuse is refused before the file is touched.
        Returns the path."""
        path = pathlib.Path(path)
        path.write_text(self.checked_json() + "\n", encoding="utf-8")
        return path

    def checked_json(self) -> str:
        """`to_json()`, refused where loading would refuse its fields (`check_fields`: a
        non-finite or boolean value, a std or correlation of the wrong shape; the fitted
        vessel's ranges are `save_vessel`'s in `to_dict`): saving writes nothing a reader
        cannot read back. **Raises** `ValueError` (one line)."""
        try:
            check_fields(self.to_dict())
        except ValueError as error:
            raise ValueError(f"cannot save the {self.model_name} result: {error}") from None
        return self.to_json()


def _constants(model) -> dict:
    """The scalar fields of a steering model that are not parameters (reference scales
    such as `RossAutopilot`'s L, U_0, n_0; the sway-yaw models' length, speed,
    draught): with `parameters` and `frozen` they rebuild the model."""
    if not isinstance(model, js.AbstractSteeringModel):
        return {}
    names = model.parameter_names()
    out = {}
    for field in dataclasses.fields(model):
        value = getattr(model, field.name, None)
        if field.name in names or isinstance(value, bool) or np.ndim(value) != 0:
            continue
        if isinstance(value, (int, float, np.number, np.ndarray, jax.Array)):
            out[field.name] = float(value)
    return out


def _structure(model) -> dict:
    """What rebuilds the model beside its values: `effects`, the class names of its
    effects in order (a model with effects), and `vessel`, the fitted vessel in the
    vessel file's content (`save_vessel`'s text read as TOML), so that a vessel of one's own
    file comes back."""
    augmented = isinstance(model, (js.effects.AugmentedSteering, js.effects.AugmentedVessel))
    base = model.base if augmented else model
    out = {}
    if augmented:
        out["effects"] = [type(effect).__name__ for effect in model.effects]
    if isinstance(base, js.AbstractVessel):
        out["vessel"] = tomllib.loads(js.save_vessel(base))  # the vessel file's content
    return out


def _with_effects(model, names):
    """`model` with the effects of the class names `names` (default values) added."""
    effects = []
    for name in names:
        cls = getattr(js.effects, str(name), None)
        if not (isinstance(cls, type) and issubclass(cls, js.effects.AbstractEffect)):
            raise ValueError(f"unknown effect {name!r} in the identify result.")
        try:
            effects.append(cls())
        except TypeError:
            raise ValueError(f"the effect {name} needs more than its parameters (a record); "
                             "it cannot be rebuilt from result.json.") from None
    return js.augment(model, *effects) if effects else model


# "RossAutopilot reference scales (frozen): L = 1.2 m, U0 = 1.1 m/s, n0 = 6.1 rev/s" (start_ross)
_ROSS_SCALES = re.compile(r"L = (\S+) m, U0 = (\S+) m/s, n0 = (\S+) rev/s")


_NUMBER = Field(label="parameter {key}")  # a value: finite, no boolean
_TABLE = Field("table", required=False, null=True)
# the fields of an identify report that rebuild its model or draw from its covariance
RESULT = {
    "model": Field("string"),
    "model_class": Field("string", required=False),
    # each record's sample interval and length, which `simulate` takes for a steering
    # model's trial: positive seconds
    "data": dataclasses.replace(_TABLE, each=Field("list", null=True, each=Field(
        "table", fields={"dt_s": Field(unit="s", low=0.0, above=True, required=False),
                         "duration_s": Field(unit="s", low=0.0, above=True,
                                             required=False)}))),
    "parameters": Field("table", each=Field(("number", "table"), label="parameter {key}", fields={
        "value": Field(label="parameter {parent}"),
        "std": Field(low=0.0, nonfinite=True, required=False, says="not negative"),
        "start": Field(nonfinite=True, required=False)})),
    "frozen": dataclasses.replace(_TABLE, each=_NUMBER),
    "constants": dataclasses.replace(_TABLE, each=_NUMBER),
    "effects": Field("list", required=False, null=True, each=Field("string")),
    "vessel": _TABLE,
    "notes": Field("list", required=False, null=True),
    "fit": dataclasses.replace(_TABLE, fields={"code": Field(("string", "integer"),
                                                             required=False)}),
    "correlation": dataclasses.replace(_TABLE, fields={
        "names": Field("list", each=Field("string")),
        "matrix": Field("matrix", size="names", nonfinite=True, required=False, null=True)}),
    "selection": _TABLE,
    "options": _TABLE,
}


def check_fields(report: dict) -> None:
    """A one-line `ValueError` naming the field where an identify report (the parsed
    `result.json`) breaks `RESULT`, before any work: each parameter's value a finite
    number (no boolean) and its `std` a number, `data` an object of lists of records,
    `correlation` an object of `names` (distinct parameter names) and a square `matrix`
    of numbers, one row per name."""
    for key, kind in (("frozen", dict), ("constants", dict), ("notes", list)):
        if report.get(key) is not None and not isinstance(report[key], kind):
            raise ValueError(f"'{key}' in the identify result is a {type(report[key]).__name__}, "
                             f"not a {kind.__name__}.")
    check(RESULT, report)
    names = (report.get("correlation") or {}).get("names") or []
    if len(set(names)) != len(names) or not all(n in report["parameters"] for n in names):
        raise ValueError("field 'correlation.names' is not a list of the parameters' distinct "
                         "names.")


def model_from_report(report: dict):
    """The fitted model of an `identify` report (`Identification.to_dict()`, i.e.
    the parsed `result.json` of `jaxship identify`): a steering model rebuilt from its
    class name, `parameters` (values), `frozen` and `constants`, or a vessel from its
    `vessel` (the vessel file's form; older reports: the preset `model`) with its
    estimated and frozen coefficients; either with the effects of `effects` (class
    names) and their fitted parameters. Reports written before `constants` existed
    rebuild `RossAutopilot` from the reference-scale note of its start.

    **Raises** `ValueError` (one line) for a report without `model` and `parameters`,
    a field of the wrong type or shape (`check_fields`), non-numeric or boolean values,
    an ARMAX model (discrete, no yaw equation to design on) or an
    effect that needs more than its parameters (a recorded disturbance)."""
    if not isinstance(report, dict) or not isinstance(report.get("parameters"), dict) or \
            "model" not in report:
        raise ValueError("not an identify result: no 'model' and 'parameters' (write one "
                         "with `jaxship identify`).")
    check_fields(report)  # every value below is a finite number from here on
    own_vessel = isinstance(report.get("vessel"), dict)
    try:
        name = model_key(report["model"])
    except ValueError:
        if not own_vessel:
            raise ValueError(f"unknown model {report['model']!r} in the identify result.") \
                from None
        name = str(report["model"])
    values = {key: float(entry["value"] if isinstance(entry, dict) else entry)
              for key, entry in report["parameters"].items()}
    values |= {key: float(value) for key, value in (report.get("frozen") or {}).items()}
    if name == "armax":
        raise ValueError("armax is a discrete model of the yaw rate: it has no yaw equation "
                         "to design an autopilot on; identify a steering model.")
    effects = report.get("effects") or []
    if any("." in key for key in values) and not effects:
        raise ValueError(f"the {name} result has effect parameters "
                         f"({', '.join(k for k in values if '.' in k)}) but no 'effects'.")
    if own_vessel or name in js.VESSELS:
        base = js.load_vessel(_finite(report["vessel"])) if own_vessel else js.get_vessel(name)
        return _set_values(_with_effects(base, effects), values, name)
    cls = getattr(js, str(report.get("model_class", "")), None)
    if not (isinstance(cls, type) and issubclass(cls, js.AbstractSteeringModel)):
        raise ValueError(f"unknown model class {report.get('model_class')!r} in the identify "
                         "result.")
    constants = report.get("constants")
    if constants is None and cls is js.RossAutopilot:
        found = [_ROSS_SCALES.search(str(note)) for note in report.get("notes", ())]
        found = [m for m in found if m]
        if not found:
            raise ValueError("the RossAutopilot result has no reference scales ('constants'); "
                             "re-run `jaxship identify` to write them.")
        try:
            constants = dict(zip(("length", "speed", "rate"), map(float, found[0].groups())))
        except ValueError:
            raise ValueError("the RossAutopilot result's reference scales are no numbers; "
                             "re-run `jaxship identify` to write them.") from None
    constants = {k: float(v) for k, v in (constants or {}).items()}
    own = {k: v for k, v in values.items() if "." not in k}
    try:
        model = cls(**constants, **own)
    except TypeError as error:
        raise ValueError(f"cannot rebuild {cls.__name__} from the identify result: "
                         f"{error}.") from None
    return _set_values(_with_effects(model, effects), values, name)


def _set_values(model, values: dict, name: str):
    """`model` with the parameters `values` (`{name or "<effect id>.<field>": value}`)."""
    unknown = [k for k in values if k not in model.parameter_names()]
    if unknown:
        raise ValueError(f"the {name} model has no coefficient {unknown[0]!r}.")
    base = getattr(model, "base", model)
    if isinstance(base, js.AbstractVessel):  # a vessel's values: the vessel file's ranges
        data = vessel_to_dict(base)
        for key, value in values.items():
            if isinstance(data.get(key), dict):
                data[key] = {**data[key], "value": value}
            elif isinstance(data.get(key), float):
                data[key] = value
        js.load_vessel(data)
    return model.with_parameters(values)


def _json_floats(data):
    """`data` with its non-finite floats as JSON can hold them: "inf", "-inf", null
    (`_finite` reads them back)."""
    if isinstance(data, dict):
        return {k: _json_floats(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_json_floats(v) for v in data]
    if isinstance(data, float) and not math.isfinite(data):
        return None if math.isnan(data) else ("inf" if data > 0 else "-inf")
    return data


def _finite(data):
    """The vessel dict of a result with the "inf" strings of JSON as floats again."""
    if isinstance(data, dict):
        return {k: _finite(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_finite(v) for v in data]
    return float(data) if data in ("inf", "-inf") else data


def unconverged_fit(report: dict, source) -> str:
    """The sentence that the fit behind `report` (a result.json, read from `source`) is
    no converged estimate, or "" when it is (or when the file has no `fit`: parameters
    written by hand). Every command that takes a result says it and exits 3."""
    fit = report.get("fit")
    code = fit.get("code") if isinstance(fit, dict) else "successful"
    return "" if code == "successful" else (
        f"The model's fit is not a converged estimate (code {code} in {source}): what this "
        "command computes from it rests on parameters the records did not determine; "
        "identify the model again on records that excite it (e.g. a zig-zag).")


def read_report(path) -> dict:
    """The parsed `result.json` of `jaxship identify` (or `Identification.save`) at `path`
    (a file, or a folder holding `result.json`). **Raises** `ValueError` (one line) when
    the file is missing or unreadable, or not JSON."""
    path = pathlib.Path(path)
    if path.is_dir():
        path = path / "result.json"
    text = read_text(path, "the result.json that `jaxship identify` wrote")
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{path} is not valid JSON ({error.msg}, line {error.lineno}).") \
            from None
    except ValueError as error:  # an integer of more than 4300 digits
        raise ValueError(f"{path} is not valid JSON ({error}).") from None
    except RecursionError:
        raise ValueError(f"{path} is nested too deeply to be an identify result.") from None


def read_result(path) -> tuple[object, dict]:
    """`(model, report)` from the `result.json` of `jaxship identify` at `path`
    (`read_report`, `model_from_report`). **Raises** `ValueError` (one line) when the file
    is missing or unreadable, not JSON, or not an identify result."""
    report = read_report(path)
    try:
        return model_from_report(report), report
    except ValueError as error:
        path = pathlib.Path(path)
        raise ValueError(f"{path / 'result.json' if path.is_dir() else path}: {error}") \
            from None
