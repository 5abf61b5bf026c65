"""Steering gear and propeller shaft: the actuator states of the simulation."""

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike


class RudderServo(eqx.Module):
    """Rudder servo with angle and rate limits (Fossen 2021, sec. 9.3; MSS `mariner.m`).

    $\\dot\\delta = \\mathrm{sat}_{\\dot\\delta_{max}}\\big((\\mathrm{sat}_{\\delta_{max}}
    (\\delta_c) - \\delta)/T_\\delta\\big)$.
    """

    max_angle: ArrayLike  # delta_max [rad]
    max_rate: ArrayLike  # delta_dot_max [rad/s]
    time_constant: ArrayLike = 1.0  # T_delta [s]

    def rate(self, delta: ArrayLike, command: ArrayLike) -> Array:
        target = jnp.clip(command, -self.max_angle, self.max_angle)
        return jnp.clip((target - delta) / self.time_constant, -self.max_rate, self.max_rate)


class Shaft(eqx.Module):
    """First-order propeller-shaft response $\\dot n = (n_c - n)/T_n$ with $|n_c| \\le n_{max}$."""

    max_rate: ArrayLike = float("inf")  # n_max [rev/s]
    time_constant: ArrayLike = 1.0  # T_n [s]

    def rate(self, n: ArrayLike, command: ArrayLike) -> Array:
        target = jnp.clip(command, -self.max_rate, self.max_rate)
        return (target - n) / self.time_constant
