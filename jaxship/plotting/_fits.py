"""Identification figures: measured against model, residual tests, parameter
correlation."""

import textwrap
from pathlib import Path

import numpy as np

from ._common import (
    _REFERENCE_COLOR,
    _emptied,
    _fixed_layout,
    _inches,
    _legend_below,
    _legend_beside,
    _range,
    _range_text,
    _title,
    plt,
)


_CHANNEL_AXES = {"psi": ("heading", "deg", 180 / np.pi), "r": ("yaw rate", "deg/s", 180 / np.pi),
                 "u": ("surge velocity", "m/s", 1.0), "v": ("sway velocity", "m/s", 1.0)}


def _channel_axes(channel):
    return _CHANNEL_AXES.get(channel, (channel, "SI", 1.0))


def _masked(values, mask):
    return np.where(mask, np.asarray(values, dtype=np.float64), np.nan)


def plot_comparison(assessment, index: int = 0, *, title: str = "", reference=None,
                    reference_label: str = "reference"):
    """Measured against model outputs of one record, with the fit % in the legend.

    **Arguments:**

    - `assessment`: a `Assessment` of the `identify` command (or anything with `data`
      (a `Dataset`), `rudder`, `predictions` {channel: (E, N)}, `mask` (E, N) and
      `metrics` {channel: `ValidationReport`}).
    - `index`: which record (experiment) of the assessment.
    - `title`: the figure title.
    - `reference`: `{channel: fit % or (low, high)}` of a reference (e.g. the thesis'
      fit), written in that channel's legend next to the model's.

    Each channel in `predictions` (heading and yaw rate in degrees) and the replayed
    rudder, legends beside the axes. **Returns:** the matplotlib `Figure`.
    """
    fig = _comparison_figure(len(assessment.predictions))
    _draw_comparison(fig, assessment, index, title=title, reference=reference,
                     reference_label=reference_label)
    return fig


def _comparison_figure(channels: int):
    rows = channels + 1
    return plt.subplots(rows, 1, figsize=(11, 2.4 * rows), sharex=True, layout="none")[0]


def _draw_comparison(fig, assessment, index, *, title="", reference=None,
                     reference_label="reference"):
    """`plot_comparison` drawn into `fig`, a new or emptied `_comparison_figure`."""
    reference = dict(reference or {})
    ds = assessment.data
    n = ds.lengths[index]
    t = np.asarray(ds.t, dtype=np.float64)[index, :n]
    channels = list(assessment.predictions)
    axes = fig.axes
    mask = np.asarray(assessment.mask)[index, :n]
    for ax, c in zip(axes, channels):
        label, unit, factor = _channel_axes(c)
        measured = factor * np.asarray(getattr(ds, c), dtype=np.float64)[index, :n]
        model = factor * _masked(assessment.predictions[c][index, :n], mask)
        fit = assessment.metrics[c].fit_per_experiment[index] if c in assessment.metrics else None
        ax.plot(t, measured, color="k", lw=1.0, label="measured")
        text = "model" if fit is None or not np.isfinite(fit) else f"model, fit {fit:.1f} %"
        ax.plot(t, model, color="tab:red", lw=1.2, label=text)
        if c in reference:
            low, high = _range(reference[c])
            ax.plot([], [], color=_REFERENCE_COLOR, lw=3, alpha=0.6,
                    label=f"{reference_label}: fit " + _range_text(low, high,
                                                                    lambda v: f"{v:.1f} %"))
        ax.set(ylabel=f"{label} [{unit}]")
    rudder = np.rad2deg(np.asarray(getattr(ds, assessment.rudder), dtype=np.float64)[index, :n])
    axes[-1].step(t, rudder, where="post", color="tab:blue", lw=1.0,
                  label=f"rudder ({assessment.rudder})")
    axes[-1].set(ylabel="rudder [deg]", xlabel="time [s]")
    legends = [_legend_beside(ax) for ax in axes]
    for ax in axes:
        ax.grid(True, alpha=0.3)
    head = _title(fig, title or f"{ds.names[index]}: measured and model", size=12.0)
    # the legends' width on the right, the title's height on top
    _fixed_layout(fig, (len(axes), 1),
                  right=0.25 + max(_inches(legend, fig)[0] for legend in legends),
                  top=0.02 * fig.get_figheight() + _inches(head, fig)[1] + 0.15,
                  bottom=0.55, hspace=0.15)


def _correlation_axes(ax, corr, label, dt=None):
    """A correlation test's values against the lag (seconds when the sample interval
    `dt` [s] is known), with its confidence band."""
    lags = np.asarray(corr.lags, dtype=np.float64) * (1.0 if dt is None else float(dt))
    ax.axhspan(-corr.band, corr.band, color="tab:blue", alpha=0.15, label="99 % band")
    ax.vlines(lags, 0.0, corr.values, color="k", lw=1.2)
    ax.plot(lags, corr.values, "o", color="k", ms=2.5)
    ax.axhline(0.0, color="k", lw=0.5)
    verdict = "passed" if corr.passed else "failed"
    ax.set(xlabel="lag [samples]" if dt is None else "lag [s]",
           title=textwrap.fill(f"{label}: test {verdict} ({corr.statistic:.3g} vs "
                               f"{corr.threshold:.3g})", 60))
    ax.title.set_fontsize("small")


def _sample_interval(ds):
    """The sample interval [s] of a `Dataset` (its first record's median step)."""
    t = np.asarray(ds.t, dtype=np.float64)[0, : ds.lengths[0]]
    return float(np.median(np.diff(t))) if t.size > 1 else None


def plot_residuals(assessment, *, title: str = ""):
    """Prediction errors and their correlation tests, one row per output channel
    (like MATLAB's `resid`): the residuals over time (each record), their
    autocorrelation and their cross-correlation with the rudder against the lag in
    seconds, with the 99 % confidence bands of `jaxship._foundation._validate`
    (Ljung 1999, sec. 16.6).

    **Arguments:** `assessment` as in `plot_comparison`; `title`.
    **Returns:** the matplotlib `Figure`.
    """
    fig = _residual_figure(len(assessment.metrics))
    _draw_residuals(fig, assessment, title=title)
    return fig


def _residual_figure(channels: int):
    return plt.subplots(channels, 3, figsize=(15, 3.4 * channels), layout="none")[0]


def _draw_residuals(fig, assessment, *, title=""):
    """`plot_residuals` drawn into `fig`, a new or emptied `_residual_figure`."""
    ds = assessment.data
    dt = _sample_interval(ds)
    channels = list(assessment.metrics)
    axes = np.reshape(fig.axes, (len(channels), 3))
    for row, c in zip(axes, channels):
        label, unit, factor = _channel_axes(c)
        measured = np.asarray(getattr(ds, c), dtype=np.float64)
        mask = np.asarray(assessment.mask)
        error = factor * _masked(measured - assessment.predictions[c], mask)
        for i, name in enumerate(ds.names):
            n = ds.lengths[i]
            row[0].plot(np.asarray(ds.t)[i, :n], error[i, :n], lw=0.8, label=name)
        row[0].set(xlabel="time [s]", ylabel=f"{label} error [{unit}]")
        report = assessment.metrics[c]
        _correlation_axes(row[1], report.autocorrelation, f"{c} residual autocorrelation", dt)
        if report.cross_correlation is not None:
            _correlation_axes(row[2], report.cross_correlation,
                              f"{c} residual x {assessment.rudder} cross-correlation", dt)
        else:
            row[2].axis("off")
        for ax in row:
            ax.grid(True, alpha=0.3)
    legend = _legend_below(fig, [axes[0, 0]], ncols=4) if len(ds.names) <= 8 else None
    kind = "prediction" if assessment.kind == "prediction" else "simulation"
    head = _title(fig, title or f"{kind} errors")
    # room for the title on top, the axes' titles above them, the legend below
    titles = max(_inches(ax.title, fig)[1] for ax in axes.flat) + 0.12
    _fixed_layout(fig, axes.shape, right=0.2, hspace=0.6 + titles,
                  top=0.02 * fig.get_figheight() + _inches(head, fig)[1] + 0.1 + titles,
                  bottom=0.6 + (0.0 if legend is None else _inches(legend, fig)[1] + 0.1))


def plot_parameter_correlation(names, correlation, *, title: str = "parameter correlation"):
    """Heat map of the estimates' correlation matrix (-1 blue to +1 red), with the
    values written in the cells; undetermined entries (NaN) are grey.
    **Returns:** the matplotlib `Figure`."""
    corr = np.asarray(correlation, dtype=np.float64)
    d = len(names)
    fig, ax = plt.subplots(figsize=(max(1.2 * d + 2.5, 6.0), 1.0 * d + 2.0), layout="none")
    cmap = plt.get_cmap("RdBu_r").with_extremes(bad="0.8")
    image = ax.imshow(np.ma.masked_invalid(corr), vmin=-1, vmax=1, cmap=cmap)
    for i in range(d):
        for j in range(d):
            text = "n/a" if not np.isfinite(corr[i, j]) else f"{corr[i, j]:+.2f}"
            ax.text(j, i, text, ha="center", va="center", fontsize="small",
                    color="w" if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.6 else "k")
    ax.set_xticks(range(d), names, rotation=45, ha="right")
    ax.set_yticks(range(d), names)
    head = _title(fig, title, size=12.0)
    # the names' width on the left, their height below, the colour bar's labels on the right
    _fixed_layout(fig, (1, 1), right=0.15, wspace=0.0,
                  left=0.3 + max((_inches(t, fig)[0] for t in ax.get_yticklabels()), default=0),
                  bottom=0.3 + max((_inches(t, fig)[1] for t in ax.get_xticklabels()), default=0),
                  top=0.02 * fig.get_figheight() + 0.3 + (_inches(head, fig)[1] if head else 0))
    fig.colorbar(image, ax=ax, shrink=0.8, label="correlation")
    return fig


def _file_part(name: str) -> str:
    keep = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in str(name))
    return keep.strip("._")[:60] or "record"


def identification_figure_names(train_names, validation_names=None) -> list[str]:
    """The file names `save_identification_figures` writes for training (and held-out)
    records of these names."""
    blocks = [("train", train_names)] + (
        [] if validation_names is None else [("validation", validation_names)])
    return ([_fit_figure_name(label, i, name) for label, names in blocks
             for i, name in enumerate(names)]
            + [f"residuals_{label}.png" for label, _ in blocks] + ["correlation.png"])


def _fit_figure_name(label: str, i: int, name: str) -> str:
    return f"fit_{label}_{i:02d}_{_file_part(name)}.png"


# zlib's fastest level: the same pixels, a third less time to write, files 10 % larger
_FAST_PNG = {"compress_level": 1}


def save_identification_figures(result, folder, *, dpi: int = 100) -> list:
    """Write the figures of a result of the `identify` command into `folder`
    and return their paths:

    - `fit_train_NN_NAME.png`, `fit_validation_NN_NAME.png`: measured vs simulated
      model (output error from the measured start) per record, fit % in the legend;
    - `residuals_train.png`: the fit criterion's prediction errors with their
      autocorrelation and rudder cross-correlation tests; `residuals_validation.png`:
      the same for the simulation errors on the held-out records;
    - `correlation.png`: the parameter correlation heat map.

    The figures of one shape are drawn into one figure object, emptied between them: the
    same pixels as new figures in less time (issue 70).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written, figures = [], {}

    def save(draw, make, shape, name, **kwargs):
        # one figure of each shape, emptied and drawn again: its axes and ticks kept
        key = (make, shape)
        fig = _emptied(figures[key]) if key in figures else figures.setdefault(key, make(shape))
        draw(fig, **kwargs)
        fig.savefig(folder / name, dpi=dpi, pil_kwargs=_FAST_PNG)
        written.append(folder / name)

    model = type(result.model).__name__
    blocks = [("train", result.train_simulation)]
    if result.validation is not None:
        blocks.append(("validation", result.validation))
    try:
        for label, block in blocks:
            for i, name in enumerate(block.names):
                save(_draw_comparison, _comparison_figure, len(block.predictions),
                     _fit_figure_name(label, i, name), assessment=block, index=i,
                     title=f"{model} on {label} record {name} (simulation from the "
                           "measured start)")
        horizon = result.train.horizon
        what = "simulation" if horizon is None else f"{horizon:g} s prediction"
        save(_draw_residuals, _residual_figure, len(result.train.metrics), "residuals_train.png",
             assessment=result.train, title=f"{model}: {what} errors on the training records")
        if result.validation is not None:
            save(_draw_residuals, _residual_figure, len(result.validation.metrics),
                 "residuals_validation.png", assessment=result.validation,
                 title=f"{model}: simulation errors on the validation records")
    finally:
        for fig in figures.values():
            plt.close(fig)
    report = result.fit.parameters
    fig = plot_parameter_correlation(report.names, report.correlation,
                                     title=f"{model}: correlation of the estimates")
    fig.savefig(folder / "correlation.png", dpi=dpi, pil_kwargs=_FAST_PNG)
    plt.close(fig)
    return written + [folder / "correlation.png"]


# ---------------------------------------------------------------------------------------
# heading autopilot (`jaxship autopilot`, thesis figs. 5.1-5.6)
