"""IMO/ITTC manoeuvre indices and criteria from one simulated or measured trajectory.

Indices are computed at the edge, after `simulate`, in NumPy: every function takes a
single `Trajectory` (padding beyond `valid` is dropped) or plain sample arrays given
by keyword (`t, x, y, psi, u, v, r, delta, n`). Events between samples (heading
passing 90 deg, the ship stopping, ...) are located by linear interpolation, never by
rounding to whole degrees or samples. Results are small frozen dataclasses in SI units
(m, s, rad, rad/s); `to_dict()` gives display units (m, s, deg, deg/s, percent) with the
unit in each name, `to_dict(units=jaxship.strategies.SIUnits())` the SI values.

Definitions follow IMO MSC.137(76) sec. 4.2 and 5.3, MSC/Circ.1053 and ITTC 7.5-04-02-01;
positions are those of the vessel's reference point (midship for every catalogue vessel),
rotated into the original-course frame at the rudder (or engine) order: `x` along the
original heading, `y` to starboard.
"""

from .criteria import (
    CriterionRow as CriterionRow,
    format_table as format_table,
    imo_criteria as imo_criteria,
    imo_overshoot_limits_deg as imo_overshoot_limits_deg,
)
from .spiral import (
    PullOutIndices as PullOutIndices,
    SpiralCurve as SpiralCurve,
    SpiralLoop as SpiralLoop,
    StoppingIndices as StoppingIndices,
    loop_width as loop_width,
    pull_out_indices as pull_out_indices,
    reverse_spiral_curve as reverse_spiral_curve,
    spiral_curve as spiral_curve,
    spiral_loop as spiral_loop,
    stopping_indices as stopping_indices,
)
from .turning import (
    InitialTurningIndices as InitialTurningIndices,
    SteadyFromCircle as SteadyFromCircle,
    SteadyFromRate as SteadyFromRate,
    TurningIndices as TurningIndices,
    ZigZagIndices as ZigZagIndices,
    initial_turning_indices as initial_turning_indices,
    turning_indices as turning_indices,
    zigzag_indices as zigzag_indices,
)
