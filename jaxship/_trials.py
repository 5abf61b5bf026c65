"""Trial specifications such as `turn:35` or `zigzag:-10/10`, and running them.

This is the edge of the library: specs are written in degrees, vessels by name.
Durations default to multiples of the vessel's time scale L/U so that the same
spec suits a 4 m model and a 160 m ship.
"""

import dataclasses
import json
import pathlib

import matplotlib.pyplot as plt
import numpy as np

from ._analysis import _indices as ix
from ._foundation._state import straight_state
from ._models import _manoeuvres as man
from ._models._vessel._base import straight_run, surge_force
from ._simulation._readers import write_trial_csv
from ._simulation._simulate import Simulator, simulate
from .plotting import plot_trajectory


SPEC_HELP = (
    "turn:ANGLE, zigzag:ANGLE/HEADING (negative ANGLE: port first), spiral, "
    "reverse-spiral, pullout:ANGLE, stop, prbs:AMPLITUDE, 3211:AMPLITUDE, thesis, "
    "heading-steps:AMPLITUDE (angles in degrees)"
)


@dataclasses.dataclass(frozen=True)
class TrialSpec:
    """A parsed trial specification (angles in degrees as written)."""

    kind: str
    values: tuple[float, ...] = ()

    @classmethod
    def parse(cls, text: str) -> "TrialSpec":
        kind, _, rest = text.strip().lower().partition(":")
        expected = {
            "turn": 1,
            "zigzag": 2,
            "spiral": 0,
            "reverse-spiral": 0,
            "pullout": 1,
            "stop": 0,
            "prbs": 1,
            "3211": 1,
            "thesis": 0,
            "heading-steps": 1,
        }
        if kind not in expected:
            raise ValueError(f"Unknown manoeuvre {text!r}; use one of: {SPEC_HELP}.")
        try:
            values = tuple(float(v) for v in rest.split("/")) if rest else ()
        except ValueError:
            raise ValueError(f"Manoeuvre {text!r}: values must be numbers in degrees.") from None
        if len(values) != expected[kind] and not (
            kind in ("pullout", "prbs", "3211") and not values
        ):
            raise ValueError(
                f"Manoeuvre {text!r} takes {expected[kind]} value(s); use one of: {SPEC_HELP}."
            )
        if kind == "zigzag" and values[1] <= 0:
            raise ValueError(f"Manoeuvre {text!r}: the heading change must be positive.")
        return cls(kind, values)


def build_manoeuvre(spec: TrialSpec, vessel, x0, *, duration=None, dt=None):
    """The manoeuvre for `spec` on `vessel` starting from `x0`."""
    speed = float(np.hypot(x0.u, x0.v)) or float(vessel.nominal_speed)
    tau = float(vessel.length) / speed  # L/U [s]
    dt = dt if dt is not None else _default_dt(tau)
    rad = np.deg2rad
    v = spec.values
    pick = lambda default: float(duration) if duration is not None else default
    if spec.kind == "turn":
        return man.Turn(rad(v[0]), duration=pick(60 * tau), dt=dt)
    if spec.kind == "zigzag":
        return man.ZigZag(rad(v[0]), rad(v[1]), duration=pick(35 * tau), dt=dt)
    if spec.kind == "spiral":
        return man.spiral(hold=30 * tau, dt=dt)
    if spec.kind == "reverse-spiral":
        levels = np.deg2rad(np.array([0.5, 0.3, 0.15, 0.05, -0.05, -0.15, -0.3, -0.5])) * 60 / tau
        hold = 30 * tau
        return man.ReverseSpiral(
            levels / 60, hold, kp=tau, ki=0.2, duration=hold * len(levels), dt=dt
        )
    if spec.kind == "pullout":
        angle = rad(v[0]) if v else rad(20.0)
        return man.pull_out(
            angle, turn_time=30 * tau, release_time=pick(60 * tau) - 30 * tau, dt=dt
        )
    if spec.kind == "stop":
        if abs(float(surge_force(vessel, x0.u, x0.n) - surge_force(vessel, x0.u, -x0.n))) < 1e-9:
            raise ValueError(
                f"{type(vessel).__name__} has no propeller model: a stop cannot be simulated."
            )
        return man.Stop(-abs(float(x0.n)), duration=pick(80 * tau), dt=dt)
    if spec.kind == "prbs":
        amp = rad(v[0]) if v else rad(10.0)
        return man.prbs(amp, bit_time=2 * tau, duration=pick(100 * tau), dt=dt)
    if spec.kind == "3211":
        amp = rad(v[0]) if v else rad(10.0)
        return man.multi_step_3211(amp, unit=tau, settle=pick(30 * tau) - 7 * tau, dt=dt)
    if spec.kind == "thesis":
        return man.thesis_manoeuvre(dt=dt)
    if spec.kind == "heading-steps":
        return man.HeadingPerturbations(
            rad(v[0]),
            period=20 * tau,
            kp=2.0,
            ki=0.02 / tau,
            kd=2 * tau,
            duration=pick(80 * tau),
            dt=dt,
        )
    raise AssertionError(spec.kind)


def _default_dt(tau):
    """A sample interval of about L/U / 20, rounded to 1, 2 or 5 times a power of ten."""
    raw = tau / 20
    exponent = np.floor(np.log10(raw))
    mantissa = max(m for m in (1, 2, 5) if m * 10**exponent <= raw * 1.0000001)
    return float(mantissa * 10**exponent)


def initial_state(vessel, *, speed=None, rpm=None):
    """Straight-run approach at `speed` [m/s] and/or `rpm`; nominal if neither is given."""
    n = None if rpm is None else rpm / 60.0
    if speed is not None and n is not None:
        return straight_state(speed, n)
    return straight_run(vessel, speed=speed, n=n)


def run_trial(vessel, spec, *, speed=None, rpm=None, duration=None, dt=None, substeps=2):
    """Simulate the trial `spec` (a string or `TrialSpec`); returns `(manoeuvre, trajectory)`.

    A turning circle is extended until it has turned at least 540 degrees (ITTC).
    """
    spec = TrialSpec.parse(spec) if isinstance(spec, str) else spec
    x0 = initial_state(vessel, speed=speed, rpm=rpm)
    manoeuvre = build_manoeuvre(spec, vessel, x0, duration=duration, dt=dt)
    simulator = Simulator(substeps=substeps)
    traj = simulate(vessel, manoeuvre, x0, simulator=simulator)
    while spec.kind == "turn" and duration is None and spec.values[0] != 0:
        if abs(float(traj.state.psi[-1] - traj.state.psi[0])) >= np.deg2rad(540):
            break
        if manoeuvre.duration > 1000 * float(vessel.length) / float(vessel.nominal_speed):
            break
        manoeuvre = man.Turn(
            manoeuvre.angle, duration=2 * float(manoeuvre.duration), dt=manoeuvre.dt
        )
        traj = simulate(vessel, manoeuvre, x0, simulator=simulator)
    return manoeuvre, traj


def trial_indices(spec, manoeuvre, traj) -> dict:
    """The indices of the trial `spec` as a JSON-ready dict (display units in the names)."""
    spec = TrialSpec.parse(spec) if isinstance(spec, str) else spec
    base = {
        "max_yaw_rate_deg_s": float(np.rad2deg(np.max(np.abs(traj.state.r)))),
        "min_speed_m_s": float(np.min(traj.speed)),
        "max_speed_m_s": float(np.max(traj.speed)),
    }
    if spec.kind == "turn" and spec.values[0] != 0:
        return base | ix.turning_indices(traj).to_dict()
    if spec.kind == "zigzag":
        return base | ix.zigzag_indices(traj, manoeuvre.heading).to_dict()
    if spec.kind == "spiral":
        hold = float(np.diff(np.unique(np.asarray(manoeuvre.times)))[0])
        curve = ix.spiral_curve(traj, hold=hold)
        return base | curve.to_dict() | {"loop_width_deg": float(np.rad2deg(ix.loop_width(curve)))}
    if spec.kind == "reverse-spiral":
        curve = ix.reverse_spiral_curve(traj, rates=manoeuvre.rates, hold=manoeuvre.hold)
        return base | curve.to_dict() | {"loop_width_deg": float(np.rad2deg(ix.loop_width(curve)))}
    if spec.kind == "pullout":
        return base | ix.pull_out_indices(traj).to_dict()
    if spec.kind == "stop":
        return base | ix.stopping_indices(traj).to_dict()
    return base


def simulate_to_folder(
    vessel, spec, out, *, speed=None, rpm=None, duration=None, dt=None, title=""
) -> dict:
    """Run `spec` on `vessel` and write `trial.csv`, `indices.json` and `trial.png` to `out`."""
    manoeuvre, traj = run_trial(vessel, spec, speed=speed, rpm=rpm, duration=duration, dt=dt)
    if not bool(traj.success):
        raise ValueError(
            f"the simulation of {spec!r} failed (non-finite state); try a smaller --dt."
        )
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_trial_csv(out / "trial.csv", traj)
    indices = {
        k: (None if isinstance(v, float) and not np.isfinite(v) else v)
        for k, v in trial_indices(spec, manoeuvre, traj).items()
    }
    (out / "indices.json").write_text(json.dumps(indices, indent=2) + "\n")
    fig = plot_trajectory(
        traj, length=float(vessel.length), title=title or str(spec), labels=[title or str(spec)]
    )
    fig.savefig(out / "trial.png", dpi=110)
    plt.close(fig)
    return indices
