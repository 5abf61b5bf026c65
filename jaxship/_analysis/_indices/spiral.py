"""Spiral curves and loop width, pull-out and stopping indices."""

import dataclasses

import numpy as np

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
