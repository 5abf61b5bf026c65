"""Matplotlib figures of simulated and measured trials (degrees and rpm on the axes)."""

import matplotlib.pyplot as plt
import numpy as np


def plot_trajectory(traj, *, length=None, title="", others=(), labels=None):
    """Track, heading/rudder, yaw rate and speed of a `Trajectory` (and optional others).

    **Arguments:**

    - `traj`: a `Trajectory` (or anything with `t` and `state.u/v/r/x/y/psi/delta`).
    - `length`: ship length [m]; the track is then drawn in ship lengths.
    - `others`: more trajectories (e.g. measurements) drawn over the first.
    - `labels`: legend labels, one per trajectory.

    **Returns:** the matplotlib `Figure`.
    """
    runs = [traj, *others]
    labels = labels or [f"run {i}" for i in range(len(runs))]
    scale, unit = (length, "L") if length else (1.0, "m")
    fig = plt.figure(figsize=(11, 7), constrained_layout=True)
    grid = fig.add_gridspec(3, 2, width_ratios=[1, 1.4])
    track = fig.add_subplot(grid[:, 0])
    heading, rate, speed = (fig.add_subplot(grid[i, 1]) for i in range(3))
    for run, label in zip(runs, labels):
        s = run.state
        valid = np.asarray(getattr(run, "valid", np.ones_like(run.t, dtype=bool)), dtype=bool)
        t = np.asarray(run.t)[valid]
        pick = lambda a: np.asarray(a)[valid]
        (line,) = track.plot(pick(s.y) / scale, pick(s.x) / scale, label=label)
        heading.plot(t, np.rad2deg(pick(s.psi)), color=line.get_color(), label=f"{label} heading")
        heading.plot(
            t, np.rad2deg(pick(s.delta)), "--", color=line.get_color(), label=f"{label} rudder"
        )
        rate.plot(t, np.rad2deg(pick(s.r)), color=line.get_color())
        speed.plot(t, np.hypot(pick(s.u), pick(s.v)), color=line.get_color())
    track.set(xlabel=f"east [{unit}]", ylabel=f"north [{unit}]", title=title or "track")
    track.set_aspect("equal", adjustable="datalim")
    track.legend(loc="best", fontsize="small")
    heading.set(ylabel="heading, rudder [deg]")
    heading.legend(loc="best", fontsize="small")
    rate.set(ylabel="yaw rate [deg/s]")
    speed.set(ylabel="speed [m/s]", xlabel="time [s]")
    for ax in (track, heading, rate, speed):
        ax.grid(True, alpha=0.3)
    return fig
