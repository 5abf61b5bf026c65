"""`jaxship discover`: identify a registered model on training records, run
`jaxship.discover` against held-out records, and write `discovery.json`,
`report.md` and figures."""

import json
import pathlib

import numpy as np

import jaxship as js

from .. import identify
from ..identification import (
    check_froude,
    fit_settings,
    logs_wind,
    preset_length,
    read_experiments,
    same_records,
)
from ._common import check_writes
from ._files import staged_folder


def run_discovery(train_paths, holdout_paths, *, model, out: pathlib.Path,
                  options=None, reading=None, progress=None, name=None):
    """Read the records (`reading`: `read_experiments`' keywords `sample_interval` [s] to
    resample to, `over_ground` for the trial CSVs' u, v, and `note`, default a stage
    report, which hears what was done to the records: files skipped, resampling; the
    command prints notes even when quiet), fit `model` (as `jaxship identify` does, for
    start values), run discovery with `options` (a `jaxship.DiscoveryOptions`, default
    its defaults) and write `out/discovery.json`, `out/report.md` and `out/figures/`.
    Returns the `DiscoveryReport`. `progress` takes the stage reports
    (`jaxship.Progress`). `model`, `name`: as `jaxship.identify` takes them (a catalogue
    name, or a model to start from, `--vessel`, fitted as the catalogue's `name`)."""
    say = (lambda message: None) if progress is None else (
        lambda message: progress(js.Progress("discover", message)))
    options = js.DiscoveryOptions() if options is None else options
    reading = dict(reading or {})
    reading["note"] = reading.get("note") or say
    settings = fit_settings(model, name=name)  # an unknown model fails here
    if options.max_effects < 1:
        raise ValueError(f"--max-effects must be at least 1, got {options.max_effects}.")
    if not 0 < options.alpha < 1:
        raise ValueError(f"--alpha must be between 0 and 1, got {options.alpha}.")
    train = read_experiments(train_paths, role="training", **reading)
    # a held-out record named as a training one (two `trial.csv`) is told apart by its folder
    holdout = read_experiments(holdout_paths, role="held-out", taken=[e.name for e in train],
                               **reading) if holdout_paths else None
    for line in same_records(train, holdout or [], role="held-out", option="--holdout"):
        reading["note"](line)
    check_writes(pathlib.Path(out), tuple(f"figures/{_figure_name(i)}"
                                          for i in range(len(holdout or train))))
    name = settings.name or "vessel"  # a vessel of one's own
    start = settings.start
    length = float(start.length) if isinstance(start, js.AbstractVessel) else \
        preset_length(name)
    if holdout and length is not None:  # identify checks the training records
        check_froude(holdout, length, "held-out", name)
    say(f"start values: identify {name} on {len(train)} training records")
    start = identify(model, train, name=name if settings.name else None).model
    report = js.discover(start, train, holdout, options=options, progress=progress)
    with staged_folder(pathlib.Path(out)) as stage:  # all or nothing
        # records that cannot judge: the figures where the disagreement could be located
        figures = save_discovery_figures(report, train, holdout, stage / "figures") \
            if report.disagreement else []
        text = report.to_markdown()
        text += "\n## Figures\n\n" * bool(figures) + "\n".join(f"![{p.stem}](figures/{p.name})"
                                                for p in figures)
        (stage / "discovery.json").write_text(json.dumps(report.to_dict(), indent=2) + "\n")
        (stage / "report.md").write_text(text + "\n")
    return report


def _figure_name(i: int) -> str:
    return f"residuals_{i:02d}.png"


def save_discovery_figures(report, train, holdout, folder: pathlib.Path) -> list[pathlib.Path]:
    """Residuals before and after on the held-out records (or the training records)."""
    import matplotlib.pyplot as plt  # with the figures only (issue 70)

    folder.mkdir(parents=True, exist_ok=True)
    records = holdout if holdout else train
    channels = tuple(report.channels)
    data = js.Dataset.from_experiments(records) if isinstance(records, list) else records
    windy = logs_wind(data)

    def simulate(model):  # with the logged wind where the model feels it, as it was fitted
        estimator = js.PredictionError(horizon=None, channels=channels,
                                       wind=windy and model.wind_loads)
        return js.predict(model, records, estimator=estimator)

    before, after = simulate(report.model_before), simulate(report.model_after)
    paths = []
    for i, name in enumerate(data.names):
        n = int(data.lengths[i])
        t = np.asarray(data.t[i, :n])
        fig, axes = plt.subplots(len(channels), 1, figsize=(8, 2.4 * len(channels)),
                                 sharex=True, squeeze=False)
        for ax, c in zip(axes[:, 0], channels):
            measured = np.asarray(getattr(data, c)[i, :n])
            scale = np.rad2deg(1.0) if c in ("psi", "r") else 1.0
            unit = {"psi": "deg", "r": "deg/s", "x": "m", "y": "m"}.get(c, "m/s")
            for label, p, style in (("before", before, "C3"), ("after", after, "C2")):
                hit = p.predicted[i, :n]
                ax.plot(t[hit], scale * (measured - p.predictions[c][i, :n])[hit], style,
                        lw=1, label=f"{label} (fit {p.metrics[c].fit_per_experiment[i]:.1f} %)")
            ax.axhline(0.0, color="0.5", lw=0.5)
            ax.set_ylabel(f"{c} residual [{unit}]")
            ax.legend(loc="upper left", fontsize=8, frameon=False)
        axes[-1, 0].set_xlabel("time [s]")
        added = ", ".join(report.named) or "nothing"
        axes[0, 0].set_title(f"{name}: measured minus simulated, before and after adding "
                             f"{added}", fontsize=9)
        fig.tight_layout()
        path = folder / _figure_name(i)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths
