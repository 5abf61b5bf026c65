"""Start values of the registered models: each model's `start(train, context)` (linear
least squares, a nested fit or a preset) and its neutral `fallback(train, context)`
for data that give no start values."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import equinox as eqx
import numpy as np

import jaxship as js

from .data import mean_valid, rms, valid_samples


@dataclasses.dataclass(frozen=True)
class StartContext:
    """What a `ModelEntry.start` function gets besides the training data:

    - `rudder`: the replayed rudder channel (`"delta"` or `"delta_c"`);
    - `channels`: the fitted output channels;
    - `estimator`: the `PredictionError` of the main fit (for nested fits);
    - `fit`: `fit(model, *, free=None, stage=...)` runs a quiet, progress-reporting
      fit on the training data with `estimator` and returns its `FitResult`
      (e.g. `nomoto2` starts from a fitted `Nomoto1`);
    - `note`: `note(text)` adds a line to the result's `notes`.
    """

    rudder: str
    channels: tuple[str, ...]
    estimator: js.PredictionError
    fit: Callable
    note: Callable


# -- Nomoto models ------------------------------------------------------------------------


def neutral_nomoto1(train: js.Dataset, rudder: str = "delta") -> js.Nomoto1:
    """K from the ratio of the yaw-rate and rudder spreads (0.1 1/s without rudder
    motion), T ten sample intervals: a start, not an estimate."""
    spread = rms(valid_samples(train, rudder) - np.mean(valid_samples(train, rudder)))
    k = rms(valid_samples(train, "r")) / spread if spread > 0 else 0.1
    k = k if math.isfinite(k) and k > 0 else 0.1
    return js.Nomoto1(K=k, T=10.0 * float(np.max(train.dt)))


def start_nomoto1(train: js.Dataset, context: StartContext) -> js.Nomoto1:
    return js.LinearStart()(js.Nomoto1(K=1.0, T=1.0), train, None, context.rudder)


def fallback_nomoto1(train: js.Dataset, context: StartContext) -> js.Nomoto1:
    return neutral_nomoto1(train, context.rudder)


def start_nomoto2(train: js.Dataset, context: StartContext) -> js.Nomoto2:
    """A fitted `Nomoto1` (K, T) spread over the three time constants
    (`Nomoto2.from_first_order`)."""
    try:
        first = start_nomoto1(train, context)
    except ValueError as error:
        context.note(f"Nomoto1 linear least-squares start failed ({error}); neutral start used.")
        first = neutral_nomoto1(train, context.rudder)
    first = context.fit(first, stage="fitting Nomoto1 for the Nomoto2 start").model
    k, t = float(first.K), float(first.T)
    context.note(f"Nomoto2 start from the fitted Nomoto1: K = {k:.6g} 1/s, T = {t:.6g} s.")
    return js.Nomoto2.from_first_order(k, t)


def fallback_nomoto2(train: js.Dataset, context: StartContext) -> js.Nomoto2:
    first = neutral_nomoto1(train, context.rudder)
    return js.Nomoto2.from_first_order(first.K, first.T)


def _linear_nonlinear(train: js.Dataset, context: StartContext, why: str) -> js.NonlinearNomoto:
    first = js.LinearStart()(js.Nomoto1(K=1.0, T=1.0), train, None, context.rudder)
    context.note(f"nonlinear Nomoto start: {why}; started from the linear Nomoto1 "
                 "least-squares K, T with n3 = 0 instead.")
    return js.NonlinearNomoto(K=first.K, T=first.T, n3=0.0)


def start_nonlinear(train: js.Dataset, context: StartContext) -> js.NonlinearNomoto:
    """Midpoint least squares with $n_1 = 1$ (course stable); if that gives $T \\le 0$,
    again with $n_1 = -1$ (course unstable). The cubic term must stabilise
    ($n_3 \\ge 0$, Norrbin); a regression that says otherwise (noise in the yaw
    acceleration biases it) is replaced by the linear Nomoto1 start with $n_3 = 0$.

    The two regressions have the same regressors and opposite data sides, so their
    estimates differ only in sign: when $n_1 = 1$ fails and $n_1 = -1$ succeeds, the
    first failed on $T \\le 0$; when both fail, on the regressors (no excitation), and
    the first error is raised."""
    try:
        start = js.LinearStart()(js.NonlinearNomoto(K=1.0, T=1.0, n1=1.0), train, None,
                                 context.rudder)
    except ValueError as error:
        try:
            start = js.LinearStart()(js.NonlinearNomoto(K=1.0, T=1.0, n1=-1.0), train, None,
                                     context.rudder)
        except ValueError:
            raise error from None
        if not start.n3 > 0:
            return _linear_nonlinear(train, context, f"with n1 = -1 the regression gives "
                                     f"n3 = {start.n3:.4g} <= 0 (unbounded turning)")
        context.note("nonlinear Nomoto start: n1 = +1 gave T <= 0, so the course-unstable "
                     "characteristic n1 = -1 is used.")
        return start
    if start.n3 < 0:
        return _linear_nonlinear(train, context, f"the regression gives n3 = {start.n3:.4g} "
                                 "< 0 (a destabilising cubic term)")
    return start


def start_norrbin_either(train: js.Dataset, context: StartContext) -> js.NonlinearNomoto:
    """The start of `nomoto1-norrbin`: `start_nonlinear`'s regression (n1 = +1 or -1, or
    the linear Nomoto1 K, T with n3 = 0). The fit then holds T (the equation's scale:
    Norrbin's model is unchanged when K, T and all $n_i$ are multiplied by one number)
    and estimates K, $n_1$ of either sign and $n_3$ (Astrom & Kallstrom 1979, sec. 2;
    thesis eq. 3.4)."""
    return start_nonlinear(train, context)


def fallback_nonlinear(train: js.Dataset, context: StartContext) -> js.NonlinearNomoto:
    first = neutral_nomoto1(train, context.rudder)
    return js.NonlinearNomoto(K=first.K, T=first.T)


# -- Ross autopilot -----------------------------------------------------------------------


def ross_scales(train: js.Dataset) -> dict:
    """Reference scales of `RossAutopilot` from the training records: $U_0$ the mean
    measured surge speed, $n_0$ the mean propeller rate (1 rev/s when not measured)
    and $L = 0.3\\,U_0/\\mathrm{rms}(r)$, which makes the scaled yaw rate $r' = rL/U_0$
    of order 0.3 (the coefficients' conditioning; any $L$ gives the same model,
    see `RossAutopilot.dimensional`)."""
    speed = abs(mean_valid(train, "u"))
    speed = speed if math.isfinite(speed) and speed > 0 else 1.0
    rate = abs(mean_valid(train, "n")) if "n" in train.channels else 0.0
    rate = rate if math.isfinite(rate) and rate > 0 else 1.0
    spread = rms(valid_samples(train, "r"))
    length = 0.3 * speed / spread if spread > 0 else 1.0
    return dict(length=float(length), speed=float(speed), rate=float(rate))


def start_ross(train: js.Dataset, context: StartContext) -> js.RossAutopilot:
    scales = ross_scales(train)
    context.note("RossAutopilot reference scales (frozen): L = {length:.6g} m, U0 = {speed:.6g} "
                 "m/s, n0 = {rate:.6g} rev/s; the estimates are the scaled coefficients a of "
                 "these (RossAutopilot.dimensional() converts them).".format(**scales))
    return js.LinearStart()(js.RossAutopilot(**scales), train, None, context.rudder)


def fallback_ross(train: js.Dataset, context: StartContext) -> js.RossAutopilot:
    """The neutral Nomoto1 in Ross form: $a_{ur}u'r'$ damping with time constant T and
    the rudder term $a_\\delta u'^2\\delta$ with gain K at the reference speed."""
    scales = ross_scales(train)
    first = neutral_nomoto1(train, context.rudder)
    length, speed = scales["length"], scales["speed"]
    return js.RossAutopilot(**scales, n_ur=-length / (speed * float(first.T)),
                            n_delta=float(first.K) * length**2 / (float(first.T) * speed**2))


# -- sway-yaw models ------------------------------------------------------------------


def _sway_yaw_start(model, train: js.Dataset, context: StartContext, preset: str):
    speed = abs(mean_valid(train, "u"))
    if math.isfinite(speed) and speed > 0:
        model = eqx.tree_at(lambda m: m.speed, model, speed)
    context.note(f"{type(model).__name__} start: the {preset} derivatives (Astrom & Kallstrom "
                 f"1979), with its length L = {float(model.length):.6g} m (the unit of the prime "
                 "system) and its mass terms (frozen); speed = the mean measured u "
                 f"{float(model.speed):.6g} m/s.")
    return model


def start_linear_sway_yaw(train: js.Dataset, context: StartContext) -> js.LinearSwayYaw:
    return _sway_yaw_start(js.LinearSwayYaw.from_vessel(js.get_vessel("sea_stratus_linear")), train,
                           context, "sea_stratus_linear")


def start_norrbin(train: js.Dataset, context: StartContext) -> js.NorrbinCrossFlow:
    return _sway_yaw_start(js.NorrbinCrossFlow.from_vessel(js.get_vessel("sea_stratus_nonlinear")),
                           train, context, "sea_stratus_nonlinear")


# -- low-speed sway-yaw model ---------------------------------------------------------


def start_low_speed(train: js.Dataset, context: StartContext) -> js.LowSpeedSwayYaw:
    """The class's start values (a 3 m tanker model at 0.3 m/s) at the records' mean
    surge speed and positive propeller rate (the conditions of `steady_turn`, not
    fitted), with the hull length $L$ of the cross-flow integrals (kept, not fitted)
    from the records' metadata (`lpp`, which the measured-data readers set) when they
    all give the same one (to 0.1 %)."""
    speed = abs(mean_valid(train, "u"))
    rate = max(mean_valid(train, "n"), 0.0) if "n" in train.channels else 0.0
    lengths = np.array([float(dict(m).get("lpp", np.nan)) for m in train.experiment_metadata])
    given = bool(np.all(lengths > 0) and np.ptp(lengths) <= 1e-3 * lengths.max())
    model = js.LowSpeedSwayYaw(speed=speed if speed > 0 else 0.3, propeller_rate=rate)
    if given:  # HSVA's 7.0 m and MARIN's 320 m / 45.714 agree to 1e-5
        model = eqx.tree_at(lambda m: m.length, model, float(lengths.mean()))
    where = ("the records' lpp" if given else
             "the class's (the records give no single lpp: another hull needs "
             "jaxship.LowSpeedSwayYaw(length=...) and jaxship.fit)")
    context.note(f"LowSpeedSwayYaw start: the class's values, with its length L = "
                 f"{float(model.length):.4g} m ({where}; kept, not fitted); speed "
                 f"{float(model.speed):.4g} m/s and propeller rate "
                 f"{float(model.propeller_rate):.4g} rev/s are the records' means.")
    return model
