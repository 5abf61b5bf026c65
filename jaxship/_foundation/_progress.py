"""Progress of long work: one report type, `Progress`, passed to a callable the caller
gives (`fit(..., progress=)`, `identify(..., progress=)`); the library itself never prints.

A fit reports its optimiser steps between parts of its run, from Python
(`reporting_steps`; `_estimate/_fit.py`'s `_solve_reporting`): no host callback inside
the compiled program, which JAX's persistent compilation cache would refuse to store
(issue 70), so a callable never recompiles a fit.
"""

import contextlib
import dataclasses
from collections.abc import Callable


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

@contextlib.contextmanager
def reporting_steps(progress: ProgressCallback | None, message: str, total: int):
    """Report a fit's optimiser steps to `progress`: `Progress("fit", message, step=0,
    total)` on entry, then yield `(step, finish)`: `step(steps, cost)` reports the steps
    taken so far, `finish(steps, cost)` the last report (`done=True`)."""
    if progress is None:
        yield (lambda steps, cost: None), (lambda steps, cost: None)
        return
    progress(Progress("fit", message, step=0, total=total))

    def report(steps, cost, done=False):
        progress(Progress("fit", message, step=int(steps), total=total, cost=float(cost),
                          done=done))

    yield report, lambda steps, cost: report(steps, cost, done=True)
