"""Helpers shared by the figures: titles, legends off the data, reference ranges."""

import textwrap

import numpy as np


_REFERENCE_COLOR = "tab:orange"


class _Pyplot:
    """`matplotlib.pyplot`, imported on first use (0.3-1 s): importing the figures costs
    nothing, so `jaxship identify --no-figures` never loads matplotlib (issue 70)."""

    def __getattr__(self, name):
        import matplotlib.pyplot

        return getattr(matplotlib.pyplot, name)


plt = _Pyplot()


def _title(fig, text, *, size=14.0):
    """`fig.suptitle(text)` wrapped to the figure's width, so that it is never clipped."""
    if not text:
        return None
    width = fig.get_figwidth() * 72.0 / (0.55 * size)  # characters that fit
    return fig.suptitle(textwrap.fill(str(text), max(30, int(width))), fontsize=size)


def _legend_below(fig, axes, *, ncols=4):
    """One legend for `axes` (labels deduplicated) outside the axes, below the figure."""
    handles, seen = [], {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            if label and not label.startswith("_") and label not in seen:
                seen[label] = handle
                handles.append(handle)
    if not handles:
        return None
    return fig.legend(handles, list(seen), loc="outside lower center",
                      ncols=min(ncols, len(handles)), fontsize="small")


def _inches(artist, fig):
    """The (width, height) [in] of `artist` as `fig` lays it out (its text measured by the
    figure's renderer; no drawing)."""
    box = artist.get_window_extent()
    return box.width / fig.dpi, box.height / fig.dpi


def _fixed_layout(fig, grid, *, right, top, bottom, hspace=0.0, left=None, wspace=None):
    """Place the axes of `fig`, a `grid` of rows x columns, with margins and gaps given in
    inches: a fixed layout in place of matplotlib's constrained one, which measures every
    artist of the figure before drawing it (about 40 % of a figure's time, issue 70).
    `left` and `wspace` left out are measured: the widest y-axis labels of each column (the
    heights placed first: they choose the y ticks; the widths do not)."""
    width, height = fig.get_size_inches()
    rows, cols = grid
    cell_h = (height - top - bottom - (rows - 1) * hspace) / rows
    fig.subplots_adjust(bottom=bottom / height, top=1 - top / height, hspace=hspace / cell_h)
    if left is None or wspace is None:
        columns = np.reshape(fig.axes[: rows * cols], grid).T
        need = [max(_y_labels(ax, fig) for ax in column) for column in columns]
        left = need[0] + 0.1 if left is None else left
        wspace = max(need[1:], default=0.0) + 0.2 if wspace is None else wspace
    cell_w = (width - left - right - (cols - 1) * wspace) / cols
    fig.subplots_adjust(left=left / width, right=1 - right / width, wspace=wspace / cell_w)


def _y_labels(ax, fig):
    """The width [in] of the y axis' tick labels and label left of `ax`."""
    box = ax.yaxis.get_tightbbox() if ax.axison else None
    return 0.0 if box is None else (ax.get_window_extent().x0 - box.x0) / fig.dpi


def _emptied(fig):
    """`fig` without its data, legends and titles, its axes and their ticks kept: to draw
    the next figure of the same shape into (new axes and ticks are a third of a figure's
    time; `Axes.clear` would make them anew)."""
    for legend in list(fig.legends):
        legend.remove()
    for ax in fig.axes:
        for artist in [*ax.lines, *ax.collections, *ax.patches, *ax.texts]:
            artist.remove()
        if ax.get_legend() is not None:
            ax.get_legend().remove()
        ax.set_title("")
        ax.set_prop_cycle(None)
        ax.relim()
        ax.set_axis_on()
    return fig


def _legend_beside(ax, **kwargs):
    """The legend of `ax` to the right of it, outside the data."""
    return ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                     fontsize="small", **kwargs)


def _range(value):
    """A reference value or (low, high) range as (low, high)."""
    if np.ndim(value) == 0:
        return float(value), float(value)
    low, high = (float(v) for v in value)
    return min(low, high), max(low, high)


def _distance(value, length):
    """A distance [m] as text, in ship lengths and metres when `length` is known."""
    metres = f"{value:,.0f} m" if abs(value) >= 100 else f"{value:.3g} m"
    return f"{value / length:.2f} L ({metres})" if length else metres


def _range_text(low, high, fmt):
    return fmt(low) if low == high else f"{fmt(low)} to {fmt(high)}"


# ---------------------------------------------------------------------------------------
# trials (`jaxship simulate`, `jaxship reproduce`)

# reference values on the time axes: name -> (axes key, factor from SI, unit)
_REFERENCE_TIME = {"heading": ("heading", 180 / np.pi, "deg"),
                   "rudder": ("rudder", 180 / np.pi, "deg"),
                   "yaw_rate": ("rate", 180 / np.pi, "deg/s"),
                   "speed": ("speed", 1.0, "m/s")}
_REFERENCE_TURNING = ("advance", "transfer", "tactical_diameter")
_REFERENCE_ZIGZAG = ("overshoot_1", "overshoot_2", "overshoot_3")
_REFERENCE_STOPPING = ("head_reach", "lateral_deviation")


def _y_range(ax, curves, window):
    """Scale the y axis of `ax` to the `curves` [(t, y)] inside the time `window`."""
    inside = [np.asarray(y)[(np.asarray(t) >= window[0]) & (np.asarray(t) <= window[1])]
              for t, y in curves]
    values = np.concatenate([v[np.isfinite(v)] for v in inside] or [np.zeros(0)])
    if values.size:
        low, high = float(values.min()), float(values.max())
        pad = 0.06 * max(high - low, 1e-3)
        ax.set_ylim(low - pad, high + pad)


# ---------------------------------------------------------------------------------------
# `jaxship reproduce`: jaxship's curves next to what the thesis states about its figures
