"""Experiment design: how informative is a planned manoeuvre, before it is run.

- `excitation_order(u)`: the order of persistent excitation of an input signal
  (Ljung 1999, Definition 13.1; the thesis, seed 000, sec. 3.3.2 and eq. 3.8-3.9):
  the largest n for which the n x n covariance matrix
  $\\bar R_n = \\bar E[\\varphi(t)\\varphi(t)^T]$ of $\\varphi(t) = (u(t-1), \\dots, u(t-n))$ is
  nonsingular. An open-loop input exciting of order n identifies a linear model
  with up to n coefficients in its B polynomial (Ljung 1999, sec. 13.2).
- `fisher_information(model, manoeuvre, noise_std)`: the Fisher information of the
  free parameters of a steering model for a planned manoeuvre with white Gaussian
  output noise, $F = \\sum_t J_t^TJ_t/\\sigma^2$, $J_t = \\partial y(t)/\\partial\\theta$
  (jax.jacfwd of the simulated output, the rudder replayed open loop as in
  estimation), and its inverse, the Cramer-Rao bound on the covariance of any
  unbiased estimate (Ljung 1999, sec. 7.4; 13.3).
"""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._foundation._contract import rebuild
from .._foundation._exported import persistent
from .._foundation._params import as_arrays, resolve_free
from .._models._holds import FirstOrderHold
from .._models._manoeuvres import AbstractManoeuvre, Replay
from .._models._steering._base import AbstractSteeringModel
from .._simulation._integrate import Simulator
from .._simulation._simulate import simulate


def excitation_order(u, *, max_order: int | None = None, rtol: float | None = None) -> int:
    """The order of persistent excitation of the sampled signal `u` (1-D).

    Estimated from the data: $\\hat R_n = \\Phi_n^T\\Phi_n/(N - n)$ with the rows of
    $\\Phi_n$ the lag vectors $(u(t-1), \\dots, u(t-n))$, t = n..N-1 (not mean-removed,
    as in Definition 13.1). The order is the largest n <= `max_order` whose
    $\\hat R_n$ has all eigenvalues above `rtol` times the largest; since $\\hat R_n$
    is a leading block of $\\hat R_{n+1}$ (up to the rows used), the orders are
    scanned upwards. `max_order` defaults to min(N // 4, 200); a return value equal
    to it means "at least".

    `rtol` defaults to 4/N: a finite record's transients (the onset of a step, a
    start-up) add eigenvalues of order 1/N that vanish in the quasi-stationary limit
    of the definition. Examples: a constant or a step is exciting of order 1, a sum
    of k sinusoids of distinct frequencies in (0, pi) of order 2k, a PRBS of period
    P samples of order P, white noise of any order.
    """
    u = np.asarray(u, dtype=np.float64)
    if u.ndim != 1 or u.size < 8:
        raise ValueError(f"`u` must be a 1-D signal of at least 8 samples, got shape {u.shape}.")
    if not np.all(np.isfinite(u)):
        raise ValueError("`u` must be finite.")
    n_max = min(u.size // 4, 200) if max_order is None else int(max_order)
    if not 1 <= n_max <= u.size // 2:
        raise ValueError(f"`max_order` must be in [1, {u.size // 2}], got {max_order}.")
    rtol = 4.0 / u.size if rtol is None else float(rtol)
    if not np.any(u):
        return 0
    order = 0
    for n in range(1, n_max + 1):
        phi = np.stack([u[n - lag: u.size - lag] for lag in range(1, n + 1)], axis=1)
        ev = np.linalg.eigvalsh(phi.T @ phi / phi.shape[0])
        if ev[0] > rtol * ev[-1]:
            order = n
        else:
            break
    return order


@dataclasses.dataclass(frozen=True)
class DesignReport:
    """Result of `fisher_information`: the free parameter `names` and nominal
    `values`, the Fisher information `fisher` (in the parameters' units), the
    Cramer-Rao bound `crb` = inverse Fisher information (covariance), the record
    `duration` [s] and number of samples, and the rudder replayed `delta` [rad]."""

    names: tuple
    values: np.ndarray
    fisher: np.ndarray
    crb: np.ndarray
    duration: float
    num_samples: int
    delta: np.ndarray

    @property
    def std(self) -> np.ndarray:
        """Cramer-Rao lower bounds on the standard deviations."""
        return np.sqrt(np.diag(self.crb))

    @property
    def relative_std(self) -> np.ndarray:
        """`std / |values|`."""
        return self.std / np.abs(self.values)

    @property
    def relative_std_per_hour(self) -> np.ndarray:
        """The relative bound scaled to one hour of the same manoeuvre repeated
        (the information grows linearly with the record length): `relative_std *
        sqrt(duration / 3600)`; compares manoeuvres per unit time."""
        return self.relative_std * np.sqrt(self.duration / 3600.0)

    @property
    def log_det(self) -> float:
        """log det of the Fisher information (D-optimality; larger is better)."""
        return float(np.linalg.slogdet(self.fisher)[1])

    def table(self) -> str:
        rows = [f"{'parameter':>10} {'value':>12} {'CRB std':>12} {'rel.':>9}"]
        for n, v, s in zip(self.names, self.values, self.std):
            rows.append(f"{n:>10} {v:12.5g} {s:12.4g} {s / abs(v):9.2%}")
        return "\n".join(rows)


def fisher_information(model: AbstractSteeringModel, manoeuvre, noise_std, *,
                       dt: float | None = None, free=None, outputs=("r",),
                       substeps: int = 1) -> DesignReport:
    """Fisher information and Cramer-Rao bounds of a planned experiment.

    **Arguments:**

    - `model`: a steering model with its nominal (expected) parameter values.
    - `manoeuvre`: an `AbstractManoeuvre` (closed-loop ones such as `ZigZag` are
      run on the nominal model with `simulate`, at the manoeuvre's `rudder_rate`, then
      their rudder is replayed open loop, as estimation does) or a 1-D array of
      rudder angles [rad] at the samples (then `dt` [s] is required).
    - `noise_std`: the standard deviation of the white measurement noise on each
      output, a number or a dict `{output: std}` (SI: rad/s for r, rad for psi).
    - `free`: the parameters (as `fit`'s `free`; default the model's free fields).
    - `outputs`: measured channels, any of `"r"`, `"psi"`.
    - `substeps`: RK4 steps per sample interval.

    The Jacobian is `jax.jacfwd` of the simulated outputs (from rest) with respect
    to the free parameters in their physical units. The bounds assume the model is
    right, the noise white and Gaussian, and the rudder known.

    **Raises:** `ValueError` for bad arguments; the Cramer-Rao bound is `inf` where
    the information matrix is singular.
    """
    if not isinstance(model, AbstractSteeringModel):
        raise ValueError(f"`model` must be a jaxship steering model, got {type(model).__name__}.")
    outputs = tuple(outputs)
    if not outputs or any(o not in ("r", "psi") for o in outputs):
        raise ValueError(f"`outputs` must be a non-empty subset of ('r', 'psi'), got {outputs}.")
    sigma = noise_std if isinstance(noise_std, dict) else {o: noise_std for o in outputs}
    for o in outputs:
        if o not in sigma or not float(sigma[o]) > 0:
            raise ValueError(f"`noise_std` for {o!r} must be a positive number, got "
                             f"{sigma.get(o)}.")
    if isinstance(manoeuvre, AbstractManoeuvre):
        if dt is not None and abs(float(dt) - float(manoeuvre.dt)) > 1e-12:
            raise ValueError("`dt` is set by the manoeuvre; leave it out.")
        dt = float(manoeuvre.dt)
        delta = np.asarray(simulate(model, manoeuvre,
                                    simulator=Simulator(substeps=substeps)).state.delta)
    else:
        delta = np.asarray(manoeuvre, dtype=np.float64)
        if delta.ndim != 1 or delta.size < 2:
            raise ValueError(f"the rudder array must be 1-D with at least 2 samples, got shape "
                             f"{delta.shape}.")
        if dt is None or not float(dt) > 0:
            raise ValueError("`dt` [s] > 0 is required with a rudder array.")
        dt = float(dt)
    specs = resolve_free(model, free)
    names = tuple(s.name for s in specs)
    values = np.array([float(getattr(model, n)) for n in names])
    jac = _jacobian(as_arrays(model), names, jnp.asarray(values), jnp.asarray(delta),
                    jnp.asarray(dt), outputs, int(substeps))
    fisher = sum(np.asarray(j).T @ np.asarray(j) / float(sigma[o]) ** 2
                 for o, j in zip(outputs, jac))
    try:
        crb = np.linalg.inv(fisher)
        if not np.all(np.isfinite(crb)) or np.any(np.diag(crb) <= 0):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        crb = np.full_like(fisher, np.inf)
    return DesignReport(names, values, fisher, crb, dt * (delta.size - 1), int(delta.size),
                        delta)


@persistent  # traced once per installation
@eqx.filter_jit
def _jacobian(model, names, values, delta, dt, outputs, substeps):
    def sim(theta):
        # the rudder interpolated between samples, one RK4 step per sample (`substeps`)
        replay = Replay(delta, dt=dt, duration=dt * (delta.shape[0] - 1),
                        delta_hold=FirstOrderHold())
        per_sample = Simulator(max_step=math.inf, substeps=substeps)
        traj = simulate(rebuild(model, names, theta), replay, simulator=per_sample)
        return tuple(getattr(traj.state, o) for o in outputs)

    return jax.jacfwd(sim)(values)
