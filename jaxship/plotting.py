"""Matplotlib figures of simulated and measured trials (degrees and rpm on the axes)."""

from pathlib import Path

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


# ---------------------------------------------------------------------------------------
# identification figures (`jaxship identify`)

# output channel: (label, display unit, factor from SI)
_CHANNEL_AXES = {"psi": ("heading", "deg", 180 / np.pi), "r": ("yaw rate", "deg/s", 180 / np.pi),
                 "u": ("surge velocity", "m/s", 1.0), "v": ("sway velocity", "m/s", 1.0)}


def _channel_axes(channel):
    return _CHANNEL_AXES.get(channel, (channel, "SI", 1.0))


def _masked(values, mask):
    return np.where(mask, np.asarray(values, dtype=np.float64), np.nan)


def plot_comparison(assessment, index: int = 0, *, title: str = ""):
    """Measured against model outputs of one record, with the fit % in the legend.

    **Arguments:**

    - `assessment`: a `jaxship.identification.Assessment` (or anything with `data`
      (a `Dataset`), `rudder`, `predictions` {channel: (E, N)}, `mask` (E, N) and
      `metrics` {channel: `ValidationReport`}).
    - `index`: which record (experiment) of the assessment.
    - `title`: the figure title.

    Each channel in `predictions` (heading and yaw rate in degrees) and the replayed
    rudder. **Returns:** the matplotlib `Figure`.
    """
    ds = assessment.data
    n = ds.lengths[index]
    t = np.asarray(ds.t, dtype=np.float64)[index, :n]
    channels = list(assessment.predictions)
    fig, axes = plt.subplots(len(channels) + 1, 1, figsize=(9, 2.4 * (len(channels) + 1)),
                             sharex=True, constrained_layout=True)
    mask = np.asarray(assessment.mask)[index, :n]
    for ax, c in zip(axes, channels):
        label, unit, factor = _channel_axes(c)
        measured = factor * np.asarray(getattr(ds, c), dtype=np.float64)[index, :n]
        model = factor * _masked(assessment.predictions[c][index, :n], mask)
        fit = assessment.metrics[c].fit_per_experiment[index] if c in assessment.metrics else None
        ax.plot(t, measured, color="k", lw=1.0, label="measured")
        text = "model" if fit is None or not np.isfinite(fit) else f"model, fit {fit:.1f} %"
        ax.plot(t, model, color="tab:red", lw=1.2, label=text)
        ax.set(ylabel=f"{label} [{unit}]")
        ax.legend(loc="best", fontsize="small")
    rudder = np.rad2deg(np.asarray(getattr(ds, assessment.rudder), dtype=np.float64)[index, :n])
    axes[-1].step(t, rudder, where="post", color="tab:blue", lw=1.0,
                  label=f"rudder ({assessment.rudder})")
    axes[-1].set(ylabel="rudder [deg]", xlabel="time [s]")
    axes[-1].legend(loc="best", fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or f"{ds.names[index]}: measured and model")
    return fig


def _correlation_axes(ax, corr, label):
    lags = np.asarray(corr.lags)
    ax.axhspan(-corr.band, corr.band, color="tab:blue", alpha=0.15, label="99 % band")
    ax.vlines(lags, 0.0, corr.values, color="k", lw=1.2)
    ax.plot(lags, corr.values, "o", color="k", ms=2.5)
    ax.axhline(0.0, color="k", lw=0.5)
    verdict = "passed" if corr.passed else "failed"
    ax.set(xlabel="lag [samples]", title=f"{label}: test {verdict} "
           f"({corr.statistic:.3g} vs {corr.threshold:.3g})")
    ax.title.set_fontsize("small")


def plot_residuals(assessment, *, title: str = ""):
    """Prediction errors and their correlation tests, one row per output channel
    (like MATLAB's `resid`): the residuals over time (each record), their
    autocorrelation and their cross-correlation with the rudder, with the 99 %
    confidence bands of `jaxship._foundation._validate` (Ljung 1999, sec. 16.6).

    **Arguments:** `assessment` as in `plot_comparison`; `title`.
    **Returns:** the matplotlib `Figure`.
    """
    ds = assessment.data
    channels = list(assessment.metrics)
    fig, axes = plt.subplots(len(channels), 3, figsize=(14, 3.2 * len(channels)),
                             squeeze=False, constrained_layout=True)
    for row, c in zip(axes, channels):
        label, unit, factor = _channel_axes(c)
        measured = np.asarray(getattr(ds, c), dtype=np.float64)
        mask = np.asarray(assessment.mask)
        error = factor * _masked(measured - assessment.predictions[c], mask)
        for i, name in enumerate(ds.names):
            n = ds.lengths[i]
            row[0].plot(np.asarray(ds.t)[i, :n], error[i, :n], lw=0.8, label=name)
        row[0].set(xlabel="time [s]", ylabel=f"{label} error [{unit}]")
        if len(ds.names) <= 8:
            row[0].legend(loc="best", fontsize="x-small")
        report = assessment.metrics[c]
        _correlation_axes(row[1], report.autocorrelation, f"{c} residual autocorrelation")
        if report.cross_correlation is not None:
            _correlation_axes(row[2], report.cross_correlation,
                              f"{c} residual x {assessment.rudder} cross-correlation")
        for ax in row:
            ax.grid(True, alpha=0.3)
    kind = "prediction" if assessment.kind == "prediction" else "simulation"
    fig.suptitle(title or f"{kind} errors")
    return fig


def plot_parameter_correlation(names, correlation, *, title: str = "parameter correlation"):
    """Heat map of the estimates' correlation matrix (-1 blue to +1 red), with the
    values written in the cells; undetermined entries (NaN) are grey.
    **Returns:** the matplotlib `Figure`."""
    corr = np.asarray(correlation, dtype=np.float64)
    d = len(names)
    fig, ax = plt.subplots(figsize=(1.2 * d + 2.5, 1.0 * d + 1.8), constrained_layout=True)
    cmap = plt.get_cmap("RdBu_r").with_extremes(bad="0.8")
    image = ax.imshow(np.ma.masked_invalid(corr), vmin=-1, vmax=1, cmap=cmap)
    for i in range(d):
        for j in range(d):
            text = "n/a" if not np.isfinite(corr[i, j]) else f"{corr[i, j]:+.2f}"
            ax.text(j, i, text, ha="center", va="center", fontsize="small",
                    color="w" if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.6 else "k")
    ax.set_xticks(range(d), names)
    ax.set_yticks(range(d), names)
    fig.colorbar(image, ax=ax, shrink=0.8, label="correlation")
    ax.set_title(title)
    return fig


def _file_part(name: str) -> str:
    keep = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in str(name))
    return keep.strip("._")[:60] or "record"


def save_identification_figures(result, folder, *, dpi: int = 100) -> list:
    """Write the figures of a `jaxship.IdentificationResult` into `folder`
    and return their paths:

    - `fit_train_NN_NAME.png`, `fit_validation_NN_NAME.png`: measured vs simulated
      model (output error from the measured start) per record, fit % in the legend;
    - `residuals_train.png`: the fit criterion's prediction errors with their
      autocorrelation and rudder cross-correlation tests; `residuals_validation.png`:
      the same for the simulation errors on the held-out records;
    - `correlation.png`: the parameter correlation heat map.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []

    def save(fig, name):
        path = folder / name
        fig.savefig(path, dpi=dpi)
        plt.close(fig)
        written.append(path)

    model = type(result.model).__name__
    blocks = [("train", result.train_simulation)]
    if result.validation is not None:
        blocks.append(("validation", result.validation))
    for label, block in blocks:
        for i, name in enumerate(block.names):
            save(plot_comparison(block, i, title=f"{model} on {label} record {name} "
                                                 "(simulation from the measured start)"),
                 f"fit_{label}_{i:02d}_{_file_part(name)}.png")
    horizon = result.train.horizon
    what = "simulation" if horizon is None else f"{horizon:g} s prediction"
    save(plot_residuals(result.train, title=f"{model}: {what} errors on the training records"),
         "residuals_train.png")
    if result.validation is not None:
        save(plot_residuals(result.validation,
                            title=f"{model}: simulation errors on the validation records"),
             "residuals_validation.png")
    report = result.fit.parameters
    save(plot_parameter_correlation(report.names, report.correlation,
                                    title=f"{model}: correlation of the estimates"),
         "correlation.png")
    return written


# ---------------------------------------------------------------------------------------
# heading autopilot (`jaxship autopilot`, thesis figs. 5.1-5.6)


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


def _y_range(ax, curves, window):
    """Scale the y axis of `ax` to the `curves` [(t, y)] inside the time `window`."""
    inside = [np.asarray(y)[(np.asarray(t) >= window[0]) & (np.asarray(t) <= window[1])]
              for t, y in curves]
    values = np.concatenate([v[np.isfinite(v)] for v in inside] or [np.zeros(0)])
    if values.size:
        low, high = float(values.min()), float(values.max())
        pad = 0.06 * max(high - low, 1e-3)
        ax.set_ylim(low - pad, high + pad)
