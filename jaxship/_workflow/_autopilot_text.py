"""The autopilot evaluation in words (`AutopilotEvaluation.summary` and `report`): the
gains and runs as markdown tables, the tuning, whether the feed-forward helped, the runs
that blew up or saturated, and the page `jaxship autopilot` writes to report.md."""

from ._autopilot import METRICS_TEXT, SATURATED_SHARE, cell


def problems(rows, window_s: float | None = None) -> tuple[str, str]:
    """`(failure, saturation)`: the sentences on runs that blew up or did not settle
    (code not_settled: `RESULTS.not_settled`) and on runs whose rudder sat on its limit
    (code rudder_saturated, or more than half the window `window_s` [s] for a run that
    did not settle either) among `rows`; "" where none."""
    where = lambda row: f"{row['controller']} at {row['rpm']:.4g} rpm, {row['speed']:.3g} m/s"
    failed = [where(row) for row in rows if not row["success"]]
    failure = (f"The closed loop blew up (not finite) for {'; '.join(failed)}: those runs "
               "have no metrics and say nothing about the autopilot." if failed else "")
    loose = [f"{where(row)} ({row['end_error_deg']:.3g} deg off)" for row in rows
             if row["code"] == "not_settled"]
    if loose:  # `SETTLED_BAND`: 5 % of the step
        failure = " ".join(text for text in (failure, (
            f"The closed loop did not settle (code not_settled) for {'; '.join(loose)}: the "
            "heading error over the window's last tenth exceeds 5 % of the step (a ship "
            "that circles, or a loop that still swings); the design's natural frequency "
            "does not suit this model (check its K and T).")) if text)
    pinned = [where(row) for row in rows if row["code"] == "rudder_saturated" or (
        window_s and (row.get("time_saturated_s") or 0.0) > SATURATED_SHARE * window_s)]
    saturation = (f"The rudder sat at its limit for more than half the window in "
                  f"{'; '.join(pinned)} (code rudder_saturated where the loop settled): "
                  "the comparison there says "
                  "little about the controllers; try a lower --natural-frequency."
                  if pinned else "")
    return failure, saturation


def gains_table(gains: dict) -> str:
    """Markdown table of `Evaluation.gains()`."""
    lines = ["| controller | K_p [-] | K_i [1/s] | K_d [s] | reference omega [rad/s] | "
             "feed-forward | its gains (acceleration, steady turn) |",
             "|---|---|---|---|---|---|---|"]
    for name, g in gains.items():
        ff = g["feedforward"]
        weights = "-" if ff is None else f"{g['ff_gain']:.3g}, {g['ff_steady_gain']:.3g}"
        lines.append(f"| {name} | {g['kp']:.4g} | {g['ki']:.4g} | {g['kd']:.4g} | "
                     f"{g['reference_frequency']:.4g} | {ff or 'none'} | {weights} |")
    return "\n".join(lines) + "\n"


def runs_table(rows: list[dict]) -> str:
    """Markdown table of run rows (`RUN_KEYS`)."""
    lines = ["| controller | rpm | speed [m/s] | sum abs error [deg] | against the ordered "
             "heading [deg] | RMS error [deg] | overshoot [deg] | settling [s] | mean abs "
             "rudder [deg] | rudder travel [deg] | rate-limited [s] |", "|---" * 11 + "|"]
    for r in rows:
        settle = "never" if r["settling_time_s"] is None else f"{r['settling_time_s']:.1f}"
        lines.append(f"| {r['controller']} | {r['rpm']:.0f} | {r['speed']:.3f} | "
                     f"{cell(r['sum_abs_error_deg'])} | "
                     f"{cell(r.get('sum_abs_error_ordered_deg'))} | "
                     f"{cell(r['rms_error_deg'], 3)} | "
                     f"{cell(r['max_overshoot_deg'])} | {settle} | "
                     f"{cell(r['mean_abs_rudder_deg'])} | {cell(r['rudder_travel_deg'], 1)} | "
                     f"{cell(r['time_rate_limited_s'], 1)} |")
    return "\n".join(lines) + "\n"


def tuning_text(tuning: dict | None) -> str:
    """`Evaluation.tuning` (`--tune`) in words; "" without it."""
    if tuning is None:
        return ""
    before = tuning["ordered_objective_before"]
    after = tuning["ordered_objective_after"]
    versus = ("" if None in (before, after) else
              f", objective against the ordered heading {before:.4g} -> {after:.4g} rad^2 "
              "(with the tuned gains)")
    return (f"Tuned (--tune): the gains by tune_autopilot against the reference model's "
            f"heading, objective {tuning['objective_before']:.4g} -> "
            f"{tuning['objective_after']:.4g} rad^2 in {tuning['steps']} steps ("
            f"{'converged' if tuning['converged'] else 'NOT converged'}); then the reference "
            f"model's bandwidth omega {tuning['reference_frequency_before']:.4g} -> "
            f"{tuning['reference_frequency_after']:.4g} rad/s against the ordered heading, the "
            f"best of {tuning['reference_candidates']} on a log grid up to "
            f"{tuning['reference_frequency_top']:.4g} rad/s, each with the feed-forward of "
            f"the step within half the rudder's angle and rate limits (with the tuned "
            f"acceleration gain {tuning['ff_gain_before_reference']:.3g} up to "
            f"{tuning['reference_frequency_bound']:.4g} rad/s; at the chosen bandwidth "
            f"{tuning['ff_gain_after_reference']:.3g}){versus}.")


def feedforward_text(rows: list[dict]) -> str:
    """Whether the feed-forward helped, per operating point: pid+ff against pid (the same
    gains), summed and RMS error with their differences; where it is worse, why in
    words: with the vessel as its own model the feed-forward (eq. 5.2/5.6) leaves
    almost no error, so a worse pid+ff means the model's inverse orders a rudder the
    vessel does not need at these rudder angles."""
    by = {(r["controller"], r["rpm"], r["speed"]): r for r in rows}
    parts, worse = [], []
    for (controller, rpm, speed), ff in by.items():
        fb = by.get(("pid", rpm, speed))
        if controller != "pid+ff" or fb is None or None in (
                ff["sum_abs_error_deg"], fb["sum_abs_error_deg"]):
            continue
        a, b = ff["sum_abs_error_deg"], fb["sum_abs_error_deg"]
        where = f"{rpm:.4g} rpm, {speed:.3g} m/s"
        parts.append(f"at {where} pid+ff {a:.1f} against pid {b:.1f} deg (difference "
                     f"{a - b:+.1f} deg; RMS {cell(ff['rms_error_deg'], 3)} against "
                     f"{cell(fb['rms_error_deg'], 3)} deg)")
        if a > b:
            worse.append(f"{where} (mean |rudder| {cell(ff['mean_abs_rudder_deg'])} deg)")
    if not parts:
        return ""
    text = "Feed-forward against feedback only: " + "; ".join(parts) + "."
    if worse:
        text += (" **The feed-forward makes the tracking worse** at " + "; ".join(worse)
                 + ": the model's inverse orders a rudder that the vessel does not need "
                 "at these rudder angles (its gain or time constant differs from the "
                 "vessel's there, e.g. a model identified from larger rudder angles); the "
                 "gains are the same, so only the feed-forward differs.")
    return text


def evaluation_report(evaluation, *, title: str = "Heading autopilot",
                      model_text: str = "", figures=()) -> str:
    """A markdown page: the design, the gains, the runs and the `figures` (paths
    relative to the page)."""
    d = evaluation.design
    limits = evaluation.to_dict()["design"]
    text = [f"# {title}\n"]
    if model_text:
        text.append(model_text + "\n")
    text.append(
        f"Pole placement (thesis eq. 5.3-5.5) with omega_n = {d.natural_frequency:g} rad/s, "
        f"zeta = {d.damping:g}, K_d = 2 zeta omega_n m"
        + (" - d" if d.subtract_damping else "") + f", K_i = omega_n K_p / 10, about the "
        f"straight run at {evaluation.design_speed:.3f} m/s ({evaluation.design_rpm:.0f} rpm). "
        f"Reference model (eq. 5.7): omega = {d.reference_frequency:g} rad/s, zeta = "
        f"{d.reference_damping:g}; heading step {d.step:g} deg at {d.step_time:g} s. Rudder "
        f"limits {limits['max_rudder_deg']:.0f} deg and {limits['max_rudder_rate_deg_s']:.0f} "
        f"deg/s; the controller updates every {d.interval:g} s. Chosen: {d.basis}.\n")
    text.append("## Gains\n\n" + gains_table(evaluation.gains()))
    text.append("## Closed-loop runs\n\n" + runs_table(evaluation.rows))
    for verdict in (feedforward_text(evaluation.rows), tuning_text(evaluation.tuning)):
        if verdict:
            text.append(verdict + "\n")
    text.append(METRICS_TEXT.format(dt=d.sample_interval, start=d.window[0],
                                    end=d.window[1]) + "\n")
    if figures:
        text.append("## Figures\n")
        text += [f"![{f}]({f})\n" for f in figures]
    return "\n".join(text)
