"""A record checked against itself: the heading against the yaw rate, the positions
against the velocities, each through the time base, so that a column in the wrong unit
(degrees labelled rad, milliseconds labelled s) is refused before any fit; and the
heading unwrapped (`unwrap_heading`).

The checks are calibrated on the measured sets (Esso Osaka, KVLCC2 HSVA and MARIN):
there the heading follows the integrated yaw rate to a scale of 0.9-1.1 and the track's
length is 1.0-1.2 times the distance run by the logged speed (MARIN's: 1.2);
a unit error is a factor of 57.3 (deg, rad) or 1000 (ms, mm).
"""

import math

import numpy as np

from ._data import _cumulative_trapezoid


def unwrap_heading(psi) -> tuple[np.ndarray, int]:
    """The heading [rad] with every jump beyond pi between two samples taken as a wrap
    (no ship turns half a circle in one sample): $\\psi_k + 2\\pi m_k$ (`np.unwrap`),
    and the number of wraps removed; none where floats as large as psi do not resolve
    a turn (beyond about 1e13 rad)."""
    psi = np.asarray(psi, dtype=np.float64)
    if psi.size == 0 or not _resolved(psi, math.pi):
        return psi, 0
    return np.unwrap(psi), int(np.count_nonzero(np.abs(np.diff(psi)) > math.pi))


# a scale s in  psi(t) - psi(t0) = s * int r dt  (or speed from the positions = s * speed)
# that is a unit error: (s, {column: (unit it is labelled, unit it likely holds)})
_DEG = 180.0 / math.pi
_SCALES = (
    (_DEG, {"psi": ("rad", "deg"), "r": ("deg/s", "rad/s")}),
    (1 / _DEG, {"psi": ("deg", "rad"), "r": ("rad/s", "deg/s")}),
    (1e-3, {"t": ("s", "ms")}),
    (1e3, {"x": ("m", "mm"), "y": ("m", "mm")}),
)
HEADING_SPAN = math.radians(5.0)  # judged when psi or the integrated r spans this much
MIN_SPEED = 0.1  # m/s: below it GNSS noise swamps the speed from the positions


def _along_track(t, si, scale) -> float:
    """The mean cosine, weighted by length, between the track's steps and the steps of
    the velocity u, v turned by the heading `scale * psi` (trapezoidal): 1 when they
    agree (0.84-1 on the measured sets: a current, GNSS noise), about 0 when the
    heading is off by a unit."""
    psi, u, v = scale * si["psi"], si["u"], si.get("v", 0.0)
    step = lambda a: 0.5 * (a[1:] + a[:-1]) * np.diff(t)
    ex, ey = step(u * np.cos(psi) - v * np.sin(psi)), step(u * np.sin(psi) + v * np.cos(psi))
    dx, dy = np.diff(si["x"]), np.diff(si["y"])
    weight = np.sum(np.hypot(ex, ey) * np.hypot(dx, dy))
    return float(np.sum(ex * dx + ey * dy) / weight) if weight > 0 else 1.0


def _resolved(values, change) -> bool:
    """Whether floats as large as `values` resolve a `change` to a thousandth."""
    return bool(change > 1e3 * np.spacing(np.max(np.abs(values))))


def _likely(scale, keys, headers, units, tolerance) -> str:
    """"is column 'psi [rad]' in deg rather than rad?" for the unit errors of the
    columns `keys` within a factor `tolerance` of `scale`."""
    guesses = [f"column '{headers[k]}' in {likely} rather than {unit}"
               for factor, columns in _SCALES
               if scale > 0 and abs(math.log(scale / factor)) < math.log(tolerance)
               for k, (unit, likely) in columns.items()
               if k in keys and k in headers and units[k] == unit]
    return f"is {' or '.join(guesses)}?" if guesses else "check the units of these columns."


def check_consistency(where: str, t, si: dict, headers: dict, units: dict) -> list[str]:
    """A one-line `ValueError` where the measured channels `si` (SI, at the times `t`)
    disagree by a unit error, naming the columns (`headers`, with their `units`) and
    the likely unit; else the sentences saying which logged pairs cannot be checked
    (`_unchecked`: a record too short, or a heading that turns too little, to tell a unit
    error from agreement), empty where every pair was judged:

    - heading against yaw rate: $\\psi - \\bar\\psi \\approx s\\,(R - \\bar R)$,
      $R(t) = \\int_{t_0}^t r\\,dt$, $s$ by least squares, must give $s \\approx 1$
      (0.5-2) where the fit explains the heading (residual below half its spread) and
      the heading or $R$ spans `HEADING_SPAN`; $s < 0$ is an opposite sign convention;
    - the heading against the track: the steps of u, v turned by psi point along the
      track's steps (`_along_track` above 0.5);
    - positions against velocities: the track's length $\\sum|\\Delta(x, y)|$ over the
      distance run $\\int\\sqrt{u^2 + v^2}\\,dt$ within 0.1-10 (a current and GNSS
      noise change it by a fifth, a unit a thousandfold), judged from a mean speed of
      `MIN_SPEED`.
    """
    t = np.asarray(t, dtype=np.float64)
    if t.shape[0] < 3:
        return _unchecked(headers, [k for k in ("psi", "r", "x", "y", "u") if k in si],
                          f"the record has {t.shape[0]} sample(s), fewer than 3")
    unchecked = []
    if "psi" in si and "r" in si and _resolved(si["psi"], math.pi):
        r_int = _cumulative_trapezoid(si["r"], t)
        a, b = r_int - r_int.mean(), si["psi"] - si["psi"].mean()
        spans = max(np.ptp(a), np.ptp(b)) >= HEADING_SPAN
        scale = float(a @ b / (a @ a)) if a @ a > 0 else math.nan
        residual = np.linalg.norm(b - scale * a) / max(np.linalg.norm(b), 1e-300)
        if not spans:
            unchecked += _unchecked(headers, ("psi", "r"), _too_little(a, b))
        elif residual >= 0.5:
            unchecked += _unchecked(headers, ("psi", "r"), (
                f"the heading follows the integrated yaw rate only to a residual of "
                f"{residual:.2f} of its spread (below 0.5 to judge a scale)"))
        if spans and residual < 0.5 and not 0.5 <= scale <= 2.0:
            cols = {k: headers[k] for k in ("psi", "r", "t")}
            if scale < 0:
                raise ValueError(
                    f"{where}: column '{cols['psi']}' turns against column '{cols['r']}' "
                    f"(psi changes {scale:.3g} times the integral of r): one of them follows "
                    "another sign convention; jaxship's heading and yaw rate are positive "
                    "to starboard: negate one column.")
            raise ValueError(
                f"{where}: column '{cols['psi']}' changes {scale:.4g} times as much as the "
                f"integral of column '{cols['r']}' over column '{cols['t']}' (1 when they "
                f"agree): {_likely(scale, ('psi', 'r', 't'), headers, units, 1.3)}")
    if {"x", "y", "u"} <= si.keys():
        unchecked += _check_track(where, t, si, headers, units)
    return unchecked


def _check_track(where, t, si, headers, units) -> list[str]:
    """`check_consistency`'s checks of the positions x, y against the velocities u, v
    and the heading psi; the pairs that cannot be checked."""
    speed = np.hypot(si["u"], si.get("v", 0.0))
    run = float(np.sum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t)))
    path = float(np.sum(np.hypot(np.diff(si["x"]), np.diff(si["y"]))))
    slow = run < MIN_SPEED * (t[-1] - t[0])
    judged = not slow and _resolved(np.hypot(si["x"], si["y"]), run)
    ratio = path / run if judged else 1.0
    unchecked = []
    if slow:
        unchecked += _unchecked(headers, ("x", "y", "u"), (
            f"the ship runs at {run / (t[-1] - t[0]):.3g} m/s on average, below the "
            f"{MIN_SPEED} m/s where GNSS noise swamps the speed from the positions"))
    elif not judged:
        unchecked += _unchecked(headers, ("x", "y", "u"), (
            "floats as large as the positions do not resolve the distance run"))
    if judged and "psi" in si and _resolved(si["psi"], math.pi):  # against the track
        agree = {k: _along_track(t, si, k) for k in (1.0, _DEG, 1 / _DEG)}
        best = max(agree, key=agree.get)
        wrong = max(agree[_DEG], agree[1 / _DEG])  # the heading off by a unit
        if "r" not in si and agree[1.0] >= 0.5 <= wrong:  # would pass as well
            unchecked += _unchecked(headers, ("psi", "x", "y"), (
                "the heading scaled by a unit error (57.3) heads the velocities along the "
                "track as well (a mean cosine of "
                f"{wrong:.2f}, at least 0.5): it turns too little"))
        if agree[1.0] < 0.5:
            hint = (_likely(1 / best, ("psi",), headers, units, 1.3) if agree[best] >= 0.8
                    else "check the units of these columns.")
            raise ValueError(
                f"{where}: column '{headers['psi']}' heads the velocities of columns "
                f"'{headers['u']}', '{headers.get('v', 'v')}' along the track of columns "
                f"'{headers['x']}', '{headers['y']}' only to a mean cosine of "
                f"{agree[1.0]:.2f} (near 1 when they agree): {hint}")
    if not 0.1 <= ratio <= 10.0:
        hint = _likely(ratio, ("t", "x", "y", "u", "v"), headers, units, 3.0)
        moved = ", ".join(f"'{headers[k]}'" for k in ("u", "v") if k in headers)
        raise ValueError(
            f"{where}: the track of columns '{headers['x']}', '{headers['y']}' is "
            f"{ratio:.4g} times as long as the distance run at the speed of columns "
            f"{moved} over column '{headers['t']}' (1 when they agree): {hint}")
    return unchecked


def _too_little(*headings) -> str:
    """Why a heading that turns too little cannot be checked for a unit error."""
    turn = math.degrees(max(float(np.ptp(h)) for h in headings))
    return (f"the heading turns by {turn:.3g} deg, less than the "
            f"{math.degrees(HEADING_SPAN):.3g} deg needed to tell a unit error (a factor of "
            "57.3) from a ship that holds its course")


def _unchecked(headers, keys, why) -> list[str]:
    """The sentence saying that the columns `keys` cannot be checked against each other
    for a unit error, and `why`; none where fewer than two of them are logged."""
    logged = [f"'{headers[k]}'" for k in keys if k in headers]
    if len(logged) < 2:
        return []
    return [f"columns {', '.join(logged)} cannot be checked against each other for a unit "
            f"error: {why}."]
