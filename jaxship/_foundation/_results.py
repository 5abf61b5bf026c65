"""`RESULTS`, the one enumeration of outcome codes: diffrax's and optimistix's (a solver's
code passes through unchanged) and jaxship's own (a simulation that blew up, a fit that
never moved, ended on a bound or determines nothing)."""

import diffrax as dfx


class RESULTS(dfx.RESULTS):
    """The outcome code of every jaxship call: optimistix's and diffrax's codes
    (`successful`, `max_steps_reached`, `nonlinear_divergence`, `singular`, `dt_min_reached`,
    ...: a solver's code is passed through) and those only a simulation or a fit can tell.
    `successful` (a simulation that stayed finite, a fit that converged) is the only
    success."""

    simulation_blew_up = ("the simulation blew up (values not finite, or, in a fit, a "
                          "thousand times beyond the measurements): a fit's estimates mean "
                          "nothing")
    did_not_move = ("the optimiser did not move from the start values although the cost "
                    "is not stationary there (a start value far out of scale?): the "
                    "estimates are the start values")
    at_bound = ("an estimate ended on a bound of its parameter: the data pull it beyond, "
                "so the fit is not a proper optimum (see the parameter flags)")
    poorly_determined = ("the data do not determine a combination of the parameters (a "
                         "singular information matrix, no excitation, or a record too "
                         "short) or, by the robust standard errors of residuals that are "
                         "not white, a parameter (relative standard error above 50 %: its "
                         "95 % interval about reaches zero): only the others are identified "
                         "(see the parameter flags)")
    not_settled = ("the closed loop did not settle: at the end of the run the heading is "
                   "outside the band about the ordered heading (or the ship circles), so "
                   "its metrics say nothing about the autopilot")
    undetermined = ("the fit explains almost nothing (no fitted channel's fit reaches 5 %) "
                    "and a parameter's 95 % interval includes zero: the data, noise to this "
                    "model, do not determine it (see the parameter flags)")


def as_code(result) -> RESULTS:
    """`result` (a `RESULTS` item, or one of diffrax, optimistix or lineax) as a `RESULTS`
    item."""
    return result if result._enumeration is RESULTS else RESULTS.promote(result)


def raise_unless_successful(outcome, throw: bool):
    """`outcome` (a result Module with a `result` code, any batch shape) as it is, or with
    `throw` an error (`equinox.error_if`, under `jit` too) carrying the code's sentence
    where a `result` is not `successful` (optimistix's `throw=`)."""
    if not throw:
        return outcome
    return outcome.result.error_if(outcome, outcome.result != RESULTS.successful)
