"""What ships can do, checked on an identified steering model and on a record's rudder
and wind:
a value outside the range is a warning naming the likely unit slip or sign, never a
silent success (issue 72).

The Nomoto indices (Nomoto et al. 1957: $T\\dot r + r = K\\delta$; Nomoto 2's
$T = T_1 + T_2 - T_3$; Norrbin's $T\\dot r + n_1 r + \\ldots = K\\delta$ has $K/n_1$,
$T/n_1$) are compared made nondimensional by the ship's length $L$ and speed $U$ (Fossen
2011, *Handbook of Marine Craft Hydrodynamics and Motion Control*, sec. 7.1:
$K' = KL/U$, $T' = TU/L$), and where $L$ or $U$ is not known by their product
$K T = K' T'$, which needs neither. Published sets span $K'$ 0.8-3.9, $|T'|$ 0.7-5.2 and
$|K'T'|$ 0.56-20: Astrom & Kallstrom's cargo ship (L = 161 m: K' 3.86, T' 5.15) and
tanker (350 m: K' 0.83, T' -3.57) as Fossen's MSS ships them, the thesis vessel (Odegard
2009, 4 m: K 0.185 1/s, T 3.02 s at 0.93 m/s) and the Esso Osaka 3 m model (K 0.171 1/s,
T 7.63 s, jaxship's fit of the measured zig-zags). A unit slip scales them by 57.3 (deg
and rad) or 1000 (ms and s): the ranges below are about ten times wider each way than
the published spread, so they take in ships and not slips. A course-unstable ship has
T < 0 and K < 0 together (Fossen 2011, sec. 7.1); K < 0 with T > 0 is a stable ship
that turns against its rudder: a rudder signed the other way (jaxship's rudder is
positive where the ship turns to starboard, r > 0).
"""

import numpy as np

import jaxship as js


K_PRIME = (0.08, 40.0)  # |K'| = |K| L / U
T_PRIME = (0.07, 50.0)  # |T'| = |T| U / L
KT = (0.05, 200.0)  # |K T| = |K' T'|, no length or speed needed
# |T| [s] beyond which no ship steers (the 350 m tanker: 154 s); t in ms labelled s keeps
# K T, so this is what tells it where L or U is unknown
T_MAX = 1000.0
# a rudder of at most 35 deg logged in rad and read as deg peaks below 0.61 "deg"
RUDDER_IN_RAD = np.radians(np.radians(35.0))
# no rudder turns beyond 35 deg each side (SOLAS II-1 reg. 29.3.2), nor is offset beyond it
MAX_RUDDER = np.radians(35.0)
TURNED = np.radians(10.0)  # ... while the heading turns this much: a manoeuvre, not drift
# a logged wind [m/s] beyond hurricane force (Beaufort 12 from 32.7 m/s, WMO No. 8) with a
# margin: no trial sails in it, and a wind in knots or km/h reads 1.9 or 3.6 times higher
MAX_WIND = 40.0


def nomoto_indices(model) -> tuple[float, float] | None:
    """`(K, T)` [1/s, s] of the linear part of a Nomoto-type steering model, None for
    other models."""
    if isinstance(model, js.Nomoto1):
        return float(model.K), float(model.T)
    if isinstance(model, js.Nomoto2):
        return float(model.K), float(model.T1 + model.T2 - model.T3)
    if isinstance(model, js.NonlinearNomoto) and float(model.n1) != 0.0:
        return float(model.K / model.n1), float(model.T / model.n1)
    return None


def implausible(model, *, length: float | None = None,
                speed: float | None = None) -> tuple[str, ...]:
    """A sentence for each value of `model` outside what ships do: a rudder offset beyond
    `MAX_RUDDER`, and of its indices (`nomoto_indices`) K < 0 with T > 0, |K'|, |T'|
    (with the ship's `length` [m] and mean `speed` [m/s]) or |K T| outside `K_PRIME`,
    `T_PRIME`, `KT`, and |T| beyond `T_MAX`, each naming the likely cause; |T| beyond
    `T_MAX` with |K T| below `KT`, which no single unit slip gives, in one sentence that
    names no unit."""
    out = [f"the rudder offset {name} = {np.degrees(value):.4g} deg is beyond any rudder's "
           f"range ({np.degrees(MAX_RUDDER):g} deg): is it in deg labelled rad?"
           for name, value in _offsets(model) if not abs(value) <= MAX_RUDDER]
    indices = nomoto_indices(model)
    if indices is None:
        return tuple(out)
    K, T = indices
    if K < 0 < T:
        out.append(f"K = {K:.4g} 1/s is negative with a stable T = {T:.4g} s: the fitted ship "
                   "turns against its rudder. Is the rudder signed the other way (positive "
                   "to port)? jaxship's rudder is positive where the ship turns to starboard "
                   "(r > 0): negate the rudder column.")
    if abs(T) > T_MAX and abs(K * T) < KT[0]:
        # no single slip gives both: t in ms keeps K T (psi logged) or raises it (r
        # logged in deg/s), a slip of r, psi or the rudder keeps T
        out.append(f"K = {K:.4g} 1/s and T = {T:.4g} s: T beyond any ship's ({T_MAX:g} s) "
                   f"and K T = {abs(K * T):.3g} below the range of ships ({KT[0]:g} to "
                   f"{KT[1]:g}), which no single unit slip gives: the records do not show "
                   "a response to the rudder that this model can describe (a course-unstable "
                   "ship, whose T < 0, or too little rudder).")
        return tuple(out)
    known = length is not None and speed is not None and length > 0 and speed > 0
    checks = ([("K'", abs(K) * length / speed, K_PRIME), ("T'", abs(T) * speed / length,
                                                          T_PRIME)] if known else [])
    checks.append(("K T", abs(K * T), KT))
    if abs(T) > T_MAX:
        out.append(f"|T| = {abs(T):.4g} s is beyond any ship's yaw time constant ({T_MAX:g} s; "
                   "a 350 m tanker's is 154 s): is t in ms labelled s?")
    for name, value, (low, high) in checks:
        if low <= value <= high:
            continue
        cause = {("K'", True): "r in rad/s labelled deg/s, or t in ms labelled s",
                 ("K'", False): "the rudder in rad labelled deg",
                 ("T'", True): "t in s labelled ms", ("T'", False): "t in ms labelled s",
                 ("K T", True): "r in rad/s labelled deg/s, or psi in rad labelled deg",
                 ("K T", False): "the rudder in rad labelled deg"}[name, value < low]
        where = f" (L = {length:g} m, U = {speed:.3g} m/s)" if name != "K T" else ""
        out.append(f"|{name}| = {value:.3g}{where} is outside the range of ships, {low:g} "
                   f"to {high:g} (K = {K:.4g} 1/s, T = {T:.4g} s): is it {cause}?")
    return tuple(out)


def _offsets(model):
    """`(name, value)` of a model's rudder offsets (`delta0`, `<effect>.delta0`)."""
    names = model.parameter_names() if isinstance(model, js.AbstractModel) else ()
    return [(n, float(model.get_parameter(n))) for n in names if n.split(".")[-1] == "delta0"]


def rudder_in_rad(experiment) -> str | None:
    """A sentence when a record's rudder stays below `RUDDER_IN_RAD` (0.61 deg) while its
    heading (logged, else the trapezoidal integral of the yaw rate) turns more than
    `TURNED`: a rudder in rad labelled deg; None otherwise (or without psi or r)."""
    delta = np.abs(np.asarray(experiment.delta, dtype=np.float64))
    if delta.size == 0 or not (experiment.has("psi") or experiment.has("r")):
        return None
    if experiment.has("psi"):
        psi = np.unwrap(np.asarray(experiment.psi, dtype=np.float64))
    else:
        r, t = (np.asarray(a, dtype=np.float64) for a in (experiment.r, experiment.t))
        psi = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t))])
    turned = float(np.ptp(psi))
    if not (np.max(delta) < RUDDER_IN_RAD and turned > TURNED):
        return None
    return (f"{experiment.name}: the rudder never exceeds {np.degrees(np.max(delta)):.3g} deg "
            f"while the heading turns {np.degrees(turned):.0f} deg: is the rudder in rad "
            "labelled deg?")


def propeller_rate_slip(experiment, vessel) -> str | None:
    """A sentence when a record's logged propeller rate, where it turns, stays below a
    tenth of `vessel`'s service rate (`jaxship.check_operating_point`'s bound: no
    steerage way; rev/s labelled rpm reads 60 times too low); None otherwise, for a
    record without n or a vessel without a propeller rate."""
    nominal = float(getattr(vessel, "nominal_n", 0.0) or 0.0)
    if not experiment.has("n") or not nominal > 0:
        return None
    peak = float(np.nanmax(np.abs(np.asarray(experiment.n, dtype=np.float64))))
    if not 0 < peak < 0.1 * nominal:
        return None
    return (f"{experiment.name}: the logged propeller rate peaks at {60 * peak:.3g} rpm, "
            f"under a tenth of the vessel's service rate ({60 * nominal:.4g} rpm): is n in "
            "rev/s labelled rpm?")


def wind_too_strong(experiment) -> str | None:
    """A sentence when a record's logged wind exceeds `MAX_WIND`; None otherwise."""
    if not experiment.has("wind_speed"):
        return None
    peak = float(np.nanmax(np.abs(np.asarray(experiment.wind_speed, dtype=np.float64))))
    if not peak > MAX_WIND:
        return None
    return (f"{experiment.name}: the logged wind reaches {peak:.4g} m/s, beyond hurricane "
            f"force (Beaufort 12 from 32.7 m/s): is wind_speed in knots or km/h?")
