"""Sample series, event-location helpers and display units shared by the manoeuvre indices."""

import dataclasses

import numpy as np

from ..._simulation._readers import DisplayUnits, SIUnits


_DEG = 180.0 / np.pi
_TOL = 1e-9  # deadband on commands [rad, rev/s] when detecting orders


# --------------------------------------------------------------------------- series


@dataclasses.dataclass(frozen=True, eq=False)
class _Series:
    t: np.ndarray
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    psi: np.ndarray | None = None
    u: np.ndarray | None = None
    v: np.ndarray | None = None
    r: np.ndarray | None = None
    delta: np.ndarray | None = None  # actual rudder angle [rad]
    delta_command: np.ndarray | None = None  # ordered rudder angle [rad]
    n: np.ndarray | None = None  # actual propeller rate [rev/s]
    n_command: np.ndarray | None = None  # ordered propeller rate [rev/s]

    def need(self, *names, what):
        missing = [k for k in names if getattr(self, k) is None]
        if missing:
            raise ValueError(
                f"{what} needs the sample arrays {', '.join(missing)}: pass a Trajectory "
                "or give them by keyword."
            )
        return tuple(getattr(self, k) for k in names)

    @property
    def rudder_order(self):
        return self.delta if self.delta_command is None else self.delta_command

    @property
    def propeller_order(self):
        return self.n if self.n_command is None else self.n_command

    def speed(self):
        """Speed through water if u, v are known, else track speed from the positions."""
        if self.u is not None and self.v is not None:
            return np.hypot(self.u, self.v)
        x, y = self.need("x", "y", what="the speed")
        return np.hypot(np.gradient(x, self.t), np.gradient(y, self.t))


_NAMES = ("t", "x", "y", "psi", "u", "v", "r", "delta", "n")


def _series(traj, arrays) -> _Series:
    """Collect the samples of one trajectory as 1-D float arrays."""
    unknown = sorted(set(arrays) - set(_NAMES))
    if unknown:
        raise ValueError(
            f"unknown sample arrays {unknown}; the names are {', '.join(_NAMES)}."
        )
    given = {k: v for k, v in arrays.items() if v is not None}
    if traj is not None:
        if given:
            raise ValueError(
                f"give either a Trajectory or sample arrays, not both (got {sorted(given)})."
            )
        s, c = traj.state, traj.command
        fields = dict(
            t=traj.t, x=s.x, y=s.y, psi=s.psi, u=s.u, v=s.v, r=s.r, delta=s.delta,
            delta_command=c.delta, n=s.n, n_command=c.n,
        )
        if not bool(np.all(np.asarray(traj.success))):
            raise ValueError("the trajectory failed (`success` is False): no indices from it.")
        valid = np.asarray(traj.valid, dtype=bool)
    else:
        if "t" not in given:
            raise ValueError("give a Trajectory or at least the sample times `t` by keyword.")
        fields, valid = given, None
    out = {}
    for name, value in fields.items():
        a = np.asarray(value, dtype=float)
        if a.ndim != 1:
            raise ValueError(
                f"`{name}` has shape {a.shape}: indices take one trajectory with 1-D samples; "
                "index a batch first, e.g. jax.tree.map(lambda a: a[i], traj)."
            )
        out[name] = a
    size = out["t"].shape[0]
    for name, a in out.items():
        if a.shape[0] != size:
            raise ValueError(f"`{name}` has {a.shape[0]} samples, `t` has {size}.")
    if valid is not None:
        if valid.shape != (size,):
            raise ValueError("`valid` must have one flag per sample.")
        out = {k: a[valid] for k, a in out.items()}
        size = out["t"].shape[0]
    if size < 2:
        raise ValueError("need at least two samples.")
    if np.any(np.diff(out["t"]) <= 0):
        raise ValueError("the sample times `t` must be strictly increasing.")
    for name, a in out.items():
        if not np.all(np.isfinite(a)):
            raise ValueError(f"`{name}` has non-finite samples.")
    return _Series(**out)


_ARRAY_DOC = """
    Give either `traj` (a single `Trajectory`; batched ones must be indexed first) or
    the samples by keyword (every index function takes the same names and ignores those
    it does not need): `t` [s], positions `x` (north), `y` (east) [m], heading `psi`
    [rad, not wrapped], body velocities `u, v` [m/s], yaw rate `r` [rad/s], rudder
    `delta` [rad] (the order, if known) and propeller rate `n` [rev/s] (the order)."""


def _docstring(f):
    f.__doc__ = f.__doc__.replace("{arrays}", _ARRAY_DOC.strip())
    return f


# --------------------------------------------------------------------------- helpers


def _crossing(t, f, level, after, *, upward=True):
    """First time >= `after` at which `f` reaches `level` (from below if `upward`), or None."""
    g = f - level if upward else level - f
    g0 = np.interp(after, t, g)
    if g0 >= 0:
        return float(after)
    later = np.nonzero(t > after)[0]
    if later.size == 0:
        return None
    tt = np.concatenate([[after], t[later]])
    gg = np.concatenate([[g0], g[later]])
    hit = np.nonzero(gg >= 0)[0]
    if hit.size == 0:
        return None
    j = hit[0]
    return float(tt[j - 1] + (tt[j] - tt[j - 1]) * (-gg[j - 1]) / (gg[j] - gg[j - 1]))


def _peak(t, f, start, stop):
    """Maximum of `f` over `[start, stop]`: `(time, value, interior)`.

    The sample maximum is refined with the parabola through it and its neighbours when
    it is an interior local maximum (exact for a quadratic peak).
    """
    inside = np.nonzero((t >= start) & (t <= stop))[0]
    if inside.size == 0:
        return None
    i = inside[np.argmax(f[inside])]
    interior = 0 < i < t.size - 1 and f[i - 1] <= f[i] >= f[i + 1] and i != inside[-1]
    if not interior:
        return float(t[i]), float(f[i]), False
    a, b, c = np.polyfit(t[i - 1:i + 2] - t[i], f[i - 1:i + 2], 2)
    if a >= 0:
        return float(t[i]), float(f[i]), True
    tau = float(np.clip(-b / (2 * a), t[i - 1] - t[i], t[i + 1] - t[i]))
    return float(t[i] + tau), float(max(c + b * tau + a * tau**2, f[i])), True


def _window_mean(t, f, a, b):
    """Time average of the piecewise-linear `f` over `[a, b]`."""
    inner = (t > a) & (t < b)
    tt = np.concatenate([[a], t[inner], [b]])
    ff = np.concatenate([[np.interp(a, t, f)], f[inner], [np.interp(b, t, f)]])
    return float(np.sum(0.5 * (ff[1:] + ff[:-1]) * np.diff(tt)) / (b - a))


def _path_length(t, x, y):
    """Cumulative length of the piecewise-linear track at each sample [m]."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])


def _order_time(t, order, baseline, what):
    """Time of the first sample at which `order` differs from `baseline`."""
    moved = np.nonzero(np.abs(order - baseline) > _TOL)[0]
    if moved.size == 0:
        raise ValueError(f"no {what} order found in the command history; give `execute_time`.")
    return float(t[moved[0]])


def _rudder_execute(s: _Series, execute_time):
    """Time of the (first) rudder order: given, or the first sample at which the order
    leaves the initial actual rudder angle (0 for plain arrays)."""
    if execute_time is not None:
        return float(execute_time)
    s.need("delta", what="detecting the rudder order")
    baseline = s.delta[0] if s.delta_command is not None else 0.0
    return _order_time(s.t, s.rudder_order, baseline, "rudder")


def _course_frame(s: _Series, t_e):
    """Positions relative to the point at `t_e`, rotated to (along, starboard of) its heading."""
    x, y, psi = s.need("x", "y", "psi", what="positions in the original-course frame")
    psi_e = np.interp(t_e, s.t, psi)
    dx, dy = x - np.interp(t_e, s.t, x), y - np.interp(t_e, s.t, y)
    c, sn = np.cos(psi_e), np.sin(psi_e)
    return c * dx + sn * dy, -sn * dx + c * dy, psi_e


def _check_units(units):
    if not isinstance(units, (DisplayUnits, SIUnits)):
        raise ValueError("`units` must be `jaxship.strategies.DisplayUnits()` or `SIUnits()`, "
                         f"got {units!r}.")


def _convert(value, unit, units):
    """SI `value` of a quantity in `unit` ('m', 's', 'rad', 'rad_s', '1') to display."""
    if isinstance(units, SIUnits):
        return value, {"rad_s": "rad_s", "1": ""}.get(unit, unit)
    factor, name = {
        "m": (1.0, "m"), "s": (1.0, "s"), "rad": (_DEG, "deg"), "rad_s": (_DEG, "deg_s"),
        "1": (100.0, "percent"),
    }[unit]
    return value * factor, name


def _named(items, units):
    _check_units(units)
    out = {}
    for base, value, unit in items:
        value, suffix = _convert(value, unit, units)
        out[f"{base}_{suffix}" if suffix else base] = (
            float(value) if np.ndim(value) == 0 else np.asarray(value).tolist()
        )
    return out
