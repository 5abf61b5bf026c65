"""The vessel file: a vessel's class and every coefficient in a TOML file, with units.

One coefficient a line, `name = { value = 3.0, unit = "m" }` where it is dimensional
and a bare number where it is not (units as in the class's `param` fields: SI, radians,
rev/s; degrees, deg/s and rpm are read too); the rudder servo and the shaft are the
tables `[rudder]` and `[shaft]`, and a wind-load model other than the default
(`FossenWindLoads`) the table `[wind_model]` (`model = "FujiwaraWindLoads"` and its
geometry). An MMG vessel may instead be given by its main particulars: `model =
"MMGVessel"` and the table `[particulars]` alone (the fields of `MainParticulars`), from
which `MMGVessel.from_particulars` computes the coefficients. Floats are written with
`repr`, so that a vessel reads back bit for bit. `vessel_to_dict` / `vessel_from_dict`
are the same content as a dict; `save_vessel(vessel)` (no path) gives the text,
`load_vessel(dict)` reads the dict (what `jaxship identify` stores in its result).
"""

import dataclasses
import inspect
import math
import pathlib
import re
import tomllib

from ..._foundation._contract import parameter_fields
from ..._foundation._schema import Field, number, read_text
from .._actuators import RudderServo, Shaft
from .._environment import FossenWindLoads
from .._fujiwara_wind import FujiwaraWindLoads
from ._base import AbstractVessel
from .esso_osaka import LowSpeedMMGVessel
from .mariner import Mariner
from .mmg import MMGVessel
from .nomoto import NomotoVessel
from .particulars import MainParticulars
from .ross import RossVessel
from .sway_yaw import SwayYawVessel


CLASSES = {c.__name__: c for c in (RossVessel, Mariner, MMGVessel, LowSpeedMMGVessel,
                                   SwayYawVessel, NomotoVessel)}
# the actuators' fields and units (RudderServo, Shaft)
ACTUATORS = {"rudder": (RudderServo, {"max_angle": "rad", "max_rate": "rad/s",
                                      "time_constant": "s"}),
             "shaft": (Shaft, {"max_rate": "rev/s", "time_constant": "s"})}
# other units read for a field's own, and the factor to it
OTHER_UNITS = {"rad": {"deg": math.pi / 180}, "rad/s": {"deg/s": math.pi / 180},
               "rev/s": {"rpm": 1 / 60}}
# physical ranges beyond the fields' bounds: sizes, masses and densities are positive
POSITIVE = {"length", "draft", "draught", "volume", "rho", "mass", "m", "mass_nd", "iz",
            "i_zz_j_zz", "propeller_diameter", "prop_diameter", "rudder_area", "rudder_span",
            "radius_of_gyration", "rudder_aspect_ratio", "nominal_speed",
            "rudder.max_rate", "rudder.time_constant", "shaft.max_rate", "shaft.time_constant"}
NON_NEGATIVE = {"nominal_n", "frontal_wind_area", "lateral_wind_area"}
# the wind-load models of the table [wind_model] (none: the default, FossenWindLoads)
WIND_MODELS = {c.__name__: c for c in (FujiwaraWindLoads,)}
WIND = "wind_model"
POSITIVE |= {f"{WIND}.{k}" for k in ("length_overall", "breadth", "superstructure_area",
                                     "area_centre_height", "bridge_height")}
UNBOUNDED_OK = {"shaft.max_rate"}  # no limit on the shaft's rate
# the table [particulars] (MainParticulars) of an MMG vessel given by its main particulars
PARTICULARS = "particulars"
POSITIVE |= {f"{PARTICULARS}.{k}" for k in (
    "length", "breadth", "draft", "speed", "propeller_diameter", "rudder_area", "rudder_span",
    "rudder_rate", "gyration_ratio", "rho", "viscosity")}
ANGLE_LIMITS = {"rudder.max_angle", f"{PARTICULARS}.rudder_max_angle",  # within (0, 90] deg
                "stall_angle"}
# added masses are positive: M_A = -diag(X_udot, Y_vdot, N_rdot) (Fossen 2011, sec. 6.3)
NOT_POSITIVE = {"x_udot", "y_vdot", "n_rdot"}
# a propeller's rate [rev/s]: model propellers run at 5-30 (the KVLCC2 7 m model 11.9, the
# thesis' 4 m model 8.3), full-scale ones at 1-3; beyond 50 (3,000 rpm) it is rpm as rev/s
MAX_PROPELLER_RATE = 50.0


def _unit(info) -> str:
    return "" if info.unit in ("", "-") else info.unit


def vessel_to_dict(vessel: AbstractVessel) -> dict:
    """`{"model": class name, field: value or {"value", "unit"}, "rudder": {...},
    "shaft": {...}}`: every field of `vessel`, floats as they are (SI); its
    `wind_model` as `"wind_model": {"model": class name, field: ...}` unless it is the
    default `FossenWindLoads`."""
    if type(vessel).__name__ not in CLASSES:
        raise ValueError(f"{type(vessel).__name__} has no vessel file form; the vessel "
                         f"classes are {', '.join(CLASSES)}.")
    params = parameter_fields(vessel)
    out = {"model": type(vessel).__name__}
    for field in dataclasses.fields(vessel):
        value = getattr(vessel, field.name)
        if field.name == WIND:
            if not isinstance(value, FossenWindLoads):
                out[WIND] = _wind_to_dict(value)
        elif field.name in ACTUATORS:
            units = ACTUATORS[field.name][1]
            out[field.name] = {k: {"value": float(getattr(value, k)), "unit": u}
                               for k, u in units.items()}
        elif isinstance(value, tuple):
            out[field.name] = [float(v) for v in value]
        else:
            unit = _unit(params[field.name])
            out[field.name] = {"value": float(value), "unit": unit} if unit else float(value)
    return out


def _wind_to_dict(model) -> dict:
    """`{"model": class name, field: {"value", "unit"}}` of a wind-load model."""
    if type(model).__name__ not in WIND_MODELS:
        raise ValueError(f"the wind model {type(model).__name__} has no vessel file form; "
                         f"the wind models are FossenWindLoads, {', '.join(WIND_MODELS)}.")
    return {"model": type(model).__name__,
            **{k: {"value": float(getattr(model, k)), "unit": info.unit}
               for k, info in parameter_fields(model).items()}}


def _wind_from_dict(entry):
    """The wind-load model of the table [wind_model] (`_wind_to_dict`'s form)."""
    if not isinstance(entry, dict) or entry.get("model") not in WIND_MODELS:
        raise ValueError(f"table [{WIND}] must name its model = one of "
                         f"{', '.join(WIND_MODELS)} (without it: FossenWindLoads).")
    cls = WIND_MODELS[entry["model"]]
    fields = parameter_fields(cls)
    _fields(cls, {k: v for k, v in entry.items() if k != "model"}, fields, f"{WIND}.")
    return cls(**{k: _value(f"{WIND}.{k}", entry[k], info.unit) for k, info in fields.items()})


# no coefficient of a ship reaches this in SI units: the largest ship built (Seawise Giant,
# 458 m, 6.6e8 kg displacement) has a yaw inertia below 1e13 kg m^2
MAX_MAGNITUDE = 1e15


def _number(where, value) -> float:
    """A dimensionless coefficient of a list (`_field`'s checks, without a range)."""
    return number(value, _field(where, "-"), f"field '{where}'")


def _field(name, unit, bounds=(-math.inf, math.inf)) -> Field:
    """The schema `Field` of the vessel file's field `name` [`unit`], its physical range
    `bounds` narrowed by `POSITIVE`, `NON_NEGATIVE`, `ANGLE_LIMITS`, `NOT_POSITIVE` and
    `MAX_MAGNITUDE`."""
    low, high = max(bounds[0], -MAX_MAGNITUDE), min(bounds[1], MAX_MAGNITUDE)
    unit = "" if unit == "-" else unit
    likely = "is it in another unit?" if (low, high) == (-MAX_MAGNITUDE, MAX_MAGNITUDE) else ""
    if name in ANGLE_LIMITS:
        return Field(unit=unit, low=0.0, high=math.pi / 2, above=True,
                     says="between 0 and 90 deg", likely="in rad: is it in deg?")
    if name in POSITIVE:
        return Field(unit=unit, low=0.0, high=high, above=True, says="positive")
    if name in NON_NEGATIVE:
        return Field(unit=unit, low=0.0, high=high, says="not negative")
    if name in NOT_POSITIVE:
        return Field(unit=unit, low=low, high=0.0, says="not positive",
                     likely="an added mass -X_udot, -Y_vdot or -N_rdot is positive")
    return Field(unit=unit, low=low, high=high, likely=likely)


def _value(name, entry, unit, bounds=(-math.inf, math.inf)) -> float:
    """The SI value of the field `name` from its `entry` (a number, or `{value, unit}`),
    checked against its `unit` and physical range (`_field`)."""
    if isinstance(entry, dict):
        extra = set(entry) - {"value", "unit"}
        if extra or "value" not in entry or "unit" not in entry:
            raise ValueError(f"field '{name}': write {{ value = ..., unit = \"{unit or '-'}\" }}"
                             f" (got the keys {', '.join(sorted(map(str, entry)))}).")
        given, value = entry["unit"], number(entry["value"], Field(nonfinite=True),
                                             f"field '{name}'")
    else:
        given, value = unit or "-", number(entry, Field(nonfinite=True), f"field '{name}'")
        if unit:
            raise ValueError(f"field '{name}': give its unit, {{ value = {value!r}, unit = "
                             f"\"{unit}\" }}.")
    if isinstance(given, str) and given in OTHER_UNITS.get(unit, {}):
        value *= OTHER_UNITS[unit][given]
    elif given != (unit or "-"):
        known = [unit or "-", *OTHER_UNITS.get(unit, {})]
        raise ValueError(f"field '{name}': unit {given!r} is wrong; give it in "
                         f"{' or '.join(repr(u) for u in known)}.")
    if name in UNBOUNDED_OK and value == math.inf:
        return value
    return number(value, _field(name, unit or "-", bounds), f"field '{name}'")


def _fields(cls, data: dict, expected: dict, where: str = "") -> dict:
    """`data`'s keys checked against `expected` (names to anything): unknown, missing."""
    for key in data:
        if key not in expected:
            raise ValueError(f"unknown field '{where}{key}' for {cls.__name__}; its fields "
                             f"are {', '.join(expected)}.")
    for key in expected:
        if key not in data:
            raise ValueError(f"missing field '{where}{key}' of {cls.__name__}.")
    return data


def particulars_to_dict(particulars: MainParticulars) -> dict:
    """`{"model": "MMGVessel", "particulars": {field: value or {"value", "unit"}}}`."""
    params = parameter_fields(particulars)
    table = {}
    for field in dataclasses.fields(particulars):
        value = getattr(particulars, field.name)
        if field.name in params:
            unit = _unit(params[field.name])
            table[field.name] = {"value": float(value), "unit": unit} if unit else float(value)
        else:  # k_t
            table[field.name] = [float(v) for v in value]
    return {"model": MMGVessel.__name__, PARTICULARS: table}


def particulars_from_dict(data: dict) -> MainParticulars:
    """The `MainParticulars` of a vessel file's content with the table [particulars]
    (`particulars_to_dict`'s form; the fields with defaults may be left out).
    **Raises** `ValueError`, one line naming the field."""
    if not isinstance(data, dict) or PARTICULARS not in data:
        raise ValueError(f"no table [{PARTICULARS}]: give the main particulars (the fields "
                         f"of MainParticulars) under [{PARTICULARS}].")
    if data.get("model") != MMGVessel.__name__ or set(data) != {"model", PARTICULARS}:
        raise ValueError(f"a vessel file with [{PARTICULARS}] has model = \"MMGVessel\" and "
                         f"no other field (got {', '.join(sorted(set(data) - {PARTICULARS}))}).")
    table = data[PARTICULARS]
    if not isinstance(table, dict):
        raise ValueError(f"field '{PARTICULARS}' must be a table [{PARTICULARS}].")
    fields = {f.name: f for f in dataclasses.fields(MainParticulars)}
    for key in table:
        if key not in fields:
            raise ValueError(f"unknown field '{PARTICULARS}.{key}'; the main particulars are "
                             f"{', '.join(fields)}.")
    for key, field in fields.items():
        if key not in table and field.default is dataclasses.MISSING:
            raise ValueError(f"missing field '{PARTICULARS}.{key}' of MainParticulars.")
    params = parameter_fields(MainParticulars)
    kwargs = {}
    for name, entry in table.items():
        where = f"{PARTICULARS}.{name}"
        if name not in params:  # k_t
            if not isinstance(entry, list) or len(entry) != 3:
                raise ValueError(f"field '{where}' must be a list of 3 numbers, [k_0, k_1, k_2].")
            kwargs[name] = tuple(_number(where, v) for v in entry)
        else:
            info = params[name]
            kwargs[name] = _value(where, entry, _unit(info), (info.lower, info.upper))
    return MainParticulars(**kwargs)


def vessel_from_dict(data: dict) -> AbstractVessel:
    """The vessel of `vessel_to_dict`'s form, or of `particulars_to_dict`'s (an MMG
    vessel by `MMGVessel.from_particulars`). **Raises** `ValueError` (one line naming
    the field) for an unknown model class, an unknown or missing field, a wrong unit or
    a value outside its physical range."""
    if not isinstance(data, dict) or "model" not in data:
        raise ValueError(f"missing field 'model' (the vessel class: {', '.join(CLASSES)}).")
    cls = CLASSES.get(data["model"]) if isinstance(data["model"], str) else None
    if cls is None:
        raise ValueError(f"field 'model': unknown vessel class {data['model']!r}; choose "
                         f"one of {', '.join(CLASSES)}.")
    if PARTICULARS in data:
        return MMGVessel.from_particulars(particulars_from_dict(data))
    params = {f.name: f.metadata.get("jaxship_parameter") for f in dataclasses.fields(cls)
              if f.name != WIND}
    kwargs = {} if WIND not in data else {WIND: _wind_from_dict(data[WIND])}
    values = _fields(cls, {k: v for k, v in data.items() if k not in ("model", WIND)}, params)
    for name, info in params.items():
        entry = values[name]
        if name in ACTUATORS:
            actuator, units = ACTUATORS[name]
            if not isinstance(entry, dict):
                raise ValueError(f"field '{name}' must be a table [{name}] of "
                                 f"{', '.join(units)}.")
            _fields(actuator, entry, units, f"{name}.")
            kwargs[name] = actuator(**{k: _value(f"{name}.{k}", entry[k], u)
                                       for k, u in units.items()})
        elif info is None:  # a tuple of dimensionless coefficients
            if not isinstance(entry, list):
                raise ValueError(f"field '{name}' must be a list of numbers.")
            kwargs[name] = tuple(_number(name, v) for v in entry)
        else:
            kwargs[name] = _value(name, entry, _unit(info), (info.lower, info.upper))
    _check_ship(kwargs, {n: _unit(i) for n, i in params.items() if i is not None})
    return cls(**kwargs)


def _check_ship(values, units) -> None:
    """Checks across fields: the centre of gravity inside the hull, |x_G| <= L/2 (0.5 in
    the prime system), at least one propeller, and a nominal propeller rate below
    `MAX_PROPELLER_RATE`."""
    for name in ("xg", "x_g"):
        if name in values and "length" in values:
            half = 0.5 if units.get(name) == "-" else 0.5 * values["length"]
            if abs(values[name]) > half:
                raise ValueError(f"field '{name}' = {values[name]:g} {units.get(name, '')}: "
                                 f"the centre of gravity lies outside the hull (|x_G| at most "
                                 f"L/2 = {half:g}).")
    if values.get("n_propellers", 1.0) < 1:
        raise ValueError(f"field 'n_propellers' = {values['n_propellers']:g}: a ship has at "
                         "least one propeller.")
    if values.get("nominal_n", 0.0) > MAX_PROPELLER_RATE:
        raise ValueError(f"field 'nominal_n' = {values['nominal_n']:g} rev/s ("
                         f"{60 * values['nominal_n']:g} rpm) is beyond any propeller's rate "
                         f"({MAX_PROPELLER_RATE:g} rev/s): is it rpm? Give "
                         "{ value = ..., unit = \"rpm\" }.")


def _comments(cls) -> dict:
    """The trailing comments of the class's field lines (symbol and source), by name."""
    try:
        source = inspect.getsource(cls)
    except (OSError, TypeError):
        return {}
    above = dict((k, v) for v, k in re.findall(r"^    #\s*(.*)\n    (\w+): ", source, flags=re.M))
    return above | dict(re.findall(r"^    (\w+): [^#\n]*#\s*(.*)$", source, flags=re.M))


def _toml_value(entry) -> str:
    if isinstance(entry, dict):
        return f"{{ value = {_float(entry['value'])}, unit = \"{entry['unit']}\" }}"
    if isinstance(entry, list):
        return "[" + ", ".join(map(_float, entry)) + "]"
    return _float(entry)


def _float(value: float) -> str:
    return repr(float(value))  # exact; TOML spells inf, -inf and nan as Python does


def vessel_text(vessel: AbstractVessel | MainParticulars, *, source: str = "") -> str:
    """The vessel file's text (TOML) of `vessel` (or of a ship's `MainParticulars`: the
    table [particulars]), with `source` (a line: where its coefficients come from) in
    the header."""
    if isinstance(vessel, MainParticulars):
        return _particulars_text(vessel, source)
    data = vessel_to_dict(vessel)
    comments = _comments(type(vessel))
    lines = ["# jaxship vessel file: `--vessel FILE` on the command line, "
             "jaxship.load_vessel in Python.",
             "# A dimensional coefficient is { value = ..., unit = \"...\" } in SI units "
             "(deg, deg/s, rpm read too);",
             "# a bare number is dimensionless. Every field is required; a [wind_model] "
             "table only for wind loads other than FossenWindLoads.",
             *([f"# {source}"] if source else []),
             f"model = \"{data.pop('model')}\""]
    tables = {k: data.pop(k) for k in (*ACTUATORS, WIND) if k in data}
    for name, entry in data.items():
        note = comments.get(name, "")
        lines.append(f"{name} = {_toml_value(entry)}" + (f"  # {note}" if note else ""))
    for name, table in tables.items():
        lines += ["", f"[{name}]"] + [f"{k} = " + (f'"{v}"' if k == "model" else _toml_value(v))
                                      for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _particulars_text(particulars: MainParticulars, source: str) -> str:
    """The vessel file of an MMG vessel given by its main particulars."""
    table = particulars_to_dict(particulars)[PARTICULARS]
    comments = _comments(MainParticulars)
    lines = ["# jaxship vessel file: an MMG vessel by its main particulars; "
             "`jaxship vessels --from-particulars FILE`",
             "# prints its coefficients (MMGVessel.from_particulars). Dimensional values "
             "{ value = ..., unit = \"...\" } in SI",
             "# units (deg, deg/s read too); x_g, gyration_ratio, rudder_max_angle, rho and "
             "viscosity may be left out (defaults).",
             *([f"# {source}"] if source else []),
             f"model = \"{MMGVessel.__name__}\"", "", f"[{PARTICULARS}]"]
    for name, entry in table.items():
        note = comments.get(name, "")
        lines.append(f"{name} = {_toml_value(entry)}" + (f"  # {note}" if note else ""))
    return "\n".join(lines) + "\n"


def save_vessel(vessel: AbstractVessel | MainParticulars, path=None, *, source: str = ""):
    """Write `vessel` as a vessel file (TOML, `vessel_text`) at `path` and return the
    path; with `path=None`, return the file's text instead (`tomllib.loads` of it is the
    dict `load_vessel` also reads). A ship's `MainParticulars` are written as the table
    [particulars], which `load_vessel` turns into `MMGVessel.from_particulars`."""
    text = vessel_text(vessel, source=source)
    try:  # saving refuses what loading would refuse (a mass of nan or -5, ...)
        vessel_from_dict(tomllib.loads(text))
    except ValueError as error:
        raise ValueError(f"cannot save {type(vessel).__name__}: {error}") from None
    if path is None:
        return text
    path = pathlib.Path(path)
    path.write_text(text, encoding="utf-8")
    return path


def _read(source, parse):
    """`parse` of the vessel file at `source` (a path), of its parsed content (a dict) or
    of its text (a string of several lines, as `save_vessel(v)` returns it); errors name
    the file."""
    if isinstance(source, dict):
        return parse(source)
    if isinstance(source, str) and "\n" in source:
        try:
            return parse(tomllib.loads(source))
        except tomllib.TOMLDecodeError as error:
            raise ValueError(f"the text given is not a vessel file (TOML): {error}.") from None
    path = pathlib.Path(source)
    try:
        data = tomllib.loads(read_text(path, "a vessel file (TOML)"))
    except tomllib.TOMLDecodeError as error:
        raise ValueError(f"{path} is not a vessel file (TOML): {error}.") from None
    try:
        return parse(data)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None


def load_vessel(source) -> AbstractVessel:
    """The vessel of the vessel file at `source` (a path; see `save_vessel`), of its text
    (`save_vessel(v)`'s), or of its content already parsed (a dict, as `tomllib` reads
    it); a file with the table [particulars] gives `MMGVessel.from_particulars` of them.
    **Raises**
    `ValueError`, one line naming the file and the field: not TOML, an unknown or
    missing field, a wrong unit, a value out of its physical range."""
    return _read(source, vessel_from_dict)

