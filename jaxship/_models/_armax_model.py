"""`ARMAXModel`: the discrete ARMAX(2, 2, 2) yaw-rate model with a delay of one sample
(Astrom & Kallstrom 1979, eq. 7), as a model with named parameters, and its noise-free
simulation (one `scipy.signal.lfilter` call per batch of records, no loop over samples).

It is estimated by `fit_armax` (one-step prediction error); `jaxship identify --model
armax` wraps it.
"""

import equinox as eqx
import numpy as np
import scipy  # scipy.signal loads on first use (an import-time saving)

from .._foundation._params import param


ARMAX_ORDERS = dict(na=2, nb=2, nc=2, nk=1)
ARMAX_NAMES = ("a1", "a2", "b0", "b1", "c1", "c2")


class ARMAXModel(eqx.Module):
    """The ARMAX model with the fixed orders `ARMAX_ORDERS` ($n_a = n_b = n_c = 2$,
    delay $n_k = 1$ sample) and $y = r$ [rad/s], $u = \\delta$ [rad]:

    $$r(t) + a_1r(t-1) + a_2r(t-2) = b_0\\delta(t-1) + b_1\\delta(t-2)
    + e(t) + c_1e(t-1) + c_2e(t-2).$$

    A discrete model of the sample interval `dt` (frozen), estimated by
    `fit_armax` (one-step prediction error)."""

    a1: float = param(0.0, unit="-")  # a_1 [-] of A(q^-1)
    a2: float = param(0.0, unit="-")  # a_2 [-]
    b0: float = param(0.0, unit="1/s")  # b_0 [(rad/s)/rad] of B(q^-1), delta(t - 1)
    b1: float = param(0.0, unit="1/s")  # b_1 [(rad/s)/rad], delta(t - 2)
    c1: float = param(0.0, unit="-")  # c_1 [-] of C(q^-1)
    c2: float = param(0.0, unit="-")  # c_2 [-]
    nk: float = param(1.0, free=False, unit="samples")  # delay n_k (frozen)
    dt: float = param(1.0, free=False, unit="s")  # sample interval [s] (frozen)

    def polynomials(self):
        """`(A, B, C)` coefficient arrays (leading 1 for A and C)."""
        f = lambda *xs: np.array([float(x) for x in xs])
        return f(1.0, self.a1, self.a2), f(self.b0, self.b1), f(1.0, self.c1, self.c2)

    def response(self, delta, r0) -> np.ndarray:
        """The noise-free response $A r = B\\delta(t - n_k)$ to the rudder `delta`
        (`simulate_armax`)."""
        return simulate_armax(self, delta, r0)

    @classmethod
    def from_result(cls, result, dt: float) -> "ARMAXModel":
        """The model of an `ARMAXResult` of `fit_armax` with `ARMAX_ORDERS`."""
        values = np.concatenate([result.A[1:], result.B, result.C[1:]])
        return cls(**dict(zip(ARMAX_NAMES, map(float, values))), nk=float(result.nk),
                   dt=float(dt))


def simulate_armax(model: ARMAXModel, delta, r0) -> np.ndarray:
    """The noise-free response $A r = B\\delta(t - n_k)$ of `model` to the rudder
    `delta` [rad], shape (N,) or (E, N) (one record per row), starting at the yaw
    rate `r0` [rad/s] (scalar or (E,)) with r and the rudder before the first sample
    held at `r0` and `delta[..., 0]`. Returns r [rad/s] of `delta`'s shape; its
    first sample is `r0`.

    Samples are causal: padding at the end of a row affects nothing before it."""
    delta = np.asarray(delta, dtype=np.float64)
    rows = np.atleast_2d(delta)
    r0 = np.broadcast_to(np.asarray(r0, dtype=np.float64), rows.shape[:1])
    A, B, _ = model.polynomials()
    b = np.concatenate([np.zeros(int(round(float(model.nk)))), B])  # delay as leading zeros
    # filter state of the past, linear in its values: r(0), r(-1), ... = r0 and
    # delta(0), delta(-1), ... = delta[..., 0]
    from_r = scipy.signal.lfiltic(b, A, np.ones(A.size - 1), np.zeros(b.size - 1))
    from_delta = scipy.signal.lfiltic(b, A, np.zeros(A.size - 1), np.ones(b.size - 1))
    zi = r0[:, None] * from_r + rows[:, :1] * from_delta
    rest = scipy.signal.lfilter(b, A, rows[:, 1:], axis=1, zi=zi)[0]
    out = np.concatenate([r0[:, None], rest], axis=1)
    return out.reshape(delta.shape)
