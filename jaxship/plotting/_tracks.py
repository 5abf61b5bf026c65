"""Trial figures: time histories, tracks with ship outlines and the indices marked,
spirals and the IMO criteria table."""

import textwrap
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .._analysis._indices import StoppingIndices, TurningIndices, ZigZagIndices
from ._common import (
    _REFERENCE_COLOR,
    _REFERENCE_STOPPING,
    _REFERENCE_TIME,
    _REFERENCE_TURNING,
    _REFERENCE_ZIGZAG,
    _distance,
    _legend_below,
    _legend_beside,
    _range,
    _range_text,
    _title,
    plt,
)


if TYPE_CHECKING:  # the annotations only: matplotlib is imported with the first figure
    from matplotlib.axes import Axes


def _run_samples(run):
    """Time and the state of one run as NumPy arrays, padding beyond `valid` dropped."""
    t = np.asarray(run.t, dtype=np.float64)
    valid = np.asarray(getattr(run, "valid", np.ones_like(t, dtype=bool)), dtype=bool)
    s = run.state
    out = {k: np.asarray(getattr(s, k), dtype=np.float64)[valid]
           for k in ("x", "y", "psi", "u", "v", "r", "delta")}
    command = getattr(run, "command", None)
    if command is not None and getattr(command, "delta", None) is not None:
        out["order"] = np.asarray(command.delta, dtype=np.float64)[valid]
    return t[valid], out


def _ship_polygon(x, y, psi, length, beam, scale):
    """Waterline outline of a ship of `length` and `beam` [m] at `x` (north), `y`
    (east) [m] and heading `psi` [rad], in (east, north) / `scale`."""
    xi = length * np.array([-0.5, -0.47, 0.28, 0.42, 0.5, 0.42, 0.28, -0.47, -0.5])
    eta = 0.5 * beam * np.array([-0.8, -1.0, -1.0, -0.6, 0.0, 0.6, 1.0, 1.0, 0.8])
    north = x + xi * np.cos(psi) - eta * np.sin(psi)
    east = y + xi * np.sin(psi) + eta * np.cos(psi)
    return np.column_stack([east, north]) / scale


def _draw_outlines(ax, t, s, *, count, length, beam, scale, color):
    """`count` ship outlines at equal intervals of distance along the track (at equal
    intervals of time if the ship does not move), up to the first full turn of the
    heading (later laps of a turning circle would draw over the first)."""
    turned = np.nonzero(np.abs(s["psi"] - s["psi"][0]) >= 2 * np.pi)[0]
    last = int(turned[0]) if turned.size else t.size - 1
    path = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(s["x"]), np.diff(s["y"])))])
    along = (path if path[last] > 0 else t - t[0])[: last + 1]
    targets = np.linspace(along[0], along[-1], count)
    picks = np.unique(np.searchsorted(along, targets).clip(0, last))
    from matplotlib.patches import Polygon  # with the figure, not on import

    for i in picks:
        ax.add_patch(Polygon(_ship_polygon(s["x"][i], s["y"][i], s["psi"][i], length, beam,
                                           scale), closed=True, facecolor=color, alpha=0.25,
                             edgecolor=color, lw=0.8, gid="ship-outline",
                             label="ship outline" if i == picks[0] else None))


class _CourseFrame:
    """The original course at an order: origin, along and starboard unit vectors, in
    (east, north) coordinates divided by `scale`."""

    def __init__(self, t, s, time, scale):
        self.origin = np.array([np.interp(time, t, s["y"]), np.interp(time, t, s["x"])])
        psi = float(np.interp(time, t, s["psi"]))
        self.along = np.array([np.sin(psi), np.cos(psi)])
        self.starboard = np.array([np.cos(psi), -np.sin(psi)])
        self.scale = scale

    def point(self, along, athwart=0.0):
        """The point `along` [m] ahead and `athwart` [m] to starboard of the origin."""
        return (self.origin + along * self.along + athwart * self.starboard) / self.scale

    def at(self, t, s, time):
        """(along, athwart) [m] of the track at `time`."""
        p = np.array([np.interp(time, t, s["y"]), np.interp(time, t, s["x"])]) - self.origin
        return float(p @ self.along), float(p @ self.starboard)


def _dimension(ax, a, b, text, *, gid, offset=(0.0, 0.0), ha="center", va="center"):
    """A double-headed dimension arrow from `a` to `b` with `text` at its middle."""
    ax.annotate("", xy=b, xytext=a, gid=f"{gid}-arrow",
                arrowprops=dict(arrowstyle="<->", color="k", lw=0.9, shrinkA=0, shrinkB=0))
    middle = 0.5 * (np.asarray(a) + np.asarray(b)) + np.asarray(offset)
    ax.text(*middle, text, fontsize="small", ha=ha, va=va, gid=gid,
            bbox=dict(boxstyle="round,pad=0.2", facecolor="white", alpha=0.85, lw=0.0))


def _reference_segment(ax, a, b, label):
    """A reference range drawn as a thick translucent segment from `a` to `b` (a
    diamond where the reference is one value)."""
    if np.allclose(a, b):
        ax.plot(*a, "D", color=_REFERENCE_COLOR, ms=7, label=label, zorder=5)
    else:
        ax.plot([a[0], b[0]], [a[1], b[1]], "-", color=_REFERENCE_COLOR, lw=7, alpha=0.55,
                solid_capstyle="butt", label=label, zorder=4)


def _turning_marks(ax, t, s, ind, *, length, scale, reference, reference_label):
    """Advance, transfer and tactical diameter (ITTC 7.5-04-02-01 2.2.1; IMO MSC.137(76)
    4.2) dimensioned on the track, from the rudder order at `ind.execute_time`."""
    frame = _CourseFrame(t, s, ind.execute_time, scale)
    side, unit = ind.side, (length or 1.0)
    t180 = ind.execute_time + ind.time_to_180
    along180, _ = frame.at(t, s, t180)
    reach = max(ind.advance, along180, 0.5 * unit) + 0.6 * unit
    course = np.array([frame.point(-1.5 * unit), frame.point(reach)])
    ax.plot(course[:, 0], course[:, 1], ls="--", color="0.45", lw=0.9,
            label="original course")
    execute, foot = frame.point(0.0), frame.point(ind.advance)
    at90 = frame.point(ind.advance, side * ind.transfer)
    at180 = frame.point(along180, side * ind.tactical_diameter)
    ax.plot(*execute, "k^", ms=6, label="rudder order")
    ax.plot([at90[0], at180[0]], [at90[1], at180[1]], "ko", ms=4,
            label="90 and 180 deg heading change")
    away = -side * 0.35 * unit * frame.starboard / scale  # text off the track
    _dimension(ax, execute, foot, f"advance\n{_distance(ind.advance, length)}", gid="advance",
               offset=away, ha="right" if side > 0 else "left")
    # room for the text beside the original course, on the side away from the turn
    ax.update_datalim([frame.point(0.5 * ind.advance, -side * 1.6 * unit)])
    _dimension(ax, foot, at90, f"transfer\n{_distance(ind.transfer, length)}", gid="transfer")
    _dimension(ax, frame.point(along180), at180,
               f"tactical diameter\n{_distance(ind.tactical_diameter, length)}",
               gid="tactical_diameter")
    for name in _REFERENCE_TURNING:
        if name not in reference:
            continue
        low, high = _range(reference[name])
        if name == "advance":
            a, b = frame.point(low), frame.point(high)
        elif name == "transfer":
            a, b = (frame.point(ind.advance, side * v) for v in (low, high))
        else:
            a, b = (frame.point(along180, side * v) for v in (low, high))
        text = _range_text(low, high, lambda v: _distance(v, length))
        _reference_segment(ax, a, b, f"{reference_label}: {name.replace('_', ' ')} {text}")


def _stopping_marks(ax, t, s, ind, *, length, scale, reference, reference_label):
    """Head reach and lateral deviation at the stop (IMO MSC.137(76) 4.2.4) dimensioned
    on the track, from the engine order at `ind.execute_time`."""
    frame = _CourseFrame(t, s, ind.execute_time, scale)
    unit = length or 1.0
    ax.plot(*frame.point(0.0), "k^", ms=6, label="engine order (full astern)")
    stop = frame.point(ind.head_reach, ind.lateral_deviation)
    ax.plot(*stop, "ks", ms=5, label="stopped (u = 0)")
    course = np.array([frame.point(-1.0 * unit), frame.point(ind.head_reach + 1.0 * unit)])
    ax.plot(course[:, 0], course[:, 1], ls="--", color="0.45", lw=0.9, label="original course")
    away = 0.6 * unit * frame.starboard / scale
    ax.update_datalim([frame.point(0.5 * ind.head_reach, 3.0 * unit)])
    _dimension(ax, frame.point(0.0), frame.point(ind.head_reach),
               f"head reach {_distance(ind.head_reach, length)}\n"
               f"track reach {_distance(ind.track_reach, length)}\n"
               f"time to stop {ind.time_to_stop:.0f} s", gid="head_reach", offset=away,
               ha="left")
    if abs(ind.lateral_deviation) > 0.02 * unit:
        _dimension(ax, frame.point(ind.head_reach), stop,
                   f"lateral deviation {_distance(ind.lateral_deviation, length)}",
                   gid="lateral_deviation")
    for name in _REFERENCE_STOPPING:
        if name in reference:
            low, high = _range(reference[name])
            if name == "head_reach":
                a, b = frame.point(low), frame.point(high)
            else:
                a, b = (frame.point(ind.head_reach, v) for v in (low, high))
            text = _range_text(low, high, lambda v: _distance(v, length))
            _reference_segment(ax, a, b, f"{reference_label}: {name.replace('_', ' ')} {text}")


_ORDINAL = {1: "1st", 2: "2nd", 3: "3rd"}


def _zigzag_marks(ax, t, s, ind, *, reference, reference_label):
    """The switch headings and each overshoot (IMO MSC.137(76) 4.2.7) annotated on the
    heading axes [deg]."""
    deg = np.rad2deg
    psi0 = float(np.interp(ind.execute_times[0], t, s["psi"]))
    for sign in (1, -1):
        ax.axhline(deg(psi0 + sign * ind.heading_switch), color="0.45", ls=":", lw=1.0,
                   label="switch heading" if sign > 0 else None)
    span = t[-1] - t[0]
    for k, (overshoot, when) in enumerate(zip(ind.overshoots, ind.overshoot_times)):
        sign = ind.side * (1 if k % 2 == 0 else -1)
        switch = deg(psi0 + sign * ind.heading_switch)
        peak = deg(psi0 + sign * (ind.heading_switch + overshoot))
        ax.annotate("", xy=(when, peak), xytext=(when, switch),
                    arrowprops=dict(arrowstyle="->", color="k", lw=0.9, shrinkA=0, shrinkB=0))
        ax.plot(when, peak, "k.", ms=6)
        name = _ORDINAL.get(k + 1, f"{k + 1}th")
        if k < 3:  # the IMO criteria use the first two; later ones only get the arrow
            ax.annotate(f"{name} overshoot\n{deg(overshoot):.1f} deg", xy=(when, peak),
                        xytext=(0, 6 * sign), textcoords="offset points", ha="center",
                        va="bottom" if sign > 0 else "top", fontsize="x-small",
                        gid=f"overshoot_{k + 1}",
                        bbox=dict(boxstyle="round,pad=0.15", facecolor="white", alpha=0.8,
                                  lw=0.0))
        key = f"overshoot_{k + 1}"
        if key in reference:
            low, high = (deg(psi0 + sign * (ind.heading_switch + v))
                         for v in _range(reference[key]))
            text = _range_text(*sorted(np.rad2deg(_range(reference[key]))),
                               lambda v: f"{v:.1f} deg")
            half = 0.03 * span
            if low == high:
                ax.hlines(low, when - half, when + half, color=_REFERENCE_COLOR, lw=2.5,
                          label=f"{reference_label}: {name} overshoot {text}")
            else:
                ax.fill_between([when - half, when + half], low, high, color=_REFERENCE_COLOR,
                                alpha=0.45, lw=0.0,
                                label=f"{reference_label}: {name} overshoot {text}")
    ax.margins(y=0.4)


def plot_trajectory(traj, *, length=None, title="", others=(), labels=None, beam=None,
                    outlines=8, indices=None, reference=None, reference_label="reference"):
    """Track, heading, rudder, yaw rate and speed of a `Trajectory` (and optional others).

    **Arguments:**

    - `traj`: a `Trajectory` (or anything with `t` and `state.u/v/r/x/y/psi/delta`).
    - `length`: ship length [m]; the track is then drawn in ship lengths (bottom and
      left axes) and metres (top and right axes), with `outlines` ship outlines (0:
      none) at equal intervals of time along the first track, `beam` [m] wide
      (default `length / 6`).
    - `others`: more trajectories (e.g. measurements) drawn over the first.
    - `labels`: legend labels, one per trajectory.
    - `indices`: indices of the first trajectory to mark: a `TurningIndices` (advance,
      transfer and tactical diameter dimensioned on the track), a `ZigZagIndices`
      (switch headings and overshoots annotated on the heading axes) or a
      `StoppingIndices` (head reach, track reach and lateral deviation on the track).
    - `reference`: values or `(low, high)` ranges of a reference (a thesis, a model
      test) drawn on the figure, SI units, labelled `reference_label`: `"advance"`,
      `"transfer"`, `"tactical_diameter"` [m] (with a `TurningIndices`),
      `"overshoot_1"`, `"overshoot_2"`, `"overshoot_3"` [rad] (with a
      `ZigZagIndices`), `"head_reach"`, `"lateral_deviation"` [m] (with a
      `StoppingIndices`), `"heading"`, `"rudder"` [rad], `"yaw_rate"` [rad/s],
      `"speed"` [m/s] (lines or bands on those axes).
    - `title`: the figure title.

    Heading (not wrapped) and rudder angle are on axes of their own, the rudder order
    of the first run dashed; the legend is below the figure. **Returns:** the
    matplotlib `Figure`.
    """
    runs = [traj, *others]
    labels = list(labels) if labels is not None else [f"run {i}" for i in range(len(runs))]
    reference = dict(reference or {})
    _check_reference(reference, indices)
    scale, unit = (float(length), "L") if length else (1.0, "m")
    fig = plt.figure(figsize=(12.5, 9), layout="constrained")
    axes = _trajectory_axes(fig)
    t, s, color = _draw_runs(axes, runs, labels, scale)
    axes.track.plot(s["y"][0] / scale, s["x"][0] / scale, "o", color=color, ms=5,
                    label="start")
    if length and outlines:
        _draw_outlines(axes.track, t, s, count=int(outlines), length=float(length),
                       beam=float(beam) if beam else float(length) / 6.0, scale=scale,
                       color=color)
    marks = dict(length=float(length) if length else None, scale=scale, reference=reference,
                 reference_label=reference_label)
    if isinstance(indices, TurningIndices):
        _turning_marks(axes.track, t, s, indices, **marks)
    elif isinstance(indices, StoppingIndices):
        _stopping_marks(axes.track, t, s, indices, **marks)
    elif isinstance(indices, ZigZagIndices):
        _zigzag_marks(axes.heading, t, s, indices, reference=reference,
                      reference_label=reference_label)
    elif indices is not None:
        raise ValueError(f"`indices` must be turning, zig-zag or stopping indices, got "
                         f"{type(indices).__name__}.")
    _reference_lines(axes, reference, reference_label)
    _label_axes(axes, length, unit)
    legend_axes = [*axes, *_propeller_rate(axes.speed, traj)]
    for ax, span in ((axes.heading, 2.0), (axes.rudder, 2.0), (axes.rate, 0.2),
                     (axes.speed, 0.1)):
        _min_span(ax, span)
    _legend_below(fig, legend_axes)
    _title(fig, title)
    return fig


class _TrajectoryAxes(NamedTuple):
    """`plot_trajectory`'s axes: the track on the left, four time histories on the right."""

    track: "Axes"
    heading: "Axes"
    rudder: "Axes"
    rate: "Axes"
    speed: "Axes"


def _check_reference(reference, indices) -> None:
    """Raise for a reference value of an unknown name, or one drawn with indices of a kind
    the run was not given."""
    known = (*_REFERENCE_TIME, *_REFERENCE_TURNING, *_REFERENCE_ZIGZAG, *_REFERENCE_STOPPING)
    unknown = sorted(set(reference) - set(known))
    if unknown:
        raise ValueError(f"unknown reference values {unknown}; use {', '.join(known)}.")
    needs = {TurningIndices: _REFERENCE_TURNING, ZigZagIndices: _REFERENCE_ZIGZAG,
             StoppingIndices: _REFERENCE_STOPPING}
    for kind, names in needs.items():
        if set(reference) & set(names) and not isinstance(indices, kind):
            raise ValueError(f"reference values {sorted(set(reference) & set(names))} are "
                             f"drawn with the run's indices: pass a {kind.__name__}.")


def _trajectory_axes(fig) -> _TrajectoryAxes:
    """The track (left, full height) and heading, rudder, yaw rate and speed sharing time."""
    grid = fig.add_gridspec(4, 2, width_ratios=[1.1, 1.3])
    track = fig.add_subplot(grid[:, 0])
    heading = fig.add_subplot(grid[0, 1])
    rudder, rate, speed = (fig.add_subplot(grid[i, 1], sharex=heading) for i in (1, 2, 3))
    return _TrajectoryAxes(track, heading, rudder, rate, speed)


def _draw_runs(axes: _TrajectoryAxes, runs, labels, scale):
    """Each run's track and time histories (the first run's rudder order dashed). Returns
    the first run's `(t, samples, color)`."""
    first = None
    for k, (run, label) in enumerate(zip(runs, labels)):
        t, s = _run_samples(run)
        (line,) = axes.track.plot(s["y"] / scale, s["x"] / scale, lw=1.3, label=label)
        color = line.get_color()
        axes.heading.plot(t, np.rad2deg(s["psi"]), color=color, lw=1.2)
        axes.rudder.plot(t, np.rad2deg(s["delta"]), color=color, lw=1.2)
        if k == 0 and "order" in s:
            axes.rudder.step(t, np.rad2deg(s["order"]), where="post", color="0.3", ls="--",
                             lw=0.9, label="rudder order")
        axes.rate.plot(t, np.rad2deg(s["r"]), color=color, lw=1.2)
        axes.speed.plot(t, np.hypot(s["u"], s["v"]), color=color, lw=1.2)
        if k == 0:
            first = (t, s, color)
    return first


def _reference_lines(axes: _TrajectoryAxes, reference, reference_label) -> None:
    """Reference heading, rudder, yaw rate or speed: a dashed line for a value, a band for
    a `(low, high)` range."""
    by_key = {"heading": axes.heading, "rudder": axes.rudder, "rate": axes.rate,
              "speed": axes.speed}
    for name, (key, factor, display) in _REFERENCE_TIME.items():
        if name in reference:
            low, high = (factor * v for v in _range(reference[name]))
            text = f"{reference_label}: {name.replace('_', ' ')} " + _range_text(
                low, high, lambda v: f"{v:.3g} {display}")
            if low == high:
                by_key[key].axhline(low, color=_REFERENCE_COLOR, ls="--", lw=1.3, label=text)
            else:
                by_key[key].axhspan(low, high, facecolor=_REFERENCE_COLOR, alpha=0.25,
                                    lw=0.0, label=text)


def _label_axes(axes: _TrajectoryAxes, length, unit) -> None:
    """Axis labels (the track in ship lengths and metres when `length` is given), equal
    track aspect, time labels on the bottom axes only, grids."""
    track = axes.track
    track.set(xlabel=f"east [{unit}]", ylabel=f"north [{unit}]", title="track")
    track.set_aspect("equal", adjustable="datalim")
    if length:
        to_m, to_l = (lambda v: v * float(length)), (lambda v: v / float(length))
        track.secondary_xaxis("top", functions=(to_m, to_l)).set_xlabel("east [m]")
        track.secondary_yaxis("right", functions=(to_m, to_l)).set_ylabel("north [m]")
    axes.heading.set(ylabel="heading [deg]")
    axes.rudder.set(ylabel="rudder angle [deg]")
    axes.rate.set(ylabel="yaw rate [deg/s]")
    axes.speed.set(ylabel="speed U [m/s]", xlabel="time [s]")
    for ax in (axes.heading, axes.rudder, axes.rate):
        ax.tick_params(labelbottom=False)
    for ax in axes:
        ax.grid(True, alpha=0.3)


def _propeller_rate(speed, traj) -> list:
    """The propeller rate on a right axis of `speed` when it varies (a propeller order,
    the stop); returns that axis in a list, or an empty list."""
    n = np.asarray(getattr(traj.state, "n", np.zeros(1)), dtype=np.float64)
    if not (n.size == np.size(traj.t) and np.ptp(n) > 1e-6 * max(1.0, np.max(np.abs(n)))):
        return []
    shaft = speed.twinx()
    t0, _ = _run_samples(traj)
    valid = np.asarray(getattr(traj, "valid", np.ones(n.size, dtype=bool)), dtype=bool)
    shaft.plot(t0, 60.0 * n[valid], color="0.35", ls="-.", lw=1.0,
               label="propeller rate (right axis)")
    shaft.set_ylabel("propeller [rpm]")
    return [shaft]


def _min_span(ax, span):
    """Widen the y axis of `ax` to at least `span` (display units) about its middle, so
    that a constant signal is not drawn as rounding noise."""
    low, high = ax.get_ylim()
    if high - low < span:
        middle = 0.5 * (low + high)
        ax.set_ylim(middle - 0.5 * span, middle + 0.5 * span)


def plot_spiral(curve, *, reverse=None, ordered=None, reference=None,
                reference_label="reference", title=""):
    """Steady yaw rate against rudder angle of a spiral (MSC/Circ.1053 app. 4 figs.
    A4-2, A4-3), with its hysteresis loop.

    **Arguments:**

    - `curve`: a `SpiralCurve`: from `spiral_curve` (a direct spiral: each branch drawn
      with arrows in the order run) or `reverse_spiral_curve` (Bech's reverse spiral,
      the points joined in order of yaw rate).
    - `reverse`: optionally a reverse spiral's `SpiralCurve` drawn with a direct one.
    - `ordered`: the reverse spiral's ordered yaw rates [rad/s], drawn as crosses at
      the mean rudder angle of each level (how well each level was held).
    - `reference`: a `SpiralCurve` of a reference (a thesis, a model test), drawn in
      grey and labelled `reference_label`.
    - `title`: the figure title.

    The loop (`SpiralCurve.loop`) is shaded over its estimated rudder range, with its
    width, bounds and height written. **Returns:** the matplotlib `Figure`.
    """
    deg = np.rad2deg
    fig, ax = plt.subplots(figsize=(10, 6), layout="constrained")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.axvline(0.0, color="k", lw=0.6)

    def draw(c, style, label, color=None, arrows=True):
        delta, r = deg(np.asarray(c.delta, dtype=float)), deg(np.asarray(c.r, dtype=float))
        branches = c.branches()
        if len(branches) == 1:  # reverse spiral: join the points in order of yaw rate
            order = np.argsort(r)
            ax.plot(delta[order], r[order], style, color=color, ms=6, lw=1.2, label=label)
            return
        names = ["to port (from starboard)", "back to starboard", "again to port"]
        for k, idx in enumerate(branches):
            (line,) = ax.plot(delta[idx], r[idx], style, ms=6, lw=1.2, color=color,
                              label=f"{label}: {names[min(k, 2)]}")
            if arrows:
                for a, b in zip(idx[:-1], idx[1:]):
                    ax.annotate("", xy=(delta[b], r[b]), xytext=(delta[a], r[a]),
                                arrowprops=dict(arrowstyle="->", color=line.get_color(),
                                                lw=0.9, shrinkA=4, shrinkB=4))

    direct = len(curve.branches()) > 1
    draw(curve, "o-", "direct spiral" if direct else "reverse spiral")
    if reverse is not None:
        draw(reverse, "s-", "reverse spiral", color="tab:green")
    rs = reverse if reverse is not None else (None if direct else curve)
    if ordered is not None and rs is not None:
        n = np.asarray(rs.r).size
        ax.plot(deg(np.asarray(rs.delta)), deg(np.asarray(ordered, dtype=float)[:n]), "kx",
                ms=7, label="ordered yaw rate (reverse spiral)")
    if reference is not None:
        draw(reference, "x--", reference_label, color="0.45", arrows=False)
    loop = curve.loop
    if loop.width > 0:
        low, high = loop.edges
        ax.axvspan(deg(low), deg(high), color="tab:red", alpha=0.12, lw=0.0,
                   label="loop (estimated rudder range)")
    text = (f"loop width {deg(loop.width):.2f} deg"
            + (f" (between {deg(loop.width_low):.2f} and {deg(loop.width_high):.2f} deg "
               "from the levels run)" if loop.width_high > loop.width_low else "")
            + f"\nloop height {deg(loop.height):.3g} deg/s")
    if loop.width == 0:
        text = "no loop: course-stable at this resolution"
    wrapped = "\n".join(textwrap.fill(line, 46) for line in text.split("\n"))
    ax.plot([], [], " ", label=wrapped, gid="loop")  # in the legend, beside the axes
    ax.set(xlabel="rudder angle [deg] (+ to starboard)",
           ylabel="steady yaw rate [deg/s] (+ to starboard)")
    ax.grid(True, alpha=0.3)
    _legend_beside(ax)
    _title(fig, title, size=12.0)
    return fig


def plot_imo_criteria(rows, *, title="IMO MSC.137(76) manoeuvrability criteria", bands=None):
    """The `imo_criteria` rows as a table figure: criterion, value, limit, the margin
    (limit - value) and the verdict (green pass, red fail); with `bands` (`{criterion:
    (low, high)}`, e.g. from parameter draws) a column of them. **Returns:** the
    matplotlib `Figure`."""
    rows = list(rows)
    bands = bands or {}
    fig, ax = plt.subplots(figsize=(11 if bands else 10, 0.45 * len(rows) + 1.3),
                           layout="constrained")
    ax.axis("off")
    labels = ["criterion", "value", "limit", "margin"] + (["band"] if bands else []) + \
        ["result"]
    cells = []
    for row in rows:
        band = bands.get(row.criterion)
        measured = np.isfinite(row.value)  # else not measured (`CriterionRow.note`)
        cells.append([row.criterion, f"{row.value:.2f} {row.unit}" if measured else
                      "not measured", f"<= {row.limit:.2f} {row.unit}",
                      f"{row.limit - row.value:+.2f}" if measured else "-"]
                     + ([f"{band[0]:.2f} to {band[1]:.2f}" if band else "-"] if bands else [])
                     + ["pass" if row.passed else "FAIL"])
    widths = [0.46, 0.12, 0.14, 0.1] + ([0.16] if bands else []) + [0.08]
    table = ax.table(cellText=cells or [["(no criteria)"] + [""] * (len(labels) - 1)],
                     colLabels=labels, colWidths=widths, loc="center", cellLoc="left")
    table.auto_set_font_size(False)
    table.set_fontsize(9)
    table.scale(1.0, 1.4)
    for (i, j), cell in table.get_celld().items():
        if i == 0:
            cell.set_text_props(weight="bold")
        elif j == len(labels) - 1 and rows:
            cell.set_facecolor("#c9f2c9" if rows[i - 1].passed else "#f6c4c4")
    _title(fig, title, size=12.0)
    return fig


# ---------------------------------------------------------------------------------------
# identification figures (`jaxship identify`)

# output channel: (label, display unit, factor from SI)
