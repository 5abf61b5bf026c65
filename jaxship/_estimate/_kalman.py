"""State estimation of steering models and vessels: extended Kalman filter and
Rauch-Tung-Striebel smoother (the innovations-form (PEM) and maximum-likelihood
fits of steering models on top of them are in `jaxship._estimate._likelihood`).

**Model.** The filter works on the state $z$ that `fit` simulates (the model contract
shared by steering models and vessels: `replay_state`, `replay_field`,
`channel_index`): for a steering model $z = (x, \\psi)$ (`state_names` followed by the
heading), for a vessel $z = (u, v, r, x, y, \\psi, \\delta, n)$ and its effects' states
(the replayed $\\delta$ and $n$ do not move). Over one sample interval the recorded
rudder and auxiliary inputs are replayed as `fit` replays them (the measured angle
linear between $\\delta_k$ and $\\delta_{k+1}$, a command held) and the interval map
$F$ is the simulator's time loop over the interval
(`jaxship._simulation._integrate.integrate`, the same numerics as `simulate` and `fit`):

$$z_{k+1} = F(z_k, \\delta_k + w_k) + v_k, \\qquad y_k = h(z_k) + e_k,$$

with $w_k \\sim N(0, q_\\delta)$ a rudder-equivalent disturbance held over the interval
(any yaw moment acting like the rudder: waves, wind), $v_k \\sim N(0, Q)$ a disturbance
on the states, and $e_k \\sim N(0, R)$ the measurement noise of the channels
(unwrapped heading and yaw rate $y = (\\psi, r)$; for a vessel also u, v, x, y).
Linearised, the process noise of an interval is $Q_k = Q + q_\\delta B_kB_k^T$,
$B_k = \\partial F/\\partial\\delta$.

**Filter** (Simon 2006, sec. 13.2; Sarkka 2013, alg. 5.4), with
$A_k = \\partial F/\\partial z$ by `jax.jacfwd` of the interval map:

$$\\hat z_{k|k-1} = F(\\hat z_{k-1|k-1}, \\delta_{k-1}), \\quad
P_{k|k-1} = A P_{k-1|k-1} A^T + Q_k,$$
$$\\varepsilon_k = y_k - h(\\hat z_{k|k-1}), \\quad S_k = H P_{k|k-1} H^T + R, \\quad
K_k = P_{k|k-1} H^T S_k^{-1},$$
$$\\hat z_{k|k} = \\hat z_{k|k-1} + K_k\\varepsilon_k, \\quad
P_{k|k} = (I - K_kH)P_{k|k-1}(I - K_kH)^T + K_kRK_k^T \\;\\text{(Joseph form)}.$$

The innovations $\\varepsilon_k$ are the one-step-ahead prediction errors of the
innovations-form predictor (Ljung 1999, sec. 4.3, eq. 4.84-4.87); for a linear model
with stationary noise the gain $K_k$ converges to the stationary Kalman gain. Sample 0
is the prior: the model's `replay_state` of the first record sample (as `fit` starts),
with covariance $P_0$; samples 1..N-1 are predicted and updated; masked (padded)
samples are predicted without update and add nothing to the likelihood.

**Likelihood** (Ljung 1999, eq. 7.86-7.88; Astrom & Kallstrom 1979 fitted ship steering
models by this approximate maximum likelihood with the Kalman filter):

$$-\\log L = \\tfrac12\\sum_k \\left(\\log\\det S_k + \\varepsilon_k^TS_k^{-1}\\varepsilon_k
+ C\\log 2\\pi\\right).$$

**Smoother** (Rauch, Tung & Striebel 1965; Sarkka 2013, alg. 9.3 for the extended form):
$G_k = P_{k|k}A_{k+1}^TP_{k+1|k}^{-1}$,
$\\hat z_{k|N} = \\hat z_{k|k} + G_k(\\hat z_{k+1|N} - \\hat z_{k+1|k})$,
$P_{k|N} = P_{k|k} + G_k(P_{k+1|N} - P_{k+1|k})G_k^T$.
"""

import dataclasses
import math
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._foundation._params import as_arrays
from .._foundation._state import STATE_FIELDS
from .._models._steering._base import AbstractSteeringModel, AuxInputs, WindowStart
from .._models._vessel._base import AbstractVessel
from .._simulation._data import Experiment
from .._simulation._integrate import Held, Simulator, integrate
from ._windows import as_dataset, check_data, resolve_holds


KALMAN_CHANNELS = ("psi", "r")
VESSEL_CHANNELS = ("psi", "r", "u", "v", "x", "y")  # what a vessel's filter can measure
REPLAYED = ("delta", "u", "v", "n")  # the recorded inputs (a vessel reads delta and n)
_LOG_2PI = math.log(2.0 * math.pi)


# -- noise specifications (host side) -------------------------------------------------


def _augmented_names(model) -> tuple[str, ...]:
    """Names of the filtered state z (module docstring)."""
    if isinstance(model, AbstractSteeringModel):
        return tuple(model.state_names) + ("psi",)
    return STATE_FIELDS + tuple(f"{e.id}.{name}" for e in getattr(model, "effects", ())
                                for name in e.state_names)


def _check_channels(model, channels) -> tuple[str, ...]:
    if isinstance(channels, str):
        channels = (channels,)
    channels = tuple(channels)
    allowed = KALMAN_CHANNELS if isinstance(model, AbstractSteeringModel) else VESSEL_CHANNELS
    if not channels:
        raise ValueError(f"`channels` is empty; choose from {allowed}.")
    for c in channels:
        if c not in allowed:
            raise ValueError(f"unknown channel {c!r} for the Kalman filter of "
                             f"{type(model).__name__}; choose from {allowed}.")
    if len(set(channels)) != len(channels):
        raise ValueError(f"`channels` repeats a channel: {channels}.")
    return channels


def _variance(name, value, what) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what}[{name!r}] must be a number (a variance), got {value!r}.") \
            from None
    if not math.isfinite(value):
        raise ValueError(f"{what}[{name!r}] is {value}; variances must be finite.")
    if value < 0:
        raise ValueError(f"{what}[{name!r}] is {value}; a variance cannot be negative.")
    return value


def _matrix(value, size, what, *, definite) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 1 and a.shape[0] == size:
        a = np.diag(a)
    if a.shape != (size, size):
        raise ValueError(f"`{what}` must be a dict, {size} variances or a ({size}, {size}) "
                         f"covariance matrix, got shape {a.shape}.")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"`{what}` contains non-finite entries (NaN or inf): {a.tolist()}.")
    if not np.allclose(a, a.T, rtol=1e-12, atol=0.0):
        raise ValueError(f"`{what}` must be symmetric.")
    eig = np.linalg.eigvalsh(a) if size else np.zeros(0)
    if np.any(np.diag(a) < 0) or (size and eig[0] < -1e-12 * max(eig[-1], 1e-300)):
        raise ValueError(f"`{what}` has a negative variance or is not positive semi-definite "
                         f"(eigenvalues {eig.tolist()}).")
    if definite and size and eig[0] <= 0:
        raise ValueError(f"`{what}` must be positive definite (every measured channel needs "
                         f"a positive noise variance), eigenvalues {eig.tolist()}.")
    return a


def process_matrices(model, process_noise) -> tuple[np.ndarray, float]:
    """`(Q, q_rudder)` from a process-noise spec: a dict `{name: variance}` with names of
    the augmented state (`model.state_names` and `"psi"`; per sample, in the state's
    units squared) and/or `"rudder"` (variance of the held rudder-equivalent disturbance
    [rad^2]), or a covariance matrix over the augmented state."""
    names = _augmented_names(model)
    if isinstance(process_noise, dict):
        q = np.zeros((len(names), len(names)))
        rudder = 0.0
        for key, value in process_noise.items():
            v = _variance(key, value, "process_noise")
            if key == "rudder":
                rudder = v
            elif key in names:
                q[names.index(key), names.index(key)] = v
            else:
                raise ValueError(f"`process_noise` names {key!r}, which is neither a state of "
                                 f"{type(model).__name__} ({', '.join(names)}) nor 'rudder'.")
        return q, rudder
    return _matrix(process_noise, len(names), "process_noise", definite=False), 0.0


def measurement_matrix(channels, measurement_noise) -> np.ndarray:
    """`R` (C, C) from a dict `{channel: variance}` (rad^2, (rad/s)^2), a sequence of
    variances in channel order or a covariance matrix; positive definite."""
    if isinstance(measurement_noise, dict):
        unknown = [k for k in measurement_noise if k not in channels]
        if unknown:
            raise ValueError(f"`measurement_noise` names {unknown[0]!r}, which is not a "
                             f"filtered channel ({', '.join(channels)}).")
        missing = [c for c in channels if c not in measurement_noise]
        if missing:
            raise ValueError(f"`measurement_noise` has no variance for channel {missing[0]!r}.")
        var = [_variance(c, measurement_noise[c], "measurement_noise") for c in channels]
        measurement_noise = np.array(var)
    return _matrix(measurement_noise, len(channels), "measurement_noise", definite=True)


def _check_measured(ds, channels):
    """The filter treats each channel as an independent measurement: a channel derived
    from another (r from psi) would count the same noise twice."""
    for i, name in enumerate(ds.names):
        for c in channels:
            if c not in ds.experiment_channels[i]:
                raise ValueError(f"experiment {name!r} (dataset entry {i}): channel {c!r} was "
                                 f"not measured (derived from the other channel); the Kalman "
                                 f"filter needs independent measurements: pass "
                                 f"channels={tuple(k for k in channels if k != c)}.")


# -- the filter and the smoother (traced) ---------------------------------------------


class KalmanOutput(eqx.Module):
    """Output of `ekf` for one record of N samples; the state is $z$ (module
    docstring; `names`).

    - `predicted`, `predicted_cov`: $\\hat z_{k|k-1}$ (N, n), $P_{k|k-1}$ (N, n, n)
      (sample 0: the prior);
    - `filtered`, `filtered_cov`: $\\hat z_{k|k}$, $P_{k|k}$;
    - `innovations` (N, C): $\\varepsilon_k$ (0 at sample 0 and at masked samples);
      `innovation_cov` (N, C, C): $S_k$;
    - `transition` (N, n, n): $A_k$, the Jacobian of the map from sample k-1 to k
      (identity at sample 0);
    - `neg_log_likelihood`: $-\\log L$ of the record (module docstring).
    """

    predicted: jax.Array
    predicted_cov: jax.Array
    filtered: jax.Array
    filtered_cov: jax.Array
    innovations: jax.Array
    innovation_cov: jax.Array
    transition: jax.Array
    neg_log_likelihood: jax.Array
    names: tuple[str, ...] = eqx.field(static=True)


def _interval_map(model, substeps, holds):
    """$F(z, \\delta + w)$: one sample interval of the simulator's time loop, the
    recorded inputs `{name: (2,)}` replayed from sample k to k + 1 with `holds` (as
    `fit` replays them) and the disturbance $w$ held over the interval."""
    simulator = Simulator(max_step=math.inf, substeps=substeps)
    replay = model.replay_field()
    field = lambda t, y, args: replay(t, y, args[0].at(t - args[1]))

    def f(z, w, inputs, dt):
        start = {k: a[0] + (w if k == "delta" else 0.0) for k, a in inputs.items()}
        slope = {k: holds[k].slope(a[0], a[1], dt) for k, a in inputs.items()}
        held = Held(start, slope)
        out, _ = integrate(field, z, (lambda t, y, s, h: (held, s), None), (0.0, dt, 1),
                           simulator, substeps, lambda y, _: y, emit="end")
        return out[0]

    return f


def _measure(model, channels, ground):
    """h(z): the channels' sensors, u and v over ground where `ground` is 1."""
    index = [model.channel_index(c) for c in channels]

    def h(z):
        z = model.with_current(z, ground)
        return jnp.stack([model.measure(c, z[i]) for c, i in zip(channels, index)])

    return h


class _Noise(NamedTuple):
    """The filter's noise: process covariance `Q` over the state, the rudder-equivalent
    disturbance's variance `q_rudder` and the measurement covariance `R`."""

    Q: jax.Array
    q_rudder: jax.Array
    R: jax.Array


def _filter(model, record, prior, noise: _Noise, rec: "_Records", ground=0.0):
    """The EKF over one record (module docstring); `record`: `(inputs, y, mask, dt)`
    with `inputs` `{name: (N,)}`, `y`: (N, C), `mask`: (N,); `prior`: `(z0, P0)` of
    sample 0; `rec`: the records' channels, substeps and holds; `ground`: 1 where its
    u, v are over ground. Returns a `KalmanOutput`."""
    inputs, y, mask, dt = record
    z0, P0 = prior
    Q, q_rudder, R = noise
    channels, substeps, holds = rec.channels, rec.substeps, rec.holds
    F = _interval_map(model, substeps, dict(holds))
    h = _measure(model, channels, ground)
    jac = jax.jacfwd(F, argnums=(0, 1))
    n = z0.shape[0]
    eye = jnp.eye(n, dtype=z0.dtype)

    def step(carry, inputs):
        z, P = carry
        d, yk, mk = inputs
        A, B = jac(z, 0.0, d, dt)
        z_pred = F(z, 0.0, d, dt)
        P_pred = A @ P @ A.T + Q + q_rudder * jnp.outer(B, B)
        P_pred = 0.5 * (P_pred + P_pred.T)
        H = jax.jacfwd(h)(z_pred)
        e = yk - h(z_pred)
        S = H @ P_pred @ H.T + R
        S = 0.5 * (S + S.T)
        chol = jnp.linalg.cholesky(S)
        # K = P H^T S^-1 via the Cholesky factor of S
        gain = jax.scipy.linalg.cho_solve((chol, True), H @ P_pred).T
        z_upd = z_pred + gain @ e
        IKH = eye - gain @ H
        P_upd = IKH @ P_pred @ IKH.T + gain @ R @ gain.T
        white = jax.scipy.linalg.solve_triangular(chol, e, lower=True)
        nll = jnp.sum(jnp.log(jnp.diag(chol))) + 0.5 * (white @ white + e.shape[0] * _LOG_2PI)
        z_new = jnp.where(mk, z_upd, z_pred)
        P_new = jnp.where(mk, P_upd, P_pred)
        out = (z_pred, P_pred, z_new, P_new, jnp.where(mk, e, 0.0), S, A, jnp.where(mk, nll, 0.0))
        return (z_new, P_new), out

    pairs = lambda v: jnp.stack([v[:-1], v[1:]], axis=-1)  # (N - 1, 2): each interval's ends
    scanned = (jax.tree.map(pairs, inputs), y[1:], mask[1:])
    _, (zp, Pp, zf, Pf, e, S, A, nll) = jax.lax.scan(step, (z0, P0), scanned)
    first = lambda a0, a: jnp.concatenate([a0[None], a])
    c = y.shape[1]
    S0 = _measure_cov0(model, channels, z0, P0, R, ground)
    return KalmanOutput(
        predicted=first(z0, zp), predicted_cov=first(P0, Pp), filtered=first(z0, zf),
        filtered_cov=first(P0, Pf), innovations=first(jnp.zeros(c, z0.dtype), e),
        innovation_cov=first(S0, S), transition=first(eye, A),
        neg_log_likelihood=jnp.sum(nll), names=(),
    )


def _measure_cov0(model, channels, z0, P0, R, ground):
    H = jax.jacfwd(_measure(model, channels, ground))(z0)
    return H @ P0 @ H.T + R


def _smooth(out: KalmanOutput):
    """RTS smoother over a `KalmanOutput` (module docstring); returns (means, covs)."""

    def step(carry, inputs):
        zs, Ps = carry
        zf, Pf, zp_next, Pp_next, A_next = inputs
        # G = P_f A^T P_p^-1 (pseudo-inverse: P_p may be singular without process noise)
        G = Pf @ A_next.T @ jnp.linalg.pinv(Pp_next, hermitian=True)
        z = zf + G @ (zs - zp_next)
        P = Pf + G @ (Ps - Pp_next) @ G.T
        P = 0.5 * (P + P.T)
        return (z, P), (z, P)

    inputs = (out.filtered[:-1], out.filtered_cov[:-1], out.predicted[1:],
              out.predicted_cov[1:], out.transition[1:])
    last = (out.filtered[-1], out.filtered_cov[-1])
    _, (zs, Ps) = jax.lax.scan(step, last, inputs, reverse=True)
    return (jnp.concatenate([zs, last[0][None]]), jnp.concatenate([Ps, last[1][None]]))


# -- data as arrays -----------------------------------------------------------------


class _Records(eqx.Module):
    """A dataset as arrays for the filter: `inputs` `{name: (E, N)}` (`REPLAYED`),
    `mask`: (E, N); `y`: (E, N, C); `dt`: (E,); `start`: `WindowStart` of sample 0,
    leaves (E,)."""

    inputs: dict
    y: jax.Array
    mask: jax.Array
    dt: jax.Array
    start: WindowStart
    channels: tuple[str, ...] = eqx.field(static=True)
    substeps: int = eqx.field(static=True)
    holds: tuple = eqx.field(static=True, default=())


def _records(ds, channels, rudder, substeps, hold=None) -> _Records:
    f = lambda a: jnp.asarray(np.asarray(a, dtype=np.float64))
    first = lambda name: f(np.asarray(getattr(ds, name), dtype=np.float64)[:, 0])
    zero = jnp.zeros(ds.num_experiments)
    start = WindowStart(r=first("r"), psi=first("psi"), delta=first(rudder), r_first=first("r"),
                        psi_first=first("psi"), delta_integral=zero, elapsed=zero,
                        aux=AuxInputs(u=first("u"), v=first("v"), n=first("n")),
                        rudder_angle=first("delta"), x=first("x"), y=first("y"),
                        ground=f(ds.over_ground))
    return _Records(
        inputs={name: f(getattr(ds, rudder if name == "delta" else name)) for name in REPLAYED},
        y=f(np.stack([np.asarray(getattr(ds, c)) for c in channels], axis=-1)),
        mask=jnp.asarray(np.asarray(ds.mask, dtype=bool)),
        dt=f(ds.dt), start=start, channels=tuple(channels), substeps=int(substeps),
        holds=resolve_holds(rudder, hold, REPLAYED),
    )


def _prior(model, start, channels, R, P0):
    """Prior of sample 0: the state `fit` starts a window from at the first sample
    (`replay_state`: a steering model's `window_state` and the measured heading; a
    vessel's measured states); covariance `P0`, or by default R on the measured
    entries and 0 on the others."""
    z0 = model.with_current(model.replay_state(start), -start.ground_scale)  # through the water
    if P0 is not None:
        return z0, P0
    diag = jnp.zeros(z0.shape[0], dtype=z0.dtype)
    for i, c in enumerate(channels):
        diag = diag.at[model.channel_index(c)].set(R[i, i])
    return z0, jnp.diag(diag)


def _batch_filter(model, rec: _Records, Q, q_rudder, R, P0=None):
    """The EKF of every record (vmapped): a `KalmanOutput` with a leading axis E."""

    def one(inputs, y, mask, dt, start):
        z0, p0 = _prior(model, start, rec.channels, R, P0)
        return _filter(model, (inputs, y, mask, dt), (z0, p0), _Noise(Q, q_rudder, R), rec,
                       start.ground_scale)

    # plain vmap: reverse mode (the ML Hessian) of a scan inside shard_map fails in
    # jax 0.10 ("context mesh ... should match"); records are few, windows are many
    return jax.vmap(one)(rec.inputs, rec.y, rec.mask, rec.dt, rec.start)


@eqx.filter_jit
def _filter_jit(model, rec, Q, q_rudder, R, P0):
    return _batch_filter(model, rec, Q, q_rudder, R, P0)


@eqx.filter_jit
def _smooth_jit(model, rec, Q, q_rudder, R, P0):
    out = _batch_filter(model, rec, Q, q_rudder, R, P0)
    zs, Ps = jax.vmap(_smooth)(out)
    return out, zs, Ps


def _check_inputs(model, data, channels, rudder, substeps, *, vessels=True):
    """`(dataset, channels)` after checking the model (a steering model, or with
    `vessels` also a vessel), the channels and the data."""
    kinds = (AbstractSteeringModel, AbstractVessel) if vessels else AbstractSteeringModel
    if not isinstance(model, kinds):
        raise ValueError(f"`model` must be a jaxship AbstractSteeringModel"
                         f"{' or AbstractVessel' if vessels else ''}, got "
                         f"{type(model).__name__}.")
    channels = _check_channels(model, channels)
    if int(substeps) < 1:
        raise ValueError(f"`substeps` must be a positive integer, got {substeps}.")
    ds = as_dataset(data)
    check_data(ds, rudder, channels)
    _check_measured(ds, channels)
    return ds, channels


class _Options(NamedTuple):
    """The keyword options `ekf` and `smooth_states` share (see `ekf`)."""

    channels: tuple
    rudder: str
    substeps: int
    process_noise: object
    measurement_noise: object
    initial_covariance: object
    hold: object


def _prepare(model, data, options: _Options):
    """`(dataset, records, Q, q_rudder, R, P0)` of the filter after checking the inputs."""
    ds, channels = _check_inputs(model, data, options.channels, options.rudder,
                                 options.substeps)
    Q, q_rudder = process_matrices(model, options.process_noise)
    R = measurement_matrix(channels, options.measurement_noise)
    P0 = None
    if options.initial_covariance is not None:
        P0 = jnp.asarray(_matrix(options.initial_covariance, Q.shape[0], "initial_covariance",
                                 definite=False))
    rec = _records(ds, channels, options.rudder, options.substeps, options.hold)
    return ds, rec, jnp.asarray(Q), jnp.asarray(q_rudder), jnp.asarray(R), P0


def ekf(model: AbstractSteeringModel | AbstractVessel, experiment, *, process_noise,
        measurement_noise, channels=KALMAN_CHANNELS, rudder: str = "delta", initial_covariance=None,
        substeps: int = 1, hold=None) -> KalmanOutput:
    """Extended Kalman filter of a steering model or a vessel over one measured record
    (module docstring for the equations).

    **Arguments:**

    - `model`: any `AbstractSteeringModel` or `AbstractVessel` (parameter values as
      they are).
    - `experiment`: a `jaxship.Experiment` (replayed rudder, the measured channels).
    - `process_noise`: dict `{name: variance}` over the state z (a steering model's
      `state_names` and `"psi"`; a vessel's u, v, r, x, y, psi, delta, n; per sample
      interval) and `"rudder"` (variance [rad^2] of a rudder-equivalent disturbance
      held over each interval), or an (n, n) covariance matrix over z.
    - `measurement_noise`: dict `{channel: variance}`, variances in channel order, or a
      (C, C) covariance; positive definite.
    - `channels`: measured outputs, `"psi"` [rad] and/or `"r"` [rad/s], unwrapped; for a
      vessel also `"u"`, `"v"` [m/s], `"x"`, `"y"` [m].
    - `rudder`: `"delta"` or `"delta_c"`.
    - `initial_covariance`: $P_0$ (n, n) of the prior at sample 0 (default: R on the
      measured states, 0 on the others).
    - `substeps`: RK4 steps per sample interval.
    - `hold`: how the recorded inputs are replayed between samples, as
      `PredictionError(hold=...)`.

    **Returns:** a `KalmanOutput` (arrays of the record's length).
    """
    if not isinstance(experiment, Experiment):
        raise ValueError(f"`experiment` must be a jaxship Experiment, got "
                         f"{type(experiment).__name__}; use smooth_states for a Dataset.")
    _, rec, Q, q, R, P0 = _prepare(model, experiment, _Options(
        channels, rudder, substeps, process_noise, measurement_noise, initial_covariance,
        hold))
    out = _filter_jit(as_arrays(model), rec, Q, q, R, P0)
    out = jax.tree.map(lambda a: a[0], out)
    return dataclasses.replace(out, names=_augmented_names(model))


def rts_smoother(filtered: KalmanOutput) -> tuple[jax.Array, jax.Array]:
    """Rauch-Tung-Striebel smoother over the output of `ekf` (module docstring):
    `(means (N, n), covariances (N, n, n))` of the augmented state given all samples."""
    return jax.jit(_smooth)(filtered)


class SmoothedStates(eqx.Module):
    """Smoothed states of one record: time `t` (N,), `names` of the augmented state,
    `mean` (N, n), `covariance` (N, n, n); `state(name)` is one column."""

    t: np.ndarray
    mean: np.ndarray
    covariance: np.ndarray
    names: tuple[str, ...] = eqx.field(static=True)
    name: str = eqx.field(static=True)

    def state(self, name: str) -> np.ndarray:
        if name not in self.names:
            raise ValueError(f"no state {name!r}; the states are {', '.join(self.names)}.")
        return self.mean[:, self.names.index(name)]

    def std(self, name: str) -> np.ndarray:
        i = self.names.index(name)
        return np.sqrt(np.maximum(self.covariance[:, i, i], 0.0))


def smooth_states(model: AbstractSteeringModel | AbstractVessel, data, *, process_noise,
                  measurement_noise, channels=KALMAN_CHANNELS, rudder: str = "delta",
                  initial_covariance=None, substeps: int = 1, hold=None
                  ) -> list[SmoothedStates]:
    """Smoothed states (EKF + RTS smoother) of every experiment of `data` (an
    `Experiment`, a list of them or a `Dataset`), e.g. for the start states of
    prediction windows or for residual forces. Arguments as `ekf`; the noise is
    typically that estimated by `fit_ml` (`result.noise`).

    **Returns:** a list of `SmoothedStates`, one per experiment, cut to its length.
    """
    # padded to a bucket length: records of nearby lengths share the compiled smoother
    # (padded samples are predicted without update, so the smoothed states are the same)
    ds, rec, Q, q, R, P0 = _prepare(model, as_dataset(data).bucketed(), _Options(
        channels, rudder, substeps, process_noise, measurement_noise, initial_covariance,
        hold))
    _, zs, Ps = _smooth_jit(as_arrays(model), rec, Q, q, R, P0)
    zs, Ps = np.asarray(zs), np.asarray(Ps)
    names = _augmented_names(model)
    return [SmoothedStates(t=np.asarray(ds.t)[i, :n], mean=zs[i, :n], covariance=Ps[i, :n],
                           names=names, name=ds.names[i]) for i, n in enumerate(ds.lengths)]
