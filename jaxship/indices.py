"""Manoeuvre indices (ITTC) and the IMO criteria (MSC.137(76)) of a simulated or
measured `Trajectory`, in SI units and radians:

    import jaxship as js
    traj = js.simulate(js.get_vessel("mariner"), js.Turn(0.61, duration=600.0, dt=0.5))
    js.indices.turning_indices(traj).tactical_diameter

`check_imo` runs a vessel's IMO trials and checks the criteria, with the band of an
identification's standard errors. `batch_turning_indices` is the jittable form for
`simulate_batch(..., output=)`.
"""

from ._analysis._indices import (
    SteadyFromCircle as SteadyFromCircle,
    SteadyFromRate as SteadyFromRate,
    format_table as format_table,
    imo_criteria as imo_criteria,
    initial_turning_indices as initial_turning_indices,
    pull_out_indices as pull_out_indices,
    reverse_spiral_curve as reverse_spiral_curve,
    spiral_curve as spiral_curve,
    stopping_indices as stopping_indices,
    turning_indices as turning_indices,
    zigzag_indices as zigzag_indices,
)
from ._simulation._batch import batch_turning_indices as batch_turning_indices
from ._workflow._imo import ImoCheck as ImoCheck, check_imo as check_imo


__all__ = [
    # analysis: Manoeuvre indices
    "turning_indices",
    "SteadyFromRate",
    "SteadyFromCircle",
    "initial_turning_indices",
    "zigzag_indices",
    "pull_out_indices",
    "spiral_curve",
    "reverse_spiral_curve",
    "stopping_indices",
    "imo_criteria",
    "format_table",
    # analysis: The IMO check
    "check_imo",
    "ImoCheck",
    # simulation: Batches
    "batch_turning_indices",
]
