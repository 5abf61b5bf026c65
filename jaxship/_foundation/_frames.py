"""pandas DataFrames of trajectories and fit results, for notebooks (pandas is an
optional dependency: `pip install "jaxship[dataframe]"`). SI units and radians, as
everywhere inside jaxship."""

import numpy as np


Z95 = 1.959963984540054  # standard normal quantile 0.975: the 95 % interval is +-Z95 std
TRAJECTORY_COLUMNS = ("t", "u", "v", "r", "x", "y", "psi", "delta", "n", "delta_c", "n_c")


def _pandas():
    try:
        import pandas
    except ImportError:
        raise ImportError("to_dataframe() needs pandas: pip install pandas (or "
                          "pip install \"jaxship[dataframe]\").") from None
    return pandas


def trajectory_to_dataframe(traj):
    """One row per valid sample of a `Trajectory` of one run, with the columns `t` [s],
    `u`, `v` [m/s], `r` [rad/s], `x`, `y` [m], `psi`, `delta` [rad], `n` [rev/s] and
    the commands `delta_c` [rad], `n_c` [rev/s].

    **Raises:** `ValueError` for a batched trajectory (index one run first, e.g.
    `jax.tree.map(lambda a: a[0], traj)`); `ImportError` without pandas."""
    pd = _pandas()
    t = np.asarray(traj.t)
    if t.ndim != 1:
        raise ValueError(f"to_dataframe() takes the trajectory of one run, got a batch of shape "
                         f"{t.shape[:-1]}; index one run first, e.g. "
                         "jax.tree.map(lambda a: a[0], traj).")
    valid = np.broadcast_to(np.asarray(traj.valid, dtype=bool), t.shape)
    s, c = traj.state, traj.command
    values = (t, s.u, s.v, s.r, s.x, s.y, s.psi, s.delta, s.n, c.delta, c.n)
    columns = {name: np.broadcast_to(np.asarray(v, dtype=np.float64), t.shape)[valid]
               for name, v in zip(TRAJECTORY_COLUMNS, values)}
    return pd.DataFrame(columns)


def fit_to_dataframe(result):
    """One row per free parameter of a `FitResult`: `name`, `value`, `std` (standard
    error), `unit`, and the 95 % interval `lower_95`, `upper_95` (value -+ 1.96 std;
    infinite where the data do not determine the parameter); plus `std_robust` where
    the fit computed standard errors that do not assume white residuals.

    **Raises:** `ImportError` without pandas."""
    pd = _pandas()
    report = result.parameters
    names = list(report.names)
    values = np.asarray(report.values, dtype=np.float64)
    std = np.asarray(report.std, dtype=np.float64)
    units = list(report.units) or [""] * len(names)
    frame = pd.DataFrame({"name": names, "value": values, "std": std, "unit": units,
                          "lower_95": values - Z95 * std, "upper_95": values + Z95 * std})
    robust = getattr(report, "std_robust", None)
    if robust is not None and np.any(~np.isnan(np.asarray(robust, dtype=np.float64))):
        frame.insert(3, "std_robust", np.asarray(robust, dtype=np.float64))
    return frame
