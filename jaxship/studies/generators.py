"""An independent generator of Mariner records: the Chislett & Strom-Tejsen (1965) model
written again from the published equations, in plain NumPy and SciPy, for testing
`jaxship.discover` on records jaxship did not simulate (issue 71).

Nothing here imports jaxship's model code: the equations and coefficients are those
of Fossen's MSS `mariner.m` (T. Lauvdal 1994; Chislett & Strom-Tejsen 1965, report Hy-5)
as the reference notes restate them (`../shared/reference/vessel-models.md`, sec. 1.1).
The records differ from jaxship's own on purpose, as a user's would:

- the equations are integrated by `scipy.integrate.solve_ivp` (RK45, relative
  tolerance 1e-9), not by jaxship's fixed-step RK4;
- the rudder servo is this module's: $\\dot\\delta = \\mathrm{sat}_{\\dot\\delta_{max}}
  ((\\mathrm{sat}_{\\delta_{max}}(\\delta_c) - \\delta)/T_\\delta)$, with its own rate limit
  and time constant (defaults: MSS's 5 deg/s, 1 s, 40 deg);
- the autopilot commands the rudder at `control_dt` intervals and holds it between
  them (a zero-order hold): a zig-zag reverses the rudder at the first control instant
  after the heading crosses its limit (found by an event of the integrator), not at
  the crossing;
- the logger samples every `dt` the servo's rudder angle, the heading, yaw rate,
  velocities and GNSS position.

Hidden effects enter as a user's logs carry them: a `current` $(V_N, V_E)$ [m/s] drifts
the track, $\\dot x = u\\cos\\psi - v\\sin\\psi + V_N$, $\\dot y = u\\sin\\psi + v\\cos\\psi + V_E$
(Fossen 2021, Property 10.1: the hydrodynamics see velocities through the water), and
the logged u, v are over ground, $u_g = u + V_N\\cos\\psi + V_E\\sin\\psi$,
$v_g = v - V_N\\sin\\psi + V_E\\cos\\psi$; a rudder `offset` [rad]: the ship feels
$\\delta + \\delta_0$ and the log shows $\\delta$; a yaw-rate sensor `gyro_bias` [rad/s]:
the log shows $r + b_r$; an `added_mass` error $s_r$ [-]: the ship's yaw inertia
$I_z - N_{\\dot r}$ is $(1 + s_r)$ times the published one (as
`jaxship.effects.AddedMassError`, Fossen 2021, eq. 6.1); a `delay` $\\tau$ [s]: the hull
feels the rudder the log showed $\\tau$ before, $\\delta(t - \\tau)$ exactly (a second
servo driven by the command of $\\tau$ before; jaxship's `RudderDelay` is a Pade
approximant of it). Noise as
`jaxship.studies.discovery.vessel_records`: heading 0.1 deg, yaw rate 0.05 deg/s, u and v
0.02 m/s, positions 1 m; rudder exact.

Sign convention: MSS takes the rudder command $u_i$ with $\\delta_{MSS} = -u_i$; here the
rudder angle $\\delta$ is $u_i$ (a positive angle turns the ship to positive yaw rate),
and the forces use $\\delta_{MSS} = -(\\delta + \\delta_0)$.
"""

import dataclasses
import math

import numpy as np
from scipy.integrate import solve_ivp

import jaxship as js  # the records only (`Experiment`): no model code of jaxship's


DEG = math.pi / 180

# Chislett & Strom-Tejsen (1965) via MSS mariner.m: nondimensional (prime system) mass,
# inertia, centre of gravity and hydrodynamic coefficients (reference notes, sec. 1.1)
MARINER = dict(
    m=798e-5, Iz=39.2e-5, xG=-0.023,
    Xudot=-42e-5, Xu=-184e-5, Xuu=-110e-5, Xuuu=-215e-5, Xvv=-899e-5, Xrr=18e-5,
    Xdd=-95e-5, Xudd=-190e-5, Xrv=798e-5, Xvd=93e-5, Xuvd=93e-5,
    Yvdot=-748e-5, Yrdot=-9.354e-5, Yv=-1160e-5, Yr=-499e-5, Yvvv=-8078e-5, Yvvr=15356e-5,
    Yvu=-1160e-5, Yru=-499e-5, Yd=278e-5, Yddd=-90e-5, Yud=556e-5, Yuud=278e-5,
    Yvdd=-4e-5, Yvvd=1190e-5, Y0=-4e-5, Y0u=-8e-5, Y0uu=-4e-5,
    Nvdot=4.646e-5, Nrdot=-43.8e-5, Nv=-264e-5, Nr=-166e-5, Nvvv=1636e-5, Nvvr=-5483e-5,
    Nvu=-264e-5, Nru=-166e-5, Nd=-139e-5, Nddd=45e-5, Nud=-278e-5, Nuud=-139e-5,
    Nvdd=13e-5, Nvvd=-489e-5, N0=3e-5, N0u=6e-5, N0uu=3e-5,
)
LENGTH = 160.93  # L_pp [m]
U0 = 7.7175  # nominal speed [m/s] (15 kn)
NOISE = (0.1, 0.05, 0.02, 0.02, 1.0)  # psi [deg], r [deg/s], u, v [m/s], x, y [m]
TRAIN = tuple((a, s) for a in (10, 20) for s in (1, -1))  # zig-zag angle [deg], side


@dataclasses.dataclass(frozen=True)
class MarinerScipy:
    """The Mariner (module text) with its servo, autopilot hold and hidden effects:
    `offset` [rad] (felt, not logged), `current` `(north, east)` [m/s], `gyro_bias`
    [rad/s], `added_mass` $s_r$ [-] (yaw inertia scaled by $1 + s_r$), `delay` [s] (the
    hull feels the logged rudder that much later); servo `max_angle` [rad], `max_rate`
    [rad/s], `time_constant` [s]; autopilot `control_dt` [s]; integrator tolerances
    `rtol`, `atol`."""

    offset: float = 0.0
    current: tuple = (0.0, 0.0)
    gyro_bias: float = 0.0
    added_mass: float = 0.0
    delay: float = 0.0
    max_angle: float = 40.0 * DEG
    max_rate: float = 5.0 * DEG
    time_constant: float = 1.0
    control_dt: float = 0.1
    rtol: float = 1e-9
    atol: float = 1e-9

    def rates(self, t, state, command, felt_command=None):
        """$\\dot x$ of `state` = (u, v, r, x, y, psi, delta, felt delta) (u, v through
        the water, u the total surge speed) at the held rudder `command` [rad]: MSS
        mariner.m's $(m' - X'_{\\dot u})\\dot u' = X'$ and the sway-yaw 2x2 mass system,
        with $u' = (u - U_0)/U$, $v' = v/U$, $r' = rL/U$, $U = \\sqrt{u^2 + v^2}$. With a
        `delay` $\\tau$ the hull feels a second servo's angle, driven by the command of
        $\\tau$ before, `felt_command(t)`: the servo's own angle $\\tau$ late, exactly (a
        time-invariant system from rest)."""
        c, L = MARINER, LENGTH
        u, v, r, _, _, psi, delta, felt = state
        U = math.hypot(u, v)
        up, vp, rp = (u - U0) / U, v / U, r * L / U
        d = -((felt if self.delay > 0 else delta) + self.offset)  # MSS's rudder sign
        X = (c["Xu"] * up + c["Xuu"] * up**2 + c["Xuuu"] * up**3 + c["Xvv"] * vp**2
             + c["Xrr"] * rp**2 + c["Xrv"] * rp * vp + c["Xdd"] * d**2
             + c["Xudd"] * up * d**2 + c["Xvd"] * vp * d + c["Xuvd"] * up * vp * d)
        Y = (c["Yv"] * vp + c["Yr"] * rp + c["Yvvv"] * vp**3 + c["Yvvr"] * vp**2 * rp
             + c["Yvu"] * vp * up + c["Yru"] * rp * up + c["Yd"] * d + c["Yddd"] * d**3
             + c["Yud"] * up * d + c["Yuud"] * up**2 * d + c["Yvdd"] * vp * d**2
             + c["Yvvd"] * vp**2 * d + c["Y0"] + c["Y0u"] * up + c["Y0uu"] * up**2)
        N = (c["Nv"] * vp + c["Nr"] * rp + c["Nvvv"] * vp**3 + c["Nvvr"] * vp**2 * rp
             + c["Nvu"] * vp * up + c["Nru"] * rp * up + c["Nd"] * d + c["Nddd"] * d**3
             + c["Nud"] * up * d + c["Nuud"] * up**2 * d + c["Nvdd"] * vp * d**2
             + c["Nvvd"] * vp**2 * d + c["N0"] + c["N0u"] * up + c["N0uu"] * up**2)
        m11 = c["m"] - c["Xudot"]
        m22, m23 = c["m"] - c["Yvdot"], c["m"] * c["xG"] - c["Yrdot"]
        m32 = c["m"] * c["xG"] - c["Nvdot"]
        m33 = (c["Iz"] - c["Nrdot"]) * (1.0 + self.added_mass)
        det = m22 * m33 - m23 * m32
        delta_dot = self._servo(command, delta)
        felt_dot = delta_dot if self.delay <= 0 else self._servo(felt_command(t), felt)
        north, east = self.current
        return (X * U**2 / L / m11,
                (m33 * Y - m23 * N) / det * U**2 / L,
                (m22 * N - m32 * Y) / det * U**2 / L**2,
                u * math.cos(psi) - v * math.sin(psi) + north,
                u * math.sin(psi) + v * math.cos(psi) + east,
                r, delta_dot, felt_dot)

    def _servo(self, command, delta):
        """The servo's $\\dot\\delta$ (module text) towards `command` [rad]."""
        target = min(max(command, -self.max_angle), self.max_angle)
        return min(max((target - delta) / self.time_constant, -self.max_rate), self.max_rate)

    def run(self, commands, duration, dt=0.5):
        """The clean trajectory at the samples `t = 0, dt, ..., duration` from the
        straight run at $U_0$ (v = r = delta = 0). `commands(psi, held)` is the
        autopilot: the rudder command [rad] it sets at a control instant, given the
        heading and the command held so far (None at the start); with attribute
        `limit(held)` (a heading [rad] whose crossing changes the command, or None) the
        integrator stops at each crossing and the command changes at the next control
        instant. Returns `{t, u, v, r, x, y, psi, delta, delta_felt}` (through the water;
        `delta_felt` the angle the hull feels, `delta` that of the servo and the log)."""
        t = np.round(np.arange(0.0, duration + dt / 2, dt), 9)
        out = np.empty((8, t.size))
        state = np.array([U0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        now, held = 0.0, commands(0.0, None)
        changes, values = [0.0], [held]  # the commands and when they were set (from rest)

        def felt_command(time):  # the command in force `delay` s before `time`
            k = np.searchsorted(changes, time - self.delay, side="right")
            return values[k - 1] if k else 0.0

        args = (held, felt_command)
        while now < duration - 1e-9:
            limit = getattr(commands, "limit", lambda held: None)(held)
            events = None
            if limit is not None:
                event = lambda s, x, *_: x[5] - limit
                event.terminal, event.direction = True, (1 if limit > 0 else -1)
                events = [event]
            sol = solve_ivp(self.rates, (now, duration), state, method="RK45", rtol=self.rtol,
                            atol=self.atol, dense_output=True, events=events, args=args)
            end = sol.t[-1]
            if sol.status == 1:  # the heading crossed the limit: on to the next control instant
                instant = math.ceil(end / self.control_dt - 1e-9) * self.control_dt
                instant = min(max(instant, end), duration)
                if instant > end:
                    sol2 = solve_ivp(self.rates, (end, instant), sol.y[:, -1], method="RK45",
                                     rtol=self.rtol, atol=self.atol, dense_output=True,
                                     args=args)
                    pieces = [(sol, now, end), (sol2, end, instant)]
                    state = sol2.y[:, -1]
                else:
                    pieces, state = [(sol, now, end)], sol.y[:, -1]
                end = instant
                psi = state[5]
                held = commands(psi, held)
                changes.append(end)
                values.append(held)
                args = (held, felt_command)
            else:
                pieces, state = [(sol, now, end)], sol.y[:, -1]
            for piece, a, b in pieces:
                inside = (t >= a - 1e-9) & (t <= b + 1e-9)
                if inside.any():
                    out[:, inside] = piece.sol(t[inside])
            now = end
        names = ("u", "v", "r", "x", "y", "psi", "delta", "delta_felt")
        return dict(t=t, **dict(zip(names, out)))


class ZigZagPilot:
    """The autopilot of a zig-zag: rudder `side * angle` [rad] from the start, reversed
    when the heading passes `+-heading` [rad] (the limit on the side the ship turns)."""

    def __init__(self, angle, heading, side=1):
        self.angle, self.heading, self.side = angle, heading, side

    def __call__(self, psi, held):
        return self.side * self.angle if held is None else -held

    def limit(self, held):
        return math.copysign(self.heading, held)


class TurnPilot:
    """The autopilot of a turning circle: the rudder `angle` [rad] held throughout."""

    def __init__(self, angle):
        self.angle = angle

    def __call__(self, psi, held):
        return self.angle


def logged(generator, clean, rng, *, noise=NOISE, name="record", n=0.0):
    """The record a user's logger writes of `clean` (`MarinerScipy.run`): u, v over
    ground, the gyro's r, the servo's rudder without the offset, the propeller rate `n`
    [rev/s] and noise (module text). A `jaxship.Experiment` with `over_ground`
    semantics."""

    t, psi = clean["t"], clean["psi"]
    north, east = generator.current
    u = clean["u"] + north * np.cos(psi) + east * np.sin(psi)
    v = clean["v"] - north * np.sin(psi) + east * np.cos(psi)
    r = clean["r"] + generator.gyro_bias
    noisy = lambda x, s: x + rng.normal(0, s, t.size)
    return js.Experiment(
        t, clean["delta"], psi=noisy(psi, noise[0] * DEG), r=noisy(r, noise[1] * DEG),
        u=noisy(u, noise[2]), v=noisy(v, noise[3]), x=noisy(clean["x"], noise[4]),
        y=noisy(clean["y"], noise[4]), n=np.full(t.size, n), name=name,
        metadata=(("velocities", "over ground"),))


def mariner_scipy_records(generator: MarinerScipy, seed, *, duration=400.0, dt=0.5,
                          noise=NOISE):
    """`(train, holdout)` of `generator` in the shape of
    `jaxship.studies.discovery.vessel_records(..., over_ground=True)`: 10/10 and 20/20
    zig-zags to both sides to train; +-35 deg turning circles and a 15/15 zig-zag held
    out; `duration` s at `1/dt` Hz."""
    rng = np.random.default_rng(seed)

    def one(pilot, name):
        return logged(generator, generator.run(pilot, duration, dt), rng, noise=noise,
                      name=name)

    train = [one(ZigZagPilot(a * DEG, a * DEG, s),
                 f"zigzag {a}/{a} {'starboard' if s > 0 else 'port'}") for a, s in TRAIN]
    holdout = [one(TurnPilot(a * DEG), f"turn {a:+d}") for a in (35, -35)]
    holdout.append(one(ZigZagPilot(15 * DEG, 15 * DEG), "zigzag 15/15"))
    return train, holdout


def generator_from_effects(effects, kind=MarinerScipy):
    """The generator `kind` (`MarinerScipy`, or `KVLCC2Shipmmg` of
    `jaxship.studies.kvlcc2_shipmmg`) with jaxship effects' sizes hidden
    (`rudder_offset.delta0`, `current.north/east`, `yaw_rate_sensor_bias.bias`,
    `added_mass_error.s_r` with `s_v = 0`, and for `MarinerScipy` `rudder_delay.delay`;
    others raise `ValueError`)."""
    options = {}
    for e in effects:
        if e.id == "rudder_offset":
            options["offset"] = float(e.delta0)
        elif e.id == "current":
            options["current"] = (float(e.north), float(e.east))
        elif e.id == "yaw_rate_sensor_bias":
            options["gyro_bias"] = float(e.bias)
        elif e.id == "added_mass_error" and float(e.s_v) == 0.0:
            options["added_mass"] = float(e.s_r)
        elif e.id == "rudder_delay" and kind is MarinerScipy:
            options["delay"] = float(e.delay)
        else:
            raise ValueError(f"the {kind.__name__} generator cannot hide {e.id!r}")
    return kind(**options)
