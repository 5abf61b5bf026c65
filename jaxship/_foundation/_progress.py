"""Progress of long work: one report type, `Progress`, passed to a callable the caller
gives (`fit(..., progress=)`, `identify(..., progress=)`); the library itself never prints.

An optimiser's steps reach the callable from inside compiled code through one
module-level hook (`step_hook`, the solver's `verbose`), so that a new callable never
recompiles a fit: `reporting_steps` routes the hook to the callable of the fit that
is running. (The route is a module-level stack, not a context variable: XLA runs host
callbacks on its own threads. Fits reporting progress from several threads at once
would mix their reports.)
"""

import contextlib
import dataclasses
from collections.abc import Callable

import jax


@dataclasses.dataclass(frozen=True)
class Progress:
    """A progress report.

    - `stage`: `"start"` (start values), `"fit"` (an optimisation), `"validate"`
      (simulation on the data), or a command's own stage;
    - `message`: what is being done, in words;
    - `step`: the optimiser's step count during a fit (None for stage messages);
    - `total`: the step limit of the fit;
    - `cost`: the cost $\\frac12\\sum\\varepsilon^2$ of the last accepted step;
    - `done`: True for the last report of a stage.
    """

    stage: str
    message: str
    step: int | None = None
    total: int | None = None
    cost: float | None = None
    done: bool = False


ProgressCallback = Callable[[Progress], None]

_RECEIVERS: list = []  # the running fits' step receivers, innermost last


def _receive(step, cost):
    if _RECEIVERS:
        receiver = _RECEIVERS[-1]
        step = int(step)  # before the first step the accepted cost is not yet known
        receiver(step, float(cost) if step > 0 else None)


def step_hook(**kwargs):
    """An optimistix `verbose` hook sending each step to the running fit's callable."""
    jax.debug.callback(_receive, kwargs["num_steps"][1], kwargs["loss_last_accepted_step"][1])


@contextlib.contextmanager
def reporting_steps(progress: ProgressCallback | None, message: str, total: int):
    """Report the optimiser steps taken inside the block to `progress` as
    `Progress("fit", message, step, total, cost)`, then one `done=True` report from
    `finish(steps, cost)` (the yielded function)."""
    if progress is None:
        yield lambda steps, cost: None
        return
    progress(Progress("fit", message, step=0, total=total))
    _RECEIVERS.append(lambda step, cost: progress(Progress("fit", message, step=step,
                                                          total=total, cost=cost)))
    try:
        yield lambda steps, cost: progress(Progress("fit", message, step=int(steps),
                                                    total=total, cost=float(cost), done=True))
    finally:
        _RECEIVERS.pop()
