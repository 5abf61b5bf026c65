"""The shared contract, run over registries of every vessel, steering model, effect and
controller: vmap equals a Python loop, forward-mode derivatives equal finite
differences, new parameter values do not retrace, an effect at zero equals its base
bit for bit, and a controller's state travels in the simulated state (so the closed
loop is differentiable and vmappable over its gains)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_equal_to_rounding, per_sample

import jaxship as js
from jaxship._foundation._contract import get_path, rebuild
from jaxship._foundation._params import default_free
from jaxship._models._steering._base import WindowStart


FOH = js.strategies.FirstOrderHold()  # the replayed rudder linear between samples


DEG = np.pi / 180
VESSELS = sorted(js.VESSELS)
STEERING = {
    "nomoto1": js.Nomoto1(K=0.06, T=25.0),
    "nomoto2": js.Nomoto2(K=0.06, T1=25.0, T2=3.0, T3=5.0),
    "nonlinear_nomoto": js.NonlinearNomoto(K=0.06, T=25.0, n3=300.0),
    "nonlinear_nomoto2": js.effects.nonlinear_nomoto2(K=0.06, T1=25.0, T2=3.0, T3=5.0, beta1=100.0),
    "ross_autopilot": js.RossAutopilot(length=4.0, speed=1.5, rate=8.0, n_ur=-4.0,
                                       n_delta=2.5, n_uv=-1.0),
    "linear_sway_yaw": js.LinearSwayYaw.from_vessel(js.get_vessel("sea_stratus_linear")),
    "norrbin_crossflow": js.NorrbinCrossFlow.from_vessel(js.get_vessel("sea_stratus_nonlinear")),
    "low_speed_sway_yaw": js.LowSpeedSwayYaw(),
}


@pytest.mark.parametrize("name", sorted(STEERING) + VESSELS)
def test_every_model_meets_the_contract_through_its_base(name):
    """Every vessel preset and steering model is a `jaxship.AbstractModel`: its replay
    state and field give a derivative of the state's shape, its outputs psi and r have
    a place, and its default free parameters resolve and rebuild it."""
    model = STEERING[name] if name in STEERING else js.get_vessel(name)
    assert isinstance(model, js.AbstractModel)
    aux = js.AuxInputs(u=1.0, v=0.0, n=1.0)
    start = WindowStart(r=0.01, psi=0.1, delta=0.05, r_first=0.0, psi_first=0.0,
                        delta_integral=0.0, elapsed=0.0, aux=aux, rudder_angle=0.05)
    y = model.replay_state(start)
    inputs = {"delta": 0.05, "u": 1.0, "v": 0.0, "n": 1.0}
    dy = model.replay_field()(0.0, y, inputs)
    assert dy.shape == y.shape and bool(jnp.all(jnp.isfinite(dy)))
    for channel in model.default_channels:
        assert 0 <= model.channel_index(channel) < y.shape[0]
    assert float(y[model.channel_index("psi")]) == 0.1
    free = default_free(model)
    values = [2.0 * float(get_path(model, n)) + 1.0 for n in free]
    rebuilt = rebuild(model, free, values)
    assert [float(get_path(rebuilt, n)) for n in free] == pytest.approx(values)


# effect, a parameter name, a non-zero value of realistic size for the Mariner and
# Nomoto 1 (K = 0.06 1/s, T = 25 s) -- one number, or one per family where the units
# differ -- and the families it acts on
U0 = 7.7175  # the Mariner's nominal speed [m/s]
EFFECTS = {
    "rudder_offset": (js.effects.RudderOffset(), "delta0", 0.02, ("vessel", "steering")),
    "yaw_moment_bias": (js.effects.YawMomentBias(), "n0", 1e-4, ("steering",)),
    "sway_force_bias": (js.effects.SwayForceBias(), "y0", 1e4, ("vessel",)),
    "yaw_rate_sensor_bias": (js.effects.YawRateSensorBias(), "bias", 1e-3, ("vessel", "steering")),
    "heading_sensor_bias": (js.effects.HeadingSensorBias(), "bias", 0.01, ("vessel", "steering")),
    "yaw_cubic_damping": (js.effects.YawCubicDamping(), "beta",
                          {"vessel": 2e12, "steering": 300.0}, ("vessel", "steering")),
    "rudder_lag": (js.effects.RudderLag(), "time_constant", 2.0, ("vessel", "steering")),
    "rudder_delay": (js.effects.RudderDelay(), "delay", 1.5, ("vessel", "steering")),
    "rudder_rate_limit": (js.effects.RudderRateLimit(), "inverse_rate", 60.0,
                          ("vessel", "steering")),
    "yaw_quadratic_damping": (js.effects.YawQuadraticDamping(), "beta",
                              {"vessel": 4e10, "steering": 10.0}, ("vessel", "steering")),
    "crossflow_drag": (js.effects.CrossflowDrag(), "coefficient", 0.04, ("vessel",)),
    "speed_dependent_rudder": (js.effects.SpeedDependentRudder(nominal_speed=U0), "kappa", 0.5,
                               ("vessel", "steering")),
    "speed_dependent_damping": (js.effects.SpeedDependentDamping(nominal_speed=U0), "kappa", 1.0,
                                ("steering",)),
    "rudder_stall": (js.effects.RudderStall(), "c", 0.3, ("vessel", "steering")),
    "propeller_asymmetry": (js.effects.PropellerAsymmetry(), "moment",
                            {"vessel": 1.4e6, "steering": 2.6e-4}, ("vessel", "steering")),
    "propeller_race": (js.effects.PropellerRace(), "gain", 2e-4, ("steering",)),
    "surge_turn_resistance": (js.effects.SurgeTurnResistance(), "x_vr", 0.004, ("vessel",)),
    "added_mass_error": (js.effects.AddedMassError(), "s_r", 0.2, ("vessel",)),
    "current": (js.effects.UniformCurrent(), "north", 0.5, ("vessel",)),
    "wind": (js.effects.Windage(), "lateral_area", 2000.0, ("vessel",)),
}
# what some effects need to show beyond a calm-water zig-zag of the Mariner from its
# straight run (or Nomoto 1 without auxiliary inputs): wind (replayed as logged wind,
# `PredictionError(wind=True)`), a propeller rate [rev/s] (the Mariner has none), the
# measured u and n of a steering model, or the track (a current leaves the
# through-water u, v, r, psi unchanged)
_T = np.arange(200) * 0.5
SHOWN_BY = {
    "wind": {"environment": js.Environment(wind=js.Wind(15.0, np.deg2rad(60.0)))},
    "current": {"track": True},
    "propeller_asymmetry": {"n": 1.5, "aux": {"n": 2.0 + 0.0 * _T}},
    "propeller_race": {"aux": {"n": 2.0 + 0.0 * _T}},
    "speed_dependent_rudder": {"aux": {"u": U0 * (0.85 + 0.15 * np.cos(2 * np.pi * _T / 80))}},
    "speed_dependent_damping": {"aux": {"u": U0 * (0.85 + 0.15 * np.cos(2 * np.pi * _T / 80))}},
}
CONTROLLERS = {
    "turn": js.Turn(15 * DEG, duration=40.0, dt=0.5),
    "zigzag": js.ZigZag(10 * DEG, 2 * DEG, duration=40.0, dt=0.5),
    "schedule": js.multi_step_3211(10 * DEG, 3.0, settle=10.0, dt=0.5),
    "reverse_spiral": js.ReverseSpiral(rates=np.array([0.002, -0.002]), hold=20.0, kp=0.5,
                                       kd=20.0, duration=40.0, dt=0.5),
    "heading_perturbations": js.heading_perturbations(5 * DEG, 30.0, kp=2.0, ki=0.01, kd=20.0,
                                             duration=40.0, dt=0.5),
    "stop": js.Stop(-0.5, duration=40.0, dt=0.5),
    "heading_autopilot": js.Controlled(
        js.design_autopilot(js.Nomoto1(K=0.06, T=40.0), natural_frequency=0.05,
                            steps=js.HeadingSteps((5.0,), (10 * DEG,))),
        duration=40.0, dt=0.5),
}


def short_run(vessel):
    return js.ZigZag(15 * DEG, 5 * DEG, duration=10 * float(vessel.length / vessel.nominal_speed),
                     dt=0.5)


def vessel_final(vessel, name, manoeuvre=None):
    """psi at the end of a short zig-zag as a function of the coefficient `name`."""
    x0 = js.straight_run(vessel)
    man = short_run(vessel) if manoeuvre is None else manoeuvre
    return lambda p: js.simulate(rebuild(vessel, (name,), (p,)), man, x0).state.psi[-1]


def check_contract(f, p0, *, eps, rtol, atol):
    """vmap equals a loop, the forward derivative equals a central difference of
    relative step `eps`, and new values do not retrace: the loop and the difference run
    through one jitted `f` that may be traced once (one compilation for all five
    calls; the arguments are float64 arrays, never weakly typed Python floats)."""
    jitted = jax.jit(eqx.debug.assert_max_traces(f, max_traces=1))
    call = lambda p: jitted(jnp.asarray(p, float))
    values = p0 * jnp.array([0.9, 1.0, 1.1])
    np.testing.assert_allclose(jax.vmap(f)(values), jnp.stack([call(v) for v in values]),
                               rtol=1e-10, atol=1e-12)
    h = eps * abs(p0)
    fd = (call(p0 + h) - call(p0 - h)) / (2 * h)
    fwd = jax.jvp(f, (jnp.asarray(p0),), (jnp.asarray(1.0),))[1]
    np.testing.assert_allclose(fwd, fd, rtol=rtol, atol=atol)


@pytest.mark.parametrize("name", VESSELS)
def test_vessel_contract(name):
    vessel = js.get_vessel(name)
    coefficient = default_free(vessel)[0]
    p0 = float(get_path(vessel, coefficient))
    # a relative step of 1e-7: the zig-zag's rudder reverses at the heading crossing inside
    # its control step, so psi is continuous in the coefficients, its slope jumping by
    # up to 0.5 % where the crossing or the servo's end of saturation passes a step
    # boundary (measured on sea_stratus_linear: one within 1e-6 of the preset's y_v);
    # the central difference must see one piece
    check_contract(vessel_final(vessel, coefficient), p0, eps=1e-7, rtol=1e-4, atol=1e-9)


def steering_final(model, name):
    delta = np.deg2rad(10) * np.sign(np.sin(2 * np.pi * np.arange(120) / 60.0) + 1e-9)
    aux = js.AuxInputs(u=1.5, v=0.05, n=8.0)
    return lambda p: js.simulate(rebuild(model, (name,), (p,)),
                                 js.Replay(delta, dt=0.5, delta_hold=FOH), aux=aux,
                                 simulator=per_sample()).state.psi[-1]


@pytest.mark.parametrize("name", sorted(STEERING))
def test_steering_model_contract(name):
    model = STEERING[name]
    parameter = next(n for n in default_free(model) if float(get_path(model, n)) != 0.0)
    p0 = float(get_path(model, parameter))
    check_contract(steering_final(model, parameter), p0, eps=1e-6, rtol=1e-5, atol=1e-10)


def _with_wind(data, environment):
    """`data` with the wind of `environment` as logged true wind."""
    wind = environment.wind
    return js.Experiment(data.t, data.delta, psi=data.psi, r=data.r, u=data.u, v=data.v,
                         x=data.x, y=data.y, n=data.n, delta_c=data.delta_c,
                         wind_speed=np.full(data.t.shape, float(wind.speed)),
                         wind_dir=np.full(data.t.shape, float(wind.direction)))


@pytest.mark.parametrize("effect", sorted(EFFECTS))
def test_effect_contract(effect):
    """At zero the augmented model equals the base (to rounding); a non-zero value changes
    it; the parameter is named "<id>.<field>", free by default and differentiable."""
    zero, field, values, families = EFFECTS[effect]
    shown = SHOWN_BY.get(effect, {})
    value = lambda family: values[family] if isinstance(values, dict) else values
    name = f"{effect}.{field}"
    assert zero.id == effect
    if "vessel" in families:
        vessel = js.get_vessel("mariner")
        environment = shown.get("environment", js.Environment())
        man = short_run(vessel)
        x0 = js.straight_state(vessel.nominal_speed, shown["n"]) if "n" in shown else \
            js.straight_run(vessel)
        base = js.simulate(vessel, man, x0, environment=environment)
        augmented = js.augment(vessel, zero)
        same = js.simulate(augmented, man, x0, environment=environment)
        for key in ("u", "v", "r", "x", "y", "psi", "delta"):
            assert_equal_to_rounding(getattr(same.state, key), getattr(base.state, key))
        assert name in default_free(augmented)
        moved = rebuild(augmented, (name,), (value("vessel"),))
        truth = js.simulate(moved, man, x0, environment=environment)
        if shown.get("track"):  # through-water velocities: only the track moves
            assert np.max(np.abs(truth.state.x - base.state.x)) > 1.0
        else:
            data = js.Experiment.from_trajectory(truth)
            wind = "environment" in shown
            data = _with_wind(data, environment) if wind else data
            plain = js.predict(augmented, data,
                               estimator=js.PredictionError(horizon=None, wind=wind))
            assert plain.fit_percent()["psi"] < 100 - 1e-6  # the effect shows in the data
    if "steering" in families:
        model = js.Nomoto1(K=0.06, T=25.0)
        delta = np.deg2rad(10) * np.sign(np.sin(2 * np.pi * np.arange(200) / 80.0) + 1e-9)
        measured = shown.get("aux", {})
        aux = js.AuxInputs(**measured)
        base = js.simulate(model, js.Replay(delta, dt=0.5, delta_hold=FOH), aux=aux,
                           simulator=per_sample())
        augmented = js.augment(model, zero)
        same = js.simulate(augmented, js.Replay(delta, dt=0.5, delta_hold=FOH), aux=aux,
                           simulator=per_sample())
        assert_equal_to_rounding(same.state.psi, base.state.psi)
        assert_equal_to_rounding(same.state.r, base.state.r)
        data = js.Experiment(np.asarray(base.t), delta, psi=np.asarray(base.state.psi),
                             r=np.asarray(base.state.r), **measured)

        def cost(p):
            m = rebuild(augmented, (name,), (p,))
            out = js.predict(m, data, estimator=js.PredictionError(horizon=None))
            return sum(float(np.sum(v**2)) for v in out.predictions.values())

        moved = rebuild(augmented, (name,), (value("steering"),))
        reading = moved.measure("psi", 0.0) != 0.0 or moved.measure("r", 0.0) != 0.0
        # a sensor bias shows in the readings; it cancels in predictions that start from
        # the measured state (a heading bias is not identifiable from psi alone)
        assert reading or cost(value("steering")) != cost(0.0)


@pytest.mark.parametrize("name", sorted(CONTROLLERS))
def test_controller_contract(name):
    """The controller's memory is part of the simulated state: its closed loop under vmap
    over the approach speed equals a loop, and the final heading is differentiable
    (forward mode equals finite differences) in a vessel coefficient through it."""
    vessel = js.get_vessel("mariner")
    man = CONTROLLERS[name]
    speeds = jnp.array([6.0, 7.7175])
    batched = js.simulate_batch(vessel, man, js.straight_state(speeds, 0.0),
                                in_axes=(None, None, 0, None))
    for i, u in enumerate(speeds):
        single = js.simulate(vessel, man, js.straight_state(u, 0.0))
        np.testing.assert_allclose(batched.state.psi[i], single.state.psi, rtol=1e-10,
                                   atol=1e-12)
    f = vessel_final(vessel, "n_r", man)
    p0 = float(vessel.n_r)
    eps = 1e-5 * abs(p0)
    fd = (f(p0 + eps) - f(p0 - eps)) / (2 * eps)
    fwd = jax.jvp(f, (jnp.asarray(p0),), (jnp.asarray(1.0),))[1]
    np.testing.assert_allclose(fwd, fd, rtol=1e-3, atol=1e-9)


def test_controller_gains_are_differentiable_and_vmappable():
    vessel = js.get_vessel("mariner")
    x0 = js.straight_run(vessel)

    def final_error(kp):
        pilot = js.heading_perturbations(5 * DEG, 120.0, kp=kp, ki=0.0, kd=30.0, duration=60.0,
                                    dt=0.5)
        return js.simulate(vessel, pilot, x0).state.psi[-1] - 5 * DEG

    gains = jnp.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(jax.vmap(final_error)(gains),
                               jnp.stack([final_error(k) for k in gains]), rtol=1e-10)
    fd = (final_error(2.0 + 1e-5) - final_error(2.0 - 1e-5)) / 2e-5
    np.testing.assert_allclose(jax.grad(final_error)(2.0), fd, rtol=1e-4)


class CourseKeeper(js.AbstractController):
    """A user-written PD heading controller with an integrator in its memory: the seam
    a designed autopilot plugs into."""

    target: float
    kp: float
    kd: float
    ki: float = 0.0

    def init(self, x0):
        return (x0.n, jnp.zeros_like(jnp.asarray(x0.psi, dtype=float)))

    def command(self, t, state, memory, h):
        n0, integral = memory
        error = self.target - state.psi
        integral = integral + error * h
        delta = jnp.clip(self.kp * error + self.ki * integral - self.kd * state.r,
                         -35 * DEG, 35 * DEG)
        return js.Command(delta, n0), (n0, integral)


def test_user_controller_runs_at_the_control_step_with_its_memory_in_the_state():
    """A controller outside the library: the heading settles on the target whatever the
    output interval; its integrator travels in the state (the result with dt = 2 s
    equals the dt = 0.5 s run at the common samples); gains vmap and differentiate."""
    vessel = js.get_vessel("mariner")
    x0 = js.straight_run(vessel)
    pilot = CourseKeeper(target=10 * DEG, kp=2.0, kd=40.0, ki=0.002)
    fine = js.simulate(vessel, js.Controlled(pilot, duration=400.0, dt=0.5), x0)
    coarse = js.simulate(vessel, js.Controlled(pilot, duration=400.0, dt=2.0), x0)
    np.testing.assert_allclose(coarse.state.psi, fine.state.psi[::4], rtol=1e-10, atol=1e-12)
    assert abs(float(fine.state.psi[-1]) - 10 * DEG) < 1.0 * DEG

    def settle(kd):
        man = js.Controlled(CourseKeeper(target=10 * DEG, kp=2.0, kd=kd), duration=200.0,
                            dt=1.0)
        return jnp.sum((js.simulate(vessel, man, x0).state.psi - 10 * DEG) ** 2)

    gains = jnp.array([30.0, 40.0, 50.0])
    np.testing.assert_allclose(jax.vmap(settle)(gains), jnp.stack([settle(k) for k in gains]),
                               rtol=1e-10)
    fd = (settle(40.0 + 1e-4) - settle(40.0 - 1e-4)) / 2e-4
    np.testing.assert_allclose(jax.grad(settle)(40.0), fd, rtol=1e-4)
