"""Output-error simulation of an identified model on records, from each record's
measured first state: `simulate_records` for steering models and 3-DOF vessels,
`simulate_armax_records` for the discrete ARMAX model; both return
`({channel: (E, N) array}, mask (E, N))`."""

from __future__ import annotations

import math

import numpy as np

import jaxship as js

from ... import ARMAXModel


def simulate_records(model, dataset: js.Dataset, rudder: str, channels=("psi", "r"),
                     substeps: int = 1, wind: bool = False):
    """Output-error simulation of a steering model or a 3-DOF vessel on every record
    of `dataset`, each from its measured state at the first sample (hidden states by
    the model's `window_state`), driven by the recorded `rudder` and the other
    recorded inputs (`jaxship.predict` with horizon None), with the logged wind
    replayed if `wind`.

    `channels`: `"psi"`, `"r"` and names of model states (e.g. a sway velocity `"v"`).

    **Returns:** `({channel: (E, N) array}, mask (E, N))`; the first sample of each
    record (the start value) and the padding are not in the mask."""
    if isinstance(model, js.AbstractSteeringModel):
        unknown = [c for c in channels if c not in ("psi", "r") + tuple(model.state_names)]
        if unknown:
            raise ValueError(f"{type(model).__name__} has no output {unknown[0]!r}; its outputs "
                             f"are psi, r and its states {', '.join(model.state_names)}.")
    out = js.predict(model, dataset, estimator=js.PredictionError(
        horizon=None, channels=tuple(channels), rudder=rudder, wind=bool(wind),
        simulator=js.Simulator(max_step=math.inf, substeps=int(substeps))))
    return out.predictions, np.asarray(out.predicted, dtype=bool)


def simulate_armax_records(model: ARMAXModel, dataset: js.Dataset, rudder: str,
                           channels=("psi", "r"), substeps: int = 1, wind: bool = False):
    """Output-error simulation of an `ARMAXModel` on every record (the noise-free
    part $A r = B\\delta(t - n_k)$, `simulate_armax`): the recursion starts at the
    measured r of the first sample, with r and the rudder before it held at their
    first values; psi integrates the simulated r (trapezoid rule) from the measured
    first heading. `substeps` and `wind` are unused (a discrete model without wind
    loads). Returns `(predictions, mask)` as `simulate_records`."""
    lengths = np.asarray(dataset.lengths)
    valid = np.arange(dataset.num_samples)[None, :] < lengths[:, None]
    r_measured = np.asarray(dataset.r, dtype=np.float64)
    rudder_values = np.asarray(getattr(dataset, rudder), dtype=np.float64)
    r = model.response(np.where(valid, rudder_values, 0.0), r_measured[:, 0])
    dt = np.asarray(dataset.dt, dtype=np.float64)[:, None]
    steps = 0.5 * dt * (r[:, 1:] + r[:, :-1])
    psi = np.asarray(dataset.psi, dtype=np.float64)[:, :1] + np.concatenate(
        [np.zeros_like(dt), np.cumsum(steps, axis=1)], axis=1)
    out = {"r": np.where(valid, r, 0.0), "psi": np.where(valid, psi, 0.0)}
    mask = valid.copy()
    mask[:, 0] = False
    return {c: out[c] for c in channels}, mask
