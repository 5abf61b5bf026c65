"""The independent Mariner generator (`jaxship.studies.generators`, issue 71): its
equations agree with jaxship's Mariner, and hidden effects show in its logs as a user's
logger writes them."""

import math

import numpy as np
import pytest

import jaxship as js
from jaxship import effects
from jaxship.studies.generators import (
    MarinerScipy,
    TurnPilot,
    ZigZagPilot,
    generator_from_effects,
    mariner_scipy_records,
)


DEG = math.pi / 180
FINE = js.Simulator(max_step=0.02)


def overshoots(psi, angle):
    """The heading overshoots [deg] of a zig-zag: the largest |psi| between successive
    zero crossings, less the check angle, from the first reversal on."""
    psi = np.asarray(psi) / DEG
    crossings = np.flatnonzero(np.diff(np.sign(psi[1:])) != 0) + 1
    edges = [1, *crossings, psi.size - 1]
    return [float(np.max(np.abs(psi[a:b + 1])) - angle) for a, b in zip(edges, edges[1:])]


def turn(x, y, psi):
    """Advance and tactical diameter [m] of a turning circle."""
    k90, k180 = np.argmax(np.abs(psi) >= math.pi / 2), np.argmax(np.abs(psi) >= math.pi)
    return float(x[k90]), float(abs(y[k180]))


def test_a_20_20_zigzag_and_a_35_deg_turn_agree_with_jaxships_mariner():
    """Measured 2026-12-07: the 35 deg turn agrees to 1e-8 relative (advance 570.46 m,
    tactical diameter 1029.39 m, steady rate 0.620 deg/s: the same equations, both
    integrated to tolerance); the 20/20 zig-zag's first overshoot 7.78 deg on both, the
    second 6.36 against 6.30 deg (0.8 %): this generator reverses the rudder at the
    first 0.1 s control instant after the crossing, jaxship at the nearest step."""
    m, g = js.get_vessel("mariner"), MarinerScipy()
    zz = g.run(ZigZagPilot(20 * DEG, 20 * DEG), 600.0)
    tu = g.run(TurnPilot(35 * DEG), 800.0)
    jz = js.simulate(m, js.ZigZag(20 * DEG, 20 * DEG, duration=600.0, dt=0.5,
                                  switch_at=js.strategies.SwitchAtNearestStep()),
                     js.straight_run(m), simulator=FINE)
    jt = js.simulate(m, js.Turn(35 * DEG, duration=800.0, dt=0.5), js.straight_run(m),
                     simulator=FINE)
    ours, theirs = overshoots(zz["psi"], 20)[:2], overshoots(jz.state.psi, 20)[:2]
    np.testing.assert_allclose(ours, theirs, rtol=0.03)
    st = jt.state
    np.testing.assert_allclose(turn(tu["x"], tu["y"], tu["psi"]),
                               turn(np.asarray(st.x), np.asarray(st.y), np.asarray(st.psi)),
                               rtol=0.01)
    np.testing.assert_allclose(tu["r"][-200:].mean(), np.asarray(st.r)[-200:].mean(),
                               rtol=0.01)


def test_hidden_effects_show_in_the_logs_as_a_users_logger_writes_them():
    """Without noise: the offset turns the ship at a logged zero rudder; the current
    drifts the track and the over-ground u, v are its rate in body axes; the gyro bias
    shifts the logged r, not the heading."""
    quiet = (0.0,) * 5
    g = MarinerScipy(offset=1.5 * DEG, current=(0.3, -0.4), gyro_bias=0.01 * DEG)
    train, holdout = mariner_scipy_records(g, 0, duration=100.0, noise=quiet)
    assert len(train) == 4 and len(holdout) == 3
    e = train[0]
    assert e.over_ground and e.name == "zigzag 10/10 starboard"
    psi, u, v = (np.asarray(getattr(e, c)) for c in ("psi", "u", "v"))
    xdot, ydot = np.gradient(np.asarray(e.x), 0.5), np.gradient(np.asarray(e.y), 0.5)
    np.testing.assert_allclose(xdot[5:-5], (u * np.cos(psi) - v * np.sin(psi))[5:-5], atol=2e-3)
    np.testing.assert_allclose(ydot[5:-5], (u * np.sin(psi) + v * np.cos(psi))[5:-5], atol=2e-3)
    np.testing.assert_allclose(np.gradient(psi, 0.5)[5:-5],
                               (np.asarray(e.r) - 0.01 * DEG)[5:-5], atol=3e-5)  # O(dt^2)
    assert abs(np.mean(np.asarray(e.r) - np.gradient(psi, 0.5)) - 0.01 * DEG) < 1e-5
    # the ship feels delta + offset, the log shows the servo's delta: at a logged zero
    # rudder the offset turns the ship
    still = MarinerScipy(offset=1.5 * DEG).run(TurnPilot(0.0), 60.0)
    assert np.all(still["delta"] == 0.0) and still["r"][-1] > 0.05 * DEG


def test_generator_from_effects_hides_the_four_effects_only():
    g = generator_from_effects((effects.RudderOffset(delta0=0.01),
                                effects.UniformCurrent(north=0.3, east=-0.4),
                                effects.YawRateSensorBias(bias=1e-4),
                                effects.AddedMassError(s_r=0.2)))
    assert (g.offset, g.current, g.gyro_bias, g.added_mass) == (0.01, (0.3, -0.4), 1e-4, 0.2)
    with pytest.raises(ValueError, match="cannot hide"):
        generator_from_effects((effects.RudderLag(time_constant=1.0),))
    with pytest.raises(ValueError, match="cannot hide"):  # the sway entry is not hidden
        generator_from_effects((effects.AddedMassError(s_v=0.2),))


def _agrees_with_jaxships_effect(zz, effect):
    """The generator's 20/20 zig-zag `zz` against jaxship's Mariner with `effect`: the
    first two overshoots agree to 3 % (as without effects: the switching instant), and
    the first differs from the unaltered generator's by more than 10 %."""
    m = js.augment(js.get_vessel("mariner"), effect)
    jz = js.simulate(m, js.ZigZag(20 * DEG, 20 * DEG, duration=600.0, dt=0.5,
                                  switch_at=js.strategies.SwitchAtNearestStep()),
                     js.straight_run(m), simulator=FINE)
    ours, theirs = overshoots(zz["psi"], 20)[:2], overshoots(jz.state.psi, 20)[:2]
    np.testing.assert_allclose(ours, theirs, rtol=0.03)
    plain = overshoots(MarinerScipy().run(ZigZagPilot(20 * DEG, 20 * DEG), 600.0)["psi"], 20)
    assert abs(ours[0] - plain[0]) > 0.1 * plain[0], (ours, plain[:2])


def test_a_yaw_added_inertia_error_agrees_with_jaxships_effect():
    """The generator's `added_mass` $s_r$ scales $I_z - N_{\\dot r}$ as
    `effects.AddedMassError(s_r)` scales $M_{33}$: the 20/20 zig-zag's first two
    overshoots agree with jaxship's Mariner with that effect as they do without it (3 %,
    the switching instant), and they differ from the unaltered ship's by more."""
    zz = MarinerScipy(added_mass=0.2).run(ZigZagPilot(20 * DEG, 20 * DEG), 600.0)
    _agrees_with_jaxships_effect(zz, effects.AddedMassError(s_r=0.2))


def test_a_rudder_delay_is_the_logged_rudder_late_and_agrees_with_jaxships_effect():
    """The generator's `delay` $\\tau$: the hull feels the servo's angle exactly $\\tau$ late
    (1.5 s, three samples), and the 20/20 zig-zag's first two overshoots agree with
    jaxship's Mariner with `effects.RudderDelay(1.5)` (a Pade approximant of the delay)
    as closely as without it, while they differ from the undelayed ship's by more."""
    zz = MarinerScipy(delay=1.5).run(ZigZagPilot(20 * DEG, 20 * DEG), 600.0)
    np.testing.assert_allclose(zz["delta_felt"][3:], zz["delta"][:-3], atol=1e-6)
    assert np.all(zz["delta_felt"][:3] == 0.0)
    _agrees_with_jaxships_effect(zz, effects.RudderDelay(delay=1.5))
    assert generator_from_effects((effects.RudderDelay(delay=1.5),)).delay == 1.5


def test_shipmmgs_kvlcc2_is_another_implementation_of_jaxships():
    """The second generator (`jaxship.studies.kvlcc2_shipmmg`, shipmmg's MMG code with the
    paper's KVLCC2 L7 coefficients) runs the same ship as jaxship's `kvlcc2` preset up to
    its own wake and drift-angle formulation: the 35 deg turn's advance within 5 % and
    tactical diameter within 10 % (measured 2026-12-07: 3.02 against 3.09 L and 2.93
    against 3.12 L), the 10/10 zig-zag's first overshoot within 1.5 deg. The hidden
    effects show in its logs as in the Mariner generator's."""
    pytest.importorskip("shipmmg")
    from jaxship.studies.kvlcc2_shipmmg import (
        LENGTH,
        KVLCC2Shipmmg,
        kvlcc2_shipmmg_records,
    )

    g, v = KVLCC2Shipmmg(), js.get_vessel("kvlcc2")
    tu, zz = g.run(TurnPilot(35 * DEG), 150.0), g.run(ZigZagPilot(10 * DEG, 10 * DEG), 150.0)
    jt = js.simulate(v, js.Turn(35 * DEG, duration=150.0, dt=0.2), js.straight_run(v),
                     simulator=FINE).state
    jz = js.simulate(v, js.ZigZag(10 * DEG, 10 * DEG, duration=150.0, dt=0.2),
                     js.straight_run(v), simulator=FINE).state
    (a, d), (ja, jd) = (turn(tu["x"], tu["y"], tu["psi"]),
                        turn(np.asarray(jt.x), np.asarray(jt.y), np.asarray(jt.psi)))
    assert abs(a / ja - 1) < 0.05 and abs(d / jd - 1) < 0.10, (a / LENGTH, ja / LENGTH,
                                                               d / LENGTH, jd / LENGTH)
    ours, theirs = overshoots(zz["psi"], 10)[0], overshoots(jz.psi, 10)[0]
    assert abs(ours - theirs) < 1.5, (ours, theirs)
    quiet = (0.0,) * 5
    train, holdout = kvlcc2_shipmmg_records(KVLCC2Shipmmg(current=(0.05, -0.05)), 0,
                                            duration=30.0, noise=quiet)
    assert len(train) == 6 and len(holdout) == 3 and train[0].over_ground
    e = train[0]
    psi, u, v_ = (np.asarray(getattr(e, c)) for c in ("psi", "u", "v"))
    xdot = np.gradient(np.asarray(e.x), 0.2)
    np.testing.assert_allclose(xdot[5:-5], (u * np.cos(psi) - v_ * np.sin(psi))[5:-5],
                               atol=2e-3)
    still = KVLCC2Shipmmg(offset=1.5 * DEG).run(TurnPilot(0.0), 30.0)
    assert np.all(still["delta"] == 0.0) and still["r"][-1] > 0.05 * DEG
