"""Where a fitted model disagrees with the records: output-error residuals broken down
by record, time window, state region and turning side, and their correlation with the
signals a missing effect would follow (the first step of the discovery workflow;
Ljung 1999, sec. 16.6, residual analysis; Astrom & Kallstrom 1979, sec. 5)."""

import numpy as np
import scipy  # scipy.signal loads on first use (an import-time saving)

from ..._estimate._fit import MeasuredStates, PredictionError
from ..._estimate._predict import predict
from ..._estimate._windows import as_dataset
from ..._models._vessel._base import AbstractVessel
from ._forces import LOADS, residual_loads, smoothed_vessel_states


# state regions, each a mask over samples from the measured signals (thresholds as
# fractions of the record's own range, so the breakdown is scale-free)
REGIONS = {
    "large rudder": "rudder above half its largest angle",
    "steady turn": "yaw rate above half its largest, yaw acceleration below a tenth of its "
                   "largest",
    "reversal": "rudder moving faster than a tenth of its largest rate",
    "speed change": "surge acceleration above a fifth of its largest (needs u)",
    "straight": "yaw rate below a tenth of its largest",
}


def _rate(x, dt):
    return np.gradient(x, dt) if x.size > 2 else np.zeros_like(x)


def _regions(delta, r, u, dt) -> dict[str, np.ndarray]:
    big = lambda x, f: np.abs(x) > f * (np.max(np.abs(x)) or np.inf)
    r_dot, d_dot = _rate(r, dt), _rate(delta, dt)
    out = {"large rudder": big(delta, 0.5),
           "steady turn": big(r, 0.5) & ~big(r_dot, 0.1),
           "reversal": big(d_dot, 0.1),
           "straight": ~big(r, 0.1)}
    if u is not None:
        out["speed change"] = big(_rate(u, dt), 0.2)
    return out


def _signals(ds, e, n) -> dict[str, np.ndarray]:
    """The regressors a missing effect would follow, for record `e` (first `n` samples)."""
    have = ds.experiment_channels[e]
    get = lambda c: np.asarray(getattr(ds, c)[e, :n], dtype=float)
    out = {"delta": get("delta"), "delta rate": _rate(get("delta"), float(ds.dt[e]))}
    for c in ("r", "psi", "u", "v", "n"):
        if c in have:
            out[c] = get(c)
    if "r" in out:
        out["r|r|"] = out["r"] * np.abs(out["r"])
        out["r^3"] = out["r"] ** 3
    if "v" in out:
        out["v|v|"] = out["v"] * np.abs(out["v"])
    return out


def locate_disagreement(model, data, channels=("psi", "r"), *, window: float = 60.0,
                        wind: bool = False) -> dict:
    """Output-error residuals $e = y - \\hat y$ of `model` simulated over `data` (the
    records it was fitted to), each channel divided by the standard deviation of its
    measured record, and where they live:

    - `records`: per record and channel, fit % and residual RMS;
    - `windows`: per record, the `window`-second stretch with the largest residual
      RMS (start, end [s], RMS) against the record's RMS, over the channels other than
      the heading (whose output error accumulates all earlier ones) where there are any;
    - `regions`: per state region (`REGIONS`) the fraction of samples, the share of
      the squared residual and their ratio (above 1: the errors gather there);
    - `sides`: per channel the mean residual while turning to starboard (r > 0) and
      to port, split into the symmetric part $(\\bar e_s + \\bar e_p)/2$ (a bias: a
      rudder offset, a constant moment) and the antisymmetric part
      $(\\bar e_s - \\bar e_p)/2$ (a term odd in r: damping, rudder gain), in residual
      standard deviations;
    - `correlations`: per channel the correlation of the residual with each signal of
      `_signals` (largest over lags of up to 10 % of a record), against the 95 % band
      $1.96/\\sqrt{N}$ of independent series; `whiteness`: the fraction of residual
      autocorrelations (lags 1-25) outside that band.
    - `forces` (vessels on records with u, v and r, or psi, r, u and the track x, y;
      else None): the residual loads X, Y, N the model lacks (`residual_loads`:
      $M\\dot\\nu - \\tau$ from the smoothed measured states, or without a logged v
      the vessel's EKF + RTS smoothed states, from which the simulations then also
      start), each with its mean and RMS [N, N m], its means while turning to
      starboard and to port, and the signals it follows.

    `wind`: replay the logged wind (for a model with wind loads).
    """
    ds = as_dataset(data)
    channels = tuple(c for c in channels if all(c in h for h in ds.experiment_channels))
    vessel = isinstance(model, AbstractVessel)
    smoothed = (smoothed_vessel_states(model, ds) if vessel and not all(
        "v" in h for h in ds.experiment_channels) else None)
    out = predict(model, ds, estimator=PredictionError(
        horizon=None, channels=channels, wind=wind,
        initial=MeasuredStates() if smoothed is None else smoothed))
    fit = out.fit_per_experiment()
    res, sig, reg = {c: [] for c in channels}, {}, {}
    records, windows = {}, {}
    for e, name in enumerate(ds.names):
        n, dt = int(ds.lengths[e]), float(ds.dt[e])
        hit = np.asarray(out.predicted[e, :n] & ds.mask[e, :n])
        records[name] = {}
        for c in channels:
            y = np.asarray(getattr(ds, c)[e, :n], dtype=float)
            err = np.where(hit, (y - out.predictions[c][e, :n]) / (np.std(y[hit]) or 1.0), 0.0)
            res[c].append(err)
            records[name][c] = {"fit_percent": float(fit[name][c]),
                                "rms": float(np.sqrt(np.mean(err[hit] ** 2)))}
        # the heading's output error integrates every earlier error: windows by the rest
        local = [c for c in channels if c != "psi"] or list(channels)
        windows[name] = _worst_window(ds, e, sum(res[c][-1] ** 2 for c in local), window)
        signals = _signals(ds, e, n)
        for key, value in signals.items():
            sig.setdefault(key, []).append(value)
        u = signals.get("u")
        for key, mask in _regions(signals["delta"], signals.get("r", np.zeros(n)), u,
                                  dt).items():
            reg.setdefault(key, []).append(mask & hit)
    res = {c: np.concatenate(v) for c, v in res.items()}
    total = sum(v**2 for v in res.values())
    regions, band = _region_shares(reg, total), 1.96 / np.sqrt(total.size)
    correlations, whiteness = _residual_correlations(res, sig, ds, band)
    loads = residual_loads(model, ds, wind=wind, smoothed=smoothed) if vessel else None
    forces = None if loads is None else {
        name: _describe_load(loads[name], sig, ds, unit) for name, unit in LOADS}
    return {"records": records, "windows": windows, "regions": regions,
            "sides": _turning_sides(res, sig), "correlations": correlations,
            "band": float(band), "whiteness": whiteness,
            "regions_defined": {k: REGIONS[k] for k in regions}, "forces": forces}


def _worst_window(ds, e, total, window) -> dict | None:
    """The `window`-second stretch of record `e` with the largest mean of `total` (the
    squared residuals summed over channels), with the record's RMS; None for a record
    no longer than the window."""
    n, dt = int(ds.lengths[e]), float(ds.dt[e])
    span = max(int(round(window / dt)), 1)
    if n <= span:
        return None
    moving = np.convolve(total, np.ones(span) / span, mode="valid")
    k = int(np.argmax(moving))
    return {"start_s": float(ds.t[e, k]), "end_s": float(ds.t[e, k + span - 1]),
            "rms": float(np.sqrt(moving[k])), "record_rms": float(np.sqrt(np.mean(total)))}


def _region_shares(reg, total) -> dict:
    """Per state region: the fraction of samples in it, its share of the squared residual
    `total`, and their ratio (None for an empty region)."""
    regions = {}
    for key, masks in reg.items():
        mask = np.concatenate(masks)
        fraction = float(np.mean(mask))
        share = float(np.sum(total[mask]) / (np.sum(total) or 1.0))
        regions[key] = {"fraction": fraction, "share": share,
                        "ratio": share / fraction if fraction > 0 else None}
    return regions


def _turning_sides(res, sig) -> dict:
    """Per channel the mean residual turning to starboard (r > 0) and to port, and its
    symmetric and antisymmetric parts, in residual standard deviations (none without r)."""
    sides = {}
    if "r" not in sig:
        return sides
    r = np.concatenate(sig["r"])
    for c, e in res.items():
        s, p, spread = e[r > 0], e[r < 0], float(np.std(e)) or 1.0
        if s.size and p.size:
            ms, mp = float(np.mean(s)), float(np.mean(p))
            sides[c] = {"starboard": ms / spread, "port": mp / spread,
                        "symmetric": 0.5 * (ms + mp) / spread,
                        "antisymmetric": 0.5 * (ms - mp) / spread}
    return sides


def _residual_correlations(res, sig, ds, band):
    """Per channel the largest correlation of its residual with each signal, and the
    fraction of its autocorrelations outside `band`."""
    ends = np.cumsum([int(n) for n in ds.lengths])[:-1]
    correlations, whiteness = {}, {}
    for c, e in res.items():
        per_record = np.split(e, ends)
        correlations[c] = {k: _largest_correlation(per_record, sig[k], ds) for k in sig}
        whiteness[c] = _outside_band(per_record, band)
    return correlations, whiteness


def _describe_load(per_record, sig, ds, unit) -> dict:
    """Mean and RMS of a residual load [its unit], its means while turning to starboard
    and to port, and the signals it follows (as `correlations`)."""
    a, r = np.concatenate(per_record), np.concatenate(sig["r"])
    side = lambda m: float(np.mean(a[m])) if np.any(m) else None
    return {"unit": unit, "mean": float(np.mean(a)), "rms": float(np.sqrt(np.mean(a**2))),
            "starboard": side(r > 0), "port": side(r < 0),
            "correlations": {k: _largest_correlation(per_record, sig[k], ds) for k in sig}}


def _lagged(residuals, signals, max_lag, centre) -> np.ndarray:
    """|correlation| of the residuals with the signals `lag` samples earlier, for each
    lag 0..`max_lag`, pooled over records (the signals' mean over the samples paired
    at that lag removed when `centre`); 0 where either is zero. The sums over lags
    come from each record's cross-correlation (`scipy.signal.correlate`) and prefix
    sums, not from a copy of the records per lag."""
    lags = np.arange(max_lag + 1)
    ab, aa, a1, bb, b1, num = (np.zeros(lags.size) for _ in range(6))
    # centring is unchanged by a shift: the pooled mean first, so that the sums below
    # do not cancel
    shift = float(np.mean(np.concatenate(signals))) if centre else 0.0
    for e, x in zip(residuals, signals):
        x, n = x - shift, e.size
        k = lags[lags < n]  # lags a record is too short for add nothing
        tail = lambda v: np.cumsum(v[::-1])[::-1][k]  # sum of v[k:]
        head = lambda v: np.cumsum(v)[n - 1 - k]  # sum of v[:n - k]
        ab[k] += scipy.signal.correlate(e, x, mode="full")[n - 1 + k]
        aa[k] += tail(e * e)
        a1[k] += tail(e)
        bb[k] += head(x * x)
        b1[k] += head(x)
        num[k] += n - k
    if centre:  # sum a (b - m) and sum (b - m)^2 with m = sum b / num
        mean = np.divide(b1, num, out=np.zeros_like(b1), where=num > 0)
        varied = bb - mean * b1
        # a constant signal (a logged rpm held fixed) centres to rounding: zero
        ab, bb = ab - mean * a1, np.where(varied > 1e-12 * bb, varied, 0.0)
    denominator = np.sqrt(aa * bb)
    return np.abs(np.divide(ab, denominator, out=np.zeros_like(ab), where=denominator > 0))


def _largest_correlation(residuals, signals, ds) -> float:
    """The largest |correlation| of residual and signal over lags 0..10 % of the
    shortest record (signal leading), pooled over records."""
    lags = max(1, min(int(n) for n in ds.lengths) // 10)
    return float(np.max(_lagged(residuals, signals, lags, True)))


def _outside_band(residuals, band, lags=25) -> float:
    """Fraction of the residual autocorrelations at lags 1..`lags` outside the band."""
    return float(np.sum(_lagged(residuals, residuals, lags, False)[1:] > band)) / lags
