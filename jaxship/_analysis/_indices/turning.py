"""Turning-circle, zig-zag and initial-turning indices."""

import dataclasses

import equinox as eqx
import numpy as np

from ..._simulation._readers import DisplayUnits
from ._series import (
    _DEG,
    _TOL,
    _course_frame,
    _crossing,
    _docstring,
    _named,
    _path_length,
    _peak,
    _rudder_execute,
    _series,
)


# --------------------------------------------------------------------------- turning


@dataclasses.dataclass(frozen=True)
class TurningIndices:
    """Turning-circle indices (IMO MSC.137(76) 4.2; ITTC 7.5-04-02-01 2.2.1), SI units.

    `steady_method` says how the steady diameter was found: `"rate"` for
    $D = 2U/|r|$ at the last sample, `"circle"` for a least-squares circle through the
    track over the last full turn.
    """

    advance: float  # [m] along the original course, rudder order -> 90 deg heading change
    transfer: float  # [m] towards the turning side at 90 deg heading change
    tactical_diameter: float  # [m] towards the turning side at 180 deg heading change
    steady_turning_diameter: float  # [m]
    speed_loss: float  # 1 - U_steady / U_0 [-]
    time_to_90: float  # [s] from the rudder order
    time_to_180: float  # [s] from the rudder order
    execute_time: float  # [s] time of the rudder order
    side: int  # +1 starboard turn, -1 port turn
    steady_method: str = "rate"

    def to_dict(self, units=DisplayUnits()) -> dict:
        return _named([
            ("advance", self.advance, "m"), ("transfer", self.transfer, "m"),
            ("tactical_diameter", self.tactical_diameter, "m"),
            ("steady_turning_diameter", self.steady_turning_diameter, "m"),
            ("speed_loss", self.speed_loss, "1"),
            ("time_to_90", self.time_to_90, "s"), ("time_to_180", self.time_to_180, "s"),
        ], units)


def _fit_circle(x, y):
    """Algebraic (Kasa) least-squares circle: centre and radius."""
    a = np.stack([x, y, np.ones_like(x)], axis=1)
    sol = np.linalg.lstsq(a, x**2 + y**2, rcond=None)[0]
    cx, cy = sol[0] / 2, sol[1] / 2
    return cx, cy, float(np.sqrt(sol[2] + cx**2 + cy**2))


class SteadyFromRate(eqx.Module):
    """`turning_indices(steady=SteadyFromRate())`: the steady diameter $D = 2U/|r|$ and
    speed from the last sample (needs `u, v, r`)."""

    name = "rate"  # `TurningIndices.steady_method`

    def diameter_and_speed(self, s, h, side, speed, reached) -> tuple[float, float]:
        s.need("u", "v", "r", what="steady=SteadyFromRate()")
        u_end, r_end = float(speed[-1]), float(s.r[-1])
        if r_end * side <= 0:
            raise ValueError("the yaw rate at the last sample is not turning the ship.")
        return 2 * u_end / abs(r_end), u_end


class SteadyFromCircle(eqx.Module):
    """`turning_indices(steady=SteadyFromCircle())`: the steady diameter of a least-squares
    circle through the track over the last 360 deg of heading change and the mean track
    speed over it."""

    name = "circle"  # `TurningIndices.steady_method`

    def diameter_and_speed(self, s, h, side, speed, reached) -> tuple[float, float]:
        last = h >= h[-1] - 2 * np.pi
        if h[-1] - 2 * np.pi < 0 or np.count_nonzero(last) < 4:
            raise ValueError("steady=SteadyFromCircle() needs a full 360 deg turn after the "
                             f"order, got {reached:.1f} deg.")
        _, _, radius = _fit_circle(s.x[last], s.y[last])
        i0 = np.nonzero(last)[0][0]
        path = _path_length(s.t, s.x, s.y)
        return 2 * radius, float((path[-1] - path[i0]) / (s.t[-1] - s.t[i0]))


@_docstring
def turning_indices(traj=None, *, execute_time=None,
                    steady: SteadyFromRate | SteadyFromCircle | None = None,
                    **arrays) -> TurningIndices:
    """Advance, transfer, tactical and steady diameters, speed loss and times of a turn.

    {arrays}

    - `execute_time`: time of the rudder order [s]; by default the first sample at which
      the rudder order leaves the initial (actual) rudder angle.
    - `steady`: how the steady diameter and speed are found: `SteadyFromRate()` (from the
      last sample's $U$ and $r$), `SteadyFromCircle()` (a circle through the track's last
      turn); None (default): from the rate when `u, v, r` are known, else the circle.

    Port and starboard turns are treated alike: distances to the turning side and heading
    changes are magnitudes. Raises `ValueError` if the heading never changes 180 deg.
    """
    s = _series(traj, arrays)
    t_e = _rudder_execute(s, execute_time)
    along, athwart, psi_e = _course_frame(s, t_e)
    change = s.psi - psi_e
    side = int(np.sign(change[-1]))
    if side == 0:
        raise ValueError("the heading did not change: no turn in this trajectory.")
    h = side * change
    reached = float(np.max(h[s.t >= t_e])) * _DEG
    t90 = _crossing(s.t, h, np.pi / 2, t_e)
    t180 = _crossing(s.t, h, np.pi, t_e)
    if t180 is None:
        raise ValueError(
            f"the heading changed only {reached:.1f} deg after the rudder order at "
            f"t = {t_e:g} s; turning indices need 180 deg: simulate longer."
        )
    speed = s.speed()
    u0 = float(np.interp(t_e, s.t, speed))
    if steady is None:
        known = all(a is not None for a in (s.u, s.v, s.r))
        steady = SteadyFromRate() if known else SteadyFromCircle()
    if not isinstance(steady, (SteadyFromRate, SteadyFromCircle)):
        raise ValueError(f"`steady` must be SteadyFromRate(), SteadyFromCircle() or None, got "
                         f"{steady!r}.")
    diameter, u_end = steady.diameter_and_speed(s, h, side, speed, reached)
    return TurningIndices(
        advance=float(np.interp(t90, s.t, along)),
        transfer=float(side * np.interp(t90, s.t, athwart)),
        tactical_diameter=float(side * np.interp(t180, s.t, athwart)),
        steady_turning_diameter=float(diameter),
        speed_loss=1.0 - u_end / u0,
        time_to_90=t90 - t_e, time_to_180=t180 - t_e, execute_time=t_e, side=side,
        steady_method=steady.name,
    )


# --------------------------------------------------------------------------- zig-zag


@dataclasses.dataclass(frozen=True)
class ZigZagIndices:
    """Zig-zag indices (IMO MSC.137(76) 4.2.7; ITTC 7.5-04-02-01 2.2.2), SI units.

    Overshoot k is the largest heading excursion beyond the switch heading (relative to
    the original heading) after rudder execute k+1. Timing indices use the interpolated
    instants at which the heading passes the switch angle (`switch_times`, the nominal
    executes 2, 3, ...): `initial_turning_time` = first switch - first execute,
    `time_to_check_yaw` = time of the first maximum heading - first switch, `period` =
    mean time between switches two apart (one full oscillation).
    """

    heading_switch: float  # psi_s [rad]
    rudder_angle: float  # |delta| at the first execute [rad]
    overshoots: tuple[float, ...]  # [rad], complete overshoots only
    overshoot_times: tuple[float, ...]  # [s] time of each maximum excursion
    execute_times: tuple[float, ...]  # [s] rudder executes found in the command history
    switch_times: tuple[float, ...]  # [s] heading passes +-psi_s (interpolated)
    initial_turning_time: float  # [s]
    time_to_check_yaw: float  # [s]
    period: float  # [s], NaN with fewer than three switches
    side: int  # +1 starboard first, -1 port first

    def to_dict(self, units=DisplayUnits()) -> dict:
        items = [(f"overshoot_{k + 1}", o, "rad") for k, o in enumerate(self.overshoots)]
        items += [
            ("initial_turning_time", self.initial_turning_time, "s"),
            ("time_to_check_yaw", self.time_to_check_yaw, "s"), ("period", self.period, "s"),
        ]
        return _named(items, units)


def _zigzag_executes(s, execute_times) -> list[float]:
    """The rudder executes [s]: `execute_times`, or the first departure of the rudder
    order from the initial angle (the first sample where the run starts with the rudder
    already at half its largest order or more: a steering model, which has no servo,
    run from t = 0) and then every reversal of its sign."""
    if execute_times is not None:
        times = [float(e) for e in np.atleast_1d(execute_times)]
        if not times or np.any(np.diff(times) <= 0):
            raise ValueError("`execute_times` must be a non-empty increasing sequence.")
        return times
    order = s.rudder_order
    t1 = float(s.t[0]) if _starts_ordered(s) else _rudder_execute(s, None)
    i = int(np.searchsorted(s.t, t1))
    times, current = [t1], int(np.sign(order[i]))
    for j in range(i + 1, s.t.size):
        if abs(order[j]) > _TOL and np.sign(order[j]) == -current:
            times.append(float(s.t[j]))
            current = -current
    return times


def _starts_ordered(s) -> bool:
    """Whether the run starts with the rudder already at half its largest order or more
    (a steering model, which has no servo, run from t = 0): executed at the first
    sample, with no rudder before it."""
    order = s.rudder_order
    return order is not None and abs(order[0]) >= 0.5 * np.max(np.abs(order)) > _TOL


def _first_side(s, t0, psi_s) -> tuple[int, float]:
    """`(side, rudder angle)` of the first order at `t0` (side 0: not told)."""
    i = int(np.searchsorted(s.t, t0))
    if s.delta is not None and i < s.t.size:
        # side of the first order relative to the rudder before it (a neutral-helm offset,
        # as in the MARIN runs, must not decide it): where it has moved half its way; a
        # record that starts with the order given (the rudder already over) has no before
        baseline = (0.0 if _starts_ordered(s) else s.delta[0] if s.delta_command is not None
                    else s.rudder_order[0] if i > 0 else 0.0)
        moved = s.rudder_order[i:] - baseline
        k = i + int(np.argmax(np.abs(moved) >= 0.5 * np.max(np.abs(moved))))
        return int(np.sign(s.rudder_order[k])), abs(float(s.rudder_order[k]))
    # no rudder history: the side the heading first passes the switch angle
    change = s.psi - np.interp(t0, s.t, s.psi)
    up = _crossing(s.t, change, psi_s, t0)
    down = _crossing(s.t, -change, psi_s, t0)
    side = 0 if up is None and down is None else (
        1 if down is None or (up is not None and up < down) else -1)
    return side, float("nan")


@_docstring
def zigzag_indices(traj=None, heading_switch=None, *, execute_times=None, initial_heading=None,
                   **arrays) -> ZigZagIndices:
    """Overshoot angles, initial turning time, time to check yaw and period of a zig-zag.

    {arrays}

    - `heading_switch`: the heading change psi_s [rad] > 0 at which the rudder is reversed.
    - `execute_times`: the rudder executes [s]; by default the first departure of the
      rudder order from the initial rudder angle (the first sample where the run starts
      with the rudder at half its largest order or more, as a steering model's from rest)
      and then every reversal of its sign.
    - `initial_heading`: the original heading [rad]; by default the heading at the first
      execute.

    The first side is the sign of the first rudder order (port first for a negative
    rudder); overshoots are measured on the side the ship was turning to, so port-first
    and starboard-first runs give positive overshoots alike.
    """
    if heading_switch is None or not float(heading_switch) > 0:
        raise ValueError(f"`heading_switch` must be a positive angle [rad], got {heading_switch}.")
    psi_s = float(heading_switch)
    s = _series(traj, arrays)
    s.need("psi", what="zigzag_indices")
    times = _zigzag_executes(s, execute_times)
    side, rudder_angle = _first_side(s, times[0], psi_s)
    if side == 0:
        raise ValueError("could not tell the side of the first rudder order.")
    psi0 = np.interp(times[0], s.t, s.psi) if initial_heading is None else float(initial_heading)
    e = side * (s.psi - psi0)  # heading change towards the first side
    switches, after, k = [], times[0], 0
    while True:
        upward = k % 2 == 0
        crossing = _crossing(s.t, e, psi_s if upward else -psi_s, after, upward=upward)
        if crossing is None:
            break
        switches.append(crossing)
        after, k = crossing, k + 1
    if not switches:
        raise ValueError(
            f"the heading never reached the switch angle {psi_s * _DEG:g} deg "
            f"(largest change {np.max(e[s.t >= times[0]]) * _DEG:.2f} deg): simulate longer."
        )
    overshoots, peak_times = [], []
    for k, start in enumerate(switches):
        sign = 1.0 if k % 2 == 0 else -1.0
        stop = switches[k + 1] if k + 1 < len(switches) else s.t[-1]
        found = _peak(s.t, sign * e, start, stop)
        if found is None:
            break
        tp, value, interior = found
        if k + 1 >= len(switches) and not interior:
            break  # the heading has not turned back yet
        overshoots.append(value - psi_s)
        peak_times.append(tp)
    if not overshoots:
        raise ValueError("no complete overshoot in this trajectory: simulate longer.")
    period = (float(np.mean(np.array(switches[2:]) - np.array(switches[:-2])))
              if len(switches) >= 3 else float("nan"))
    return ZigZagIndices(
        heading_switch=psi_s, rudder_angle=rudder_angle, overshoots=tuple(overshoots),
        overshoot_times=tuple(peak_times), execute_times=tuple(times),
        switch_times=tuple(switches), initial_turning_time=switches[0] - times[0],
        time_to_check_yaw=peak_times[0] - switches[0], period=period, side=side,
    )


# --------------------------------------------------------------------------- initial turning


@dataclasses.dataclass(frozen=True)
class InitialTurningIndices:
    """Initial turning (IMO MSC.137(76) 5.3.1.2): distance travelled by the time the
    heading has changed `heading_change` (10 deg with 10 deg rudder) from the original."""

    heading_change: float  # [rad]
    time: float  # [s] from the rudder order
    distance: float  # [m] along the path of the reference point (the IMO "travelled")
    advance: float  # [m] along the original course

    def to_dict(self, units=DisplayUnits()) -> dict:
        return _named([
            ("heading_change", self.heading_change, "rad"), ("time", self.time, "s"),
            ("distance", self.distance, "m"), ("advance", self.advance, "m"),
        ], units)


@_docstring
def initial_turning_indices(traj=None, *, heading_change=np.deg2rad(10.0), execute_time=None,
                            **arrays) -> InitialTurningIndices:
    """Time and distance to a heading change of `heading_change` [rad] after the rudder order.

    {arrays}

    - `execute_time`: time of the rudder order [s] (default as in `turning_indices`).
    """
    s = _series(traj, arrays)
    t_e = _rudder_execute(s, execute_time)
    along, _, psi_e = _course_frame(s, t_e)
    change = s.psi - psi_e
    side = np.sign(change[-1]) or 1.0
    tc = _crossing(s.t, side * change, float(heading_change), t_e)
    if tc is None:
        raise ValueError(
            f"the heading changed only {np.max(np.abs(change[s.t >= t_e])) * _DEG:.2f} deg, "
            f"less than {float(heading_change) * _DEG:g} deg: simulate longer."
        )
    path = _path_length(s.t, s.x, s.y)
    return InitialTurningIndices(
        heading_change=float(heading_change), time=tc - t_e,
        distance=float(np.interp(tc, s.t, path) - np.interp(t_e, s.t, path)),
        advance=float(np.interp(tc, s.t, along)),
    )
