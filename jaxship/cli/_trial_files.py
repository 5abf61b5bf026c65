"""`jaxship simulate`'s files: a trial run into `trial.csv`, `indices.json` and its
figures (the trial itself is the library's, `jaxship.StandardTrial`)."""

import json
import pathlib

import numpy as np

from .. import Experiment, StandardTrial, simulate, write_trial_csv
from ..plotting import plot_imo_criteria, plot_spiral, plot_trajectory


def simulate_to_folder(
    vessel, spec, out, *, speed=None, rpm=None, duration=None, dt=None, title=""
) -> dict:
    """Run `spec` on `vessel` and write `trial.csv`, `indices.json` and `trial.png` to `out`,
    with `spiral.png` (the r-delta curve) for a spiral and `imo_criteria.png` (and the
    rows under "imo_criteria" in `indices.json`) for a trial that an IMO criterion
    checks."""
    import matplotlib.pyplot as plt  # with the figures only (issue 70)

    spec = StandardTrial.parse(spec) if isinstance(spec, str) else spec
    manoeuvre, x0 = spec.sized(vessel, speed=speed, rpm=rpm, duration=duration, dt=dt)
    traj = simulate(vessel, manoeuvre, x0, simulator=spec.simulator)
    if not bool(traj.success):
        raise ValueError(
            f"the simulation of {spec!r} failed (non-finite state); try a smaller --dt."
        )
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    record = Experiment.from_trajectory(traj)
    if not np.any(record.n):  # a vessel without a propeller model: no column of zeros
        record = Experiment(record.t, record.delta, name=record.name, **{
            c: getattr(record, c) for c in record.channels if c not in ("delta", "n")})
    write_trial_csv(out / "trial.csv", record)
    indices = {
        k: (None if isinstance(v, float) and not np.isfinite(v) else v)
        for k, v in spec.indices(manoeuvre, traj).items()
    }
    marks = spec.marks(manoeuvre, traj)
    criteria = spec.criteria(vessel, traj, marks)
    if criteria:
        indices["imo_criteria"] = [row.to_dict() for row in criteria]
    (out / "indices.json").write_text(json.dumps(indices, indent=2) + "\n")
    name = title or str(spec)
    fig = plot_trajectory(traj, length=float(vessel.length), title=name, labels=[name],
                          indices=marks)
    fig.savefig(out / "trial.png", dpi=110)
    plt.close(fig)
    if spec.kind in ("spiral", "reverse-spiral"):
        curve = spec.curve(manoeuvre, traj)
        ordered = manoeuvre.rates if spec.kind == "reverse-spiral" else None
        fig = plot_spiral(curve, title=f"{name}: steady yaw rate against rudder angle",
                          ordered=ordered)
        fig.savefig(out / "spiral.png", dpi=110)
        plt.close(fig)
    if criteria:
        fig = plot_imo_criteria(criteria, title=f"{name}: IMO MSC.137(76) criteria")
        fig.savefig(out / "imo_criteria.png", dpi=110)
        plt.close(fig)
    return indices


def simulate_steering_to_folder(model, spec, out, *, dt, duration, title="") -> dict:
    """Run `spec` on the steering `model` from rest (`jaxship.simulate`'s closed loop on
    its heading and yaw rate), its time scale `duration / 35` (a zig-zag's 35 L/U),
    and write `trial.csv` (t, delta, r, psi), `indices.json` and `trial.png` to `out`."""
    import matplotlib.pyplot as plt  # with the figures only (issue 70)

    manoeuvre, _ = spec.sized(model, duration=duration, dt=dt, time_scale=duration / 35)
    traj = simulate(model, manoeuvre, simulator=spec.simulator)
    if not bool(traj.success):
        raise ValueError(f"the simulation of {spec} failed (non-finite state); "
                         "try a smaller --dt.")
    record = Experiment.from_trajectory(traj)
    record = Experiment(record.t, record.delta, name=record.name, r=record.r, psi=record.psi)
    write_trial_csv(pathlib.Path(out) / "trial.csv", record)
    indices = {k: (None if isinstance(v, float) and not np.isfinite(v) else v)
               for k, v in spec.indices(manoeuvre, traj).items()
               if k != "min_speed_m_s" and k != "max_speed_m_s"}
    (pathlib.Path(out) / "indices.json").write_text(json.dumps(indices, indent=2) + "\n")
    name = title or str(spec)
    fig = plot_trajectory(traj, title=name, labels=[name],
                          indices=spec.marks(manoeuvre, traj))
    fig.savefig(pathlib.Path(out) / "trial.png", dpi=110)
    plt.close(fig)
    return indices
