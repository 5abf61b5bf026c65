"""Assessment of an identified model on records: its outputs (the fit criterion or an
output-error simulation) with loss, FPE, AIC/BIC, fit % and residual tests per channel,
and their JSON form."""

from __future__ import annotations

import dataclasses

import numpy as np

import jaxship as js


CHANNEL_UNITS = {"psi": "rad", "r": "rad/s", "u": "m/s", "v": "m/s"}


@dataclasses.dataclass(frozen=True)
class Assessment:
    """A model's outputs on a set of records and their validation figures.

    - `kind`: `"prediction"` (the fit criterion: windows of `horizon` seconds from
      the measured state) or `"simulation"` (output error from the first sample);
    - `horizon`: the prediction horizon [s] (None for output error);
    - `data`: the `Dataset`; `rudder`: its replayed rudder channel;
    - `start`: `"measured"` (each window starts from the measured r, psi) or
      `"estimated"` (the fit estimated corrections of them);
    - `predictions`: `{channel: (E, N) array}` [rad, rad/s]; `mask`: (E, N) samples
      that were predicted;
    - `metrics`: `{channel: ValidationReport}` (loss, FPE, AIC, BIC, fit %,
      whiteness and residual-input tests).
    """

    kind: str
    horizon: float | None
    data: js.Dataset
    rudder: str
    predictions: dict
    mask: np.ndarray
    metrics: dict
    start: str = "measured"

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.data.names)

    def residuals(self, channel: str) -> np.ndarray:
        """Measured minus predicted `channel`, (E, N), 0 where not predicted."""
        measured = np.asarray(getattr(self.data, channel), dtype=np.float64)
        return np.where(self.mask, measured - self.predictions[channel], 0.0)

    def to_dict(self) -> dict:
        """JSON-ready: kind, horizon, experiments and per-channel figures."""
        return {
            "kind": self.kind,
            "horizon_s": self.horizon,
            "start": self.start,
            "rudder": self.rudder,
            "experiments": list(self.names),
            "channels": {c: _metrics_dict(m, self.names) for c, m in self.metrics.items()},
        }


def _test_dict(corr) -> dict | None:
    if corr is None:
        return None
    test = corr.to_dict()
    return {
        "passed": test["passed"],
        "statistic": test["statistic"],
        "threshold_99": test["threshold"],
        "band_99": test["band"],
        "max_lag": int(np.max(np.abs(corr.lags))),
        "lags_outside_band": test["num_outside"],
    }


def _metrics_dict(m, names) -> dict:
    unit = CHANNEL_UNITS.get(m.channel, "")
    plain = m.to_dict()
    return {
        "unit": unit,
        "loss": plain["loss"],
        "loss_unit": f"({unit})^2" if unit else "",
        **{k: plain[k] for k in ("fpe", "aic", "bic", "fit_percent")},
        "fit_percent_per_experiment": dict(zip(names, plain["fit_per_experiment"])),
        **{k: plain[k] for k in ("rms", "mean", "num_samples", "num_params")},
        "whiteness": _test_dict(m.autocorrelation),
        "input_independence": _test_dict(m.cross_correlation),
    }


def assess(kind, horizon, ds, rudder, predicted, sizes, notes=None,
           start="measured") -> Assessment:
    """The `Assessment` of the `predicted = (predictions, mask)` on `ds`, with `sizes =
    (num_params, max_lag)` of the residual tests. A record whose outputs become
    non-finite is assessed on the samples before (and a note says so)."""
    predictions, mask = predicted
    num_params, max_lag = sizes
    u = np.asarray(getattr(ds, rudder), dtype=np.float64)
    mask = np.array(mask, dtype=bool)
    bad = np.zeros(mask.shape, dtype=bool)
    for yhat in predictions.values():
        bad |= mask & ~np.isfinite(yhat)
    for i in np.nonzero(bad.any(axis=1))[0]:  # keep the samples before the blow-up
        k = int(np.argmax(bad[i]))
        mask[i, k:] = False
        if notes is not None:
            notes.append(f"the {kind} of record {ds.names[i]!r} diverged at t = "
                         f"{float(ds.t[i, k]):.6g} s (non-finite outputs); its metrics use the "
                         "samples before.")
    metrics = {}
    for c, yhat in predictions.items():
        measured = np.asarray(getattr(ds, c), dtype=np.float64)
        metrics[c] = js.validate(measured, yhat, mask, num_params=num_params, u=u,
                                 max_lag=max_lag, channel=c)
    return Assessment(kind, horizon, ds, rudder, dict(predictions), mask, metrics, start)
