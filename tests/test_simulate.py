"""Core simulator: invariants, numerics, batching, gradients and tracing."""

import math

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import central_difference, linear_test_vessel, tree_allclose

import jaxship as js


AT_SAMPLES = js.Simulator(max_step=math.inf)  # one step per output sample
ADAPTIVE = js.Simulator(dfx.Tsit5(), stepsize_controller=dfx.PIDController(rtol=1e-8, atol=1e-8))
DEG = np.pi / 180


@pytest.fixture(scope="module")
def vessel():
    return linear_test_vessel()


@pytest.fixture(scope="module")
def x0(vessel):
    return js.straight_run(vessel)


def test_straight_run_is_equilibrium(vessel, x0):
    tau = vessel.forces(x0.u, x0.v, x0.r, x0.delta, x0.n)
    np.testing.assert_allclose(tau, 0.0, atol=1e-6)
    # solving for speed at the found rate gives the speed back
    again = js.straight_run(vessel, n=x0.n)
    np.testing.assert_allclose(again.u, vessel.nominal_speed, rtol=1e-12)


def test_zero_rudder_keeps_straight_course(vessel, x0):
    traj = js.simulate(vessel, js.Turn(0.0, duration=300.0), x0)
    assert traj.success
    np.testing.assert_allclose(traj.state.r, 0.0, atol=1e-14)
    np.testing.assert_allclose(traj.state.y, 0.0, atol=1e-10)
    np.testing.assert_allclose(traj.state.x[-1], 300.0 * x0.u, rtol=1e-10)


def test_mirror_symmetry(vessel, x0):
    stbd = js.simulate(vessel, js.ZigZag(20 * DEG, 20 * DEG, duration=400.0), x0)
    port = js.simulate(vessel, js.ZigZag(-20 * DEG, 20 * DEG, duration=400.0), x0)
    for name, sign in dict(u=1, v=-1, r=-1, x=1, y=-1, psi=-1, delta=-1).items():
        np.testing.assert_allclose(
            getattr(port.state, name), sign * getattr(stbd.state, name), atol=1e-9, err_msg=name
        )


def test_steady_turn_is_reached(vessel, x0):
    traj = js.simulate(vessel, js.Turn(20 * DEG, duration=1500.0, dt=0.5), x0)
    r = traj.state.r
    assert r[-1] > 0
    # the last 200 s: yaw rate and speed constant to 1e-6 relative
    tail = traj.t > traj.t[-1] - 200
    assert np.ptp(r[tail]) < 1e-6 * abs(r[-1])
    assert np.ptp(traj.speed[tail]) < 1e-6 * traj.speed[-1]
    assert traj.speed[-1] < x0.u  # speed loss in the turn


def test_kinetic_energy_decays_without_thrust(vessel):
    """With n = 0 and rudder midships, hull damping only removes energy (C(nu) is skew)."""
    start = js.ShipState(u=6.0, v=0.5, r=0.01, x=0.0, y=0.0, psi=0.0, delta=0.0, n=0.0)
    traj = js.simulate(
        vessel, js.Turn(0.0, duration=300.0, n=0.0), start, simulator=js.Simulator(substeps=4)
    )
    nu = jnp.stack([traj.state.u, traj.state.v, traj.state.r])
    energy = 0.5 * jnp.einsum("it,ij,jt->t", nu, vessel.mass_matrix(), nu)
    assert np.all(np.diff(energy) <= 1e-9 * energy[0])
    assert energy[-1] < 0.5 * energy[0]


def test_fixed_step_converges_to_adaptive(vessel, x0):
    man = js.Turn(20 * DEG, duration=300.0, dt=1.0)  # open loop: the same input for all
    exact = js.simulate(vessel, man, x0, simulator=ADAPTIVE)
    assert exact.success
    errors = []
    for substeps in (1, 2, 4):
        fixed = js.simulate(vessel, man, x0,
                            simulator=js.Simulator(max_step=math.inf, substeps=substeps))
        errors.append(float(jnp.max(jnp.abs(fixed.state.psi - exact.state.psi))))
    assert errors[-1] < 1e-6
    # fourth order: halving the step cuts the error by about 16
    assert errors[0] / errors[1] > 10 and errors[1] / errors[2] > 10


def test_diffrax_fixed_step_matches_fast_path(vessel, x0):
    man = js.Turn(35 * DEG, duration=100.0)
    fast = js.simulate(vessel, man, x0)
    slow = js.simulate(
        vessel,
        man,
        x0,
        simulator=js.Simulator(dfx.Tsit5(), stepsize_controller=dfx.ConstantStepSize()),
    )
    np.testing.assert_allclose(fast.state.psi, slow.state.psi, rtol=1e-7, atol=1e-9)


def test_vmap_equals_loop(vessel, x0):
    angles = jnp.array([5.0, -10.0, 20.0]) * DEG
    rates = jnp.array([1.0, 1.5, 2.0])
    batch = eqx.filter_vmap(
        lambda a, n: js.simulate(vessel, js.ZigZag(a, 10 * DEG, duration=200.0, n=n), x0)
    )(angles, rates)
    for i in range(3):
        single = js.simulate(vessel, js.ZigZag(angles[i], 10 * DEG, duration=200.0, n=rates[i]), x0)
        assert tree_allclose(jax.tree.map(lambda a: a[i], batch), single, rtol=1e-12, atol=1e-12)


def test_vmap_over_parameters_and_initial_states(vessel, x0):
    nr = jnp.array([-0.0015, -0.002])
    vessels = eqx.filter_vmap(lambda v: eqx.tree_at(lambda s: s.nr, vessel, v))(nr)
    starts = eqx.filter_vmap(lambda u: js.straight_state(u, x0.n))(jnp.array([6.0, 7.0]))
    man = js.Turn(20 * DEG, duration=100.0)
    batch = eqx.filter_vmap(lambda v, s: js.simulate(v, man, s))(vessels, starts)
    single = js.simulate(
        eqx.tree_at(lambda s: s.nr, vessel, -0.002),
        man,
        starts.__class__(
            **{k: getattr(starts, k)[1] for k in ("u", "v", "r", "x", "y", "psi", "delta", "n")}
        ),
    )
    np.testing.assert_allclose(batch.state.r[1], single.state.r, rtol=1e-12)


def test_padded_batch_marks_valid_samples(vessel, x0):
    short = js.Turn(10 * DEG, duration=50.0, num_samples=1001)
    long = js.Turn(10 * DEG, duration=100.0)
    assert short.num_samples == long.num_samples == 1001
    stacked = jax.tree.map(lambda a, b: jnp.stack([a, b]), short, long)
    # under vmap the sample interval is traced: one step per sample, or say so
    both = eqx.filter_vmap(lambda m: js.simulate(vessel, m, x0, simulator=AT_SAMPLES))(stacked)
    assert int(both.valid[0].sum()) == 501 and bool(both.valid[1].all())
    with pytest.raises(ValueError, match="simulate_batch"):
        eqx.filter_vmap(lambda m: js.simulate(vessel, m, x0))(stacked)
    batch = js.simulate_batch(vessel, stacked, x0, in_axes=(None, 0, None, None))
    np.testing.assert_array_equal(batch.valid, both.valid)


def _final_heading(vessel, x0, simulator):
    def f(nr):
        v = eqx.tree_at(lambda s: s.nr, vessel, nr)
        return js.simulate(
            v, js.Turn(20 * DEG, duration=60.0, dt=0.5), x0, simulator=simulator
        ).state.psi[-1]

    return f


@pytest.mark.parametrize(
    "simulator",
    [js.Simulator(substeps=2),
     js.Simulator(dfx.Tsit5(), stepsize_controller=dfx.PIDController(rtol=1e-8, atol=1e-8),
                  adjoint=dfx.ForwardMode())],
    ids=["rk4-scan", "diffrax-forward"],
)
def test_forward_gradient_matches_finite_difference(vessel, x0, simulator):
    f = _final_heading(vessel, x0, simulator)
    nr = jnp.asarray(vessel.nr)
    _, tangent = jax.jvp(f, (nr,), (jnp.ones_like(nr),))
    fd = central_difference(f, nr, eps=1e-7)
    np.testing.assert_allclose(tangent, fd, rtol=1e-5)


@pytest.mark.parametrize(
    "simulator", [js.Simulator(substeps=2), ADAPTIVE], ids=["rk4-scan", "diffrax"]
)
def test_reverse_gradient_matches_finite_difference(vessel, x0, simulator):
    f = _final_heading(vessel, x0, simulator)
    nr = jnp.asarray(vessel.nr)
    fd = central_difference(f, nr, eps=1e-7)
    np.testing.assert_allclose(jax.grad(f)(nr), fd, rtol=1e-5)


def test_new_parameter_values_do_not_retrace(vessel, x0):
    from jaxship._simulation._simulate import _as_arrays, _simulate

    man = js.Turn(10 * DEG, duration=20.0)
    counted = eqx.debug.assert_max_traces(_simulate.__wrapped__, max_traces=1)
    jitted = eqx.filter_jit(counted)
    for nr, angle in [(-0.0016, 10.0), (-0.0020, 25.0), (-0.0030, -5.0)]:
        v = eqx.tree_at(lambda s: s.nr, vessel, nr)
        m = eqx.tree_at(lambda s: s.angle, man, angle * DEG)
        jitted(*_as_arrays((v, m, x0, js.Environment())), js.Simulator(), 1)


def test_python_floats_do_not_retrace(vessel, x0):
    """Plain-float parameters are traced by `simulate`: the jit cache does not grow."""
    from jaxship._simulation._simulate import _simulate

    js.simulate(vessel, js.Turn(10 * DEG, duration=20.0), x0)
    size = _simulate._cached._cache_size()
    js.simulate(vessel, js.Turn(11 * DEG, duration=20.0), x0)
    js.simulate(eqx.tree_at(lambda s: s.mass, vessel, 1.8e7), js.Turn(12 * DEG, duration=20.0), x0)
    assert _simulate._cached._cache_size() == size


def test_current_drifts_the_track_only(vessel, x0):
    current = js.Environment(current=js.Current(speed=1.0, direction=np.pi / 2))
    calm = js.simulate(vessel, js.Turn(15 * DEG, duration=200.0), x0)
    drift = js.simulate(vessel, js.Turn(15 * DEG, duration=200.0), x0, environment=current)
    np.testing.assert_allclose(drift.state.r, calm.state.r, rtol=1e-12)
    np.testing.assert_allclose(drift.state.y - calm.state.y, drift.t * 1.0, atol=1e-8)
    np.testing.assert_allclose(drift.state.x, calm.state.x, atol=1e-8)


def test_beam_wind_pushes_to_leeward(vessel, x0):
    """Wind from starboard (from east at heading north) drifts the ship to port (west)."""
    wind = js.Environment(wind=js.Wind(speed=20.0, direction=np.pi / 2))
    traj = js.simulate(vessel, js.Turn(0.0, duration=60.0), x0, environment=wind)
    assert traj.state.v[-1] < 0 and traj.state.y[-1] < 0
    head = js.Environment(wind=js.Wind(speed=20.0, direction=0.0))
    slowed = js.simulate(vessel, js.Turn(0.0, duration=60.0), x0, environment=head)
    assert slowed.state.u[-1] < x0.u
    np.testing.assert_allclose(slowed.state.r, 0.0, atol=1e-14)


def test_replay_reproduces_closed_loop_run(vessel, x0):
    # reversed at a 0.1 s control step (not inside one): the commands at the 0.1 s
    # samples are all it ordered
    closed = js.simulate(vessel, js.ZigZag(10 * DEG, 10 * DEG, duration=200.0,
                                           switch_at=js.strategies.SwitchAtNearestStep()), x0)
    replay = js.Replay(closed.command.delta, closed.command.n, dt=0.1)
    opened = js.simulate(vessel, replay, x0)
    np.testing.assert_allclose(opened.state.psi, closed.state.psi, atol=1e-12)


def test_blow_up_is_reported(vessel):
    bad = eqx.tree_at(lambda s: s.resistance, vessel, -1e9)  # negative resistance: runaway
    traj = js.simulate(bad, js.Turn(0.0, duration=200.0), js.straight_state(7.7, 1.5))
    assert not bool(traj.success)
    assert bool(traj.result == js.RESULTS.simulation_blew_up)
    with pytest.raises(Exception, match="the simulation blew up"):
        js.simulate(bad, js.Turn(0.0, duration=200.0), js.straight_state(7.7, 1.5), throw=True)
    good = js.simulate(vessel, js.Turn(0.0, duration=20.0), throw=True)
    assert bool(good.result == js.RESULTS.successful) and bool(good.success)


def test_the_solvers_code_passes_through():
    """Issue 59: `Simulator.step` passed diffrax's result on as a bool. An adaptive solver
    allowed 2 steps per control step (of a whole 1 s sample) cannot finish one at a
    tolerance of 1e-12: the trajectory carries diffrax's own code, `max_steps_reached`,
    not `simulation_blew_up` or a bare False."""
    model = js.Nomoto1(K=0.06, T=25.0)
    tight = js.Simulator(solver=dfx.Tsit5(), stepsize_controller=dfx.PIDController(
        rtol=1e-12, atol=1e-12), max_steps=2, max_step=math.inf)
    traj = js.simulate(model, js.ZigZag(10 * DEG, 10 * DEG, duration=60.0, dt=1.0),
                       simulator=tight)
    assert bool(traj.result == js.RESULTS.max_steps_reached) and not bool(traj.success)
