"""IMO/ITTC manoeuvre indices and criteria from one simulated or measured trajectory.

Indices are computed at the edge, after `simulate`, in NumPy: every function takes a
single `Trajectory` (padding beyond `valid` is dropped) or plain sample arrays given
by keyword (`t, x, y, psi, u, v, r, delta, n`). Events between samples (heading
passing 90 deg, the ship stopping, ...) are located by linear interpolation, never by
rounding to whole degrees or samples. Results are small frozen dataclasses in SI units
(m, s, rad, rad/s); `to_dict()` gives display units (m, s, deg, deg/s, percent) with the
unit in each name, `to_dict(units="si")` the SI values.

Definitions follow IMO MSC.137(76) sec. 4.2 and 5.3, MSC/Circ.1053 and ITTC 7.5-04-02-01;
positions are those of the vessel's reference point (midship for every catalogue vessel),
rotated into the original-course frame at the rudder (or engine) order: `x` along the
original heading, `y` to starboard.
"""

import dataclasses
from collections.abc import Sequence

import numpy as np


_DEG = 180.0 / np.pi
_TOL = 1e-9  # deadband on commands [rad, rev/s] when detecting orders


# --------------------------------------------------------------------------- series


@dataclasses.dataclass(frozen=True, eq=False)
class _Series:
    t: np.ndarray
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    psi: np.ndarray | None = None
    u: np.ndarray | None = None
    v: np.ndarray | None = None
    r: np.ndarray | None = None
    delta: np.ndarray | None = None  # actual rudder angle [rad]
    delta_command: np.ndarray | None = None  # ordered rudder angle [rad]
    n: np.ndarray | None = None  # actual propeller rate [rev/s]
    n_command: np.ndarray | None = None  # ordered propeller rate [rev/s]

    def need(self, *names, what):
        missing = [k for k in names if getattr(self, k) is None]
        if missing:
            raise ValueError(
                f"{what} needs the sample arrays {', '.join(missing)}: pass a Trajectory "
                "or give them by keyword."
            )
        return tuple(getattr(self, k) for k in names)

    @property
    def rudder_order(self):
        return self.delta if self.delta_command is None else self.delta_command

    @property
    def propeller_order(self):
        return self.n if self.n_command is None else self.n_command

    def speed(self):
        """Speed through water if u, v are known, else track speed from the positions."""
        if self.u is not None and self.v is not None:
            return np.hypot(self.u, self.v)
        x, y = self.need("x", "y", what="the speed")
        return np.hypot(np.gradient(x, self.t), np.gradient(y, self.t))


_NAMES = ("t", "x", "y", "psi", "u", "v", "r", "delta", "n")


def _series(traj, arrays) -> _Series:
    """Collect the samples of one trajectory as 1-D float arrays."""
    unknown = sorted(set(arrays) - set(_NAMES))
    if unknown:
        raise ValueError(
            f"unknown sample arrays {unknown}; the names are {', '.join(_NAMES)}."
        )
    given = {k: v for k, v in arrays.items() if v is not None}
    if traj is not None:
        if given:
            raise ValueError(
                f"give either a Trajectory or sample arrays, not both (got {sorted(given)})."
            )
        s, c = traj.state, traj.command
        fields = dict(
            t=traj.t, x=s.x, y=s.y, psi=s.psi, u=s.u, v=s.v, r=s.r, delta=s.delta,
            delta_command=c.delta, n=s.n, n_command=c.n,
        )
        if not bool(np.all(np.asarray(traj.success))):
            raise ValueError("the trajectory failed (`success` is False): no indices from it.")
        valid = np.asarray(traj.valid, dtype=bool)
    else:
        if "t" not in given:
            raise ValueError("give a Trajectory or at least the sample times `t` by keyword.")
        fields, valid = given, None
    out = {}
    for name, value in fields.items():
        a = np.asarray(value, dtype=float)
        if a.ndim != 1:
            raise ValueError(
                f"`{name}` has shape {a.shape}: indices take one trajectory with 1-D samples; "
                "index a batch first, e.g. jax.tree.map(lambda a: a[i], traj)."
            )
        out[name] = a
    size = out["t"].shape[0]
    for name, a in out.items():
        if a.shape[0] != size:
            raise ValueError(f"`{name}` has {a.shape[0]} samples, `t` has {size}.")
    if valid is not None:
        if valid.shape != (size,):
            raise ValueError("`valid` must have one flag per sample.")
        out = {k: a[valid] for k, a in out.items()}
        size = out["t"].shape[0]
    if size < 2:
        raise ValueError("need at least two samples.")
    if np.any(np.diff(out["t"]) <= 0):
        raise ValueError("the sample times `t` must be strictly increasing.")
    for name, a in out.items():
        if not np.all(np.isfinite(a)):
            raise ValueError(f"`{name}` has non-finite samples.")
    return _Series(**out)


_ARRAY_DOC = """
    Give either `traj` (a single `Trajectory`; batched ones must be indexed first) or
    the samples by keyword (every index function takes the same names and ignores those
    it does not need): `t` [s], positions `x` (north), `y` (east) [m], heading `psi`
    [rad, not wrapped], body velocities `u, v` [m/s], yaw rate `r` [rad/s], rudder
    `delta` [rad] (the order, if known) and propeller rate `n` [rev/s] (the order)."""


def _docstring(f):
    f.__doc__ = f.__doc__.replace("{arrays}", _ARRAY_DOC.strip())
    return f


# --------------------------------------------------------------------------- helpers


def _crossing(t, f, level, after, *, upward=True):
    """First time >= `after` at which `f` reaches `level` (from below if `upward`), or None."""
    g = f - level if upward else level - f
    g0 = np.interp(after, t, g)
    if g0 >= 0:
        return float(after)
    later = np.nonzero(t > after)[0]
    if later.size == 0:
        return None
    tt = np.concatenate([[after], t[later]])
    gg = np.concatenate([[g0], g[later]])
    hit = np.nonzero(gg >= 0)[0]
    if hit.size == 0:
        return None
    j = hit[0]
    return float(tt[j - 1] + (tt[j] - tt[j - 1]) * (-gg[j - 1]) / (gg[j] - gg[j - 1]))


def _peak(t, f, start, stop):
    """Maximum of `f` over `[start, stop]`: `(time, value, interior)`.

    The sample maximum is refined with the parabola through it and its neighbours when
    it is an interior local maximum (exact for a quadratic peak).
    """
    inside = np.nonzero((t >= start) & (t <= stop))[0]
    if inside.size == 0:
        return None
    i = inside[np.argmax(f[inside])]
    interior = 0 < i < t.size - 1 and f[i - 1] <= f[i] >= f[i + 1] and i != inside[-1]
    if not interior:
        return float(t[i]), float(f[i]), False
    a, b, c = np.polyfit(t[i - 1:i + 2] - t[i], f[i - 1:i + 2], 2)
    if a >= 0:
        return float(t[i]), float(f[i]), True
    tau = float(np.clip(-b / (2 * a), t[i - 1] - t[i], t[i + 1] - t[i]))
    return float(t[i] + tau), float(max(c + b * tau + a * tau**2, f[i])), True


def _window_mean(t, f, a, b):
    """Time average of the piecewise-linear `f` over `[a, b]`."""
    inner = (t > a) & (t < b)
    tt = np.concatenate([[a], t[inner], [b]])
    ff = np.concatenate([[np.interp(a, t, f)], f[inner], [np.interp(b, t, f)]])
    return float(np.sum(0.5 * (ff[1:] + ff[:-1]) * np.diff(tt)) / (b - a))


def _path_length(t, x, y):
    """Cumulative length of the piecewise-linear track at each sample [m]."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])


def _order_time(t, order, baseline, what):
    """Time of the first sample at which `order` differs from `baseline`."""
    moved = np.nonzero(np.abs(order - baseline) > _TOL)[0]
    if moved.size == 0:
        raise ValueError(f"no {what} order found in the command history; give `execute_time`.")
    return float(t[moved[0]])


def _rudder_execute(s: _Series, execute_time):
    """Time of the (first) rudder order: given, or the first sample at which the order
    leaves the initial actual rudder angle (0 for plain arrays)."""
    if execute_time is not None:
        return float(execute_time)
    s.need("delta", what="detecting the rudder order")
    baseline = s.delta[0] if s.delta_command is not None else 0.0
    return _order_time(s.t, s.rudder_order, baseline, "rudder")


def _course_frame(s: _Series, t_e):
    """Positions relative to the point at `t_e`, rotated to (along, starboard of) its heading."""
    x, y, psi = s.need("x", "y", "psi", what="positions in the original-course frame")
    psi_e = np.interp(t_e, s.t, psi)
    dx, dy = x - np.interp(t_e, s.t, x), y - np.interp(t_e, s.t, y)
    c, sn = np.cos(psi_e), np.sin(psi_e)
    return c * dx + sn * dy, -sn * dx + c * dy, psi_e


def _check_units(units):
    if units not in ("display", "si"):
        raise ValueError(f"`units` must be 'display' or 'si', got {units!r}.")


def _convert(value, unit, units):
    """SI `value` of a quantity in `unit` ('m', 's', 'rad', 'rad_s', '1') to display."""
    if units == "si":
        return value, {"rad_s": "rad_s", "1": ""}.get(unit, unit)
    factor, name = {
        "m": (1.0, "m"), "s": (1.0, "s"), "rad": (_DEG, "deg"), "rad_s": (_DEG, "deg_s"),
        "1": (100.0, "percent"),
    }[unit]
    return value * factor, name


def _named(items, units):
    _check_units(units)
    out = {}
    for base, value, unit in items:
        value, suffix = _convert(value, unit, units)
        out[f"{base}_{suffix}" if suffix else base] = (
            float(value) if np.ndim(value) == 0 else np.asarray(value).tolist()
        )
    return out


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

    def to_dict(self, units="display") -> dict:
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


@_docstring
def turning_indices(traj=None, *, execute_time=None, steady="auto", **arrays) -> TurningIndices:
    """Advance, transfer, tactical and steady diameters, speed loss and times of a turn.

    {arrays}

    - `execute_time`: time of the rudder order [s]; by default the first sample at which
      the rudder order leaves the initial (actual) rudder angle.
    - `steady`: `"rate"`: steady diameter $D = 2U/|r|$ and speed from the last sample
      (needs `u, v, r`); `"circle"`: least-squares circle through the track over the
      last 360 deg of heading change and the mean track speed over it; `"auto"`: `"rate"`
      when `u, v, r` are known.

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
    if steady == "auto":
        steady = "rate" if all(a is not None for a in (s.u, s.v, s.r)) else "circle"
    if steady == "rate":
        s.need("u", "v", "r", what='steady="rate"')
        u_end, r_end = float(speed[-1]), float(s.r[-1])
        if r_end * side <= 0:
            raise ValueError("the yaw rate at the last sample is not turning the ship.")
        diameter = 2 * u_end / abs(r_end)
    elif steady == "circle":
        last = h >= h[-1] - 2 * np.pi
        if h[-1] - 2 * np.pi < 0 or np.count_nonzero(last) < 4:
            raise ValueError(
                f'steady="circle" needs a full 360 deg turn after the order, got {reached:.1f} deg.'
            )
        _, _, radius = _fit_circle(s.x[last], s.y[last])
        diameter = 2 * radius
        i0 = np.nonzero(last)[0][0]
        u_end = float((_path_length(s.t, s.x, s.y)[-1] - _path_length(s.t, s.x, s.y)[i0])
                      / (s.t[-1] - s.t[i0]))
    else:
        raise ValueError(f"`steady` must be 'auto', 'rate' or 'circle', got {steady!r}.")
    return TurningIndices(
        advance=float(np.interp(t90, s.t, along)),
        transfer=float(side * np.interp(t90, s.t, athwart)),
        tactical_diameter=float(side * np.interp(t180, s.t, athwart)),
        steady_turning_diameter=float(diameter),
        speed_loss=1.0 - u_end / u0,
        time_to_90=t90 - t_e, time_to_180=t180 - t_e, execute_time=t_e, side=side,
        steady_method=steady,
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

    def to_dict(self, units="display") -> dict:
        items = [(f"overshoot_{k + 1}", o, "rad") for k, o in enumerate(self.overshoots)]
        items += [
            ("initial_turning_time", self.initial_turning_time, "s"),
            ("time_to_check_yaw", self.time_to_check_yaw, "s"), ("period", self.period, "s"),
        ]
        return _named(items, units)


@_docstring
def zigzag_indices(traj=None, heading_switch=None, *, execute_times=None, initial_heading=None,
                   **arrays) -> ZigZagIndices:
    """Overshoot angles, initial turning time, time to check yaw and period of a zig-zag.

    {arrays}

    - `heading_switch`: the heading change psi_s [rad] > 0 at which the rudder is reversed.
    - `execute_times`: the rudder executes [s]; by default the first departure of the
      rudder order from the initial rudder angle and then every reversal of its sign.
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
    if execute_times is None:
        t1 = _rudder_execute(s, None)
        order, i = s.rudder_order, int(np.searchsorted(s.t, t1))
        times, current = [t1], int(np.sign(order[i]))
        for j in range(i + 1, s.t.size):
            if abs(order[j]) > _TOL and np.sign(order[j]) == -current:
                times.append(float(s.t[j]))
                current = -current
    else:
        times = [float(e) for e in np.atleast_1d(execute_times)]
        if not times or np.any(np.diff(times) <= 0):
            raise ValueError("`execute_times` must be a non-empty increasing sequence.")
    i = int(np.searchsorted(s.t, times[0]))
    if s.delta is not None and i < s.t.size:
        # side of the first order relative to the rudder before it (a neutral-helm offset,
        # as in the MARIN runs, must not decide it): where it has moved half its way
        baseline = s.delta[0] if s.delta_command is not None else s.rudder_order[0]
        moved = s.rudder_order[i:] - baseline
        k = i + int(np.argmax(np.abs(moved) >= 0.5 * np.max(np.abs(moved))))
        side, rudder_angle = int(np.sign(s.rudder_order[k])), abs(float(s.rudder_order[k]))
    else:  # no rudder history: the side the heading first passes the switch angle
        change = s.psi - np.interp(times[0], s.t, s.psi)
        up = _crossing(s.t, change, psi_s, times[0])
        down = _crossing(s.t, -change, psi_s, times[0])
        side = 0 if up is None and down is None else (
            1 if down is None or (up is not None and up < down) else -1)
        rudder_angle = float("nan")
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


# --------------------------------------------------------------------------- spirals


@dataclasses.dataclass(frozen=True, eq=False)
class SpiralCurve:
    """Steady yaw rate against rudder angle, one point per level, in the order run."""

    delta: np.ndarray  # rudder angle [rad]
    r: np.ndarray  # yaw rate [rad/s]

    def to_dict(self, units="display") -> dict:
        return _named([("delta", self.delta, "rad"), ("r", self.r, "rad_s")], units)

    @property
    def loop_width(self) -> float:
        return loop_width(self)


def _levels(s: _Series, hold, start):
    hold = float(hold)
    if not hold > 0:
        raise ValueError(f"`hold` must be positive, got {hold}.")
    start = float(s.t[0] if start is None else start)
    count = int(np.floor((s.t[-1] - start) / hold + 1e-9))
    if count < 1:
        raise ValueError(
            f"the trajectory ({s.t[-1] - start:g} s after `start`) is shorter than one hold."
        )
    return hold, start, count


@_docstring
def spiral_curve(traj=None, *, hold, start=None, average=0.0, **arrays) -> SpiralCurve:
    """Steady yaw rate at the end of each rudder level of a direct spiral (`jaxship.spiral()`).

    {arrays}

    - `hold`: time each rudder level is held [s]; levels start at `start` (default:
      the first sample).
    - `average`: average the yaw rate over the last `average` seconds of each hold
      (0: the value at the end of the hold).

    The rudder of each level is the order in the middle of its hold.
    """
    s = _series(traj, arrays)
    s.need("r", "delta", what="spiral_curve")
    hold, start, count = _levels(s, hold, start)
    if not 0 <= average < hold:
        raise ValueError(f"`average` must be in [0, hold), got {average}.")
    ends = start + hold * np.arange(1, count + 1)
    ends = np.minimum(ends, s.t[-1])
    levels = np.array([s.rudder_order[np.searchsorted(s.t, e - hold / 2)] for e in ends])
    if average == 0:
        rates = np.interp(ends, s.t, s.r)
    else:
        rates = np.array([_window_mean(s.t, s.r, e - average, e) for e in ends])
    return SpiralCurve(delta=levels, r=rates)


@_docstring
def reverse_spiral_curve(traj=None, *, rates, hold, start=None, settle=0.5,
                         **arrays) -> SpiralCurve:
    """Mean rudder angle and yaw rate per level of a reverse spiral (`jaxship.ReverseSpiral`).

    {arrays}

    - `rates`, `hold`: the yaw-rate levels [rad/s] and the time each is held [s], e.g.
      `manoeuvre.rates, manoeuvre.hold`; levels start at `start` (default: first sample).
    - `settle`: fraction of each hold left out before averaging (the controller settling).

    Means are time averages of the actual rudder angle (the order if that is all there is)
    and of the yaw rate over the rest of each hold.
    """
    s = _series(traj, arrays)
    s.need("r", "delta", what="reverse_spiral_curve")
    rates = np.atleast_1d(np.asarray(rates, dtype=float))
    hold, start, count = _levels(s, hold, start)
    if not 0 <= settle < 1:
        raise ValueError(f"`settle` must be in [0, 1), got {settle}.")
    count = min(count, rates.size)
    mean_delta, mean_r = [], []
    for k in range(count):
        a, b = start + (k + settle) * hold, min(start + (k + 1) * hold, s.t[-1])
        mean_delta.append(_window_mean(s.t, s.delta, a, b))
        mean_r.append(_window_mean(s.t, s.r, a, b))
    return SpiralCurve(delta=np.array(mean_delta), r=np.array(mean_r))


def loop_width(curve: SpiralCurve) -> float:
    """Rudder range of the spiral hysteresis loop [rad]; 0 for a course-stable ship.

    With the points sorted by yaw rate, the width is the largest drop of the rudder angle
    as the yaw rate increases, $\\max_{r_i < r_j} (\\delta_i - \\delta_j)^+$: the unstable
    (negative-slope) part of a reverse-spiral curve, or the rudder range between the two
    branches of a direct spiral. From a direct spiral it is resolved to the rudder step
    (a lower bound of the true width); lag from holds that are too short adds to it.
    """
    delta = np.asarray(curve.delta, dtype=float)
    order = np.argsort(np.asarray(curve.r, dtype=float), kind="stable")
    d = delta[order]
    running_max = np.maximum.accumulate(d)
    return float(max(0.0, np.max(running_max - d)))


# --------------------------------------------------------------------------- pull-out


@dataclasses.dataclass(frozen=True)
class PullOutIndices:
    """Pull-out (ITTC 7.5-04-02-01 2.2.6): yaw rates at the release of the rudder to
    midships and residual rates at the end, per side [rad/s]; NaN for a side not run.

    A course-stable ship returns to zero residual rate from both sides; the residual
    rates of an unstable ship are about the height of its spiral loop.
    """

    release_rate_starboard: float
    residual_rate_starboard: float
    release_rate_port: float
    residual_rate_port: float

    def to_dict(self, units="display") -> dict:
        return _named([
            ("release_rate_starboard", self.release_rate_starboard, "rad_s"),
            ("residual_rate_starboard", self.residual_rate_starboard, "rad_s"),
            ("release_rate_port", self.release_rate_port, "rad_s"),
            ("residual_rate_port", self.residual_rate_port, "rad_s"),
        ], units)


def _pull_out_side(traj, release_time, window):
    s = _series(traj, {})
    order = s.rudder_order
    if release_time is None:
        turned = np.nonzero(np.abs(order) > _TOL)[0]
        if turned.size == 0 or turned[-1] + 1 >= s.t.size:
            raise ValueError("no release of the rudder to midships found; give `release_time`.")
        release_time = float(s.t[turned[-1] + 1])
    before = order[s.t < release_time]
    if before.size == 0:
        raise ValueError("no rudder order before the release.")
    side = int(np.sign(before[-1]))
    if side == 0:
        raise ValueError("the rudder was midships before the release.")
    if window > 0:
        residual = _window_mean(s.t, s.r, max(s.t[-1] - window, release_time), s.t[-1])
    else:
        residual = float(s.r[-1])
    return side, float(np.interp(release_time, s.t, s.r)), residual


def pull_out_indices(first, second=None, *, release_time=None, window=0.0) -> PullOutIndices:
    """Yaw rate at release and residual yaw rate from one or two pull-out trajectories.

    `first`, `second`: `Trajectory`s of `jaxship.pull_out(+angle)` and `pull_out(-angle)`
    in either order (each is assigned to its side by the sign of its rudder before the
    release). `release_time` [s]: default, the first sample after the last nonzero rudder
    order. `window` [s]: average the residual rate over the last `window` seconds
    (0: the last sample).
    """
    values = {}
    for traj in (first, second):
        if traj is None:
            continue
        side, at_release, residual = _pull_out_side(traj, release_time, float(window))
        if side in values:
            raise ValueError("both pull-out trajectories turn to the same side.")
        values[side] = (at_release, residual)
    nan = (float("nan"), float("nan"))
    stbd, port = values.get(1, nan), values.get(-1, nan)
    return PullOutIndices(stbd[0], stbd[1], port[0], port[1])


# --------------------------------------------------------------------------- stopping


@dataclasses.dataclass(frozen=True)
class StoppingIndices:
    """Full-astern stopping (IMO MSC.137(76) 4.2; ITTC 2.2.7), from the engine order to
    the ship stopped in the water (surge velocity through water u = 0)."""

    head_reach: float  # [m] along the original course
    track_reach: float  # [m] along the path of the reference point
    lateral_deviation: float  # [m] perpendicular to the original course at the stop, + starboard
    time_to_stop: float  # [s]
    execute_time: float  # [s] time of the astern order

    def to_dict(self, units="display") -> dict:
        return _named([
            ("head_reach", self.head_reach, "m"), ("track_reach", self.track_reach, "m"),
            ("lateral_deviation", self.lateral_deviation, "m"),
            ("time_to_stop", self.time_to_stop, "s"),
        ], units)


@_docstring
def stopping_indices(traj=None, *, execute_time=None, **arrays) -> StoppingIndices:
    """Head reach, track reach, lateral deviation and time to stop of a `jaxship.Stop` run.

    {arrays}

    - `execute_time`: time of the astern order [s]; by default the first sample at which
      the propeller order differs from the initial propeller rate (the actual rate for a
      `Trajectory`, `n[0]` for arrays).

    Raises `ValueError` if the surge velocity never reaches zero after the order.
    """
    s = _series(traj, arrays)
    (u,) = s.need("u", what="stopping_indices")
    if execute_time is None:
        s.need("n", what="detecting the engine order")
        execute_time = _order_time(s.t, s.propeller_order, s.n[0], "engine")
    t_e = float(execute_time)
    t_stop = _crossing(s.t, u, 0.0, t_e, upward=False)
    if t_stop is None:
        raise ValueError(
            f"the ship did not stop: u = {u[-1]:.3g} m/s at the last sample; simulate longer."
        )
    along, athwart, _ = _course_frame(s, t_e)
    path = _path_length(s.t, s.x, s.y)
    return StoppingIndices(
        head_reach=float(np.interp(t_stop, s.t, along)),
        track_reach=float(np.interp(t_stop, s.t, path) - np.interp(t_e, s.t, path)),
        lateral_deviation=float(np.interp(t_stop, s.t, athwart)),
        time_to_stop=t_stop - t_e, execute_time=t_e,
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

    def to_dict(self, units="display") -> dict:
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
    """One IMO criterion: `value` and `limit` in `unit` (`"L"`: ship lengths, `"deg"`)."""

    criterion: str
    value: float
    limit: float
    unit: str
    passed: bool

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


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
        add("turning: advance, 35 deg turn", adv / length, 4.5, "L")
        add("turning: tactical diameter, 35 deg turn", tac / length, 5.0, "L")
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
        add("yaw checking: 1st overshoot, 10/10 zig-zag", first * _DEG, os1, "deg")
        if all(len(z.overshoots) >= 2 for z in (
                zigzag10 if isinstance(zigzag10, Sequence) else [zigzag10])):
            second = _worst(zigzag10, "zigzag10", ZigZagIndices, lambda i: i.overshoots[1])
            add("course keeping: 2nd overshoot, 10/10 zig-zag", second * _DEG, os2, "deg")
        else:
            raise ValueError("`zigzag10` needs a second overshoot: simulate longer.")
    if zigzag20 is not None:
        _check_switch(zigzag20, "zigzag20", 20.0)
        first = _worst(zigzag20, "zigzag20", ZigZagIndices, lambda i: i.overshoots[0])
        add("yaw checking: 1st overshoot, 20/20 zig-zag", first * _DEG, os20, "deg")
    if stopping is not None:
        reach = _worst(stopping, "stopping", StoppingIndices, lambda i: i.track_reach)
        add("stopping: track reach, full astern", reach / length, float(stopping_limit), "L")
    return rows


def format_table(rows: Sequence[CriterionRow], *, digits=2) -> str:
    """Markdown table of `imo_criteria` rows: criterion, value, limit, pass/fail."""
    lines = ["| criterion | value | limit | result |", "| --- | ---: | ---: | :---: |"]
    for row in rows:
        lines.append(
            f"| {row.criterion} | {row.value:.{digits}f} {row.unit} | "
            f"{row.limit:.{digits}f} {row.unit} | {'pass' if row.passed else 'FAIL'} |"
        )
    return "\n".join(lines)
