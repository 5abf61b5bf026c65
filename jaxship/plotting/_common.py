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
