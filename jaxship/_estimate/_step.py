"""The integration step follows the model: RK4 steps per sample interval enough for a
model's fastest mode (`fit`, `predict`)."""

import math

import equinox as eqx
import jax
import numpy as np

from .._foundation._exported import persistent
from .._foundation._params import as_arrays


# the most substeps the start model may ask for: beyond, a time constant that short is
# no steering dynamics the samples can show
MAX_SUBSTEPS = 64


def stable_substeps(model, windows, refuse: bool = True) -> int:
    """RK4 steps per sample interval that keep `model`'s fastest mode stable:
    $\\lceil \\rho\\,dt / 2.5 \\rceil$, $\\rho$ the largest eigenvalue modulus of the
    field's Jacobian at the first window start (`ValueError` beyond `MAX_SUBSTEPS`, with
    `refuse`)."""
    # the first window's start and inputs, indexed on the host (no dispatch per leaf)
    start = jax.tree.map(lambda a: np.asarray(a)[0, 0], windows.start)
    inputs = {k: np.asarray(a)[0, 0, 0] for k, a in windows.records.items()}
    jac = np.asarray(_field_jacobian(as_arrays(model), start, inputs, windows.servo))
    rho = float(np.max(np.abs(np.linalg.eigvals(jac)))) if np.all(np.isfinite(jac)) \
        else math.inf
    dt = float(np.max(np.asarray(windows.dt)))
    needed = max(1, math.ceil(rho * dt / 2.5)) if math.isfinite(rho) else MAX_SUBSTEPS + 1
    if needed > MAX_SUBSTEPS and refuse:
        raise ValueError(f"the start {type(model).__name__} has a time constant of "
                         f"{1 / rho:.3g} s, too short to simulate over samples {dt:g} s "
                         f"apart (it needs {needed} steps per sample); start from values "
                         "whose time constants the samples can resolve.")
    return needed


@persistent  # traced once per installation: a dozen model types in one `discover`
@eqx.filter_jit
def _field_jacobian(model, start, inputs, servo: bool):
    """The replay field's Jacobian at a window `start` with the replayed `inputs` there
    (one compilation per model type; its eigenvalues are taken on the host, where
    NumPy's LAPACK call costs nothing to compile)."""
    y0 = model.replay_state(start, servo)
    field = model.replay_field(servo)
    return jax.jacfwd(lambda y: field(0.0, y, inputs))(y0)
