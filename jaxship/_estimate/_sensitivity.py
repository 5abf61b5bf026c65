"""Residuals and their sensitivities at a model's current parameter values, laid out
for tests on the fit (the score tests of `jaxship.discover`).

The residuals are those `fit` minimises with the same estimator (weighted, per
channel and prediction window); the sensitivities are forward-mode derivatives with
respect to named parameters (`"K"`, `"rudder_offset.delta0"`, ...), or, for a
parameter whose derivative at its current value is not informative (a lag switched
off below a threshold), the secant $(e(\\beta_p) - e(\\beta_0))/(\\beta_p - \\beta_0)$
to a probe value $\\beta_p$.
"""

import dataclasses

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from .._foundation._contract import get_path, rebuild
from .._foundation._exported import persistent
from .._simulation._simulate import _as_arrays as as_arrays
from ._fit import _residuals
from ._lm import blockwise_jacfwd, value_and_jacfwd
from ._prepare import prepare_fit
from ._step import MAX_SUBSTEPS, stable_substeps


@dataclasses.dataclass(frozen=True)
class Sensitivities:
    """Residual rows and their Jacobian at the model's values.

    - `residuals` (N,): the weighted residuals at valid window samples (channels
      stacked), as `fit` sees them;
    - `jacobian` (N, d): their derivatives with respect to `names`;
    - `channel`, `experiment`, `window`, `sample` (N,): where each row comes from
      (`sample`: its index in the experiment's timeline);
    - `num_samples`: the timeline length; `channels`: the channel names."""

    names: tuple[str, ...]
    residuals: np.ndarray
    jacobian: np.ndarray
    channel: np.ndarray
    experiment: np.ndarray
    window: np.ndarray
    sample: np.ndarray
    num_samples: int
    channels: tuple[str, ...]

    @property
    def cost(self) -> float:
        """$\\frac12\\sum e^2$, the cost `fit` reports."""
        return 0.5 * float(np.sum(self.residuals**2))


def _evaluate(q, model, names, windows, shape):
    """Residuals at the parameters q[:d] (and window-start offsets q[d:], if any)."""
    d = len(names)
    offsets = jnp.reshape(q[d:], shape) if shape is not None else None
    return _residuals(rebuild(model, names, q[:d]), windows, offsets)


@persistent  # traced once per installation
@eqx.filter_jit
def _residual_jacobian(q, model, names, windows, shape):
    f = lambda x: _evaluate(x, model, names, windows, shape)
    if shape is None:
        return value_and_jacfwd(f, q)
    return blockwise_jacfwd(len(names), shape[:-1])(f, q)  # each window's own offsets


_residuals_at = eqx.filter_jit(_evaluate)


def sensitivities(model, dataset, estimator, names, probes=None,
                  start_offsets=None) -> Sensitivities:
    """Residuals of `model` on `dataset` under `estimator` (a `PredictionError`) and
    their Jacobian with respect to the parameters `names` at the model's values.
    `probes`: `{name: value}` for parameters differentiated by a secant to `value`.
    `start_offsets` (E, W, 2): the window-start corrections of a fit with
    `initial=EstimatedStarts()` (`FitResult.start_offsets`); they are differentiated too, as
    the parameters `"start[k]"` (appended to `names`). The integration step follows
    the fastest mode of the model and of each probe, as in `fit`."""
    probes = dict(probes or {})
    ds, windows, layout = prepare_fit(model, dataset, estimator)
    base = as_arrays(model)
    names = tuple(names)
    probed = [rebuild(base, (k,), (float(v),)) for k, v in probes.items()]
    needed = min(MAX_SUBSTEPS, max(stable_substeps(m, windows, refuse=False)
                                   for m in [base, *probed]))
    if needed > windows.substeps:
        windows = dataclasses.replace(windows, substeps=needed)
    p0 = jnp.asarray([float(get_path(model, n)) for n in names], dtype=float)
    shape = None
    if start_offsets is not None:
        offsets = np.asarray(start_offsets, dtype=np.float64)
        shape = offsets.shape
        p0 = jnp.concatenate([p0, jnp.asarray(offsets.reshape(-1))])
    res, jac = _residual_jacobian(p0, base, names, windows, shape)
    res, jac = np.asarray(res, np.float64), np.array(jac, np.float64)
    for name, value in probes.items():
        i = names.index(name)
        step = float(value) - float(p0[i])
        moved = np.asarray(_residuals_at(p0.at[i].set(float(value)), base, names, windows,
                                         shape))
        jac[..., i] = (moved - res) / step
    mask = layout["mask"]
    target = np.asarray(layout["target"])
    num_channels = res.shape[0]
    e_idx, w_idx, _ = np.indices(mask.shape)
    rows = lambda a: np.concatenate([a[c][mask] for c in range(num_channels)])
    repeat = lambda a: np.tile(a[mask], num_channels)
    if shape is not None:
        names = names + tuple(f"start[{k}]" for k in range(int(np.prod(shape))))
    return Sensitivities(
        names=names, residuals=rows(res), jacobian=rows(jac),
        channel=np.repeat(np.arange(num_channels), int(mask.sum())),
        experiment=repeat(e_idx), window=repeat(e_idx * mask.shape[1] + w_idx),
        sample=repeat(target), num_samples=int(ds.num_samples),
        channels=tuple(windows.channels))
