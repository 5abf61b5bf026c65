"""The schema of the files a user hands jaxship (vessel files, `result.json`, records):
`open_text` / `read_text` open one with the shared refusals, and `Field` specs checked
by `check` give every value its type, shape and physical range. A refusal is one
`ValueError` line naming the field (the readers put the file in front) and, where a
unit is the likely cause, the unit; it comes before any work (issue 72)."""

import dataclasses
import json
import math
import numbers
import pathlib


def check_path(path, what: str) -> pathlib.Path:
    """`path` as a `Path`, refused in one line naming it and `what` to pass instead where
    it is missing, a folder, a pipe or a device (reading a FIFO could block)."""
    path = pathlib.Path(path)
    if path.is_dir():
        raise ValueError(f"{path} is a folder; pass {what}.")
    if not path.exists():
        raise ValueError(f"{path}: no such file (cannot read it); pass {what}.")
    if not path.is_file():
        raise ValueError(f"{path} is not a regular file (a pipe or a device); pass {what}.")
    return path


def open_text(path, what: str, *, encoding: str = "utf-8", newline=None):
    """`path` (`check_path`'s refusals) opened for reading text; unreadable: a one-line
    `ValueError`."""
    path = check_path(path, what)
    try:
        return open(path, newline=newline, encoding=encoding)
    except OSError as error:
        raise ValueError(f"{path}: cannot read the file ({error.strerror or error}).") from None


UTF16_MARKS = (b"\xff\xfe", b"\xfe\xff")  # the byte-order marks of UTF-16 text


def not_text(path, encoding: str = "utf-8") -> ValueError:
    """The error for a file that is not `encoding` text, naming the first bad line."""
    path = pathlib.Path(path)
    try:
        data = path.read_bytes()
        data.decode(encoding)
    except UnicodeDecodeError as error:
        if data.startswith(UTF16_MARKS):
            return ValueError(f"{path}: the file is UTF-16 text; save it as UTF-8 (or ASCII) "
                              "text.")
        line = data.count(b"\n", 0, error.start) + 1
        return ValueError(f"{path}: line {line} is not {encoding.split('-sig')[0].upper()} text "
                          f"(byte 0x{data[error.start]:02x}): it is not a text file; save it "
                          "as UTF-8 or ASCII text.")
    except OSError as error:
        return ValueError(f"{path}: cannot read the file ({error.strerror or error}).")
    return ValueError(f"{path}: not {encoding} text; save the file as UTF-8 or ASCII text.")


def read_text(path, what: str, *, encoding: str = "utf-8") -> str:
    """The whole text of the file `path` (`open_text`'s refusals, and `not_text`'s)."""
    with open_text(path, what, encoding=encoding) as f:
        try:
            return f.read()
        except UnicodeDecodeError:
            raise not_text(path, encoding) from None
        except OSError as error:
            raise ValueError(f"{path}: cannot read the file ({error.strerror or error}).") \
                from None


@dataclasses.dataclass(frozen=True)
class Field:
    """One field of a file: its `kind` (`number`, `integer`, `string`, `table`, `list`,
    `matrix`: square, of the size `size` names, a sibling list; or several kinds as a
    tuple), SI `unit`, physical range `low`..`high` (`above`: `low` excluded) from
    `source`, what the range `says` in words (default: from the bounds), the `likely`
    slip outside it ("is it rpm?"), whether it is `required`, may be `null`, may be a
    non-finite number as JSON writes one (`nonfinite`: null, "inf", "-inf"); a table's
    `fields` (a spec) or `each` (a `Field` for every value), a list's `each`; `label`:
    how a refusal names it ("{path}", "{key}", "{parent}": the key of the table it is in)."""

    kind: str | tuple = "number"
    unit: str = ""
    low: float = -math.inf
    high: float = math.inf
    above: bool = False
    source: str = ""
    says: str = ""
    likely: str = ""
    required: bool = True
    null: bool = False
    nonfinite: bool = False
    fields: dict | None = None
    each: "Field | None" = None
    size: str = ""
    label: str = "field '{path}'"

    def range_text(self) -> str:
        if self.says:
            return self.says
        if self.low == 0 and self.high == math.inf:
            return "positive" if self.above else "not negative"
        if self.low == -math.inf and self.high == 0:
            return "not positive"
        return f"between {self.low:g} and {self.high:g}"


KINDS = {dict: "an object", list: "a list", str: "a string", bool: "a boolean",
         type(None): "null"}


def kind_of(value) -> str:
    return KINDS.get(type(value), "a number")


def shown(value) -> str:
    """`value` as JSON writes it (true, null, "a"), or its repr."""
    try:
        return json.dumps(value)
    except (TypeError, ValueError):
        return repr(value)


def number(value, field: Field = Field(), name: str = "field") -> float:
    """`value` as a float checked against `field` (no boolean, finite unless
    `field.nonfinite`, within its range); `name` is how the refusal names it."""
    if field.nonfinite and (value is None or isinstance(value, str) and value in ("inf", "-inf")):
        return math.nan if value is None else float(value)
    if isinstance(value, bool) and not field.nonfinite:
        raise ValueError(f"{name} is {shown(value)}, a boolean, not a number.")
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} is {shown(value)}, not a number.")
    try:
        value = float(value)
    except OverflowError:  # an integer beyond any float
        value = math.inf if value > 0 else -math.inf
    if field.kind == "integer" and math.isfinite(value) and not value.is_integer():
        raise ValueError(f"{name} is {value!r}, not a whole number.")
    if not (math.isfinite(value) or field.nonfinite):
        raise ValueError(f"{name} is {value!r}: give a finite number.")
    if math.isfinite(value) and not (field.low < value if field.above else field.low <= value) \
            or value > field.high:
        likely = f" ({field.likely})" if field.likely else ""
        source = f" ({field.source})" if field.source else ""
        raise ValueError(f"{name} = {f'{value!r} {field.unit}'.strip()} is out of its physical "
                         f"range: it must be {field.range_text()}{likely}{source}.")
    return value


def check(spec: dict, data, path: str = "", *, file: str = "", parent: str = "") -> None:
    """Check the parsed mapping `data` against `spec` (`{name: Field}`): a one-line
    `ValueError` `"<file>: field '<path.name>' ..."` at the first field that is missing,
    of the wrong kind or shape, non-finite or out of its range. Fields not in `spec` are
    left alone (the reader's own business)."""
    try:
        for name, field in spec.items():
            where = f"{path}.{name}" if path else name
            if name not in data:
                if field.required:
                    raise ValueError(f"{_name(field, where, name, parent)} is missing.")
                continue
            _value(field, data[name], where, name, data, parent)
    except ValueError as error:
        raise ValueError(f"{file}: {error}" if file else str(error)) from None


def _name(field: Field, where: str, key: str, parent: str) -> str:
    return field.label.format(path=where, key=key, parent=parent)


def _value(field: Field, value, where: str, key: str, siblings, parent: str) -> None:
    name = _name(field, where, key, parent)
    if value is None and field.null:
        return
    kinds = field.kind if isinstance(field.kind, tuple) else (field.kind,)
    if "table" in kinds and isinstance(value, dict):
        if field.fields is not None:
            check(field.fields, value, where, parent=key)
        for k, v in value.items() if field.each is not None else ():
            _value(field.each, v, f"{where}.{k}", k, value, key)
    elif "list" in kinds and isinstance(value, list):
        for i, v in enumerate(value if field.each is not None else ()):
            _value(field.each, v, f"{where}[{i}]", str(i), value, key)
    elif "string" in kinds and isinstance(value, str):
        pass
    elif "matrix" in kinds:
        _matrix(field, value, name, siblings)
    elif "number" in kinds or "integer" in kinds:
        number(value, field, name)
    else:
        wanted = " or ".join({"table": "an object", "list": "a list", "string": "a string"}[k]
                             for k in kinds)
        raise ValueError(f"{name} is {kind_of(value)}, not {wanted}.")


def _matrix(field: Field, matrix, name: str, siblings) -> None:
    """A square matrix of numbers, one row and column per entry of the sibling list
    `field.size`."""
    size = len(siblings.get(field.size) or [])
    if not (isinstance(matrix, list) and len(matrix) == size
            and all(isinstance(row, list) and len(row) == size for row in matrix)):
        first = matrix[0] if isinstance(matrix, list) and matrix else None
        shape = (f"{len(matrix)} x {len(first) if isinstance(first, list) else 0}"
                 if isinstance(matrix, list) else kind_of(matrix))
        raise ValueError(f"{name} is {shape}, not {size} x {size} for its {size} "
                         f"{field.size}.")
    for i, row in enumerate(matrix):
        for j, value in enumerate(row):
            try:
                number(value, dataclasses.replace(field, kind="number"))
            except ValueError:
                raise ValueError(f"{name} row {i + 1}, column {j + 1} is {shown(value)}, not "
                                 f"a number{'' if field.nonfinite else ' (finite)'}.") from None
