"""The standard trials of a vessel (`StandardTrial`): specs such as `turn:35` or
`zigzag:-10/10`, sized for the vessel, and their indices.

Specs are strings in degrees, as written on the command line (`jaxship simulate
--manoeuvre`). Durations default to multiples of the vessel's time scale L/U so that the same
spec suits a 4 m model and a 160 m ship; this module is the one place of that rule.
"""

import dataclasses
from typing import ClassVar

import jax
import jax.numpy as jnp
import numpy as np

import jaxship as js

from .. import AbstractVessel, Simulator, simulate, straight_run, straight_state
from .._analysis._indices.criteria import CRITERIA, CriterionRow, criterion_limits
from .._models._vessel._base import surge_force


SPEC_HELP = (
    "turn:ANGLE, zigzag:ANGLE/HEADING (negative ANGLE: port first), spiral, "
    "reverse-spiral, pullout:ANGLE, stop, prbs:AMPLITUDE, 3211:AMPLITUDE, thesis, "
    "heading-steps:AMPLITUDE (angles in degrees)"
)
# how many values each kind takes (pullout, prbs and 3211 may take none: their defaults)
VALUES = {"turn": 1, "zigzag": 2, "spiral": 0, "reverse-spiral": 0, "pullout": 1, "stop": 0,
          "prbs": 1, "3211": 1, "thesis": 0, "heading-steps": 1}


@dataclasses.dataclass(frozen=True)
class StandardTrial:
    """A standard trial as `jaxship simulate --manoeuvre` names it (`StandardTrial.parse(
    "zigzag:20/20")`: `kind` and `values`, angles in degrees as written), sized for a
    vessel by one rule (`sized`) and read by its indices (`indices`, `marks`, `criteria`).

    The size: durations in multiples of the time scale $\\tau = L/U$ (a turn 60 $\\tau$,
    extended until it has turned 540 deg (ITTC 7.5-04-02-01 2.2.1); a zig-zag 35
    $\\tau$; a spiral's levels `js.spiral`'s, each held 30 $\\tau$; a pull-out 30
    $\\tau$ turning, 30 $\\tau$ released; a stop 80 $\\tau$, ended when the ship lies
    stopped (ITTC 2.2.7); a PRBS 100 $\\tau$ with a bit every 2 $\\tau$; a 3-2-1-1 in
    units of $\\tau$, 30 $\\tau$ in all; heading steps every 10 $\\tau$ for 80 $\\tau$),
    the sample interval about $\\tau/20$ (1, 2 or 5 times a power
    of ten). `js.simulate(vessel, *trial.sized(vessel), simulator=trial.simulator)` is
    the trajectory of `jaxship simulate`.
    """

    kind: str
    values: tuple[float, ...] = ()
    # the trials' numerics: at least two RK4 steps per sample
    simulator: ClassVar[Simulator] = Simulator(substeps=2)
    # the kinds a steering model runs (it has no track, speed or propeller)
    steering_kinds: ClassVar[tuple[str, ...]] = ("zigzag", "prbs", "3211", "heading-steps",
                                                  "thesis")

    @classmethod
    def parse(cls, text: str) -> "StandardTrial":
        """The trial of `text` (`turn:35`, `zigzag:-10/10`, `spiral`, ...). **Raises**
        `ValueError` for an unknown kind or values it cannot take."""
        kind, _, rest = text.strip().lower().partition(":")
        if kind not in VALUES:
            raise ValueError(f"Unknown manoeuvre {text!r}; use one of: {SPEC_HELP}.")
        try:
            values = tuple(float(v) for v in rest.split("/")) if rest else ()
        except ValueError:
            raise ValueError(f"Manoeuvre {text!r}: values must be numbers in degrees.") from None
        if len(values) != VALUES[kind] and not (kind in ("pullout", "prbs", "3211")
                                                and not values):
            raise ValueError(
                f"Manoeuvre {text!r} takes {VALUES[kind]} value(s); use one of: {SPEC_HELP}."
            )
        for value in values:
            if not np.isfinite(value):
                raise ValueError(f"Manoeuvre {text!r}: values must be finite numbers in degrees, "
                                 f"got {value:g}.")
        trial = cls(kind, values)
        _check_values(trial, text)
        return trial

    @classmethod
    def imo(cls, vessel) -> tuple["StandardTrial", ...]:
        """The trials of IMO MSC.137(76) 5.3 for `vessel`: the 35 deg turn, the 10/10 and
        20/20 zig-zags and the stop, the stop only where `vessel` has a propeller model
        (astern thrust differs from ahead)."""
        trials = [cls.parse(s) for s in ("turn:35", "zigzag:10/10", "zigzag:20/20")]
        u, n = float(vessel.nominal_speed), float(vessel.nominal_n)
        if n and float(surge_force(vessel, u, n) - surge_force(vessel, u, -n)) != 0.0:
            trials.append(cls.parse("stop"))
        return tuple(trials)

    @property
    def rudder_angles(self) -> tuple[float, ...]:
        """The rudder angles [deg] the trial orders (its own or the defaults), for checks
        against a vessel's rudder limit; heading values are not included."""
        if self.kind in ("turn", "zigzag"):
            return self.values[:1]
        if self.kind == "pullout":
            return self.values or (20.0,)
        if self.kind in ("prbs", "3211"):
            return self.values or (10.0,)
        return ()

    def __str__(self) -> str:
        """The trial as written: `turn:35`, `zigzag:10/10`, `spiral`."""
        values = "/".join(f"{v:g}" for v in self.values)
        return f"{self.kind}:{values}" if values else self.kind

    def sized(self, model, *, speed=None, rpm=None, duration=None, dt=None,
              time_scale=None) -> tuple:
        """`(manoeuvre, x0)`: the trial sized for `model` (see the class) from the straight
        run at `speed` [m/s] and/or `rpm` (the nominal one if neither); `duration` and
        `dt` [s] replace the rule's (a turn is then not extended, a stop not ended).

        A steering model has no length, speed or propeller: give `time_scale` [s] (L/U)
        and `duration`; `x0` is then None (at rest) and only the kinds of
        `steering_kinds` run."""
        if isinstance(model, AbstractVessel):
            check_operating_point(model, speeds=[speed] if speed else [],
                                  rpms=[rpm] if rpm else [])
            x0 = initial_state(model, speed=speed, rpm=rpm)
            tau = length_over_speed(model, x0)
        elif self.kind not in self.steering_kinds or time_scale is None or duration is None:
            raise ValueError(f"a {type(model).__name__} steering model has no track, speed or "
                             f"propeller: give time_scale and duration, and one of "
                             f"{', '.join(self.steering_kinds)} (not {self}).")
        else:
            x0 = None
        tau = tau if time_scale is None else float(time_scale)
        manoeuvre, traj = _size(self, model, x0, tau, duration=duration, dt=dt)
        if self.kind == "stop" and traj is not None and bool(traj.success):
            manoeuvre = _until_stopped(manoeuvre, traj)
        return manoeuvre, x0

    def indices(self, manoeuvre, traj) -> dict:
        """The indices of this trial run as `(manoeuvre, traj)`, as a JSON-ready dict
        (display units in the names): the largest yaw rate and the speed's range, then
        the trial's own (`js.indices.turning_indices`, `zigzag_indices`, `spiral_curve`
        with its loop, `reverse_spiral_curve`, `pull_out_indices`, `stopping_indices`)."""
        base = {
            "max_yaw_rate_deg_s": float(np.rad2deg(np.max(np.abs(traj.state.r)))),
            "min_speed_m_s": float(np.min(traj.speed)),
            "max_speed_m_s": float(np.max(traj.speed)),
        }
        if self.kind in ("spiral", "reverse-spiral"):
            curve = self.curve(manoeuvre, traj)
            ordered = ({} if self.kind == "spiral" else {"r_ordered_deg_s": np.rad2deg(
                np.asarray(manoeuvre.rates, dtype=float)[: curve.r.size]).tolist()})
            return base | curve.to_dict() | ordered | curve.loop.to_dict()
        reading = {"turn": js.indices.turning_indices, "pullout": js.indices.pull_out_indices,
                   "stop": js.indices.stopping_indices}.get(self.kind)
        if self.kind == "turn" and self.values[0] == 0:
            return base
        if self.kind == "zigzag":
            return base | js.indices.zigzag_indices(traj, manoeuvre.heading).to_dict()
        return base | reading(traj).to_dict() if reading else base

    def curve(self, manoeuvre, traj):
        """The steady yaw rate against the rudder of a spiral (`js.indices.spiral_curve`)
        or a reverse spiral (`js.indices.reverse_spiral_curve`)."""
        if self.kind == "spiral":
            hold = float(np.diff(np.unique(np.asarray(manoeuvre.times)))[0])
            return js.indices.spiral_curve(traj, hold=hold)
        return js.indices.reverse_spiral_curve(traj, rates=manoeuvre.rates, hold=manoeuvre.hold)

    def marks(self, manoeuvre, traj):
        """The indices drawn on the trial's figure: turning, zig-zag or stopping; None for
        the other trials, or where the run is too short for them."""
        try:
            if self.kind == "turn" and self.values[0] != 0:
                return js.indices.turning_indices(traj)
            if self.kind == "zigzag":
                return js.indices.zigzag_indices(traj, manoeuvre.heading)
            if self.kind == "stop":
                return js.indices.stopping_indices(traj)
        except ValueError:
            return None
        return None

    def criteria(self, vessel, traj, marks) -> list:
        """The IMO MSC.137(76) 5.3 criteria that this trial checks (a 35 deg turn, a 10/10
        or 20/20 zig-zag, the stop) from its `marks`, as `CriterionRow`s
        (`js.indices.imo_criteria` at the approach speed of `traj`); [] for the others. A
        criterion the run could not measure (no marks; a 10/10 zig-zag whose ship never
        checks its swing against the counter-rudder) is listed, not met, with the reason."""
        angle = abs(self.values[0]) if self.values else None
        key = {("turn", 35): "turning35", ("stop", None): "stopping"}.get((self.kind, angle))
        if self.kind == "zigzag" and angle == self.values[1] in (10, 20):
            key = f"zigzag{angle:g}"
        if key is None:
            return []
        length, speed = float(vessel.length), float(np.hypot(traj.state.u[0], traj.state.v[0]))
        limits = criterion_limits(length, speed)
        if marks is None:
            why = (f"not measured: the {self} run gave none of its indices (the heading never "
                   "reached a switch, or the run is too short for them)")
            return [CriterionRow.not_measured(c, *limits[c], why) for c in CRITERIA[key]]
        if key == "zigzag10" and len(marks.overshoots) < 2:
            why = (f"not measured: the ship never checked its swing against the 10 deg "
                   f"counter-rudder ({len(marks.overshoots)} of the 2 overshoots measured)")
            first = [CriterionRow(CRITERIA[key][0], float(np.degrees(marks.overshoots[0])),
                                  *limits[CRITERIA[key][0]], False)] if marks.overshoots else []
            first = [dataclasses.replace(r, passed=r.value <= r.limit) for r in first]
            return first + [CriterionRow.not_measured(c, *limits[c], why)
                            for c in CRITERIA[key][len(first):]]
        return js.indices.imo_criteria(length, speed, **{key: marks})


def _check_values(trial, text):
    """Refuse values a trial cannot take: a rudder beyond 90 deg, a zero rudder, a heading
    change outside (0, 180) deg, a PRBS amplitude or heading steps not positive."""
    kind, values = trial.kind, trial.values
    for angle in trial.rudder_angles:
        if abs(angle) > 90:
            raise ValueError(f"Manoeuvre {text!r}: the rudder angle {angle:g} deg is beyond "
                             "90 deg; give a rudder angle in degrees within the vessel's "
                             "limit (e.g. 35).")
    if kind == "zigzag" and values[0] == 0:
        raise ValueError(f"Manoeuvre {text!r}: the rudder angle must not be 0 (e.g. "
                         "zigzag:20/20, or zigzag:-20/20 to port first).")
    if kind == "zigzag" and not 0 < values[1] < 180:
        raise ValueError(f"Manoeuvre {text!r}: the heading change must be positive and below "
                         "180 deg (e.g. zigzag:20/20).")
    if kind in ("pullout", "3211") and values and values[0] == 0:
        raise ValueError(f"Manoeuvre {text!r}: the rudder angle must not be 0.")
    if kind == "prbs" and values and values[0] <= 0:
        raise ValueError(f"Manoeuvre {text!r}: the amplitude must be positive (the sequence "
                         "takes both signs).")
    if kind == "heading-steps" and not 0 < values[0] <= 180:
        raise ValueError(f"Manoeuvre {text!r}: the heading amplitude must be positive and at "
                         "most 180 deg (the steps take both signs).")


def _size(trial, model, x0, tau, *, duration, dt):
    """`(manoeuvre, trajectory or None)`: the manoeuvre of `trial` on `model` from `x0`
    with durations in multiples of `tau` [s]; a turn with no `duration` simulated and
    doubled until it has turned 540 deg (ITTC 7.5-04-02-01 2.2.1; at most 1000 nominal
    L/U), a stop with none simulated (`sized` ends it at the stop)."""
    manoeuvre = build_manoeuvre(trial, model, x0, tau, duration=duration, dt=dt)
    turn = trial.kind == "turn" and trial.values[0] != 0
    if duration is not None or not (turn or trial.kind == "stop"):
        return manoeuvre, None
    traj = simulate(model, manoeuvre, x0, simulator=StandardTrial.simulator)
    longest = 1000 * float(model.length) / float(model.nominal_speed)
    while turn and abs(float(traj.state.psi[-1] - traj.state.psi[0])) < np.deg2rad(540):
        if manoeuvre.duration > longest:
            break
        manoeuvre = js.Turn(manoeuvre.angle, duration=2 * float(manoeuvre.duration),
                            dt=manoeuvre.dt)
        traj = simulate(model, manoeuvre, x0, simulator=StandardTrial.simulator)
    return manoeuvre, traj


def build_manoeuvre(trial, vessel, x0, tau, *, duration=None, dt=None):
    """The manoeuvre of `trial` on `vessel` from `x0`, its durations in multiples of the
    time scale `tau` [s] (L/U) unless `duration` [s] is given."""
    dt = dt if dt is not None else _default_dt(tau)
    rad = np.deg2rad
    v = trial.values
    pick = lambda default: float(duration) if duration is not None else default
    if trial.kind == "turn":
        return js.Turn(rad(v[0]), duration=pick(60 * tau), dt=dt)
    if trial.kind == "zigzag":
        return js.ZigZag(rad(v[0]), rad(v[1]), duration=pick(35 * tau), dt=dt)
    if trial.kind == "spiral":
        return js.spiral(_whole(30 * tau, dt), dt=dt)
    if trial.kind == "reverse-spiral":
        return reverse_spiral(vessel, x0, hold=_whole(30 * tau, dt), dt=dt)
    if trial.kind == "pullout":
        angle = rad(v[0]) if v else rad(20.0)
        return js.pull_out(
            angle, turn_time=30 * tau, release_time=pick(60 * tau) - 30 * tau, dt=dt
        )
    if trial.kind == "stop":
        if abs(float(surge_force(vessel, x0.u, x0.n) - surge_force(vessel, x0.u, -x0.n))) < 1e-9:
            raise ValueError(
                f"{type(vessel).__name__} has no propeller model: a stop cannot be simulated."
            )
        return js.Stop(-abs(float(x0.n)), duration=pick(80 * tau), dt=dt, until_stopped=True)
    if trial.kind == "prbs":
        amp = rad(v[0]) if v else rad(10.0)
        return js.prbs(amp, bit_time=2 * tau, duration=pick(100 * tau), dt=dt)
    if trial.kind == "3211":
        amp = rad(v[0]) if v else rad(10.0)
        return js.multi_step_3211(amp, unit=tau, settle=pick(30 * tau) - 7 * tau, dt=dt)
    if trial.kind == "thesis":
        return js.thesis_manoeuvre(dt=dt)
    if trial.kind == "heading-steps":
        return js.heading_perturbations(
            rad(v[0]),
            period=20 * tau,
            kp=2.0,
            ki=0.02 / tau,
            kd=2 * tau,
            duration=pick(80 * tau),
            dt=dt,
        )
    raise AssertionError(trial.kind)


# reverse spiral levels: fractions of the steady yaw rate at the direct spiral's largest
# rudder angle, from starboard to port; the small ones fall inside the loop of an
# unstable ship (the S-shaped part of Bech's delta(r) curve)
REVERSE_SPIRAL_FRACTIONS = (0.8, 0.55, 0.35, 0.2, 0.1, 0.03)


def _whole(duration, dt):
    """`duration` [s] rounded to a whole number (at least one) of sample intervals `dt`."""
    return float(max(1, round(duration / dt)) * dt)


def linear_yaw(vessel, x0):
    """First-order Nomoto model $r/\\delta = K/(1 + T s)$ of `vessel` about the state `x0`,
    as `(b, a)` with $b = K/T$ [1/s^2] and $a = 1/T$ [1/s] ($\\dot r = -a r + b \\delta$;
    $a < 0$: course-unstable).

    The sway-yaw equations linearised about `x0` (the Jacobian of the loads, solved with
    the mass matrix) give $r/\\delta = K (1 + T_3 s)/((1 + T_1 s)(1 + T_2 s))$; Nomoto's
    first-order model keeps $K$ and $T = T_1 + T_2 - T_3$ (Nomoto et al. 1957; Fossen
    2021 sec. 7.2). With $b$ and $a$ written without dividing by the determinant they
    stay finite for a marginally stable ship. A vessel without sway dynamics (the sway
    row is zero) gives the yaw equation alone.
    """
    u0, v0, r0, d0, n0 = (float(getattr(x0, k)) for k in ("u", "v", "r", "delta", "n"))
    loads = lambda z: vessel.loads(0.0, z[0], z[1], z[2], z[3], n0)
    jac = np.asarray(jax.jacfwd(loads)(jnp.array([u0, v0, r0, d0])), dtype=float)
    mass = np.asarray(vessel.mass_matrix(), dtype=float)
    system = np.linalg.solve(mass, jac)
    a2, b2 = system[1:, 1:3], system[1:, 3]
    trace, det = np.trace(a2), np.linalg.det(a2)
    c0 = a2[1, 0] * b2[0] - a2[0, 0] * b2[1]  # K det
    denominator = -trace * c0 - b2[1] * det  # K det T
    scale = abs(trace * c0) + abs(b2[1] * det)
    if scale > 0 and abs(denominator) > 1e-9 * scale:
        return float(c0 * c0 / denominator), float(det * c0 / denominator)
    return float(b2[1]), float(-a2[1, 1])  # no sway coupling: the yaw equation


def yaw_rate_gains(b, a, bandwidth, damping=0.8):
    """Heading-autopilot gains `(kp, kd)` of `ReverseSpiral` (no integral) that place
    the closed-loop poles of the first-order yaw model $\\dot r = -a r + b\\delta$ at
    natural frequency `bandwidth` [rad/s] and relative damping `damping`: with
    $\\delta = K_p\\tilde\\psi + K_d\\tilde r$ and $\\dot{\\tilde\\psi} = \\tilde r$,
    $s^2 + (a + b K_d) s + b K_p = s^2 + 2\\zeta\\omega s + \\omega^2$ (thesis eq.
    5.3-5.5 with $m = 1/b$, $d = a/b$). The frequency is raised to $a/\\zeta$ for a ship
    whose own yaw damping is faster, so $K_d > 0$."""
    if not b > 0:
        raise ValueError(f"the rudder must turn the ship to starboard (b = {b:g} 1/s^2).")
    omega = max(float(bandwidth), float(a) / damping)
    return omega**2 / b, (2 * damping * omega - a) / b


def reverse_spiral(vessel, x0, *, hold, dt, max_angle=np.deg2rad(25.0),
                   fractions=REVERSE_SPIRAL_FRACTIONS):
    """Bech's reverse spiral (MSC/Circ.1053 app. 4 2.2; Bech 1968) for `vessel` from `x0`.

    The yaw-rate levels are `fractions` (to starboard, then the same to port) of the
    steady yaw rate the vessel reaches at `max_angle` of rudder (the smaller of the two
    sides, from a simulated turn to each side), so that they span the direct spiral's
    range and reach into an unstable ship's loop; the PI gains come from the vessel's
    linearised yaw dynamics (`linear_yaw`, `yaw_rate_gains`, closed-loop bandwidth
    U/(2L)), so that every level is reached within its `hold` [s]; the heading
    autopilot flies the levels (`ReverseSpiral`).
    """
    speed = float(np.hypot(x0.u, x0.v)) or float(vessel.nominal_speed)
    tau = float(vessel.length) / speed
    turn = _whole(20 * tau, dt)
    angles = np.array([0.0, max_angle, max_angle, -max_angle])
    both = simulate(vessel, js.Schedule(np.array([0.0, 0.0, turn, turn]), angles,
                                         duration=2 * turn, dt=dt), x0)
    t, r = np.asarray(both.t), np.asarray(both.state.r)
    ends = np.array([turn, 2 * turn])
    steady = np.abs(np.interp(ends, t, r))
    drift = np.abs(np.interp(ends, t, r) - np.interp(ends - 0.25 * turn, t, r))
    if not (bool(both.success) and np.all(np.isfinite(steady)) and np.min(steady) > 0
            and np.all(drift <= 0.02 * steady)):
        raise ValueError(
            f"{type(vessel).__name__}: no steady turn at {np.rad2deg(max_angle):g} deg of "
            "rudder to size the reverse spiral's yaw-rate levels."
        )
    side = np.asarray(fractions, dtype=float) * float(np.min(steady))
    rates = np.concatenate([side, -side[::-1]])  # from starboard to port
    kp, kd = yaw_rate_gains(*linear_yaw(vessel, x0), bandwidth=0.5 / tau)
    limit = float(vessel.rudder.max_angle)
    return js.ReverseSpiral(rates, hold, kp=kp, kd=kd, duration=hold * rates.size, dt=dt,
                             max_angle=limit)


def _default_dt(tau):
    """A sample interval of about L/U / 20, rounded to 1, 2 or 5 times a power of ten."""
    raw = tau / 20
    exponent = np.floor(np.log10(raw))
    mantissa = max(m for m in (1, 2, 5) if m * 10**exponent <= raw * 1.0000001)
    return float(mantissa * 10**exponent)


def check_operating_point(vessel, *, speeds=(), rpms=(), name: str | None = None) -> None:
    """`ValueError` (one line, naming the vessel `name`) for approach speeds [m/s] and
    propeller rates [rpm] the vessel cannot sail at: above 10 times its service speed or
    rate, a speed or rate below a tenth of the service one (dead slow ahead is about a
    third of it: below a tenth the rudder has no steerage way; rpm given as rev/s?), or a rate
    where it has no propeller model (the net surge force does not change with n)."""
    name = name or type(vessel).__name__
    nominal = float(vessel.nominal_speed)
    for speed in speeds:
        if speed > 10 * nominal:
            raise ValueError(f"speed {speed:g} m/s: more than 10 times the service speed of "
                             f"{name} ({nominal:.3g} m/s); give an approach speed in m/s.")
        if speed < 0.1 * nominal:
            raise ValueError(f"speed {speed:g} m/s: less than a tenth of the service speed of "
                             f"{name} ({nominal:.3g} m/s), too slow to steer; give an approach "
                             "speed in m/s.")
    thrust = lambda n: float(vessel.forces(nominal, 0.0, 0.0, 0.0, n)[0])  # v = r = delta = 0
    if rpms and thrust(1.0) == thrust(0.0):
        raise ValueError(f"rpm: {name} has no propeller model, so the propeller rate does "
                         "nothing; give a speed instead.")
    service = 60.0 * float(vessel.nominal_n)
    for rpm in rpms:
        if rpm > 10 * service:
            raise ValueError(f"rpm {rpm:g}: more than 10 times the service propeller rate of "
                             f"{name} ({service:.4g} rpm).")
        if rpm < 0.1 * service:
            raise ValueError(f"rpm {rpm:g}: less than a tenth of the service propeller rate of "
                             f"{name} ({service:.4g} rpm), too slow to steer; is it in rev/s "
                             "rather than rpm?")


def initial_state(vessel, *, speed=None, rpm=None):
    """Straight-run approach at `speed` [m/s] and/or `rpm`; nominal if neither is given."""
    n = None if rpm is None else rpm / 60.0
    if speed is not None and n is not None:
        return straight_state(speed, n)
    return straight_run(vessel, speed=speed, n=n)


def length_over_speed(vessel, x0) -> float:
    """The time scale L/U [s] of `vessel` at the approach speed of `x0` (its nominal
    speed where `x0` lies still)."""
    return float(vessel.length) / (float(np.hypot(x0.u, x0.v)) or float(vessel.nominal_speed))


def _cut_at_stop(traj):
    """The stopping trial ends with the ship stopped in the water (ITTC 7.5-04-02-01
    2.2.7): keep the samples up to the stop and a tenth of the time to stop after it
    (the ship lying stopped); the whole run if it did not stop."""
    try:
        stop = js.indices.stopping_indices(traj)
    except ValueError:
        return traj
    t = np.asarray(traj.t)
    end = stop.execute_time + 1.1 * stop.time_to_stop
    keep = min(t.size, int(np.searchsorted(t, end)) + 2)
    size = t.size
    return jax.tree.map(lambda a: a[:keep] if np.ndim(a) and np.shape(a)[0] == size else a,
                        traj)


def _until_stopped(stop, traj):
    """The `Stop` manoeuvre `stop`, run as `traj`, shortened to end where `_cut_at_stop`
    ends its run."""
    cut = _cut_at_stop(traj)
    return js.Stop(stop.astern_n, duration=float(cut.t[-1] - cut.t[0]), dt=stop.dt,
                   execute=stop.execute, until_stopped=stop.until_stopped)
