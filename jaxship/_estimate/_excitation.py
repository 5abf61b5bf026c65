"""Whether records can determine a model at all: a rudder that moves (excitation) and
more fitted values than unknowns."""

import numpy as np


# how the flags of records that determine nothing begin (`excitation_flags`)
TOO_POOR = ("the rudder input is constant in every experiment", "the records hold")

def excitation_flags(ds, rudder, values=None, unknowns=None) -> tuple[list[str], bool]:
    """Flags of experiments whose rudder never moves, and of records holding no more
    fitted `values` (residuals) than `unknowns` (parameters and start states: any data
    then fit exactly); and whether the data determine nothing (all rudders constant, or
    too few values)."""
    flags, constant = [], []
    for i, name in enumerate(ds.names):
        d = np.asarray(getattr(ds, rudder))[i, : ds.lengths[i]]
        if np.ptp(d) == 0.0:
            constant.append(name)
    if constant and len(constant) == ds.num_experiments:
        flags.append(
            f"the rudder input is constant in every experiment ({', '.join(constant)}): the "
            "data contain no excitation, so the steering parameters cannot be identified; "
            "use a zig-zag, PRBS or turning record."
        )
    elif constant:
        flags.append(f"the rudder input is constant in experiment(s) {', '.join(constant)}: "
                     "they add no excitation.")
    too_few = values is not None and values <= unknowns
    if too_few:
        flags.append(f"the records hold {values} fitted values for {unknowns} unknowns "
                     "(parameters and start states): too few to determine the parameters; "
                     "use a longer record.")
    return flags, too_few or bool(constant) and len(constant) == ds.num_experiments
