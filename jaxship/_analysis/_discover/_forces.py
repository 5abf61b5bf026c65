"""Residual loads of a vessel along measured records: the surge force, sway force and
yaw moment its model lacks, from the measured states and their smoothed derivatives.

The equations of motion $M\\dot\\nu = \\tau(\\nu, \\delta, n)$ (Fossen 2021, eq. 6.1;
jaxship's vessels put the Coriolis terms in $\\tau$) solved for what is missing,
$\\tau_{miss} = M\\dot\\nu - \\tau - \\tau_{wind}$, with $\\nu = (u, v, r)$ measured and
$\\dot\\nu$ from a Savitzky-Golay smoother (cubic, least squares over a sliding window;
Savitzky & Golay 1964). Where u, v and r are all logged, every state is measured and
the smoother of each channel is the smoothed state. Where v is not logged but psi, r, u
and the track x, y are, the velocities are the vessel's smoothed states (`jaxship.smooth_states`:
EKF and RTS smoother of the vessel measuring those; the track makes the drift
observable), with a process noise that lets them leave the model's prediction as a
random walk of 2e-4 (m/s)^2 per second (`ACCELERATION_NOISE`): the missing loads move
the states, so a filter that trusted the model would hide them.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import scipy  # scipy.signal loads on first use (an import-time saving)

from ..._estimate._kalman import _augmented_names, smooth_states
from ..._estimate._windows import as_dataset
from ..._foundation._params import as_arrays
from ..._models._environment import Wind


LOADS = (("X", "N"), ("Y", "N"), ("N", "N m"))  # name, unit
# [m^2/s^3] spectral density of the unexplained surge and sway accelerations the filter
# allows (yaw: divided by L^2): a variance of 1e-4 (m/s)^2 per 0.5 s interval. On Mariner
# records without v it recovers a hidden 30 kN sway force or 3 MN m yaw moment within
# 3 %, where a hundred times less recovers 89 % and 53 % of them: a filter that trusts
# the model hides what it lacks (tests/test_discover.py)
ACCELERATION_NOISE = 2e-4
FILTERED = ("psi", "r", "u", "x", "y")  # what the filter measures where v is not logged


def _noise(a, span) -> float:
    """Measurement-noise variance of one channel: the variance of what a cubic
    Savitzky-Golay smoother over `span` samples leaves (floored for exact data)."""
    rest = a - scipy.signal.savgol_filter(a, span, 3)
    return max(float(np.var(rest)), 1e-12 * (float(np.var(a)) + 1e-12))


def _span(smoothing, dt) -> int:
    return 2 * int(round(0.5 * smoothing / dt)) + 1


def smoothed_vessel_states(vessel, data, *, smoothing: float = 10.0):
    """`SmoothedStates` (`_estimate._kalman`) of `vessel` for every record of `data`, each measuring
    psi, r, u and the track x, y (module docstring; measurement noise: what a cubic
    Savitzky-Golay smoother over `smoothing` seconds leaves of each channel; the prior:
    the first sample's measured states, the drift unknown to 10 % of the speed). None
    when a record lacks one of those channels or is shorter than `smoothing`."""
    ds = as_dataset(data)
    out = []
    for e in range(ds.num_experiments):
        record, dt = ds.experiment(e), float(ds.dt[e])
        span = _span(smoothing, dt)
        if not set(FILTERED) <= set(record.channels) or not 5 <= span <= record.t.size:
            return None
        q = ACCELERATION_NOISE * dt
        process = {"u": q, "v": q, "r": q / float(vessel.length) ** 2}
        noise = {c: _noise(np.asarray(getattr(record, c), dtype=np.float64), span)
                 for c in FILTERED}
        prior = {**noise, "v": (0.1 * float(record.u[0])) ** 2}
        start = np.diag([prior.get(name, 0.0) for name in _augmented_names(vessel)])
        out += smooth_states(vessel, record, process_noise=process, measurement_noise=noise,
                             channels=FILTERED, initial_covariance=start)
    return out


def residual_loads(vessel, data, *, smoothing: float = 10.0, wind: bool = False,
                   smoothed=None):
    """`{"X", "Y", "N"}`: per record an array of the missing loads [N, N, N m] at its
    samples, $M\\dot\\nu - \\tau(\\nu, \\delta, n)$ (minus the wind loads of the logged
    wind with `wind`), $\\dot\\nu$ the derivative of a cubic Savitzky-Golay fit over
    `smoothing` seconds; where a record lacks v, u, v, r of every record are the
    vessel's smoothed states (`smoothed`, or else `smoothed_vessel_states`). None when
    a record lacks u, v or r and the smoothed states cannot be had, or is shorter than
    `smoothing`."""
    ds = as_dataset(data)
    mass = np.asarray(vessel.mass_matrix())
    out = {name: [] for name, _ in LOADS}
    logged = all({"u", "v", "r"} <= set(have) for have in ds.experiment_channels)
    if not logged:
        smoothed = smoothed or smoothed_vessel_states(vessel, ds, smoothing=smoothing)
        if smoothed is None:
            return None
    records = []
    for e in range(ds.num_experiments):
        n, dt = int(ds.lengths[e]), float(ds.dt[e])
        span = _span(smoothing, dt)
        if span < 5 or span > n:
            return None
        get = lambda c, e=e, n=n: np.asarray(getattr(ds, c)[e, :n], dtype=np.float64)
        nu = np.stack([get("u"), get("v"), get("r")] if logged else
                      [smoothed[e].state(c) for c in ("u", "v", "r")])
        records.append((get, nu, span, dt))
    # the loads of every record's samples in one program (op by op, each operation of the
    # vessel's loads was a program to lower and look up: 250 in the README's `discover`)
    signals = [np.concatenate(parts) for parts in zip(*[
        (get("t"), *nu, get("delta"), get("n")) for get, nu, _, _ in records])]
    loads = np.split(np.asarray(_sample_loads(as_arrays(vessel), *signals)),
                     np.cumsum([nu.shape[1] for _, nu, _, _ in records])[:-1], axis=0)
    for (get, nu, span, dt), tau in zip(records, loads):
        nu_dot = scipy.signal.savgol_filter(nu, span, 3, deriv=1, delta=dt, axis=1)
        tau = tau.T
        if wind:
            gust = Wind(jnp.asarray(get("wind_speed")), jnp.asarray(get("wind_dir")))
            tau = tau + np.stack(np.broadcast_arrays(*gust.loads(
                nu[0], nu[1], get("psi"), vessel.frontal_wind_area, vessel.lateral_wind_area,
                vessel.length)))
        missing = mass @ nu_dot - tau
        for i, (name, _) in enumerate(LOADS):
            out[name].append(missing[i])
    return out


@eqx.filter_jit
def _sample_loads(vessel, *signals):
    """`vessel.loads` sample by sample (N, 3) of the signals (t, u, v, r, delta, n) (N,)."""
    return jax.vmap(vessel.loads)(*signals)
