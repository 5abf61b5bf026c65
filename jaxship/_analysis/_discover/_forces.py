"""Residual loads of a vessel along measured records: the surge force, sway force and
yaw moment its model lacks, from the measured states and their smoothed derivatives.

The equations of motion $M\\dot\\nu = \\tau(\\nu, \\delta, n)$ (Fossen 2021, eq. 6.1;
jaxship's vessels put the Coriolis terms in $\\tau$) solved for what is missing,
$\\tau_{miss} = M\\dot\\nu - \\tau - \\tau_{wind}$, with $\\nu = (u, v, r)$ measured and
$\\dot\\nu$ from a Savitzky-Golay smoother (cubic, least squares over a sliding window;
Savitzky & Golay 1964). Where u, v and r are all logged this is the smoothed-state
route of the discovery design without a filter: every state is measured, so the
smoother of each channel is the smoothed state.
"""

import jax
import jax.numpy as jnp
import numpy as np
from scipy.signal import savgol_filter

from ..._estimate._windows import as_dataset
from ..._models._environment import Wind


LOADS = (("X", "N"), ("Y", "N"), ("N", "N m"))  # name, unit


def residual_loads(vessel, data, *, smoothing: float = 10.0, wind: bool = False):
    """`{"X", "Y", "N"}`: per record an array of the missing loads [N, N, N m] at its
    samples, $M\\dot\\nu - \\tau(\\nu, \\delta, n)$ (minus the wind loads of the logged
    wind with `wind`), $\\dot\\nu$ the derivative of a cubic Savitzky-Golay fit over
    `smoothing` seconds. None when a record lacks u, v or r, or is shorter than that."""
    ds = as_dataset(data)
    mass = np.asarray(vessel.mass_matrix())
    out = {name: [] for name, _ in LOADS}
    for e in range(ds.num_experiments):
        if not {"u", "v", "r"} <= set(ds.experiment_channels[e]):
            return None
        n, dt = int(ds.lengths[e]), float(ds.dt[e])
        span = 2 * int(round(0.5 * smoothing / dt)) + 1
        if span < 5 or span > n:
            return None
        get = lambda c: np.asarray(getattr(ds, c)[e, :n], dtype=np.float64)
        nu = np.stack([get("u"), get("v"), get("r")])
        nu_dot = savgol_filter(nu, span, 3, deriv=1, delta=dt, axis=1)
        signals = [jnp.asarray(a) for a in (get("t"), *nu, get("delta"), get("n"))]
        tau = np.asarray(jax.vmap(vessel.loads)(*signals)).T  # sample by sample
        if wind:
            gust = Wind(jnp.asarray(get("wind_speed")), jnp.asarray(get("wind_dir")))
            tau = tau + np.stack(np.broadcast_arrays(*gust.loads(
                nu[0], nu[1], get("psi"), vessel.frontal_wind_area, vessel.lateral_wind_area,
                vessel.length)))
        missing = mass @ nu_dot - tau
        for i, (name, _) in enumerate(LOADS):
            out[name].append(missing[i])
    return out
