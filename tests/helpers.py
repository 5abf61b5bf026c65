"""Shared test helpers: tree comparison, finite differences and a small test vessel."""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxship as js


def tree_allclose(a, b, *, rtol=1e-10, atol=1e-10) -> bool:
    leaves_a, leaves_b = jax.tree.leaves(a), jax.tree.leaves(b)
    if jax.tree.structure(a) != jax.tree.structure(b):
        return False
    return all(np.allclose(x, y, rtol=rtol, atol=atol) for x, y in zip(leaves_a, leaves_b))


def assert_equal_to_rounding(actual, desired, ulps=4):
    """`actual` equals `desired` within `ulps` units in the last place of the largest
    |desired|: what two compiled programs computing the same sums may differ by when
    the compiler orders or fuses them differently (bit for bit under XLA's default
    CPU pipeline; the tests' faster settings, `conftest.py`, fuse differently)."""
    desired = np.asarray(desired)
    scale = float(np.max(np.abs(desired), initial=0.0))
    np.testing.assert_allclose(actual, desired, rtol=0.0,
                               atol=ulps * np.finfo(desired.dtype).eps * scale)


def central_difference(f, x, eps=1e-6):
    """Derivative of a scalar-input function by central differences."""
    return (f(x + eps) - f(x - eps)) / (2 * eps)


class LinearTestVessel(js.AbstractVessel):
    """Davidson & Schiff (1946) linear sway-yaw model with quadratic surge resistance and thrust.

    Mariner-like prime derivatives (Fossen 2021, Table 7.x order of magnitude); a
    course-stable, port/starboard symmetric reference model for core tests.
    """

    length: float = 160.0
    rudder: js.RudderServo = js.RudderServo(np.deg2rad(35.0), np.deg2rad(5.0))
    shaft: js.Shaft = js.Shaft(max_rate=3.0, time_constant=5.0)
    nominal_speed: float = 7.7
    nominal_n: float = 1.5
    frontal_wind_area: float = 500.0
    lateral_wind_area: float = 2500.0
    wind_model: js.wind_loads.FossenWindLoads = js.wind_loads.FossenWindLoads()
    mass: float = 1.7e7  # m [kg]
    yv: float = -0.0116  # Y'_v
    yr: float = -0.00499 + 0.0085  # Y'_r: Mariner's total Y'_r less the Coriolis -m11' r'
    nv: float = -0.00264 + 0.00708  # N'_v: Mariner's total N'_v less the Munk moment in -C(nu)nu
    nr: float = -0.00166  # N'_r
    ydelta: float = 0.00278  # Y'_delta
    ndelta: float = -0.00139 * -1  # N'_delta (positive rudder -> r > 0)
    resistance: float = 2.0e4  # X_|u|u [N s^2/m^2]
    thrust: float = 2.0e4 * 7.7**2 / 1.5**2  # T_nn [N s^2]

    def mass_matrix(self):
        L, m, half = self.length, self.mass, 0.5 * 1025 * self.length**3
        return jnp.diag(
            jnp.array([1.05 * m, m + 0.00748 * half, m * (0.25 * L) ** 2 + 0.000438 * half * L**2])
        )

    def forces(self, u, v, r, delta, n):
        L, q = self.length, 0.5 * 1025 * self.length**2
        m11, m22, _ = jnp.diag(self.mass_matrix())
        U = jnp.abs(u)  # derivatives dimensionalised with the surge speed
        # -C(nu) nu with the skew-symmetric Coriolis matrix of M (Fossen 2021, eq. 6.43)
        coriolis = jnp.stack([m22 * v * r, -m11 * u * r, (m11 - m22) * u * v])
        X = -self.resistance * jnp.abs(u) * u + self.thrust * jnp.abs(n) * n
        Y = q * (self.yv * U * v + self.yr * U * r * L + self.ydelta * u * U * delta)
        N = q * L * (self.nv * U * v + self.nr * U * r * L + self.ndelta * u * U * delta)
        return jnp.stack([X, Y, N]) + coriolis


def linear_test_vessel():
    return LinearTestVessel()


__all__ = ["tree_allclose", "central_difference", "linear_test_vessel", "eqx"]


def per_sample(substeps: int = 1) -> js.Simulator:
    """`substeps` fixed RK4 steps per sample interval, whatever its length: the numerics
    of a rudder record replayed sample by sample (`Simulator(max_step=inf)`)."""
    return js.Simulator(max_step=math.inf, substeps=substeps)
