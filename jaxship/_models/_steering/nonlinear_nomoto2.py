"""The second-order nonlinear response model of Lu & Zhao (2008, eq. 4; seed 002)."""

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ..._foundation._params import param
from ._base import AbstractSteeringModel, AuxInputs, WindowStart


class NonlinearNomoto2(AbstractSteeringModel):
    """Second-order Nomoto model with a cubic yaw damping term (Lu & Zhao 2008, eq. 4)

    $$T_1T_2\\ddot r + (T_1 + T_2)\\dot r + \\alpha_1 r + \\beta_1 r^3
    = K(\\delta + \\delta_0) + KT_3\\dot\\delta,$$

    realised like `Nomoto2` without the rudder rate, with the states $(r, r_{aux})$,
    $r_{aux} = T_1T_2\\dot r + (T_1 + T_2)r - KT_3(\\delta + \\delta_0)$:

    $$\\dot r = \\frac{r_{aux} - (T_1 + T_2)r + KT_3(\\delta + \\delta_0)}{T_1T_2},
    \\qquad \\dot r_{aux} = K(\\delta + \\delta_0) - \\alpha_1 r - \\beta_1 r^3.$$

    $\\alpha_1$ is fixed at 1 (frozen) for identifiability, as Lu & Zhao do.

    **Window starts.** $r_{aux}(t_s)$ follows from the record as for `Nomoto2`, except
    for the integral of $\\beta_1 r^3$, which `WindowStart` does not carry: it is
    neglected, so prediction-error fits with
    short windows are biased when $\\beta_1 r^3$ matters; fit with one window per
    record (simulation error) or use the discrete model (`fit_discrete_response`).
    """

    K: float = param(unit="1/s")  # K [1/s]
    T1: float = param(lower=0.0, unit="s")  # T_1 [s]
    T2: float = param(lower=0.0, unit="s")  # T_2 [s]
    T3: float = param(unit="s")  # T_3 [s]
    beta1: float = param(0.0, unit="s/rad^2")  # beta_1 [s/rad^2], cubic coefficient
    alpha1: float = param(1.0, free=False, unit="-")  # alpha_1 [-], fixed linear coefficient
    delta0: float = param(0.0, free=False, scale=0.01, unit="rad")  # delta_0 [rad], offset

    state_names = ("r", "r_aux")

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        del aux
        r, r_aux = state[0], state[1]
        rudder = delta + self.delta0
        r_dot = (r_aux - (self.T1 + self.T2) * r + self.K * self.T3 * rudder) / (
            self.T1 * self.T2
        )
        return jnp.stack([r_dot, self.K * rudder - self.alpha1 * r - self.beta1 * r**3])

    def output(self, state: Array) -> Array:
        return state[0]

    def initial_state(self, r: ArrayLike) -> Array:
        # steady turn: K (delta + delta0) = alpha1 r + beta1 r^3
        r = jnp.asarray(r, dtype=float)
        return jnp.stack([r, (self.T1 + self.T2) * r - self.T3 * (self.alpha1 * r
                                                                  + self.beta1 * r**3)])

    def window_state(self, start: WindowStart) -> Array:
        r0 = jnp.asarray(start.r_first, dtype=float)
        r_aux0 = (self.T1 + self.T2) * r0 - self.T3 * (self.alpha1 * r0 + self.beta1 * r0**3)
        r_aux = (r_aux0 + self.K * (start.delta_integral + self.delta0 * start.elapsed)
                 - self.alpha1 * (start.psi - start.psi_first))
        return jnp.stack([jnp.asarray(start.r, dtype=float), r_aux])
