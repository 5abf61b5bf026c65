"""Held-out checks of a discovery: the cost and fit % of a model simulated over
records it was not fitted to (output error; positions over windows), and the
manoeuvre indices of each record, measured and predicted."""

import numpy as np

from ..._estimate._fit import MeasuredStates, PredictionError
from ..._estimate._predict import predict
from ..._estimate._windows import as_dataset
from .._indices import turning_indices, zigzag_indices
from .._indices._series import _peak


def holdout_check(model, holdout, channels, wind: bool = False, window=None,
                  initial=MeasuredStates()) -> dict:
    """Output-error predictions of `holdout` by `model` (with the logged wind replayed
    if `wind`): `cost` (half the sum of squared residuals, each channel divided by the
    standard deviation of its measured record, so models compare on one scale),
    `fit_percent` per channel, the predicted timelines `predictions`
    `{channel: (E, N)}` and each sample's share of the cost `terms` (E, N, with `t`
    and `mask`). Positions x, y are predicted over `window`-second stretches from
    the measured state (None: whole records too): over a whole record a position
    integrates every heading error before it, which the heading's own residual
    already counts, while a window shows the drift a current or a heading bias makes.
    `initial`: where predictions start (`PredictionError.initial`: smoothed states
    where a vessel's records lack v)."""
    ds = as_dataset(holdout)
    tracks = tuple(c for c in channels if c in ("x", "y") and window is not None)
    parts = [(None, tuple(c for c in channels if c not in tracks)), (window, tracks)]
    fit, filled, terms = {}, {}, np.zeros(ds.mask.shape)
    for horizon, group in (part for part in parts if part[1]):
        out = predict(model, ds, estimator=PredictionError(horizon=horizon, channels=group,
                                                           wind=wind, initial=initial))
        fit.update(out.fit_percent())
        for c in group:
            measured = np.asarray(getattr(ds, c), dtype=np.float64)
            hit = out.predicted & ds.mask
            scale = float(np.std(measured[hit])) or 1.0
            terms += np.where(hit, 0.5 * ((measured - out.predictions[c]) / scale) ** 2, 0.0)
            filled[c] = np.where(out.predicted, out.predictions[c], measured)  # start samples
    return {"cost": float(terms.sum()), "fit_percent": fit, "predictions": filled,
            "terms": terms, "t": np.asarray(ds.t), "mask": np.asarray(ds.mask)}


def cost_rise(before: dict, after: dict, block: float) -> tuple[float, float]:
    r"""The held-out cost's change $\Delta = C_{after} - C_{before}$ and its standard error
    $\sqrt{\tfrac{B}{B-1} \sum_b (\Delta_b - \bar\Delta)^2}$ over the B stretches of
    `block` seconds of each record (`holdout_check` outputs). A disturbance that moves
    the heading for less than a block makes the stretches' changes about independent,
    so a rise within a couple of standard errors is the disturbance's, not the model's
    (the cluster-robust variance of a sum, with the stretches as clusters)."""
    t, mask = after["t"], after["mask"]
    stretch = np.floor((t - t[:, :1]) / block).astype(int)[mask]
    record = np.broadcast_to(np.arange(t.shape[0])[:, None], t.shape)[mask]
    _, keys = np.unique(np.stack([record, stretch]), axis=1, return_inverse=True)
    change = np.bincount(keys.ravel(), (after["terms"] - before["terms"])[mask])
    spread = np.sqrt(change.size / max(change.size - 1, 1) * np.sum((change - change.mean()) ** 2))
    return float(change.sum()), float(spread)


def _track(t, psi, u, v):
    """North-east positions from speed through water and heading (trapezoid rule)."""
    xdot = u * np.cos(psi) - v * np.sin(psi)
    ydot = u * np.sin(psi) + v * np.cos(psi)
    step = np.diff(t)
    x = np.concatenate([[0.0], np.cumsum(0.5 * step * (xdot[1:] + xdot[:-1]))])
    y = np.concatenate([[0.0], np.cumsum(0.5 * step * (ydot[1:] + ydot[:-1]))])
    return x, y


def record_kind(delta) -> str | None:
    """`"zigzag"` when the rudder reverses at least twice with one amplitude,
    `"turn"` when it goes to one side and stays, else None."""
    delta = np.asarray(delta, dtype=float)
    amplitude = float(np.max(np.abs(delta)))
    if amplitude < np.deg2rad(2.0):
        return None
    large = delta[np.abs(delta) > 0.5 * amplitude]
    reversals = int(np.sum(np.diff(np.sign(large)) != 0))
    if reversals >= 2:
        return "zigzag"
    if reversals == 0 and np.mean(np.abs(delta[-len(delta) // 3:])) > 0.5 * amplitude:
        return "turn"
    return None


def record_indices(t, delta, psi, u=None, v=None, measured_psi=None) -> dict:
    """The indices of one record [deg, m]: a zig-zag's first and second overshoots, a
    turn's advance and tactical diameter (track from u, v and the heading). Empty when
    neither. A zig-zag's heading switch is the rudder amplitude (as in x/x zig-zags),
    its first execute and side are read from the `measured_psi` (default `psi`) and the
    rudder, its reversals from the rudder; each overshoot is the peak heading change
    from the first execute between one reversal and the next, less the switch. On the
    measured heading that is the IMO overshoot; a prediction replaying the logged
    rudder is measured the same way, even where its heading never reaches the switch
    (it then comes out negative)."""
    kind = record_kind(delta)
    try:
        if kind == "zigzag":
            large = np.flatnonzero(np.abs(delta) > 0.5 * np.max(np.abs(delta)))
            switch = float(np.median(np.abs(delta[large])))
            z = zigzag_indices(heading_switch=switch, t=t, delta=delta,  # the first execute
                               psi=psi if measured_psi is None else measured_psi)
            change = z.side * (psi - np.interp(z.execute_times[0], t, psi))
            # the rudder's reversals: where it leaves the half of its way on one side
            bounds = np.append(large[:-1][np.diff(np.sign(delta[large])) != 0], t.size)
            out = {}
            for k in (1, 2):  # after the first and the second reversal
                if k > bounds.size - 1:
                    break
                _, peak, interior = _peak(t, (-1) ** (k + 1) * change,  # its turning side
                                          t[bounds[k - 1]], t[bounds[k] - 1])
                if bounds[k] == t.size and not interior:
                    break  # the record ends before the heading turns back
                out[f"overshoot_{k}_deg"] = float(np.rad2deg(peak - switch))
            return out
        if kind == "turn" and u is not None and v is not None:
            x, y = _track(t, psi, u, v)
            ti = turning_indices(t=t, x=x, y=y, psi=psi, u=u, v=v, delta=delta)
            return {"advance_m": float(ti.advance),
                    "tactical_diameter_m": float(ti.tactical_diameter)}
    except ValueError:  # the record does not complete the manoeuvre
        return {}
    return {}


def holdout_indices(holdout, before: dict, after: dict) -> dict:
    """`{record: {index: {"measured", "before", "after"}}}` from the measured records
    and the predictions of the base and the augmented models."""
    ds = as_dataset(holdout)
    out = {}
    for i, name in enumerate(ds.names):
        n = int(ds.lengths[i])
        t = np.asarray(ds.t[i, :n])
        delta = np.asarray(ds.delta[i, :n])
        measured_uv = "u" in ds.experiment_channels[i] and "v" in ds.experiment_channels[i]
        u = np.asarray(ds.u[i, :n]) if measured_uv else None
        v = np.asarray(ds.v[i, :n]) if measured_uv else None
        psi = np.asarray(ds.psi[i, :n])

        def indices(source, u=u, v=v):
            if source and "u" in source and "v" in source:
                u, v = np.asarray(source["u"][i, :n]), np.asarray(source["v"][i, :n])
            return record_indices(t, delta, np.asarray(source["psi"][i, :n]) if source else psi,
                                  u, v, measured_psi=psi)

        measured = indices(None)
        b, a = indices(before), indices(after)
        out[name] = {k: {"measured": measured[k], "before": b.get(k), "after": a.get(k)}
                     for k in measured}
    return out
