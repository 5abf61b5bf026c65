"""First-order Nomoto yaw model with Norrbin's nonlinear manoeuvring characteristic."""

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..._foundation._params import param
from .._actuators import RudderServo, Shaft
from .._environment import AbstractWindLoads, FossenWindLoads
from ._base import AbstractVessel


class NomotoVessel(AbstractVessel):
    """Yaw-only steering model $T\\dot r + H(r) = K\\delta$ (Nomoto et al. 1957; Norrbin 1963).

    $H(r) = n_3 r^3 + n_2 r^2 + n_1 r + n_0$ is Norrbin's manoeuvring characteristic
    (thesis eq. 3.4-3.5); the defaults $n_1 = 1$, $n_0 = n_2 = n_3 = 0$ give the linear
    Nomoto model $T\\dot r + r = K\\delta$ (thesis eq. 3.3). Surge speed is constant and
    sway is zero: the model is written as $M = \\mathrm{diag}(1, 1, T)$ and
    $\\tau = (0, 0, K\\delta - H(r))$, so $M\\dot\\nu = \\tau$ is the Nomoto equation.
    `K` and `T` are the dimensional constants at `nominal_speed`; they do not change
    with the speed of the simulated state.
    """

    length: float = param(free=False, unit="m")  # L
    rudder: RudderServo
    # U, the constant surge speed the constants belong to
    nominal_speed: float = param(free=False, unit="m/s")
    # K, steady r/delta; positive: positive delta turns to starboard
    gain: float = param(free=True, unit="1/s")
    # T (negative for a course-unstable linear model)
    time_constant: float = param(free=True, unit="s")
    # n_1, +1 course-stable, -1 unstable (Norrbin 1963)
    n1: float = param(1.0, free=False, unit="-")
    n3: float = param(0.0, free=False, unit="s^2/rad^2")  # n_3
    n2: float = param(0.0, free=False, unit="s/rad")  # n_2
    n0: float = param(0.0, free=False, unit="rad/s")  # n_0, bias
    shaft: Shaft = Shaft()  # no propeller
    nominal_n: float = param(0.0, free=False, unit="rev/s")
    frontal_wind_area: float = param(0.0, free=False, unit="m^2")  # A_F, no windage
    lateral_wind_area: float = param(0.0, free=False, unit="m^2")  # A_L
    wind_model: AbstractWindLoads = FossenWindLoads()  # wind loads on A_F, A_L

    def mass_matrix(self) -> Array:
        return jnp.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, self.time_constant]])

    def characteristic(self, r) -> Array:
        """Norrbin's $H(r) = n_3 r^3 + n_2 r^2 + n_1 r + n_0$ [rad/s]."""
        return ((self.n3 * r + self.n2) * r + self.n1) * r + self.n0

    def forces(self, u, v, r, delta, n) -> Array:
        del n
        N = self.gain * delta - self.characteristic(r)
        zero = jnp.zeros_like(N)
        return jnp.stack(jnp.broadcast_arrays(zero * u, zero * v, N))


def sea_scout() -> NomotoVessel:
    """Tanker Sea Scout in ballast, Nomoto model (Astrom & Kallstrom (1979) Table 1, E1).

    255 000 tdw tanker; ML estimates of Nomoto's model in continuous time, experiment E1
    (T_p = T_s): K' = -1.04, T' = 1.37. The scanned Table 1 has lost its T' row; we read
    its K' row as (K', T') pairs per column: initial -0.56/1.31, E1 -1.04/1.37
    (continuous) and -1.08/1.33 (discrete), E2 -0.94/1.64 and -1.01/1.43, E3 -0.94/1.43
    and -1.02/1.20. The report writes Nomoto's model as r/delta = K/(s + 1/T) (eq. 6),
    so its K is the initial yaw acceleration per rudder angle and the steady gain is
    K T; in the prime system K = K' V^2/L^2, T = T' L/V, hence here
    gain = -K'T' V/L (sign flipped: their K' < 0 means positive delta turns to port)
    and time_constant = T' L/V.

    Assumed particulars (not in the source; typical 255 000 tdw tanker): L = 320 m,
    V = 8 m/s; steering gear 35 deg, 2.3 deg/s.
    """
    k_prime, t_prime = -1.04, 1.37  # Table 1, E1 continuous time, their rudder sign
    length, speed = 320.0, 8.0
    return NomotoVessel(
        length=length,
        rudder=RudderServo(float(np.deg2rad(35.0)), float(np.deg2rad(2.3)), 1.0),
        nominal_speed=speed,
        gain=-k_prime * t_prime * speed / length,
        time_constant=t_prime * length / speed,
    )
