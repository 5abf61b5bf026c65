"""Figures of the `jaxship reproduce` report: trials, fits and tracking next to what
the thesis states."""


import numpy as np

from ._common import _fixed_layout, _inches, plt


def _thesis_marks(ax, bands=(), lines=()):
    """Mark the `bands` [(low, high, label)] as a bar outside the right edge of the
    axes, and draw the `lines` [(value, label)]: what a thesis figure states (its axis
    range, which is no tolerance and so is kept off the data, or a reported value), not
    a thesis curve."""
    for low, high, label in bands:
        ax.plot([1.01, 1.01], [low, high], color="tab:orange", lw=4, solid_capstyle="butt",
                transform=ax.get_yaxis_transform(), clip_on=False, label=label)
    for value, label in lines:
        ax.axhline(value, color="tab:orange", ls="--", lw=1.2, label=label)


def plot_trial_vs_thesis(traj, *, bands=None, lines=None, track_note="", title="",
                         label="jaxship"):
    """A trial (track, heading and rudder, yaw rate, speed) with what the thesis states
    about the same trial drawn over it.

    **Arguments:**

    - `traj`: a `Trajectory` (`t`, `state.x/y/psi/delta/r`, `speed`).
    - `bands`: `{panel: [(low, high, label)]}`, panels `"heading"` [deg], `"yaw_rate"`
      [deg/s] and `"speed"` [m/s]: ranges marked beside the axes, e.g. the tick range of a thesis
      figure's axis (the thesis prints no curve values).
    - `lines`: `{panel: [(value, label)]}`: dashed lines, e.g. a peak value the thesis
      text reports.
    - `track_note`: a text written into the track axes (e.g. the extent of the
      thesis' track plot, whose origin is unknown).
    - `title`, `label`: the figure title and the legend label of the trajectory.

    **Returns:** the matplotlib `Figure`.
    """
    bands, lines = bands or {}, lines or {}
    s = traj.state
    t = np.asarray(traj.t, dtype=np.float64)
    # a track as wide as the time panels: the thesis manoeuvre's spans a kilometre; a fixed
    # layout [in], not the constrained one (which measures every artist first: half of
    # the figure's time, issue 70), its right margin the legends' measured width
    fig = plt.figure(figsize=(13.0, 7.0))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.3, 1.4])
    _inch_margins(fig, grid, left=0.8, right=3.0, bottom=0.55, top=0.65, wspace=0.95,
                  hspace=0.4)
    track = fig.add_subplot(grid[:, 0])
    axes = {k: fig.add_subplot(grid[i, 1]) for i, k in enumerate(("heading", "yaw_rate",
                                                                   "speed"))}
    track.plot(np.asarray(s.y), np.asarray(s.x), label=label)
    track.set(xlabel="east [m]", ylabel="north [m]", title="track")
    track.set_aspect("equal", adjustable="datalim")
    if track_note:
        track.text(0.02, 0.02, track_note, transform=track.transAxes, fontsize="small",
                   va="bottom", wrap=True, bbox=dict(facecolor="white", alpha=0.8, lw=0.0))
    axes["heading"].plot(t, np.rad2deg(np.asarray(s.psi)), label=f"{label} heading")
    # the rudder (tens of degrees) on its own axis: beside a heading of 1000 deg it is flat
    rudder = axes["heading"].twinx()
    rudder.plot(t, np.rad2deg(np.asarray(s.delta)), "--", color="tab:red",
                label=f"{label} rudder")
    rudder.set_ylabel("rudder [deg]", color="tab:red")
    axes["yaw_rate"].plot(t, np.rad2deg(np.asarray(s.r)), label=label)
    axes["speed"].plot(t, np.asarray(traj.speed), label=label)
    units = {"heading": "heading [deg]", "yaw_rate": "yaw rate [deg/s]",
             "speed": "speed [m/s]"}
    for key, ax in axes.items():
        _thesis_marks(ax, bands.get(key, ()), lines.get(key, ()))
        ax.set(ylabel=units[key])
        handles, names = ax.get_legend_handles_labels()
        if key == "heading":
            more = rudder.get_legend_handles_labels()
            handles, names = handles + more[0], names + more[1]
        ax.legend(handles, names, loc="upper left", bbox_to_anchor=(1.13, 1.0),
                  borderaxespad=0.0, fontsize="small")
        ax.grid(True, alpha=0.3)
    axes["speed"].set(xlabel="time [s]")
    track.grid(True, alpha=0.3)
    fig.suptitle(title)
    panel = axes["speed"].get_position().width * fig.get_figwidth()
    widest = max(_inches(ax.get_legend(), fig)[0] for ax in axes.values())
    _inch_margins(fig, grid, left=0.8, right=0.13 * panel + widest + 0.1, bottom=0.55,
                  top=0.65, wspace=0.95, hspace=0.4)
    return fig


def _inch_margins(fig, grid, *, left, right, bottom, top, wspace, hspace):
    """Set the margins and gaps of `grid` (a `GridSpec` of `fig`) in inches."""
    width, height = fig.get_size_inches()
    rows, cols = grid.get_geometry()
    grid.update(left=left / width, right=1 - right / width, bottom=bottom / height,
                top=1 - top / height,
                wspace=wspace / ((width - left - right - (cols - 1) * wspace) / cols),
                hspace=hspace / ((height - bottom - top - (rows - 1) * hspace) / rows))


def plot_model_outputs(t, measured, panels, *, ylabel="yaw rate [deg/s]", title="",
                       measured_label="record"):
    """One measured signal against model outputs, one axes per group of models.

    **Arguments:**

    - `t` [s], `measured`: the record (display units, e.g. deg/s); `t` may be one
      array or a list of arrays, one per panel (then `measured` is a list too).
    - `panels`: `{panel title: [(label, values)]}`: the model outputs drawn over the
      measured signal in each axes (same length as `t`; NaN where not predicted).
    - `ylabel`, `title`, `measured_label`: labels.

    **Returns:** the matplotlib `Figure`.
    """
    names = list(panels)
    many = isinstance(t, (list, tuple))
    fig, axes = plt.subplots(len(names), 1, figsize=(12, 3.0 * len(names)), squeeze=False,
                             sharex=not many)
    for i, (ax, name) in enumerate(zip(axes[:, 0], names)):
        ti = np.asarray(t[i] if many else t, dtype=np.float64)
        yi = np.asarray(measured[i] if many else measured, dtype=np.float64)
        ax.plot(ti, yi, color="k", lw=0.8, label=measured_label)
        for label, values in panels[name]:
            ax.plot(ti, np.asarray(values, dtype=np.float64), lw=1.3, label=label)
        ax.set(ylabel=ylabel, title=name)
        ax.title.set_fontsize("medium")
        ax.grid(True, alpha=0.3)
        # beside the axes: inside, the legend covered the curves
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                  fontsize="small")
    axes[-1, 0].set(xlabel="time [s]")
    fig.suptitle(title)
    _layout_beside_legends(fig, axes[:, 0], top=0.75, hspace=0.75)
    return fig


def _layout_beside_legends(fig, axes, *, top, hspace):
    """A fixed layout (`_fixed_layout`) of a column of `axes` whose legends stand right of
    them: the right margin the widest legend's measured width, the left one the y labels'
    (constrained layout measured every artist: half of a figure's time, issue 70)."""
    widest = max(_inches(ax.get_legend(), fig)[0] for ax in axes)
    _fixed_layout(fig, (len(axes), 1), right=widest + 0.3, top=top, bottom=0.6,
                  hspace=hspace)


def plot_heading_tracking(t, desired, runs, *, window=None, bands=None, title=""):
    """Closed-loop heading runs of several autopilots on the same order: heading
    (desired and actual), error (desired minus actual) and rudder, over time.

    **Arguments:**

    - `t` [s], `desired` [deg]: the reference model's heading.
    - `runs`: `[(label, heading [deg], rudder [deg])]`, one per autopilot.
    - `window`: (start, end) [s] of the time axis.
    - `bands`: `{"heading" | "error" | "rudder": [(low, high, label)]}`: ranges marked
      beside the axes, e.g. a thesis figure's axis range.
    - `title`: the figure title.

    **Returns:** the matplotlib `Figure`.
    """
    bands = bands or {}
    t = np.asarray(t, dtype=np.float64)
    desired = np.asarray(desired, dtype=np.float64)
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    heading, error, rudder = axes
    heading.plot(t, desired, "k--", lw=1.4, label="desired (reference model)")
    # runs that agree lie on one another: each later one thinner and dashed, so that
    # every run stays visible
    styles = [dict(lw=2.6, ls="-"), dict(lw=1.6, ls="--"), dict(lw=1.2, ls="-."),
              dict(lw=1.0, ls=":")]
    for k, (label, psi, delta) in enumerate(runs):
        style = styles[k % len(styles)]
        (line,) = heading.plot(t, np.asarray(psi, dtype=np.float64), label=label, **style)
        error.plot(t, desired - np.asarray(psi, dtype=np.float64), color=line.get_color(),
                   label=label, **style)
        rudder.plot(t, np.asarray(delta, dtype=np.float64), color=line.get_color(),
                    label=label, **style)
    for key, ax in (("heading", heading), ("error", error), ("rudder", rudder)):
        _thesis_marks(ax, bands.get(key, ()))
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                  fontsize="small")
    heading.set(ylabel="heading [deg]", title=title)
    error.set(ylabel="heading error\ndesired - actual [deg]")
    rudder.set(ylabel="rudder [deg]", xlabel="time [s]")
    if window is not None:
        rudder.set_xlim(*window)
    _layout_beside_legends(fig, axes, top=0.45, hspace=0.25)
    return fig
