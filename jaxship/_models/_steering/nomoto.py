"""Nomoto's response models: first and second order, and the nonlinear first-order
model with Norrbin's manoeuvring characteristic (thesis eq. 3.1-3.5)."""

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ..._foundation._params import param
from ._base import AbstractSteeringModel, AuxInputs, WindowStart


class Nomoto1(AbstractSteeringModel):
    """First-order Nomoto model (Nomoto et al. 1957; thesis eq. 3.2-3.3)

    $$T\\dot r + r = K(\\delta + \\delta_0).$$

    `delta0` is the rudder offset in the form of Lu & Zhao (2008, eq. 1; seed 002):
    the rudder angle the model adds to the measured one (a misaligned rudder
    indicator or a hull asymmetry), so the ship goes straight at $\\delta = -\\delta_0$.
    Frozen at 0 by default; free it with `fit(..., free=("K", "T", "delta0"))`.
    Positive `K` turns to starboard for positive rudder. `T > 0` (course stable) is
    the default bound: a course-unstable ship is the nonlinear model with $n_1 = -1$.
    """

    K: float = param(unit="1/s")  # K [1/s], steady yaw rate per rudder angle
    T: float = param(lower=0.0, unit="s")  # T [s], time constant (T1 + T2 - T3)
    delta0: float = param(0.0, free=False, scale=0.01, unit="rad")  # delta_0 [rad], offset

    state_names = ("r",)
    yaw_term_unit = "rad/s"  # T r' + r = K delta + f

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        del aux
        return (self.K * (delta + self.delta0) - state) / self.T

    def output(self, state: Array) -> Array:
        return state[0]

    def forcing(self, state: Array) -> Array:
        # T r' + ... = K delta + f
        return jnp.ones_like(state) / self.T

    def initial_state(self, r: ArrayLike) -> Array:
        return jnp.reshape(jnp.asarray(r, dtype=float), (1,))

    def window_state(self, start: WindowStart) -> Array:
        return self.initial_state(start.r)


class Nomoto2(AbstractSteeringModel):
    """Second-order Nomoto model (thesis eq. 3.1; Astrom & Kallstrom 1979, eq. 4)

    $$\\frac{r}{\\delta + \\delta_0}(s) = \\frac{K(1 + T_3 s)}{(1 + T_1 s)(1 + T_2 s)},$$

    i.e. $T_1T_2\\ddot r + (T_1 + T_2)\\dot r + r = K(\\delta + \\delta_0) + KT_3\\dot\\delta$,
    realised without the rudder rate (the rudder is piecewise constant) with the
    states $(r, r_{aux})$:

    $$\\dot r = \\frac{r_{aux} - (T_1 + T_2) r + KT_3(\\delta + \\delta_0)}{T_1T_2},
    \\qquad \\dot r_{aux} = K(\\delta + \\delta_0) - r,$$

    so $r_{aux} = T_1T_2\\dot r + (T_1 + T_2) r - KT_3(\\delta + \\delta_0)$ [rad] (at
    rest 0; in a steady turn $(T_1 + T_2 - T_3) r$, which is `initial_state(r)`).
    Both states are continuous when the rudder steps.

    **Window starts.** Since $\\dot r_{aux} = K(\\delta + \\delta_0) - r$, the hidden
    state at a window start $t_s$ follows from the record without differentiating:
    $r_{aux}(t_s) = r_{aux}(t_0) + K\\int_{t_0}^{t_s}(\\delta + \\delta_0)\\,dt -
    (\\psi(t_s) - \\psi(t_0))$, with the measured heading, the exact integral of the
    held rudder, and $r_{aux}(t_0)$ of a steady state at the first sample of the
    experiment (a straight run or steady turn, as trials start; a record that
    starts mid-manoeuvre biases the fit: cut it with `Experiment.segment`). The
    measured r is used as it is.
    $T_1$ and $T_2$ are interchangeable; the start values decide which is which.
    """

    K: float = param(unit="1/s")  # K [1/s], steady yaw rate per rudder angle
    T1: float = param(lower=0.0, unit="s")  # T_1 [s], the slow (yaw) time constant
    T2: float = param(lower=0.0, unit="s")  # T_2 [s], the fast (sway) time constant
    T3: float = param(unit="s")  # T_3 [s], the zero (lead) time constant
    delta0: float = param(0.0, free=False, scale=0.01, unit="rad")  # delta_0 [rad], offset

    state_names = ("r", "r_aux")
    yaw_term_unit = "rad/s"  # T r' + r = K delta + f

    @classmethod
    def from_first_order(cls, K, T) -> "Nomoto2":
        """The start of a fit from a first-order model's $K$, $T$: the same effective
        $T = T_1 + T_2 - T_3$ (Nomoto's first-order approximation) spread as
        $T_1 = 1.1\\,T$, $T_2 = 0.2\\,T$, $T_3 = 0.3\\,T$ (a small lead-lag pair; $T_2
        \\ne T_3$ so that neither cancels), the rule of `jaxship.identify`'s start."""
        return cls(K=K, T1=1.1 * T, T2=0.2 * T, T3=0.3 * T)

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        del aux
        r, r_aux = state[0], state[1]
        rudder = delta + self.delta0
        r_dot = (r_aux - (self.T1 + self.T2) * r + self.K * self.T3 * rudder) / (
            self.T1 * self.T2
        )
        return jnp.stack([r_dot, self.K * rudder - r])

    def output(self, state: Array) -> Array:
        return state[0]

    def forcing(self, state: Array) -> Array:
        # T1 T2 r'' + (T1 + T2) r' + r = K (delta + delta0) + K T3 delta' + f enters
        # where K (delta + delta0) does: r_aux' = K (delta + delta0) - r + f
        return jnp.zeros_like(state).at[1].set(1.0)

    def initial_state(self, r: ArrayLike) -> Array:
        r = jnp.asarray(r, dtype=float)
        return jnp.stack([r, (self.T1 + self.T2 - self.T3) * r])

    def window_state(self, start: WindowStart) -> Array:
        # r_aux' = K (delta + delta0) - r integrates to
        # r_aux(t_s) = r_aux(t_0) + K (int delta dt + delta0 (t_s - t_0)) - (psi(t_s) - psi(t_0)),
        # with the measured heading and a steady state at the start of the record
        r_aux0 = (self.T1 + self.T2 - self.T3) * start.r_first
        r_aux = (r_aux0 + self.K * (start.delta_integral + self.delta0 * start.elapsed)
                 - (start.psi - start.psi_first))
        return jnp.stack([jnp.asarray(start.r, dtype=float), r_aux])


class NonlinearNomoto(AbstractSteeringModel):
    """Nonlinear first-order Nomoto model with Norrbin's manoeuvring characteristic
    (Norrbin 1963; Bech; thesis eq. 3.4-3.5)

    $$T\\dot r + H_N(r) = K\\delta, \\qquad H_N(r) = n_3 r^3 + n_2 r^2 + n_1 r + n_0.$$

    The equation is unchanged when K, T and all $n_i$ are multiplied by one number,
    so one of them is fixed: $n_1 = 1$ (course stable) or $-1$ (unstable), frozen by
    default. $n_2$ (port/starboard asymmetry) and $n_0$ (a bias, $-K\\delta_0$ of
    `Nomoto1`) are frozen at 0 by default; `K`, `T` and `n3` are free. The model of
    Lu & Zhao (2008, eq. 2) is $n_1 = 1$, $n_3 = \\alpha$, $n_0 = -K\\delta_r$.
    """

    K: float = param(unit="1/s")  # K [1/s]
    T: float = param(lower=0.0, unit="s")  # T [s]
    n3: float = param(0.0, unit="s^2/rad^2")  # n_3 [s^2/rad^2]
    n2: float = param(0.0, free=False, unit="s/rad")  # n_2 [s/rad]
    n1: float = param(1.0, free=False, unit="-")  # n_1 [-], +1 stable, -1 unstable
    n0: float = param(0.0, free=False, scale=1e-3, unit="rad/s")  # n_0 [rad/s]

    state_names = ("r",)
    yaw_term_unit = "rad/s"  # T r' + r = K delta + f

    def characteristic(self, r: ArrayLike) -> Array:
        """Norrbin's $H_N(r)$ [rad/s]."""
        return ((self.n3 * r + self.n2) * r + self.n1) * r + self.n0

    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        del aux
        return (self.K * delta - self.characteristic(state)) / self.T

    def output(self, state: Array) -> Array:
        return state[0]

    def forcing(self, state: Array) -> Array:
        # T r' + ... = K delta + f
        return jnp.ones_like(state) / self.T

    def initial_state(self, r: ArrayLike) -> Array:
        return jnp.reshape(jnp.asarray(r, dtype=float), (1,))

    def window_state(self, start: WindowStart) -> Array:
        return self.initial_state(start.r)

