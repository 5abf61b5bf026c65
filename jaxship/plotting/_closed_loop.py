"""Autopilot figures: heading, error and rudder of closed-loop runs."""


import numpy as np

from ._common import (
    _y_range,
    plt,
)


def _wrap_deg(angle):
    """Angle [rad] as degrees in [-180, 180)."""
    return np.rad2deg((np.asarray(angle, dtype=np.float64) + np.pi) % (2 * np.pi) - np.pi)


def plot_autopilot(run, *, index: int = 0, others=(), labels=None, max_angle=None,
                   window=None, title: str = ""):
    """Heading, heading error and rudder of closed-loop autopilot runs, on three axes
    over time (like thesis figs. 5.1-5.6).

    **Arguments:**

    - `run`: a `jaxship.ClosedLoop` (from `closed_loop`); `others`: more of them
      drawn over it (e.g. another controller). Every autopilot of each is drawn at
      operating point `index` (the speeds axis).
    - `labels`: one per autopilot drawn (default "run 0", "run 1", ...).
    - `max_angle`: the rudder limit [rad], drawn as dashed lines at +-`max_angle`.
    - `window`: (start, end) [s] of the time axis (default: the whole run); the
      heading and error axes are scaled to the curves inside it.
    - `title`: the figure title.

    The top axes show the ordered heading (the step), the desired heading of the
    reference model and each actual heading; the middle axes the error desired minus
    actual; the bottom axes the actual rudder angle. Degrees throughout; the legends
    sit to the right of the axes, so they cover no curve. **Returns:** the Figure.
    """
    loops = [run, *others]
    count = sum(int(np.shape(loop.psi)[0]) for loop in loops)
    labels = list(labels) if labels is not None else [f"run {i}" for i in range(count)]
    if len(labels) != count:
        raise ValueError(f"{count} autopilot runs but {len(labels)} labels.")
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True, constrained_layout=True)
    heading, error, rudder = axes
    curves = {ax: [] for ax in axes}  # (t, values) drawn on each axes, for the y range

    def draw(ax, t, y, *args, step=False, **kwargs):
        (ax.step if step else ax.plot)(t, y, *args, **kwargs)
        curves[ax].append((t, y))
        return ax.get_lines()[-1]

    t0 = np.asarray(run.t, dtype=np.float64)
    draw(heading, t0, np.rad2deg(np.asarray(run.psi_ref[0, index], dtype=np.float64)),
         step=True, where="post", color="0.55", lw=1.0, ls=":", label="ordered (step)")
    draw(heading, t0, np.rad2deg(np.asarray(run.psi_d[0, index], dtype=np.float64)),
         color="k", lw=1.4, ls="--", label="desired (reference model)")
    k = 0
    for loop in loops:
        t = np.asarray(loop.t, dtype=np.float64)
        for a in range(np.shape(loop.psi)[0]):
            psi = np.asarray(loop.psi[a, index], dtype=np.float64)
            color = draw(heading, t, np.rad2deg(psi), lw=1.2,
                         label=f"{labels[k]}: actual").get_color()
            draw(error, t, _wrap_deg(np.asarray(loop.psi_d[a, index]) - psi), color=color,
                 lw=1.2, label=labels[k])
            draw(rudder, t, np.rad2deg(np.asarray(loop.delta[a, index], dtype=np.float64)),
                 color=color, lw=1.2, label=labels[k])
            k += 1
    if max_angle is not None:
        limit = float(np.rad2deg(max_angle))
        for sign in (1, -1):
            rudder.axhline(sign * limit, color="tab:red", ls="--", lw=1.0,
                           label="rudder limit" if sign > 0 else None)
            curves[rudder].append((np.asarray(window or (t0[0], t0[-1])),
                                   np.full(2, sign * limit)))
    error.axhline(0.0, color="k", lw=0.5)
    heading.set(ylabel="heading [deg]", title=title or "heading autopilot")
    error.set(ylabel="heading error\ndesired - actual [deg]")
    rudder.set(ylabel="rudder angle [deg]", xlabel="time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                  fontsize="small")
    if window is not None:
        rudder.set_xlim(*window)
        for ax in axes:
            _y_range(ax, curves[ax], window)
    return fig
