"""Simulation throughput: jaxship against SciPy `solve_ivp` and a hand-written `lax.scan` RK4.

A 600 s a/a zig-zag (a = 20 deg for the single run) at 0.1 s output, float64, for the
Mariner (Chislett & Strom-Tejsen 1965) and the thesis vessel (Ross-type DTMB 5415 model):
one run, and batches of 64 and 1024 runs over a grid of rudder angles (10-30 deg, the
switching heading equal to the angle) and, for the thesis vessel, propeller rates
(400-600 rpm, each from its own straight run); the Mariner has no propeller term, so its
batch varies the approach speed U_0 (5-10 m/s) instead (a batched vessel).

Three implementations of the same right-hand side, measured side by side in one run
(interleaved, best of `--repeats`):

- **jaxship**: `simulate` (single run) and `simulate_batch` (batches), RK4 with one
  step per 0.1 s sample, zig-zag logic at the samples (zero-order hold).
- **hand scan**: the practical limit: a hand-written `jax.lax.scan` RK4 with the same
  step over a flat state vector, the right-hand side written out below (independent of
  jaxship), the mass matrix inverted in advance, the coefficients passed as traced
  arguments as in jaxship. Same devices as jaxship.
- **SciPy**: the same right-hand side in plain Python/NumPy, `scipy.integrate.solve_ivp`
  (RK45, rtol 1e-8, atol 1e-9) in a Python loop over the runs. The zig-zag switch is
  taken exactly as jaxship takes it: a terminal event finds the heading crossing, the
  integration continues with the old rudder order to the next 0.1 s sample, and the new
  order starts there. The batches are *estimated* from `--scipy-subset` runs spread over
  the batch (the output says so).

The right-hand sides are checked against jaxship's `state_derivative` at random states
before timing, and the trajectories of the three against each other.

Run: `python benchmarks/simulation.py [--vessels mariner,thesis] [--repeats 5]
[--scipy-subset 16] [--devices N]` (`--devices N` splits the CPU into N XLA devices;
jaxship and the hand scan then both shard their batches over them).
"""

import argparse
import math
import os
import sys
import time


def _parse():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vessels", default="mariner,thesis")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scipy-subset", type=int, default=16)
    parser.add_argument("--batches", default="64,1024")
    parser.add_argument("--duration", type=float, default=600.0)
    parser.add_argument("--devices", type=int, default=1, help="XLA CPU devices to split into")
    return parser.parse_args()


ARGS = _parse() if __name__ == "__main__" else None
if ARGS is not None and ARGS.devices > 1:
    os.environ["XLA_FLAGS"] = (
        os.environ.get("XLA_FLAGS", "") + f" --xla_force_host_platform_device_count={ARGS.devices}"
    )

import jax  # noqa: E402


jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
from jax.sharding import Mesh, PartitionSpec as P  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import jaxship as js  # noqa: E402


DEG = math.pi / 180
DT = 0.1  # sample interval and RK4 step [s]


# --------------------------------------------------------------------------- right-hand sides
# Written once against a small namespace `xp` so that the very same code runs on Python
# floats (SciPy baseline: `math` functions, fastest for scalars) and in JAX (hand scan).


class _Math:
    sqrt, sin, cos, tanh, atan2 = math.sqrt, math.sin, math.cos, math.tanh, math.atan2
    abs = staticmethod(abs)

    @staticmethod
    def clip(x, lo, hi):
        return min(max(x, lo), hi)

    @staticmethod
    def maximum(a, b):
        return max(a, b)

    @staticmethod
    def where(c, a, b):
        return a if c else b

    @staticmethod
    def stack(xs):
        return np.array(xs)


class _Jax:
    sqrt, sin, cos, tanh, atan2 = jnp.sqrt, jnp.sin, jnp.cos, jnp.tanh, jnp.arctan2
    abs, clip, maximum, where, stack = jnp.abs, jnp.clip, jnp.maximum, jnp.where, jnp.stack


def _inverse_entries(m11, m22, m23, m32, m33):
    det = m22 * m33 - m23 * m32
    return dict(i11=1 / m11, i22=m33 / det, i23=-m23 / det, i32=-m32 / det, i33=m22 / det)


def mariner_params(vessel) -> dict:
    """Coefficients of a jaxship `Mariner` as plain floats, with the inverse mass matrix."""
    p = {k: float(getattr(vessel, k)) for k in vessel.__dataclass_fields__
         if isinstance(getattr(vessel, k), float)}
    p.update(dmax=vessel.rudder.max_angle, ddmax=vessel.rudder.max_rate,
             tdelta=vessel.rudder.time_constant)
    L, s = p["length"], 0.5 * p["rho"] * p["length"] ** 3
    p.update(_inverse_entries(
        s * (p["m"] - p["x_udot"]), s * (p["m"] - p["y_vdot"]),
        s * L * (p["m"] * p["xg"] - p["y_rdot"]), s * L * (p["m"] * p["xg"] - p["n_vdot"]),
        s * L**2 * (p["iz"] - p["n_rdot"]),
    ))
    return p


def mariner_rhs(xp, p, y, dc, nc):
    """Mariner (MSS `mariner.m` equations, rudder sign flipped): state u v r x y psi delta."""
    del nc
    u, v, r, psi, d = y[0], y[1], y[2], y[5], y[6]
    L = p["length"]
    U = xp.sqrt(u * u + v * v)
    a, b, c, e = (u - p["nominal_speed"]) / U, v / U, r * L / U, -d
    X = (p["x_u"] * a + p["x_uu"] * a * a + p["x_uuu"] * a**3 + p["x_vv"] * b * b
         + p["x_rr"] * c * c + p["x_rv"] * c * b + p["x_dd"] * e * e + p["x_udd"] * a * e * e
         + p["x_vd"] * b * e + p["x_uvd"] * a * b * e)
    Y = (p["y_v"] * b + p["y_r"] * c + p["y_vvv"] * b**3 + p["y_vvr"] * b * b * c
         + p["y_vu"] * b * a + p["y_ru"] * c * a + p["y_d"] * e + p["y_ddd"] * e**3
         + p["y_ud"] * a * e + p["y_uud"] * a * a * e + p["y_vdd"] * b * e * e
         + p["y_vvd"] * b * b * e + p["y_0"] + p["y_0u"] * a + p["y_0uu"] * a * a)
    N = (p["n_v"] * b + p["n_r"] * c + p["n_vvv"] * b**3 + p["n_vvr"] * b * b * c
         + p["n_vu"] * b * a + p["n_ru"] * c * a + p["n_d"] * e + p["n_ddd"] * e**3
         + p["n_ud"] * a * e + p["n_uud"] * a * a * e + p["n_vdd"] * b * e * e
         + p["n_vvd"] * b * b * e + p["n_0"] + p["n_0u"] * a + p["n_0uu"] * a * a)
    q = 0.5 * p["rho"] * L * L * U * U
    X, Y, N = q * X, q * Y, q * L * N
    cs, sn = xp.cos(psi), xp.sin(psi)
    ddot = xp.clip((xp.clip(dc, -p["dmax"], p["dmax"]) - d) / p["tdelta"], -p["ddmax"], p["ddmax"])
    return xp.stack([p["i11"] * X, p["i22"] * Y + p["i23"] * N, p["i32"] * Y + p["i33"] * N,
                     u * cs - v * sn, u * sn + v * cs, r, ddot])


def ross_params(vessel) -> dict:
    """Coefficients of a jaxship `RossVessel` as plain floats, with the inverse mass matrix."""
    p = {k: float(getattr(vessel, k)) for k in vessel.__dataclass_fields__
         if isinstance(getattr(vessel, k), (int, float))}
    p.update(dmax=vessel.rudder.max_angle, ddmax=vessel.rudder.max_rate,
             tdelta=vessel.rudder.time_constant, nmax=vessel.shaft.max_rate,
             tn=vessel.shaft.time_constant)
    m, xg = p["mass"], p["xg"]
    p.update(_inverse_entries(m - p["x_udot"], m - p["y_vdot"], m * xg - p["y_rdot"],
                              m * xg - p["y_rdot"], p["iz"] - p["n_rdot"]))
    return p


def ross_rhs(xp, p, y, dc, nc):
    """Thesis vessel (Ross-type model of `jaxship.RossVessel`): state u v r x y psi delta n."""
    u, v, r, psi, d, n = y[0], y[1], y[2], y[5], y[6], y[7]
    m, xg = p["mass"], p["xg"]
    au, av, ar = xp.abs(u), xp.abs(v), xp.abs(r)
    X = m * (v * r + xg * r * r) - (p["y_vdot"] * v + p["y_rdot"] * r) * r
    Y = -m * u * r + p["x_udot"] * u * r
    N = -m * xg * u * r + (p["y_vdot"] - p["x_udot"]) * u * v + p["y_rdot"] * u * r
    X += p["x_uu"] * au * u + p["x_uuu"] * u**3 + p["x_vv"] * v * v * xp.tanh(u / p["u_sigma"])
    Y += (p["y_uv"] * au * v + p["y_ur"] * au * r + p["y_uuv"] * u * u * v
          + p["y_uur"] * u * u * r + p["y_vvv"] * v**3 + p["y_rrr"] * r**3
          + p["y_vvr"] * v * v * r + p["y_rrv"] * r * r * v + p["y_absv_v"] * av * v
          + p["y_absr_v"] * ar * v + p["y_absv_r"] * av * r + p["y_absr_r"] * ar * r)
    N += (p["n_uv"] * au * v + p["n_ur"] * au * r + p["n_uuv"] * u * u * v
          + p["n_uur"] * u * u * r + p["n_vvv"] * v**3 + p["n_rrr"] * r**3
          + p["n_vvr"] * v * v * r + p["n_rrv"] * r * r * v + p["n_absv_v"] * av * v
          + p["n_absr_v"] * ar * v + p["n_absv_r"] * av * r + p["n_absr_r"] * ar * r)
    D, rho = p["prop_diameter"], p["rho"]
    ua = (1.0 - p["wake"]) * u
    an = xp.abs(n)
    T = rho * D**4 * (p["kt0"] * n * an + p["kt1"] * an * ua / D
                      + p["kt2"] * ua * xp.abs(ua) / D**2)
    X += p["n_propellers"] * (1.0 - p["thrust_deduction"]) * T
    race = xp.sqrt(ua * ua + 8.0 * xp.maximum(T, 0.0) / (math.pi * rho * D * D) + 1e-20)
    u_r = p["race_epsilon"] * ((1.0 - p["race_kappa"]) * ua + p["race_kappa"] * race)
    v_r = p["flow_straightening"] * (v + p["x_rudder"] * r)
    alpha = d + xp.atan2(v_r, xp.where((u_r == 0.0) & (v_r == 0.0), 1.0, u_r))
    sa, w = p["stall_angle"], p["stall_width"]
    s = 0.5 * (1.0 + xp.tanh((alpha * alpha - sa * sa) / (2.0 * sa * w)))
    cn = xp.sin(alpha) * (p["lift_slope"] * (1.0 - s) + p["normal_force_90"] * s)
    fn = 0.5 * rho * p["rudder_area"] * (u_r * u_r + v_r * v_r) * cn
    sd, cd = xp.sin(d), xp.cos(d)
    X, Y, N = X - fn * sd, Y - fn * cd, N - p["x_rudder"] * fn * cd
    cs, sn = xp.cos(psi), xp.sin(psi)
    ddot = xp.clip((xp.clip(dc, -p["dmax"], p["dmax"]) - d) / p["tdelta"], -p["ddmax"], p["ddmax"])
    ndot = (xp.clip(nc, -p["nmax"], p["nmax"]) - n) / p["tn"]
    return xp.stack([p["i11"] * X, p["i22"] * Y + p["i23"] * N, p["i32"] * Y + p["i33"] * N,
                     u * cs - v * sn, u * sn + v * cs, r, ddot, ndot])


# --------------------------------------------------------------------------- cases


class Case:
    """One vessel's benchmark: jaxship inputs, hand-scan inputs and SciPy runs."""

    def __init__(self, name, duration):
        self.name = name
        self.vessel = js.get_vessel(name)
        self.duration = duration
        self.num = int(round(duration / DT)) + 1
        if name == "mariner":
            self.params, self.rhs, self.nstate = mariner_params(self.vessel), mariner_rhs, 7
        elif name == "thesis":
            self.params, self.rhs, self.nstate = ross_params(self.vessel), ross_rhs, 8
        else:
            raise ValueError(f"no hand-written right-hand side for {name!r}")

    def grid(self, size):
        """Rudder angles [rad] and (speed [m/s], rate [rev/s]) of a batch of `size` runs."""
        levels = 2 ** (int(math.log2(size)) // 2)  # 8 for 64, 32 for 1024
        angles = np.linspace(10, 30, size // levels) * DEG
        if self.name == "mariner":
            second = np.linspace(5.0, 10.0, levels)  # approach speed U_0 [m/s]
        else:
            second = np.linspace(400, 600, levels) / 60  # propeller rate [rev/s]
        a, b = np.meshgrid(angles, second, indexing="ij")
        return a.ravel(), b.ravel()

    def starts(self, second):
        """Initial straight runs: speeds and rates (numpy arrays)."""
        if self.name == "mariner":
            return np.asarray(second, float), np.zeros_like(second)
        x = js.straight_run(self.vessel, n=np.asarray(second, float))
        return np.asarray(x.u), np.asarray(x.n)

    def jaxship_args(self, angles, second):
        u0, n0 = self.starts(second)
        # the rudder reversed at the first step after the crossing, as the hand scan and
        # SciPy do (jaxship's default reverses it at the crossing, inside the step)
        manoeuvre = js.ZigZag(angles, angles, duration=self.duration, dt=DT,
                              n=None if self.name == "mariner" else n0,
                              switch_at=js.strategies.SwitchAtNextStep())
        x0 = js.straight_state(u0, n0)
        if self.name == "mariner":  # the approach speed is a vessel parameter
            vessel = eqx.tree_at(lambda v: v.nominal_speed, self.vessel, u0)
            return (vessel, manoeuvre, x0), (0, 0, 0, None)
        return (self.vessel, manoeuvre, x0), (None, 0, 0, None)

    def hand_args(self, angles, second):
        """(params, y0, angle, n command) with a leading batch axis where batched."""
        u0, n0 = self.starts(second)
        y0 = np.zeros((len(u0), self.nstate))
        y0[:, 0] = u0
        if self.nstate == 8:
            y0[:, 7] = n0
        params = {k: np.float64(v) for k, v in self.params.items()}
        axes = {k: None for k in params}
        if self.name == "mariner":
            params["nominal_speed"] = u0
            axes["nominal_speed"] = 0
        return params, axes, y0, np.asarray(angles, float), n0


def hand_zigzag(rhs, p, y0, angle, nc, num, per_field=False):
    """Hand-written RK4 `lax.scan` of an a/a zig-zag, switching at the samples like jaxship.

    Returns the states at the samples, `(num, n)`; with `per_field`, a tuple of `(num,)`
    arrays, one per state component, which is the faster layout under `vmap` (the
    same choice jaxship's batching layer makes).
    """
    h, xp = DT, _Jax

    def step(carry, _):
        y, side = carry
        change = y[5] - y0[5]
        side = jnp.where((side > 0) & (change >= angle), -1.0, side)
        side = jnp.where((side < 0) & (change <= -angle), 1.0, side)
        dc = side * angle
        f = lambda z: rhs(xp, p, z, dc, nc)
        k1 = f(y)
        k2 = f(y + h / 2 * k1)
        k3 = f(y + h / 2 * k2)
        k4 = f(y + h * k3)
        out = tuple(y[i] for i in range(y.shape[0])) if per_field else y
        return (y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), side), out

    # `num` steps, the last one thrown away, as jaxship does
    return jax.lax.scan(step, (y0, jnp.sign(angle)), None, length=num)[1]


def hand_batch_fn(case, axes, devices):
    """The jitted hand-scan batch, sharded over `devices` with `shard_map` like jaxship."""
    one = lambda p, y0, a, nc: hand_zigzag(case.rhs, p, y0, a, nc, case.num, per_field=True)
    batch = jax.vmap(one, in_axes=(axes, 0, 0, 0))
    if len(devices) == 1:
        return jax.jit(batch)
    mesh = Mesh(np.array(devices), ("batch",))
    p_specs = {k: P("batch") if ax == 0 else P() for k, ax in axes.items()}
    return jax.jit(jax.shard_map(batch, mesh=mesh, in_specs=(p_specs, P("batch"), P("batch"),
                                                             P("batch")), out_specs=P("batch")))


def scipy_zigzag(case, p, y0, angle, nc):
    """One a/a zig-zag with `solve_ivp` (RK45), the switch taken at the next sample."""
    t = np.arange(case.num) * DT
    out = np.empty((case.num, case.nstate))
    out[0] = y0
    fun = lambda _, y, dc: case.rhs(_Math, p, y, dc, nc)
    side, k, y, psi0 = math.copysign(1.0, angle), 0, np.asarray(y0, float), y0[5]
    while k < case.num - 1:
        # heading crossing that makes the zig-zag logic switch at a later sample
        event = lambda _, y, dc, s=side: s * (y[5] - psi0) - angle
        event.terminal, event.direction = True, 1.0
        sol = solve_ivp(fun, (t[k], t[-1]), y, method="RK45", rtol=1e-8, atol=1e-9,
                        t_eval=t[k:], events=event, args=(side * angle,))
        got = sol.y.shape[1]
        out[k:k + got] = sol.y.T
        if sol.status != 1:  # reached the end
            break
        t_cross = sol.t_events[0][0]
        j = k + got  # first sample after the crossing
        if got == 0 or t[j - 1] < t_cross:  # finish the interval with the old order
            tail = solve_ivp(fun, (t_cross, t[j]), sol.y_events[0][0], method="RK45",
                             rtol=1e-8, atol=1e-9, args=(side * angle,))
            out[j] = tail.y[:, -1]
        else:  # the crossing fell exactly on a sample
            j -= 1
        side, k, y = -side, j, out[j].copy()
    return out


def numpy_rk4_zigzag(case, p, y0, angle, nc):
    """The same fixed-step RK4 and sample-time switching as jaxship, in a Python loop."""
    h, num = DT, case.num
    out = np.empty((num, case.nstate))
    y, side, psi0 = np.asarray(y0, float), math.copysign(1.0, angle), y0[5]
    f = lambda z, dc: case.rhs(_Math, p, z, dc, nc)
    for k in range(num):
        out[k] = y
        change = y[5] - psi0
        if side > 0 and change >= angle:
            side = -1.0
        elif side < 0 and change <= -angle:
            side = 1.0
        dc = side * angle
        k1 = f(y, dc)
        k2 = f(y + h / 2 * k1, dc)
        k3 = f(y + h / 2 * k2, dc)
        k4 = f(y + h * k3, dc)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return out


def time_python(function, *args, repeats=1):
    """Best wall time of a plain-Python run and its result."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        result = function(*args)
        best = min(best, time.perf_counter() - start)
    return best, result


# --------------------------------------------------------------------------- timing


def _time(f):
    start = time.perf_counter()
    jax.block_until_ready(f())
    return time.perf_counter() - start


def best_of(functions: dict, repeats: int) -> dict:
    """Interleaved timings: the best of `repeats` for each function (called once before)."""
    for f in functions.values():
        jax.block_until_ready(f())
    times = {k: [] for k in functions}
    for _ in range(repeats):
        for k, f in functions.items():
            times[k].append(_time(f))
    return {k: min(v) for k, v in times.items()}


def check_rhs(case):
    """Largest relative difference of the hand-written and jaxship right-hand sides."""
    rng = np.random.default_rng(0)
    p = case.params
    worst = 0.0
    for _ in range(20):
        y = np.array([rng.uniform(0.5, 1.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.02, 0.02),
                      rng.uniform(-100, 100), rng.uniform(-100, 100), rng.uniform(-3, 3),
                      rng.uniform(-0.5, 0.5), rng.uniform(3, 10)])
        y[0] *= case.vessel.nominal_speed
        y[1] *= case.vessel.nominal_speed
        if case.name == "mariner":
            y[7] = 0.0
        dc, nc = rng.uniform(-0.6, 0.6), rng.uniform(3, 10)
        state = js.ShipState(*[jnp.asarray(a) for a in y])
        ref = js.state_derivative(case.vessel, state, js.Command(jnp.asarray(dc), jnp.asarray(nc)),
                                  js.Environment())
        ref = np.array([ref.u, ref.v, ref.r, ref.x, ref.y, ref.psi, ref.delta, ref.n])
        got = case.rhs(_Math, p, y[:case.nstate], dc, nc)
        scale = np.maximum(np.abs(ref[:case.nstate]), 1e-12)
        worst = max(worst, float(np.max(np.abs(got - ref[:case.nstate]) / scale)))
    return worst


def run_case(case, args, devices, rows):
    print(f"\n## {case.name}: {case.vessel.__class__.__name__}, {case.duration:g} s a/a "
          f"zig-zags at dt = {DT} s, {case.num} samples, float64, {len(devices)} XLA device(s)")
    print(f"hand-written RHS vs jaxship state_derivative: max relative difference "
          f"{check_rhs(case):.1e}")
    # ---------------------------------------------------------------- single run
    angle = 20 * DEG
    u0, n0 = case.starts(np.array([case.vessel.nominal_speed if case.name == "mariner"
                                   else case.vessel.nominal_n]))
    x0 = js.straight_state(float(u0[0]), float(n0[0]))
    man = js.ZigZag(angle, angle, duration=case.duration, dt=DT,
                    n=None if case.name == "mariner" else float(n0[0]),
                    switch_at=js.strategies.SwitchAtNextStep())
    p = {k: np.float64(v) for k, v in case.params.items()}
    if case.name == "mariner":
        p["nominal_speed"] = np.float64(u0[0])
    y0 = np.zeros(case.nstate)
    y0[0] = u0[0]
    if case.nstate == 8:
        y0[7] = n0[0]
    hand_one = jax.jit(lambda p, y0, a, nc: hand_zigzag(case.rhs, p, y0, a, nc, case.num))
    fs = {
        "jaxship": lambda: js.simulate(case.vessel, man, x0),
        "hand": lambda: hand_one(p, y0, angle, n0[0]),
    }
    t1 = best_of(fs, args.repeats)
    pp = case.params | {"nominal_speed": float(u0[0])}
    t_scipy, ref = time_python(scipy_zigzag, case, pp, y0, angle, n0[0], repeats=2)
    t_rk4, rk4 = time_python(numpy_rk4_zigzag, case, pp, y0, angle, n0[0], repeats=2)
    traj = js.simulate(case.vessel, man, x0)
    hand = np.asarray(hand_one(p, y0, angle, n0[0]))
    mine = np.stack([traj.state.u, traj.state.v, traj.state.r, traj.state.x, traj.state.y,
                     traj.state.psi, traj.state.delta, traj.state.n], axis=1)[:, :case.nstate]
    dpsi = lambda a, b: np.max(np.abs(a[:, 5] - b[:, 5])) / DEG
    dpos = lambda a, b: np.max(np.hypot(*(a[:, 3:5] - b[:, 3:5]).T))
    print(f"accuracy of the single 20/20 run (max |d psi| [deg], max position difference [m]):"
          f"\n  jaxship vs hand scan: {dpsi(mine, hand):.1e}, {dpos(mine, hand):.1e}"
          f"\n  jaxship vs NumPy RK4 loop: {dpsi(mine, rk4):.1e}, {dpos(mine, rk4):.1e}"
          f"\n  jaxship (RK4, {DT} s) vs SciPy (RK45, rtol 1e-8): {dpsi(mine, ref):.1e}, "
          f"{dpos(mine, ref):.1e}")
    rows.append((case.name, 1, 1 / t1["jaxship"], 1 / t1["hand"], 1 / t_scipy, 1 / t_rk4,
                 "measured (best of 2)"))
    # ---------------------------------------------------------------- batches
    for size in [int(b) for b in args.batches.split(",")]:
        angles, second = case.grid(size)
        jargs, in_axes = case.jaxship_args(angles, second)
        hp, axes, hy0, ha, hn = case.hand_args(angles, second)
        hand_b = hand_batch_fn(case, axes, devices)
        fs = {
            "jaxship": lambda: js.simulate_batch(*jargs, in_axes=in_axes, devices=devices),
            "hand": lambda: hand_b(hp, hy0, ha, hn),
        }
        tb = best_of(fs, max(2, args.repeats // (2 if size > 64 else 1)))
        # check: the batch equals the hand scan run by run
        traj = js.simulate_batch(*jargs, in_axes=in_axes, devices=devices)
        hand_psi = np.asarray(hand_b(hp, hy0, ha, hn)[5])
        diff = np.max(np.abs(np.asarray(traj.state.psi) - hand_psi))
        # SciPy: a subset spread over the batch, per-run time extrapolated
        subset = np.unique(np.linspace(0, size - 1, min(args.scipy_subset, size)).astype(int))
        t_scipy = t_rk4 = 0.0
        for i in subset:
            pi = case.params | ({"nominal_speed": float(hp["nominal_speed"][i])}
                                if case.name == "mariner" else {})
            run = (case, pi, hy0[i], float(ha[i]), float(hn[i]))
            t_scipy += time_python(scipy_zigzag, *run)[0]
            t_rk4 += time_python(numpy_rk4_zigzag, *run)[0]
        per_run, per_run_rk4 = t_scipy / len(subset), t_rk4 / len(subset)
        print(f"batch {size}: jaxship vs hand scan max |d psi| = {diff / DEG:.1e} deg; "
              f"SciPy time estimated from {len(subset)} of {size} runs "
              f"({per_run:.2f} s per run; NumPy RK4 loop {per_run_rk4:.2f} s)")
        rows.append((case.name, size, size / tb["jaxship"], size / tb["hand"], 1 / per_run,
                     1 / per_run_rk4, f"estimated from {len(subset)} runs"))


def main(args):
    devices = jax.devices()
    print(f"jax {jax.__version__}, {jax.default_backend()}, devices: {len(devices)}, "
          f"x64: {jax.config.jax_enable_x64}, python {sys.version.split()[0]}")
    rows = []
    for name in args.vessels.split(","):
        run_case(Case(name.strip(), args.duration), args, devices, rows)
    print("\n| vessel | runs | jaxship runs/s | hand scan runs/s | SciPy RK45 runs/s | "
          "NumPy RK4 runs/s | jaxship / SciPy | jaxship / NumPy RK4 | jaxship / hand scan | "
          "SciPy, NumPy timing |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for name, size, j, h, s, r, note in rows:
        print(f"| {name} | {size} | {j:.1f} | {h:.1f} | {s:.2f} | {r:.2f} | {j / s:.0f}x | "
              f"{j / r:.0f}x | {100 * j / h:.0f} % | {note} |")


if __name__ == "__main__":
    main(ARGS)
