"""Spiral curves and loop width, pull-out and stopping indices."""

import dataclasses

import numpy as np

from ..._simulation._readers import DisplayUnits
from ._series import (
    _TOL,
    _course_frame,
    _crossing,
    _docstring,
    _named,
    _order_time,
    _path_length,
    _Series,
    _series,
    _window_mean,
)


# --------------------------------------------------------------------------- spirals


@dataclasses.dataclass(frozen=True, eq=False)
class SpiralCurve:
    """Steady yaw rate against rudder angle, one point per level, in the order run.

    `kind`: `"direct"` (from `spiral_curve`: rudder levels, each run on the way to port
    and back), `"reverse"` (from `reverse_spiral_curve`: yaw-rate levels) or `None`:
    direct when most of its rudder angles are run more than once.
    """

    delta: np.ndarray  # rudder angle [rad]
    r: np.ndarray  # yaw rate [rad/s]
    kind: str | None = None

    @property
    def direct(self) -> bool:
        """Whether this is a direct spiral's curve (see `kind`)."""
        if self.kind is not None:
            return self.kind == "direct"
        return _is_direct(self.delta)

    def to_dict(self, units=DisplayUnits()) -> dict:
        return _named([("delta", self.delta, "rad"), ("r", self.r, "rad_s")], units)

    @property
    def loop_width(self) -> float:
        return loop_width(self)

    @property
    def loop(self) -> "SpiralLoop":
        """The hysteresis loop: width with its bounds and height (`spiral_loop`)."""
        return spiral_loop(self)

    def branches(self) -> list[np.ndarray]:
        """Indices of the points of each sweep of the rudder, in the order run: a
        direct spiral from starboard to port and back gives two (the branches of
        MSC/Circ.1053 app. 4 fig. A4-3), each sharing the turning level with the
        next; a reverse spiral, whose rudder is not monotone, one."""
        delta = np.asarray(self.delta, dtype=float)
        if not self.direct:
            return [np.arange(delta.size)]
        step = np.sign(np.diff(delta))
        step = np.where(step == 0, 1.0, step)
        cuts = np.nonzero(step[1:] != step[:-1])[0] + 1  # index of each turning level
        edges = [0, *cuts.tolist(), delta.size - 1]
        return [np.arange(a, b + 1) for a, b in zip(edges[:-1], edges[1:])]


@dataclasses.dataclass(frozen=True)
class SpiralLoop:
    """The hysteresis loop of a spiral curve (MSC/Circ.1053 app. 4 2.1.5; Bech 1968 for
    the reverse spiral): the rudder range over which a course-unstable ship has two
    steady yaw rates, one on each branch. 0 width: a course-stable ship.

    From a direct spiral (each rudder level run on the way to port and on the way
    back) the levels whose two steady rates differ by more than `tolerance` of the
    largest rate are inside the loop; the loop's edges lie between the outermost of
    them and the next levels run, so `width_low` (the span of the inside levels) and
    `width_high` (the span to the next levels) bound it and `width` is their mean
    (edges half-way). From a reverse spiral (the S-shaped delta(r) curve) the width is
    the largest drop of the rudder angle as the yaw rate increases, and
    `width_low = width = width_high`.
    """

    width: float  # [rad] estimate
    width_low: float  # [rad] lower bound from the levels run
    width_high: float  # [rad] upper bound (inf: the loop reaches past the levels run)
    height: float  # [rad/s] largest difference of the steady yaw rates at one rudder angle
    inside: tuple[float, ...] = ()  # [rad] direct spiral: the levels with two branches
    edges: tuple[float, float] = (float("nan"), float("nan"))  # [rad] estimated rudder range

    def to_dict(self, units=DisplayUnits()) -> dict:
        return _named([
            ("loop_width", self.width, "rad"), ("loop_width_min", self.width_low, "rad"),
            ("loop_width_max", self.width_high, "rad"),
            ("loop_height", self.height, "rad_s"),
        ], units)


def _is_direct(delta) -> bool:
    """A direct spiral's levels: most rudder angles run more than once, exactly."""
    _, counts = np.unique(np.round(np.asarray(delta, dtype=float), 9), return_counts=True)
    return bool(np.count_nonzero(counts > 1) >= 0.5 * counts.size)


def _levels(s: _Series, hold, start):
    hold = float(hold)
    if not hold > 0:
        raise ValueError(f"`hold` must be positive, got {hold}.")
    start = float(s.t[0] if start is None else start)
    # the last level counts when its hold ends within half a sample of the last sample
    # (a hold that is not a whole number of samples)
    half = 0.5 * float(np.median(np.diff(s.t)))
    count = int(np.floor((s.t[-1] + half - start) / hold + 1e-9))
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
    return SpiralCurve(delta=levels, r=rates, kind="direct")


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
    return SpiralCurve(delta=np.array(mean_delta), r=np.array(mean_r), kind="reverse")


def loop_width(curve: SpiralCurve) -> float:
    """Rudder range of the spiral hysteresis loop [rad]; 0 for a course-stable ship.

    The estimate of `spiral_loop` (see `SpiralLoop`): from a direct spiral, the span of
    the levels at which the two branches differ plus half the step to the next level on
    each side; from a reverse spiral, the largest drop of the rudder angle as the yaw
    rate increases.
    """
    return spiral_loop(curve).width


def _largest_drop(delta, r):
    """$\\max_{r_i < r_j} (\\delta_i - \\delta_j)^+$ and the pair (i, j) in sorted order."""
    order = np.argsort(r, kind="stable")
    d = delta[order]
    running_max = np.maximum.accumulate(d)
    drop = running_max - d
    j = int(np.argmax(drop))
    i = int(np.argmax(d[: j + 1]))
    return float(max(0.0, drop[j])), order, i, j


def _crossings(r, delta, level):
    """Yaw rates where the piecewise-linear delta(r) crosses `level`."""
    f = delta - level
    out = []
    for k in range(r.size - 1):
        if f[k] == 0:
            out.append(r[k])
        elif f[k] * f[k + 1] < 0:
            out.append(r[k] + (r[k + 1] - r[k]) * f[k] / (f[k] - f[k + 1]))
    if f[-1] == 0:
        out.append(r[-1])
    return out


def spiral_loop(curve: SpiralCurve, *, tolerance: float = 0.1) -> SpiralLoop:
    """Width (with bounds) and height of the hysteresis loop of a spiral curve.

    - `curve`: a `SpiralCurve` from `spiral_curve` (direct) or `reverse_spiral_curve`.
    - `tolerance`: two steady yaw rates at one rudder level of a direct spiral belong to
      different branches when they differ by more than `tolerance` times the largest
      |r| of the curve (what lag from holds too short leaves is well below 10 %).

    See `SpiralLoop` for the definitions.
    """
    delta = np.asarray(curve.delta, dtype=float)
    r = np.asarray(curve.r, dtype=float)
    drop, order, i, j = _largest_drop(delta, r)
    if drop > 0:  # the S-shaped part of the curve (with r sorted)
        rs, ds = r[order], delta[order]
        cross = _crossings(rs, ds, 0.5 * (ds[i] + ds[j]))
        s_loop = SpiralLoop(drop, drop, drop,
                            float(max(cross) - min(cross)) if len(cross) >= 2 else 0.0,
                            edges=(float(ds[j]), float(ds[i])))
    else:
        s_loop = SpiralLoop(0.0, 0.0, 0.0, 0.0)
    if not curve.direct:  # reverse spiral: the S-curve itself
        return s_loop
    rounded = np.round(delta, 9)
    keys = np.unique(rounded)
    levels = np.array([np.mean(delta[rounded == k]) for k in keys])  # the angles run
    scale = float(np.max(np.abs(r))) or 1.0
    gaps = {}
    for key, level in zip(keys, levels):
        rates = r[rounded == key]
        if rates.size >= 2:
            gaps[float(level)] = float(np.max(rates) - np.min(rates))
    inside = sorted(k for k, g in gaps.items() if g > tolerance * scale)
    if not inside:  # the branches agree: the largest drop, if any
        return s_loop
    low_level, high_level = inside[0], inside[-1]
    below, above = levels[levels < low_level], levels[levels > high_level]
    width_low = max(float(high_level - low_level), drop)
    if below.size and above.size:
        width_high = float(above[0] - below[-1])
        width = 0.5 * (width_low + width_high)
        edges = (0.5 * float(low_level + below[-1]), 0.5 * float(high_level + above[0]))
    else:
        width_high, width = float("inf"), width_low
        edges = (float(low_level), float(high_level))
    return SpiralLoop(width, width_low, width_high, max(gaps[k] for k in inside),
                      tuple(float(k) for k in inside), edges)


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

    def to_dict(self, units=DisplayUnits()) -> dict:
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

    def to_dict(self, units=DisplayUnits()) -> dict:
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
