"""jaxship's Levenberg-Marquardt (MINPACK's cost test on top of optimistix's) and the
stored-Jacobian residuals of `jaxship/_estimate/_lm.py`."""

import equinox as eqx
import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
import optimistix as optx
import pytest
from helpers import assert_equal_to_rounding

from jaxship import LevenbergMarquardt
from jaxship._estimate._lm import (
    BlockDampedNewtonDescent,
    NielsenDamping,
    solve_least_squares,
    stored_jacobian,
)


T = jnp.linspace(0.0, 10.0, 200)
# two decaying exponentials with noise: a nonzero-residual problem whose last
# parameter digits settle slowly (an ill-conditioned sum of exponentials)
DATA = (2.0 * jnp.exp(-0.3 * T) + 0.5 * jnp.exp(-1.7 * T)
        + 0.01 * np.random.default_rng(0).standard_normal(200))
Z0 = jnp.array([1.0, 0.5, 1.0, 1.0])


def residuals(z, args):
    a, b, c, d = z
    return a * jnp.exp(-b * T) + c * jnp.exp(-d * T) - DATA


def solve(solver):
    sol = optx.least_squares(residuals, solver, Z0, max_steps=1000, throw=False)
    r = residuals(sol.value, None)
    return sol, 0.5 * float(r @ r)


def test_ftol_zero_with_the_classical_trust_region_is_optimistix_levenberg_marquardt():
    """The cost test adds nothing at ftol=0: with optimistix's own damping rule in place
    of Nielsen's, the solver is optimistix's, step for step."""
    ref, cost_ref = solve(optx.LevenbergMarquardt(rtol=1e-12, atol=1e-12))
    classical = eqx.tree_at(lambda s: s.search,
                            LevenbergMarquardt(rtol=1e-12, atol=1e-12, ftol=0.0),
                            optx.ClassicalTrustRegion())
    sol, cost = solve(classical)
    assert int(sol.stats["num_steps"]) == int(ref.stats["num_steps"])
    np.testing.assert_array_equal(sol.value, ref.value)
    assert cost == cost_ref


def test_nielsens_damping_reaches_the_same_cost_in_fewer_steps():
    """On the sum of exponentials, from the same start: the classical trust region and
    Nielsen's damping update (the default) end at the same cost, Nielsen's in fewer
    steps; a step that is not finite is rejected and the damping raised."""
    classical = eqx.tree_at(lambda s: s.search, LevenbergMarquardt(rtol=1e-12, atol=1e-12),
                            optx.ClassicalTrustRegion())
    ref, cost_ref = solve(classical)
    sol, cost = solve(LevenbergMarquardt(rtol=1e-12, atol=1e-12))
    assert isinstance(LevenbergMarquardt(rtol=1e-9, atol=1e-9).search, NielsenDamping)
    assert sol.result == optx.RESULTS.successful
    assert int(sol.stats["num_steps"]) < int(ref.stats["num_steps"])
    assert abs(cost - cost_ref) <= 1e-9 * cost_ref
    damping = NielsenDamping()
    state = damping.init(Z0, None)
    info = optx.FunctionInfo.ResidualJac(residuals(Z0, None),
                                         lx.MatrixLinearOperator(jax.jacfwd(residuals)(Z0, None)))
    bad = optx.FunctionInfo.Residual(jnp.full(T.shape, jnp.nan))
    step, accept, _, after = damping.step(jnp.array(False), Z0, Z0 + 0.1, info, bad, state)
    assert not accept and float(step) == 0.5 and float(after.nu) == 4.0


def test_cost_test_stops_earlier_at_the_same_cost():
    """With tight parameter tolerances optimistix keeps stepping after the cost has
    settled; the cost test stops sooner, at a cost equal to 1e-9 relative."""
    ref, cost_ref = solve(optx.LevenbergMarquardt(rtol=1e-12, atol=1e-12))
    sol, cost = solve(LevenbergMarquardt(rtol=1e-12, atol=1e-12, ftol=1e-10))
    assert sol.result == optx.RESULTS.successful
    assert int(sol.stats["num_steps"]) < int(ref.stats["num_steps"])
    assert abs(cost - cost_ref) <= 1e-9 * cost_ref
    # a loose ftol stops earlier still, and the cost shows it
    loose, cost_loose = solve(LevenbergMarquardt(rtol=1e-12, atol=1e-12, ftol=1e-3))
    assert int(loose.stats["num_steps"]) < int(sol.stats["num_steps"])
    assert cost_loose > cost_ref * (1 + 1e-9)


# Meyer's function (More, Garbow & Hillstrom 1981, problem 10): a curved, badly scaled
# valley that Levenberg-Marquardt follows in many short steps; minimum cost 87.9458 / 2
MEYER_T = 45.0 + 5.0 * jnp.arange(16.0)
MEYER_Y = jnp.array([34780.0, 28610, 23650, 19630, 16370, 13720, 11540, 9744, 8261, 7030,
                     6005, 5147, 4427, 3820, 3307, 2872])


def meyer(z, args):
    return z[0] * jnp.exp(z[1] / (MEYER_T + z[2])) - MEYER_Y


def test_geodesic_acceleration_follows_a_curved_valley_in_fewer_steps():
    """With geodesic acceleration (`geodesic=True`) the solver reaches Meyer's minimum in
    fewer than half the steps it takes without (measured 45 against 164)."""
    z0 = jnp.array([0.02, 4000.0, 250.0])
    out = []
    for geodesic in (False, True):
        solver = LevenbergMarquardt(rtol=1e-10, atol=1e-10, geodesic=geodesic)
        sol = optx.least_squares(meyer, solver, z0, max_steps=1000, throw=False)
        r = meyer(sol.value, None)
        assert sol.result == optx.RESULTS.successful
        out.append((int(sol.stats["num_steps"]), 0.5 * float(r @ r)))
    (plain, cost_plain), (geodesic, cost) = out
    assert 2 * geodesic < plain
    assert abs(cost - 87.9458 / 2) < 1e-4 and abs(cost - cost_plain) <= 1e-9 * cost_plain


def test_geodesic_acceleration_is_nothing_on_a_linear_problem():
    """For linear residuals the second directional derivative is zero: the accelerated
    solver takes the plain solver's steps."""
    A = jnp.asarray(np.random.default_rng(2).standard_normal((30, 4)))
    b = jnp.arange(30.0)
    linear = lambda z, args: A @ z - b
    sols = [optx.least_squares(linear, LevenbergMarquardt(rtol=1e-12, atol=1e-12,
                                                          geodesic=g), Z0, throw=False)
            for g in (False, True)]
    assert int(sols[0].stats["num_steps"]) == int(sols[1].stats["num_steps"])
    np.testing.assert_allclose(sols[1].value, sols[0].value, rtol=1e-10)
    np.testing.assert_allclose(sols[1].value, jnp.linalg.lstsq(A, b)[0], rtol=1e-8)


def test_negative_ftol_raises():
    with pytest.raises(ValueError, match="ftol"):
        LevenbergMarquardt(rtol=1e-9, atol=1e-9, ftol=-1.0)


@pytest.mark.parametrize("damping", [0.0, -1.0, float("inf"), float("nan")])
def test_a_damping_that_is_not_positive_and_finite_raises(damping):
    with pytest.raises(ValueError, match="damping"):
        LevenbergMarquardt(rtol=1e-9, atol=1e-9, damping=damping)


def test_a_warm_start_with_light_damping_reaches_the_optimum_in_fewer_steps():
    """From the optimum with one term removed (as `discover` refits a model with a new
    term at zero), a first damping of 1e-3 reaches the same cost in under half the steps
    of the default 1, which Nielsen's update lowers only threefold per step."""
    optimum = optx.least_squares(residuals, LevenbergMarquardt(rtol=1e-12, atol=1e-12), Z0,
                                 max_steps=1000)
    warm = optimum.value.at[2].set(0.0)
    steps, costs = [], []
    for damping in (1.0, 1e-3):
        sol = optx.least_squares(residuals, LevenbergMarquardt(rtol=1e-12, atol=1e-12,
                                                               damping=damping),
                                 warm, max_steps=1000, throw=False)
        assert sol.result == optx.RESULTS.successful
        r = residuals(sol.value, None)
        steps.append(int(sol.stats["num_steps"]))
        costs.append(0.5 * float(r @ r))
    assert 2 * steps[1] < steps[0]
    np.testing.assert_allclose(costs[1], costs[0], rtol=1e-12)


def test_stored_jacobian_values_and_linearisation():
    f = stored_jacobian(residuals)
    z = jnp.array([1.7, 0.4, 0.3, 2.0])
    value, jac = f(z, None)
    assert_equal_to_rounding(value, residuals(z, None))  # one program with the JVP, one without
    np.testing.assert_allclose(jac, jax.jacfwd(residuals)(z, None), rtol=1e-13, atol=1e-15)
    # the JVP through the custom rule equals the JVP of the plain function
    dz = jnp.array([0.3, -1.0, 2.0, 0.5])
    _, lin = jax.linearize(lambda q: f(q, None)[0], z)
    _, ref = jax.jvp(lambda q: residuals(q, None), (z,), (dz,))
    np.testing.assert_allclose(lin(dz), ref, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("solver", [LevenbergMarquardt(rtol=1e-10, atol=1e-10),
                                    optx.BFGS(rtol=1e-10, atol=1e-10)],
                         ids=["gauss-newton", "minimiser"])
def test_solve_least_squares_returns_physical_jacobian(solver):
    """Residuals and Jacobian at the solution: the Gauss-Newton solver's stored ones
    and, for another solver, a fresh evaluation; both with respect to q = 2 z."""
    scaled = lambda z, args: residuals(2.0 * z, args)
    out = jax.jit(lambda z: solve_least_squares(scaled, solver, z, None, 1000,
                                                lambda z: 2.0 * z))(Z0 / 2.0)
    z, result, _, q, res, jac = out
    assert result == optx.RESULTS.successful
    np.testing.assert_allclose(q, 2.0 * z)
    np.testing.assert_allclose(q, [2.02014445, 0.30187279, 0.48552742, 1.83116784], rtol=1e-6)
    np.testing.assert_allclose(res, residuals(q, None), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(jac, jax.jacfwd(residuals)(q, None), rtol=1e-12, atol=1e-15)


def test_the_block_descent_is_optimistix_damped_newton_step():
    """Shared parameters and two nuisance parameters per block (residuals of 2 channels x
    2 x 3 blocks x 5 samples, one block all zero as a padded window is): the block
    elimination gives optimistix's damped Gauss-Newton step (one QR of the whole
    stacked matrix) to rounding, from a damping that is almost nothing to a large one."""
    rng = np.random.default_rng(3)
    n, k, blocks, shape = 3, 2, (2, 3), (2, 2, 3, 5)
    count = int(np.prod(blocks))
    shared = rng.standard_normal(shape + (n,))
    own = rng.standard_normal(shape + (k,))
    own[:, 1, 2] = shared[:, 1, 2] = 0.0  # a padded block: no rows move
    eye = np.eye(count).reshape((1,) + blocks + (1, count, 1))
    spread = (own[..., None, :] * eye).reshape(shape + (count * k,))
    jac = jnp.asarray(np.concatenate([shared, spread], axis=-1))
    residual = jnp.asarray(rng.standard_normal(shape))
    operator = lx.FunctionLinearOperator(lambda t: jac @ t,
                                         jax.ShapeDtypeStruct((jac.shape[-1],), jac.dtype))
    info = optx.FunctionInfo.ResidualJac(residual, operator)
    y = jnp.zeros(jac.shape[-1])

    def steps(descent):
        state = descent.query(y, info, descent.init(y, info))
        return [descent.step(jnp.asarray(1 / lam), state)[0] for lam in (1e-12, 1e-2, 1e4)]

    for got, want in zip(steps(BlockDampedNewtonDescent(n, blocks)),
                         steps(optx.DampedNewtonDescent())):
        assert np.linalg.norm(want) > 0
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
