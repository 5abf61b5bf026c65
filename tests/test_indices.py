"""IMO/ITTC manoeuvre indices: analytic trajectories, IMO limits, bad input, toy-vessel runs."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.optimize

import jaxship as js
from jaxship._analysis._indices import (
    CriterionRow,
    InitialTurningIndices,
    SpiralCurve,
    StoppingIndices,
    TurningIndices,
    ZigZagIndices,
    imo_overshoot_limits_deg,
    loop_width,
)
from jaxship.indices import (
    format_table,
    imo_criteria,
    initial_turning_indices,
    pull_out_indices,
    reverse_spiral_curve,
    spiral_curve,
    stopping_indices,
    turning_indices,
    zigzag_indices,
)


DEG = np.pi / 180


class ToyVessel(js.AbstractVessel):
    """Linear Davidson & Schiff (1946) sway-yaw model with quadratic surge resistance.

    Prime derivatives of Mariner-like magnitude (made up for tests, not a real ship);
    course-stable for the default yaw damping `nr` (C = Y'_v N'_r - N'_v (Y'_r - m') > 0).
    """

    length: float = 100.0  # L [m]
    rudder: js.RudderServo = js.RudderServo(35 * DEG, 2.5 * DEG, 0.5)
    shaft: js.Shaft = js.Shaft(max_rate=3.0, time_constant=2.0)
    nominal_speed: float = 6.0  # U_0 [m/s]
    nominal_n: float = 1.0  # n_0 [rev/s]
    frontal_wind_area: float = 0.0
    lateral_wind_area: float = 0.0
    wind_model: js.wind_loads.FossenWindLoads = js.wind_loads.FossenWindLoads()
    mass: float = 5.0e6  # m [kg]
    yv: float = -0.012  # Y'_v [-]
    yr: float = 0.003  # Y'_r [-], hydrodynamic part (m u r written separately)
    nv: float = -0.0025  # N'_v [-]
    nr: float = -0.0018  # N'_r [-], the yaw damping varied in the tests
    yd: float = 0.003  # Y'_delta [-]
    nd: float = 0.0015  # N'_delta [-], > 0: positive rudder turns to starboard
    xuu: float = 1.2e4  # X_|u|u [N s^2/m^2]

    def mass_matrix(self):
        L, m, h = self.length, self.mass, 0.5 * 1025 * self.length**3
        return jnp.diag(jnp.array([1.05 * m, m + 0.008 * h, m * (L / 4) ** 2 + 0.0004 * h * L**2]))

    def forces(self, u, v, r, delta, n):
        L, m, q = self.length, self.mass, 0.5 * 1025 * self.length**2
        thrust = self.xuu * self.nominal_speed**2 / self.nominal_n**2
        X = -self.xuu * jnp.abs(u) * u + thrust * jnp.abs(n) * n + 1.05 * m * v * r
        Y = q * (self.yv * u * v + self.yr * u * r * L + self.yd * u**2 * delta) - m * u * r
        N = q * L * (self.nv * u * v + self.nr * u * r * L + self.nd * u**2 * delta)
        return jnp.stack([X, Y, N])


@pytest.fixture(scope="module")
def toy():
    return ToyVessel()


# --------------------------------------------------------------------------- analytic data


def circle_track(*, side, psi0=30 * DEG, u0=8.0, u1=5.0, radius=400.0, t_e=20.0, dt=0.1,
                 turned=400 * DEG, x_e=100.0, y_e=-50.0):
    """Straight approach at `u0` on heading `psi0`, then (from `t_e`) a perfect circle of
    `radius` at speed `u1` to the `side` (+1 starboard). Returns keyword sample arrays."""
    t = t_e + dt * np.arange(-int(round(t_e / dt)), int(turned * radius / u1 / dt) + 1)
    tau = t - t_e  # the order at a sample, the 90 and 180 deg points between samples
    theta = np.where(tau > 0, u1 * tau / radius, 0.0)
    along = np.where(tau > 0, radius * np.sin(theta), u0 * tau)
    athwart = side * radius * (1 - np.cos(theta))
    c, s = np.cos(psi0), np.sin(psi0)
    return dict(
        t=t, x=x_e + c * along - s * athwart, y=y_e + s * along + c * athwart,
        psi=psi0 + side * theta, u=np.where(tau > 0, u1, u0), v=np.zeros_like(t),
        r=np.where(tau > 0, side * u1 / radius, 0.0),
        delta=np.where(tau >= 0, side * 35 * DEG, 0.0),
    )


@pytest.mark.parametrize("side", [1, -1])
def test_turning_indices_of_a_perfect_circle(side):
    radius, u0, u1, t_e = 400.0, 8.0, 5.0, 20.0
    data = circle_track(side=side, radius=radius, u0=u0, u1=u1, t_e=t_e)
    for steady in (js.indices.SteadyFromRate(), js.indices.SteadyFromCircle()):
        ind = turning_indices(**data, steady=steady)
        assert ind.side == side and ind.steady_method == steady.name
        assert ind.execute_time == t_e
        np.testing.assert_allclose(ind.advance, radius, rtol=1e-6)
        np.testing.assert_allclose(ind.transfer, radius, rtol=1e-6)
        np.testing.assert_allclose(ind.tactical_diameter, 2 * radius, rtol=1e-6)
        np.testing.assert_allclose(ind.steady_turning_diameter, 2 * radius, rtol=1e-6)
        np.testing.assert_allclose(ind.time_to_90, np.pi / 2 * radius / u1, rtol=1e-9)
        np.testing.assert_allclose(ind.time_to_180, np.pi * radius / u1, rtol=1e-9)
        np.testing.assert_allclose(ind.speed_loss, 1 - u1 / u0, rtol=1e-5)
    d = ind.to_dict()
    assert set(d) == {"advance_m", "transfer_m", "tactical_diameter_m",
                      "steady_turning_diameter_m", "speed_loss_percent", "time_to_90_s",
                      "time_to_180_s"}
    np.testing.assert_allclose(d["speed_loss_percent"], 100 * (1 - u1 / u0), rtol=1e-5)
    assert ind.to_dict(units=js.strategies.SIUnits())["speed_loss"] == pytest.approx(ind.speed_loss)


def test_turning_interpolates_between_coarse_samples():
    """Coarse 2 s samples: linear interpolation keeps the error at O((U dt)^2 / R)."""
    data = circle_track(side=1, dt=2.0, t_e=20.0)
    ind = turning_indices(**data)
    np.testing.assert_allclose(ind.time_to_90, np.pi / 2 * 400 / 5, rtol=1e-12)
    np.testing.assert_allclose(ind.advance, 400, atol=(5 * 2.0) ** 2 / 400)
    np.testing.assert_allclose(ind.tactical_diameter, 800, atol=(5 * 2.0) ** 2 / 400)


def test_turning_errors():
    data = circle_track(side=1, turned=170 * DEG)
    with pytest.raises(ValueError, match=r"only 170\.0 deg"):
        turning_indices(**data)
    data = circle_track(side=1, turned=200 * DEG)
    with pytest.raises(ValueError, match="360"):
        turning_indices(**data, steady=js.indices.SteadyFromCircle())
    with pytest.raises(ValueError, match="steady"):
        turning_indices(**circle_track(side=1), steady="circle")
    straight = circle_track(side=1, turned=0.0, t_e=50.0)
    with pytest.raises(ValueError, match="did not change"):
        turning_indices(**straight, execute_time=10.0)
    with pytest.raises(ValueError, match="unknown sample arrays"):
        turning_indices(**circle_track(side=1), heading=np.zeros(3))
    with pytest.raises(ValueError, match="both"):
        turning_indices(object(), t=np.arange(3.0))
    with pytest.raises(ValueError, match="need.*psi"):
        turning_indices(t=np.arange(3.0), x=np.zeros(3), y=np.zeros(3), execute_time=0.0)
    with pytest.raises(ValueError, match="increasing"):
        turning_indices(**dict(circle_track(side=1), t=np.zeros_like(circle_track(side=1)["t"])))


def zigzag_heading(*, side, amplitudes, psi_s, omega=2 * np.pi / 120, t1=10.0, dt=0.1,
                   psi0=45 * DEG, tail=0.5):
    """Half-sine heading oscillations of `amplitudes[k]` after the first execute at `t1`,
    with the rudder order reversed at the first sample past each +-psi_s crossing."""
    t = np.arange(0.0, t1 + (len(amplitudes) + tail) * np.pi / omega, dt)
    tau = np.maximum(t - t1, 0.0)  # t1 on a sample, the switches between samples
    k = np.minimum((tau * omega / np.pi).astype(int), len(amplitudes) - 1)
    amp = np.asarray(amplitudes)[k]
    e = amp * np.sin(omega * tau)  # sin changes sign every half period: e alternates
    halves = np.asarray(amplitudes)[np.minimum(np.arange(len(amplitudes) + 1), len(amplitudes) - 1)]
    switches = [t1 + (j * np.pi + np.arcsin(psi_s / a)) / omega
                for j, a in enumerate(halves) if a > psi_s]
    switches = [ts for ts in switches if ts <= t[-1]]
    order = np.where(t >= t1, 1.0, 0.0)
    for j, ts in enumerate(switches):
        order = np.where(t > ts, (-1.0) ** (j + 1), order)
    return dict(t=t, psi=psi0 + side * e, delta=side * 10 * DEG * order), switches


@pytest.mark.parametrize("side", [1, -1])
def test_zigzag_indices_of_a_known_heading_history(side):
    psi_s, omega, t1 = 10 * DEG, 2 * np.pi / 120, 10.0
    amplitudes = np.array([16.0, 19.0, 17.5, 18.0]) * DEG
    data, switches = zigzag_heading(side=side, amplitudes=amplitudes, psi_s=psi_s, omega=omega,
                                    t1=t1)
    ind = zigzag_indices(None, psi_s, **data)
    assert ind.side == side
    np.testing.assert_allclose(ind.overshoots, amplitudes - psi_s, atol=1e-6 * DEG)
    # linear interpolation of the crossing: error ~ omega dt^2 / 8 / cos(...)
    np.testing.assert_allclose(ind.switch_times, switches, atol=1e-4)
    # executes at the first sample after each crossing
    assert ind.execute_times[0] == t1
    executes, switches = np.array(ind.execute_times[1:]), np.array(switches)
    assert executes.size == switches.size == 5
    assert np.all((executes > switches) & (executes <= switches + 0.1 + 1e-12))
    np.testing.assert_allclose(ind.initial_turning_time, switches[0] - t1, atol=1e-4)
    np.testing.assert_allclose(ind.time_to_check_yaw,
                               (np.pi / 2 - np.arcsin(psi_s / amplitudes[0])) / omega, atol=1e-4)
    expected_period = np.mean(np.array(switches[2:]) - np.array(switches[:-2]))
    np.testing.assert_allclose(ind.period, expected_period, atol=1e-4)
    np.testing.assert_allclose(ind.rudder_angle, 10 * DEG)
    d = ind.to_dict()
    names = [f"overshoot_{k}_deg" for k in range(1, 5)]
    assert [k for k in d if k.startswith("overshoot")] == names
    np.testing.assert_allclose(d["overshoot_2_deg"], 9.0, atol=1e-6)
    assert {"initial_turning_time_s", "time_to_check_yaw_s", "period_s"} <= set(d)
    # the same from the heading alone, with explicit executes
    again = zigzag_indices(None, psi_s, t=data["t"], psi=data["psi"], execute_times=[t1])
    np.testing.assert_allclose(again.overshoots, ind.overshoots, atol=1e-12)
    assert again.side == side


@pytest.mark.parametrize("side", [1, -1])
def test_a_zigzag_logged_from_its_execute_on(side):
    """A record that starts with the first order already given (the rudder over at the
    first sample, as a log cut at the execute or an instant rudder has it): the side is
    that order's. Before, the order at the first sample was taken for a neutral helm and
    the first reversal for the first order: the wrong side, one leg late."""
    amplitudes = np.array([16.0, 19.0, 17.5, 18.0]) * DEG
    data, _ = zigzag_heading(side=side, amplitudes=amplitudes, psi_s=10 * DEG, t1=0.0)
    assert data["delta"][0] == side * 10 * DEG
    ind = zigzag_indices(None, 10 * DEG, **data)
    assert ind.side == side and ind.execute_times[0] == 0.0
    np.testing.assert_allclose(ind.overshoots, amplitudes - 10 * DEG, atol=1e-6 * DEG)


def test_zigzag_incomplete_last_overshoot_is_dropped():
    amplitudes = np.array([16.0, 19.0, 17.5]) * DEG
    data, _ = zigzag_heading(side=1, amplitudes=amplitudes, psi_s=10 * DEG, tail=0.0)
    cut = data["t"] < 155.0  # the third peak is at 10 + 120 + 30 s
    ind = zigzag_indices(None, 10 * DEG, **{k: a[cut] for k, a in data.items()})
    np.testing.assert_allclose(ind.overshoots, amplitudes[:2] - 10 * DEG, atol=1e-6 * DEG)


def test_zigzag_errors():
    data, _ = zigzag_heading(side=1, amplitudes=np.array([8.0, 8.0]) * DEG, psi_s=10 * DEG)
    with pytest.raises(ValueError, match="never reached"):
        zigzag_indices(None, 10 * DEG, **data)
    with pytest.raises(ValueError, match="positive"):
        zigzag_indices(None, -10 * DEG, **data)
    with pytest.raises(ValueError, match="no rudder order"):
        zigzag_indices(None, 5 * DEG, **dict(data, delta=np.zeros_like(data["t"])))


def test_stopping_indices_of_a_decelerating_straight_line():
    u0, a, t_e, k, psi0 = 8.0, 0.0503, 30.0, 0.1, -60 * DEG  # order at a sample, stop between
    t = np.arange(0.0, t_e + u0 / a + 40.0, 0.1)
    tau = np.maximum(t - t_e, 0.0)
    u = u0 - a * tau
    along = u0 * (t - t_e) - 0.5 * a * tau**2
    athwart = k * along * (t > t_e)  # drifts to starboard along a straight line
    c, s = np.cos(psi0), np.sin(psi0)
    x, y = c * along - s * athwart, s * along + c * athwart
    n = np.where(t >= t_e, -1.0, 1.0)
    ind = stopping_indices(t=t, x=x, y=y, psi=np.full_like(t, psi0), u=u, n=n,
                           execute_time=t_e)
    reach = u0**2 / (2 * a)
    np.testing.assert_allclose(ind.time_to_stop, u0 / a, rtol=1e-10)
    np.testing.assert_allclose(ind.head_reach, reach, atol=1e-3)
    np.testing.assert_allclose(ind.lateral_deviation, k * reach, atol=1e-3)
    np.testing.assert_allclose(ind.track_reach, np.hypot(1, k) * reach, atol=1e-3)
    detected = stopping_indices(t=t, x=x, y=y, psi=np.full_like(t, psi0), u=u, n=n)
    assert detected.execute_time == pytest.approx(t[t >= t_e][0])
    assert set(ind.to_dict()) == {"head_reach_m", "track_reach_m", "lateral_deviation_m",
                                  "time_to_stop_s"}
    with pytest.raises(ValueError, match="did not stop"):
        stopping_indices(t=t, x=x, y=y, psi=np.full_like(t, psi0), u=u + 10, n=n)
    with pytest.raises(ValueError, match="engine order"):
        stopping_indices(t=t, x=x, y=y, psi=np.full_like(t, psi0), u=u, n=np.ones_like(t))


def test_initial_turning_of_a_circle():
    radius, u1, t_e = 400.0, 5.0, 20.0
    data = circle_track(side=-1, radius=radius, u1=u1, t_e=t_e, turned=30 * DEG)
    ind = initial_turning_indices(**data)
    theta = 10 * DEG
    np.testing.assert_allclose(ind.time, theta * radius / u1, rtol=1e-9)
    np.testing.assert_allclose(ind.distance, theta * radius, rtol=1e-6)  # arc length
    np.testing.assert_allclose(ind.advance, radius * np.sin(theta), rtol=1e-6)
    assert ind.to_dict()["heading_change_deg"] == pytest.approx(10.0)
    with pytest.raises(ValueError, match="less than 45"):
        initial_turning_indices(**data, execute_time=t_e, heading_change=45 * DEG)


# --------------------------------------------------------------------------- spirals


def cubic_branch(delta, b1, previous):
    """Steady r of delta = r^3 + b1 r (Bech), the real root nearest `previous`."""
    roots = np.roots([1.0, 0.0, b1, -delta])
    real = roots[np.abs(roots.imag) < 1e-9].real
    return real[np.argmin(np.abs(real - previous))]


@pytest.mark.parametrize("b1", [1.0, -1.0])
def test_loop_width_of_cubic_spiral_curves(b1):
    # reverse spiral: the full S-curve, points including the turning points r = +-1/sqrt(3)
    r = np.concatenate([np.linspace(-1.5, 1.5, 61), [-1 / np.sqrt(3), 1 / np.sqrt(3)]])
    reverse = SpiralCurve(delta=r**3 + b1 * r, r=r)
    true_width = 0.0 if b1 > 0 else 4 / (3 * np.sqrt(3))
    np.testing.assert_allclose(loop_width(reverse), true_width, atol=1e-12)
    # direct spiral: steps of 0.1 down from +1 to -1 and back, each on the nearest branch
    levels = np.round(np.concatenate([np.arange(1.0, -1.05, -0.1), np.arange(-0.9, 1.05, 0.1)]), 10)
    rates, previous = [], 2.0
    for d in levels:
        previous = cubic_branch(d, b1, previous)
        rates.append(previous)
    direct = SpiralCurve(delta=levels, r=np.array(rates))
    assert direct.direct and not reverse.direct
    if b1 > 0:
        assert loop_width(direct) == 0.0
        assert direct.loop.height == 0.0 and reverse.loop.height == 0.0
    else:
        # resolved to the rudder step: the levels -0.3 ... 0.3 have two branches, the
        # edges lie between them and the next levels, +-0.4
        loop = direct.loop
        np.testing.assert_allclose(loop.inside, np.arange(-3, 4) / 10, atol=1e-12)
        assert loop.width_low == pytest.approx(0.6) and loop.width_high == pytest.approx(0.8)
        assert loop.width_low <= true_width <= loop.width_high
        assert direct.loop_width == pytest.approx(0.7)  # edges half-way
        assert abs(loop.width - true_width) <= 0.1  # within half a step on each side
        # height: the branches at zero rudder, r = +-1
        assert loop.height == pytest.approx(2.0, abs=1e-9)
        # the reverse spiral's S-curve: height between the outer branches at the middle
        # of the loop (delta = 0: r = -1 ... +1)
        assert reverse.loop.height == pytest.approx(2.0, abs=1e-9)
        np.testing.assert_allclose(reverse.loop.edges, [-true_width / 2, true_width / 2],
                                   atol=1e-12)


def test_spiral_curve_reads_the_end_of_each_hold():
    hold, dt, T = 100.0, 0.5, 10.0
    levels = np.array([10.0, 5.0, 0.0, -5.0, -10.0]) * DEG
    t = np.arange(0.0, hold * levels.size + dt / 2, dt)
    k = np.minimum((t // hold).astype(int), levels.size - 1)
    delta = levels[k]
    # first-order yaw response r = K delta with lag T, restarted at each level
    gain, r, value = 0.05, np.zeros_like(t), 0.0
    for i in range(1, t.size):
        value += dt * (gain * delta[i - 1] - value) / T  # explicit Euler: exact sample values
        r[i] = value
    curve = spiral_curve(t=t, r=r, delta=delta, hold=hold)
    np.testing.assert_allclose(curve.delta, levels)
    ends = np.searchsorted(t, hold * np.arange(1, levels.size + 1))
    np.testing.assert_allclose(curve.r, r[ends], atol=1e-15)
    lag = 2 * gain * np.max(np.abs(levels)) * np.exp(-hold / T)  # left from the level before
    np.testing.assert_allclose(curve.r, gain * levels, atol=lag)
    averaged = spiral_curve(t=t, r=r, delta=delta, hold=hold, average=20.0)
    np.testing.assert_allclose(averaged.r, gain * levels, atol=lag * np.exp(20.0 / T))
    assert set(curve.to_dict()) == {"delta_deg", "r_deg_s"}
    with pytest.raises(ValueError, match="shorter than one hold"):
        spiral_curve(t=t, r=r, delta=delta, hold=1e4)


def test_reverse_spiral_curve_averages_the_settled_part():
    hold, dt = 60.0, 0.25
    rates = np.array([0.4, -0.2, 0.1]) * DEG
    t = np.arange(0.0, hold * rates.size + dt / 2, dt)
    k = np.clip(np.ceil(t / hold).astype(int) - 1, 0, rates.size - 1)  # boundary sample: old level
    local = t - k * hold
    mid = 0.75 * hold
    settle = np.where(local < hold / 2, np.exp(-local), 0.0)  # transient, left out
    delta = np.array([3.0, -1.0, 2.0])[k] * DEG + 1e-3 * (local - mid) + settle
    r = rates[k] + 1e-4 * np.sin(2 * np.pi * local / (hold / 2))  # zero mean on the half
    curve = reverse_spiral_curve(t=t, r=r, delta=delta, rates=rates, hold=hold)
    np.testing.assert_allclose(curve.delta, np.array([3.0, -1.0, 2.0]) * DEG, atol=1e-12)
    np.testing.assert_allclose(curve.r, rates, atol=1e-8)


# issue 13: the KVLCC2 direct spiral (5 deg steps) read r = +0.094 and -1.158 deg/s at
# zero rudder on its two branches, and its loop width came out 0.0
KVLCC2_LEVELS = np.concatenate([np.arange(25, -26, -5), np.arange(-20, 26, 5)]) * DEG
KVLCC2_R = np.array([2.935, 2.748, 2.507, 2.180, 1.676, 0.094, -2.095, -2.478, -2.741, -2.939,
                     -3.091, -2.939, -2.741, -2.478, -2.094, -1.158, 1.678, 2.182, 2.508,
                     2.749, 2.935]) * DEG


def test_loop_of_a_direct_spiral_whose_branches_differ_at_zero_rudder():
    curve = SpiralCurve(delta=KVLCC2_LEVELS, r=KVLCC2_R)
    loop = curve.loop
    assert loop.inside == (0.0,)  # two steady rates at zero rudder, one at +-5 deg
    assert loop_width(curve) > 0
    # the edges lie between 0 and the next levels: width between 0 and 10 deg, 5 estimated
    assert loop.width_low == 0.0 and loop.width_high == pytest.approx(10 * DEG)
    assert loop.width == pytest.approx(5 * DEG)
    np.testing.assert_allclose(loop.edges, [-2.5 * DEG, 2.5 * DEG])
    assert loop.height == pytest.approx((0.094 + 1.158) * DEG)
    shown = loop.to_dict()
    assert shown["loop_width_deg"] == pytest.approx(5.0)
    assert shown["loop_height_deg_s"] == pytest.approx(1.252)
    # branches in the order run, sharing the turning level
    down, up = curve.branches()
    np.testing.assert_array_equal(down, np.arange(11))
    np.testing.assert_array_equal(up, np.arange(10, 21))
    # lag that holds too short leave between the branches is not a loop
    stable = SpiralCurve(delta=KVLCC2_LEVELS, r=np.where(KVLCC2_R == -1.158 * DEG, 0.0,
                                                         KVLCC2_R) + 0.05 * DEG)
    assert stable.loop.width == 0.0 and stable.loop.inside == ()


def test_spiral_curves_count_a_last_hold_that_is_not_a_whole_number_of_samples():
    # 30 L/U of the KVLCC2 (178.1 s) sampled every 0.2 s: the run ends 0.1 s before the
    # 21st hold does, which was dropped
    hold, dt, count = 178.1170453, 0.2, 21
    t = np.arange(0.0, round(hold * count / dt) * dt + dt / 2, dt)
    assert t[-1] < hold * count
    k = np.minimum((t // hold).astype(int), count - 1)
    levels = np.linspace(0.3, -0.3, count)
    delta, r = levels[k], 0.01 * levels[k]
    curve = spiral_curve(t=t, r=r, delta=delta, hold=hold)
    assert curve.r.size == count and curve.kind == "direct"
    np.testing.assert_allclose(curve.delta, levels)
    rates = 0.01 * levels
    reverse = reverse_spiral_curve(t=t, r=r, delta=delta, rates=rates, hold=hold)
    assert reverse.r.size == count and reverse.kind == "reverse"
    # (a level's edge between two samples is interpolated: within 1 % of a step)
    np.testing.assert_allclose(reverse.r, rates, atol=0.01 * 0.0003)


def test_kvlcc2_direct_spiral_shows_its_loop():
    # the simulated trial (`jaxship simulate --manoeuvre spiral`): finer steps near
    # midships; the loop of this MMG model lies between about 0 and 0.5 deg of rudder
    vessel = js.get_vessel("kvlcc2")
    trial = js.StandardTrial.parse("spiral")
    manoeuvre, x0 = trial.sized(vessel)
    traj = js.simulate(vessel, manoeuvre, x0, simulator=trial.simulator)
    indices = trial.indices(manoeuvre, traj)
    hold = float(np.diff(np.unique(np.asarray(manoeuvre.times)))[0])
    curve = spiral_curve(traj, hold=hold)
    assert curve.r.size == 29 and len(indices["r_deg_s"]) == 29  # every level
    at_zero = curve.r[np.abs(curve.delta) < 1e-12]
    assert at_zero.size == 2 and at_zero[0] > -0.1 * DEG and at_zero[1] < -1.0 * DEG
    loop = curve.loop
    assert loop.inside == (0.0,)
    assert loop.width_low <= np.deg2rad(0.5) <= loop.width_high  # brackets the true width
    assert loop.width == pytest.approx(1.0 * DEG, rel=1e-6)
    assert indices["loop_width_deg"] == pytest.approx(1.0, rel=1e-6)
    assert indices["loop_height_deg_s"] > 1.0


# --------------------------------------------------------------------------- pull-out


def pull_out_data(side, release=200.0, residual=0.0, rate=0.5 * DEG, T=30.0):
    t = np.arange(0.0, 800.0, 0.5)
    after = t >= release
    r = np.where(after, (side * rate - residual) * np.exp(-(t - release) / T) + residual,
                 side * rate)
    return t, r, np.where(after, 0.0, side * 20 * DEG)


def _as_trajectory(t, r, delta):
    """A Trajectory holding only what the pull-out needs (others zero)."""
    z = jnp.zeros_like(t)
    state = js.ShipState(u=z + 5, v=z, r=jnp.asarray(r), x=z, y=z, psi=z,
                         delta=jnp.asarray(delta), n=z)
    return js.Trajectory(t=jnp.asarray(t), state=state, command=js.Command(jnp.asarray(delta), z),
                         valid=jnp.ones(t.shape, bool), result=js.RESULTS.successful)


def test_pull_out_indices_both_sides():
    stbd = _as_trajectory(*pull_out_data(1, residual=0.1 * DEG))
    port = _as_trajectory(*pull_out_data(-1, residual=-0.05 * DEG))
    ind = pull_out_indices(port, stbd)  # either order
    np.testing.assert_allclose(ind.release_rate_starboard, 0.5 * DEG, rtol=1e-12)
    np.testing.assert_allclose(ind.release_rate_port, -0.5 * DEG, rtol=1e-12)
    np.testing.assert_allclose(ind.residual_rate_starboard, 0.1 * DEG, rtol=1e-6)
    np.testing.assert_allclose(ind.residual_rate_port, -0.05 * DEG, rtol=1e-6)
    assert ind.to_dict()["residual_rate_starboard_deg_s"] == pytest.approx(0.1, rel=1e-6)
    one = pull_out_indices(stbd)
    assert np.isnan(one.residual_rate_port)
    with pytest.raises(ValueError, match="same side"):
        pull_out_indices(stbd, stbd)


# --------------------------------------------------------------------------- IMO limits


def test_imo_overshoot_limits_at_the_boundaries():
    assert imo_overshoot_limits_deg(5.0) == (10.0, 25.0, 25.0)
    assert imo_overshoot_limits_deg(10.0) == (10.0, 25.0, 25.0)
    assert imo_overshoot_limits_deg(20.0) == (15.0, 32.5, 25.0)
    assert imo_overshoot_limits_deg(30.0) == (20.0, 40.0, 25.0)
    assert imo_overshoot_limits_deg(45.0) == (20.0, 40.0, 25.0)
    eps = 1e-9
    for lv in (10.0, 30.0):  # continuous at both breakpoints
        below, above = imo_overshoot_limits_deg(lv - eps), imo_overshoot_limits_deg(lv + eps)
        np.testing.assert_allclose(below, above, atol=1e-8)
    # reference-notes cross-check: Mariner L/V = 20.85 s -> 15.4 deg and 33.1 deg
    first, second, _ = imo_overshoot_limits_deg(20.85)
    assert round(first, 1) == 15.4 and round(second, 1) == 33.1
    arrays = imo_overshoot_limits_deg(np.array([5.0, 20.0, 40.0]))
    np.testing.assert_allclose(arrays[0], [10.0, 15.0, 20.0])
    np.testing.assert_allclose(arrays[1], [25.0, 32.5, 40.0])
    with pytest.raises(ValueError, match="positive"):
        imo_overshoot_limits_deg(0.0)


def _zz(first, second, switch=10 * DEG):
    return ZigZagIndices(switch, switch, (first * DEG, second * DEG), (0.0, 0.0), (0.0,),
                         (0.0,), 0.0, 0.0, float("nan"), 1)


def test_imo_criteria_table():
    L, V = 200.0, 10.0  # L/V = 20 s: 1st 10/10 limit 15 deg, 2nd 32.5 deg
    turning = [TurningIndices(880.0, 400.0, 950.0, 800.0, 0.3, 80.0, 150.0, 0.0, 1),
               TurningIndices(910.0, 400.0, 1010.0, 800.0, 0.3, 80.0, 150.0, 0.0, -1)]
    rows = imo_criteria(
        L, V, turning35=turning, zigzag10=_zz(14.9, 33.0), zigzag20=_zz(12.0, 9.0, 20 * DEG),
        stopping=StoppingIndices(2800.0, 3100.0, 50.0, 400.0, 0.0),
        initial_turning=InitialTurningIndices(10 * DEG, 30.0, 480.0, 470.0),
    )
    assert all(isinstance(row, CriterionRow) for row in rows)
    got = {row.criterion: row for row in rows}
    assert len(rows) == len(got) == 7
    adv = next(r for r in rows if "advance" in r.criterion)
    assert (adv.value, adv.limit, adv.passed) == (pytest.approx(910 / 200), 4.5, False)  # worst
    tac = next(r for r in rows if "tactical" in r.criterion)
    assert tac.value == pytest.approx(5.05) and not tac.passed
    os1 = next(r for r in rows if "1st overshoot, 10/10" in r.criterion)
    assert os1.limit == pytest.approx(15.0) and os1.passed
    os2 = next(r for r in rows if "2nd overshoot" in r.criterion)
    assert os2.limit == pytest.approx(32.5) and not os2.passed
    assert got["stopping: track reach, full astern"].passed is False  # 15.5 L > 15 L
    assert got["initial turning: distance to 10 deg heading change"].value == pytest.approx(2.4)
    table = format_table(rows)
    assert table.count("\n") == 1 + len(rows)
    assert table.count("FAIL") == 4 and table.count("pass") == 3
    assert "| 4.55 L | 4.50 L | FAIL |" in table
    relaxed = imo_criteria(L, V, stopping=StoppingIndices(2800.0, 3100.0, 50.0, 400.0, 0.0),
                           stopping_limit=20.0)
    assert relaxed[0].passed and relaxed[0].limit == 20.0


def test_imo_criteria_bad_input():
    with pytest.raises(ValueError, match="10/10"):
        imo_criteria(200.0, 10.0, zigzag10=_zz(5.0, 5.0, 20 * DEG))
    with pytest.raises(ValueError, match="positive"):
        imo_criteria(-200.0, 10.0)
    with pytest.raises(ValueError, match="TurningIndices"):
        imo_criteria(200.0, 10.0, turning35=_zz(5.0, 5.0))
    with pytest.raises(ValueError, match="units"):
        _zz(5.0, 5.0).to_dict(units="imperial")


# --------------------------------------------------------------------------- toy-vessel runs


def test_turning_indices_of_a_simulated_turn_port_and_starboard(toy):
    x0 = js.straight_run(toy)
    stbd = js.simulate(toy, js.Turn(35 * DEG, duration=700.0, dt=0.5, execute=10.0), x0)
    port = js.simulate(toy, js.Turn(-35 * DEG, duration=700.0, dt=0.5, execute=10.0), x0)
    a, b = turning_indices(stbd), turning_indices(port)
    assert a.execute_time == 10.0 and (a.side, b.side) == (1, -1)
    for name in ("advance", "transfer", "tactical_diameter", "steady_turning_diameter",
                 "time_to_90", "time_to_180", "speed_loss"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-9, err_msg=name)
    # a steady turn: the fitted circle over the last turn agrees with 2 U / r
    circle = turning_indices(stbd, steady=js.indices.SteadyFromCircle())
    np.testing.assert_allclose(circle.steady_turning_diameter, a.steady_turning_diameter,
                               rtol=1e-3)
    assert 0 < a.transfer < a.tactical_diameter and a.speed_loss > 0
    # padding beyond the manoeuvre is ignored
    padded = js.simulate(toy, js.Turn(35 * DEG, duration=700.0, dt=0.5, execute=10.0,
                                      num_samples=1600), x0)
    np.testing.assert_allclose(turning_indices(padded).steady_turning_diameter,
                               a.steady_turning_diameter, rtol=1e-12)
    batch = jax.tree.map(lambda s: jnp.stack([s, s]), stbd)
    with pytest.raises(ValueError, match="one trajectory"):
        turning_indices(batch)


def test_zigzag_overshoot_decreases_with_yaw_damping(toy):
    x0 = js.straight_run(toy)
    firsts = []
    for nr in (-0.0018, -0.003, -0.005):
        traj = js.simulate(ToyVessel(nr=nr), js.ZigZag(10 * DEG, 10 * DEG, duration=400.0,
                                                       dt=0.2, execute=5.0), x0)
        ind = zigzag_indices(traj, 10 * DEG)
        firsts.append(ind.overshoots[0])
        # simulated executes: the first sample after the reversal, which is ordered at
        # the crossing itself (inside a 0.1 s control step; to the 0.2 s samples'
        # interpolation of the crossing)
        executes, switches = np.array(ind.execute_times[1:]), np.array(ind.switch_times)
        n = min(executes.size, switches.size)
        assert np.all((executes[:n] >= switches[:n] - 0.01)
                      & (executes[:n] < switches[:n] + 0.2 + 1e-9))
        assert ind.execute_times[0] == 5.0 and ind.rudder_angle == pytest.approx(10 * DEG)
    assert firsts[0] > firsts[1] > firsts[2] > 0
    port = js.simulate(toy, js.ZigZag(-10 * DEG, 10 * DEG, duration=400.0, dt=0.2, execute=5.0),
                       x0)
    mirrored = zigzag_indices(port, 10 * DEG)
    assert mirrored.side == -1
    np.testing.assert_allclose(mirrored.overshoots[0], firsts[0], rtol=1e-9)


def test_stop_and_pull_out_of_a_simulated_stable_ship(toy):
    x0 = js.straight_run(toy)
    stop = js.simulate(toy, js.Stop(-toy.nominal_n, duration=300.0, dt=0.5, execute=20.0), x0)
    ind = stopping_indices(stop)
    assert ind.execute_time == 20.0
    # straight crash stop of a symmetric ship: head reach = track reach (to the linear
    # interpolation over the last interval, where the ship turns back), no deviation
    np.testing.assert_allclose(ind.track_reach, ind.head_reach, rtol=1e-5)
    np.testing.assert_allclose(ind.lateral_deviation, 0.0, atol=1e-9)
    assert 0 < ind.head_reach < x0.u * ind.time_to_stop
    pulls = [js.simulate(toy, js.pull_out(s * 20 * DEG, 300.0, 1200.0, dt=1.0), x0)
             for s in (1, -1)]
    po = pull_out_indices(*pulls)
    np.testing.assert_allclose(po.release_rate_port, -po.release_rate_starboard, rtol=1e-9)
    assert po.release_rate_starboard > 0.1 * DEG
    assert abs(po.residual_rate_starboard) < 1e-3 * po.release_rate_starboard  # stable ship


def test_direct_spiral_of_a_stable_ship_has_no_loop(toy):
    x0 = js.straight_run(toy)
    traj = js.simulate(toy, js.spiral(400.0, levels=np.arange(10, 0, -2) * DEG, dt=1.0), x0)
    curve = spiral_curve(traj, hold=400.0)
    levels = np.concatenate([np.arange(10, -11, -2), np.arange(-8, 11, 2)]) * DEG
    np.testing.assert_allclose(curve.delta, levels, atol=1e-12)
    down, up = curve.r[:11], curve.r[10:]
    assert np.all(np.diff(down) < 0) and np.all(np.diff(up) > 0)  # r follows the rudder
    assert curve.loop_width == 0.0
    # both branches nearly coincide (holds of 400 s against a slowest time constant ~150 s)
    np.testing.assert_allclose(down[::-1], up, atol=0.03 * np.max(np.abs(curve.r)))


def test_mariner_cross_check_numbers():
    """Indices of the Mariner against the independent numpy/RK4 re-implementation in
    shared/reference/vessel-models.md sec. 6 (mariner.m equations, h = 0.05 s, order at
    t = 0 from a steady approach; its "internal delta = +35 deg" turn is a port turn here)."""
    vessel = js.get_vessel("mariner")
    x0 = js.straight_run(vessel)
    turn = turning_indices(js.simulate(vessel, js.Turn(-35 * DEG, duration=700.0, dt=0.1), x0,
                                       simulator=js.Simulator(substeps=2)))
    np.testing.assert_allclose(
        [turn.advance, turn.transfer, turn.tactical_diameter], [596.7, 439.6, 1070.3], atol=0.1)
    np.testing.assert_allclose(turn.steady_turning_diameter / 2, 576.0, atol=1.0)
    for angle, overshoots in ((10, [4.95, 4.47, 6.18, 4.46]), (20, [7.78, 6.32, 7.21, 6.22])):
        # the reference's convention: the rudder reversed at its first 0.05 s step after
        # the crossing
        zigzag = js.ZigZag(angle * DEG, angle * DEG, duration=500.0, dt=0.05,
                           switch_at=js.strategies.SwitchAtNextStep())
        traj = js.simulate(vessel, zigzag, x0, simulator=js.Simulator(max_step=0.05))
        ind = zigzag_indices(traj, angle * DEG)
        np.testing.assert_allclose(np.array(ind.overshoots[:4]) / DEG, overshoots, atol=0.006)
    initial = initial_turning_indices(js.simulate(vessel, js.Turn(10 * DEG, duration=60.0,
                                                                  dt=0.05), x0))
    np.testing.assert_allclose(initial.time, 30.1, atol=0.1)
    np.testing.assert_allclose(initial.distance, 231.0, atol=0.5)
    l_over_v = vessel.length / float(x0.u)
    assert round(l_over_v, 2) == 20.85
    rows = imo_criteria(vessel.length, float(x0.u), turning35=turn, initial_turning=initial)
    assert [row.passed for row in rows] == [True, False, True]  # fails the 5 L tactical diameter


def test_a_steering_models_zigzag_from_rest_is_read_from_its_first_order():
    """A steering model has no servo: run from t = 0 its rudder is at the order at the
    first sample, and the executes were read from the first reversal, half a cycle late
    (found by the audit of 2026-12-07: Nomoto 1, K = 0.05 1/s, T = 10 s, gave an initial
    turning time of 38 s and the second overshoot as the first). Against the closed
    form of T r' + r = K delta: psi = K d (t - T (1 - exp(-t/T))) to the switch, then
    r relaxes to -K d, peaking where r = 0."""
    K, T, d = 0.05, 10.0, np.radians(10.0)
    trial = js.StandardTrial.parse("zigzag:10/10")
    model = js.Nomoto1(K=K, T=T)
    manoeuvre, _ = trial.sized(model, duration=120.0, dt=0.01, time_scale=120.0 / 35)
    got = trial.indices(manoeuvre, js.simulate(model, manoeuvre, simulator=trial.simulator))
    t_s = scipy.optimize.brentq(lambda t: K * d * (t - T * (1 - np.exp(-t / T))) - d, 1, 100)
    r_s = K * d * (1 - np.exp(-t_s / T))
    rise = T * np.log((r_s + K * d) / (K * d))  # from the switch to the peak
    overshoot = -K * d * rise + T * (r_s + K * d) * (1 - np.exp(-rise / T))
    np.testing.assert_allclose(got["initial_turning_time_s"], t_s, atol=0.02)
    np.testing.assert_allclose(got["time_to_check_yaw_s"], rise, atol=0.02)
    np.testing.assert_allclose(np.radians(got["overshoot_1_deg"]), overshoot, rtol=2e-3)
