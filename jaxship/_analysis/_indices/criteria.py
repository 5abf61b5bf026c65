"""IMO MSC.137(76) manoeuvring criteria and their table (`imo_criteria`, `format_table`)."""

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from ._series import _DEG
from .spiral import StoppingIndices
from .turning import InitialTurningIndices, TurningIndices, ZigZagIndices


# --------------------------------------------------------------------------- IMO criteria


def imo_overshoot_limits_deg(l_over_v):
    """IMO MSC.137(76) 5.3.3 overshoot limits [deg] at $L/V$ [s] (L in m, V in m/s).

    Returns `(first_10, second_10, first_20)`: the 1st and 2nd overshoot limits of the
    10/10 zig-zag (10 deg below L/V = 10 s, 20 deg from 30 s, 5 + L/(2V) between; 25, 40
    and 17.5 + 0.75 L/V), and the 1st overshoot limit of the 20/20 zig-zag (25 deg).
    Continuous at L/V = 10 s and 30 s; works elementwise on arrays.
    """
    lv = np.asarray(l_over_v, dtype=float)
    if np.any(~(lv > 0)):
        raise ValueError(f"`l_over_v` must be positive [s], got {l_over_v}.")
    first = np.where(lv < 10, 10.0, np.where(lv >= 30, 20.0, 5.0 + 0.5 * lv))
    second = np.where(lv < 10, 25.0, np.where(lv >= 30, 40.0, 17.5 + 0.75 * lv))
    full = np.full_like(lv, 25.0)
    if lv.ndim == 0:
        return float(first), float(second), 25.0
    return first, second, full


@dataclasses.dataclass(frozen=True)
class CriterionRow:
    """One IMO criterion: `value` and `limit` in `unit` (`"L"`: ship lengths, `"deg"`);
    a criterion the trial could not measure has `value` nan, is not `passed`, and
    `note` says why (`not_measured`)."""

    criterion: str
    value: float
    limit: float
    unit: str
    passed: bool
    note: str = ""

    @classmethod
    def not_measured(cls, criterion: str, limit: float, unit: str, why: str) -> "CriterionRow":
        """The row of a criterion that the trial could not measure, for the reason `why`:
        not met (a ship that cannot be measured on a trial does not meet it)."""
        return cls(criterion, math.nan, float(limit), unit, False, why)

    def to_dict(self) -> dict:
        """The row as JSON has it: a value not measured is null, with its `note`."""
        row = dataclasses.asdict(self)
        if not row.pop("note"):
            return row
        return row | {"value": self.value if math.isfinite(self.value) else None,
                      "note": self.note}


# the criteria each trial checks (MSC.137(76) 5.3), in the order `imo_criteria` gives them
CRITERIA = {
    "turning35": ("turning: advance, 35 deg turn", "turning: tactical diameter, 35 deg turn"),
    "zigzag10": ("yaw checking: 1st overshoot, 10/10 zig-zag",
                 "course keeping: 2nd overshoot, 10/10 zig-zag"),
    "zigzag20": ("yaw checking: 1st overshoot, 20/20 zig-zag",),
    "stopping": ("stopping: track reach, full astern",),
}


def criterion_limits(length: float, speed: float, stopping_limit: float = 15.0) -> dict:
    """`{criterion: (limit, unit)}` of every IMO MSC.137(76) 5.3 criterion for a ship of
    `length` [m] tested at `speed` [m/s] (`CRITERIA`; the overshoots' limits by
    `imo_overshoot_limits_deg`)."""
    os1, os2, os20 = imo_overshoot_limits_deg(float(length) / float(speed))
    limits = ((4.5, "L"), (5.0, "L"), (os1, "deg"), (os2, "deg"), (os20, "deg"),
              (float(stopping_limit), "L"))
    return dict(zip((c for names in CRITERIA.values() for c in names), limits))


def _worst(results, name, kind, attribute):
    items = results if isinstance(results, Sequence) else [results]
    if not items or not all(isinstance(i, kind) for i in items):
        raise ValueError(f"`{name}` must be a {kind.__name__} or a sequence of them.")
    return max(attribute(i) for i in items)


def _check_switch(zz, name, degrees):
    for z in zz if isinstance(zz, Sequence) else [zz]:
        if isinstance(z, ZigZagIndices) and abs(z.heading_switch * _DEG - degrees) > 0.5:
            raise ValueError(
                f"`{name}` must come from a {degrees:g}/{degrees:g} zig-zag, got a heading "
                f"switch of {z.heading_switch * _DEG:g} deg."
            )


def imo_criteria(length, speed, *, turning35=None, zigzag10=None, zigzag20=None, stopping=None,
                 initial_turning=None, stopping_limit=15.0) -> list[CriterionRow]:
    """Check manoeuvre indices against the IMO MSC.137(76) 5.3 criteria.

    **Arguments:**

    - `length`: $L_{pp}$ [m]; `speed`: test speed V [m/s] (the approach speed).
    - `turning35`: `TurningIndices` of the 35 deg turning circle (advance <= 4.5 L,
      tactical diameter <= 5 L).
    - `initial_turning`: `InitialTurningIndices` for 10 deg heading change with 10 deg
      rudder (distance travelled, along the path, <= 2.5 L).
    - `zigzag10`: `ZigZagIndices` of the 10/10 zig-zag (first and second overshoot,
      limits depending on L/V, see `imo_overshoot_limits_deg`).
    - `zigzag20`: `ZigZagIndices` of the 20/20 zig-zag (first overshoot <= 25 deg).
    - `stopping`: `StoppingIndices` of the full-astern stop (track reach <=
      `stopping_limit` L; 15 L, which the Administration may raise up to 20 L).

    Each may also be a sequence (port and starboard runs); the worst value is checked.
    Returns one `CriterionRow` per criterion for the results given (see `format_table`).
    """
    length, speed = float(length), float(speed)
    if not (length > 0 and speed > 0):
        raise ValueError(f"`length` and `speed` must be positive, got {length} m, {speed} m/s.")
    os1, os2, os20 = imo_overshoot_limits_deg(length / speed)
    rows = []

    def add(criterion, value, limit, unit):
        rows.append(CriterionRow(criterion, float(value), float(limit), unit,
                                 bool(value <= limit)))

    if turning35 is not None:
        adv = _worst(turning35, "turning35", TurningIndices, lambda i: i.advance)
        tac = _worst(turning35, "turning35", TurningIndices, lambda i: i.tactical_diameter)
        add(CRITERIA["turning35"][0], adv / length, 4.5, "L")
        add(CRITERIA["turning35"][1], tac / length, 5.0, "L")
    if initial_turning is not None:
        for i in initial_turning if isinstance(initial_turning, Sequence) else [initial_turning]:
            if isinstance(i, InitialTurningIndices) and abs(i.heading_change * _DEG - 10) > 0.5:
                raise ValueError("`initial_turning` must be for a 10 deg heading change.")
        dist = _worst(initial_turning, "initial_turning", InitialTurningIndices,
                         lambda i: i.distance)
        add("initial turning: distance to 10 deg heading change", dist / length, 2.5, "L")
    if zigzag10 is not None:
        _check_switch(zigzag10, "zigzag10", 10.0)
        first = _worst(zigzag10, "zigzag10", ZigZagIndices, lambda i: i.overshoots[0])
        add(CRITERIA["zigzag10"][0], first * _DEG, os1, "deg")
        if all(len(z.overshoots) >= 2 for z in (
                zigzag10 if isinstance(zigzag10, Sequence) else [zigzag10])):
            second = _worst(zigzag10, "zigzag10", ZigZagIndices, lambda i: i.overshoots[1])
            add(CRITERIA["zigzag10"][1], second * _DEG, os2, "deg")
        else:
            raise ValueError("`zigzag10` needs a second overshoot: simulate longer.")
    if zigzag20 is not None:
        _check_switch(zigzag20, "zigzag20", 20.0)
        first = _worst(zigzag20, "zigzag20", ZigZagIndices, lambda i: i.overshoots[0])
        add(CRITERIA["zigzag20"][0], first * _DEG, os20, "deg")
    if stopping is not None:
        reach = _worst(stopping, "stopping", StoppingIndices, lambda i: i.track_reach)
        add(CRITERIA["stopping"][0], reach / length, float(stopping_limit), "L")
    return rows


def format_table(rows: Sequence[CriterionRow], *, digits=2) -> str:
    """Markdown table of `imo_criteria` rows: criterion, value, limit, pass/fail."""
    lines = ["| criterion | value | limit | result |", "| --- | ---: | ---: | :---: |"]
    for row in rows:
        value = f"{row.value:.{digits}f} {row.unit}" if math.isfinite(row.value) else \
            "not measured"
        lines.append(f"| {row.criterion} | {value} | {row.limit:.{digits}f} {row.unit} | "
                     f"{'pass' if row.passed else 'FAIL'} |")
    return "\n".join(lines)
