"""Levenberg-Marquardt for prediction-error fits: optimistix's solver with Nielsen's damping
update, optional geodesic acceleration and MINPACK's cost-based stopping rule, and residual
functions whose Jacobian is computed once.

Stopping. `optimistix.LevenbergMarquardt` stops when both the parameters and every
residual settle (`|dy| < atol + rtol |y|` and `|df| < atol + rtol |f|`, elementwise).
On the ill-conditioned fits of vessel coefficients the parameters keep drifting
along an unidentifiable valley long after the cost has settled, so the solver
crawls for dozens of steps that change the cost at rounding level. MINPACK's
`lmder` (More 1978; Garbow, Hillstrom & More 1980, the `ftol` test) also stops when
an accepted step reduces the cost $S = \\frac12 \\|f\\|^2$ by a relative amount
$(S_{k-1} - S_k) / S_{k-1} \\le \\text{ftol}$; `LevenbergMarquardt` here adds exactly
that test (a step is accepted only when the actual reduction is at least 1 % of the
predicted one, so its predicted reduction is small too, as MINPACK requires).

Damping. optimistix's trust region (`ClassicalTrustRegion`) changes the damping only by
fixed factors and leaves it alone while the gain ratio $\\rho$ (actual over predicted
cost reduction) lies between 0.01 and 0.99, which on these fits it mostly does: the
20-coefficient vessel fit of `benchmarks/fit.py` walked its valley at one damping for
about 20 steps at a time. `NielsenDamping` updates it from $\\rho$ at every step
(Nielsen 1999), which took the same fit to the same cost (8.625501298) in 34 steps
instead of 61; with geodesic acceleration (`LevenbergMarquardt(geodesic=True)`), which
bends each step along the valley, in 20.

Jacobians. For `jac="fwd"` optimistix calls `jax.linearize` on the residuals and
materialises the linear map column by column; through a long `lax.scan` that costs
about twice a plain `jax.jacfwd` (measured on the 20-coefficient vessel fit:
1.15 s against 0.50 s per Jacobian). `stored_jacobian` gives the residual function a
custom JVP that computes the full forward-mode Jacobian once and multiplies by it,
so linearising costs one `jacfwd` and materialising one small matrix product; and it
is traced once per fit (`_traced_once`), not once for the solver's closure conversion
and again for the rule. Where each prediction window's start is estimated too
(`EstimatedStarts`), those columns are block-sparse: `blockwise_jacfwd` computes them
with a few seeded JVPs and `BlockDampedNewtonDescent` solves each step block by block.
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx

from .._foundation._results import RESULTS, as_code


class _DampingState(eqx.Module):
    step_size: jax.Array  # 1 / lambda
    nu: jax.Array  # lambda's factor after the next rejected step
    # the part of the last proposed step beyond the Gauss-Newton step (the geodesic
    # acceleration of `LevenbergMarquardt`): not in the predicted reduction
    correction: object


class NielsenDamping(optx.ClassicalTrustRegion):
    """The Levenberg-Marquardt damping $\\lambda$ (= 1 / step size) updated from the gain
    ratio $\\rho$ of each step (Nielsen 1999, IMM-REP-1999-05; Madsen, Nielsen & Tingleff
    2004, *Methods for non-linear least squares problems*, eq. 3.16): a step is accepted
    when $\\rho \\ge$ `low_cutoff` (optimistix's test), and then $\\lambda \\leftarrow
    \\lambda \\max(1/3, 1 - (2\\rho - 1)^3)$, $\\nu \\leftarrow 2$; otherwise $\\lambda
    \\leftarrow \\nu\\lambda$, $\\nu \\leftarrow 2\\nu$. The predicted reduction is the
    Gauss-Newton model's for the Gauss-Newton step, as in optimistix's
    `ClassicalTrustRegion` (with geodesic acceleration: for the step without it, as
    Transtrum & Sethna 2012 do). `damping` is the first step's $\\lambda$."""

    damping: float = 1.0

    def init(self, y, f_info_struct):
        return _DampingState(step_size=jnp.array(1.0 / self.damping), nu=jnp.array(2.0),
                             correction=jax.tree.map(jnp.zeros_like, y))

    def step(self, first_step, y, y_eval, f_info, f_eval_info, state):
        newton_step = jax.tree.map(lambda a, b, c: a - b - c, y_eval, y, state.correction)
        predicted = self.predict_reduction(newton_step, f_info)
        actual = f_eval_info.as_min() - f_info.as_min()  # both negative for a good step
        # optimistix's acceptance test: a step that is not finite is rejected, and a null
        # step (the damping so large that nothing moves) is accepted, so the solver stops
        accept = first_step | (actual <= self.low_cutoff * predicted)
        descends = predicted < 0
        rho = actual / jnp.where(descends, predicted, -1.0)
        gain = jnp.where(descends, jnp.maximum(1 / 3, 1 - (2 * rho - 1) ** 3), 1.0)
        lam_factor = jnp.where(accept, gain, state.nu)
        step_size = jnp.where(first_step, state.step_size, state.step_size / lam_factor)
        nu = jnp.where(accept, 2.0, 2 * state.nu)
        return (step_size, accept, optx.RESULTS.successful,
                _DampingState(step_size, nu, state.correction))


class LevenbergMarquardt(optx.AbstractGaussNewton):
    """`optimistix.LevenbergMarquardt` (damped Gauss-Newton) with Nielsen's damping
    update (`NielsenDamping`) in place of its classical trust region, optional geodesic
    acceleration, and MINPACK's cost test: it also stops when an accepted step lowers
    the cost $S = \\frac12\\|f\\|^2$ by no more than `ftol` relative,
    $(S_{k-1} - S_k) \\le \\text{ftol}\\, S_{k-1}$ (`ftol=0`: optimistix's stopping
    rule alone).

    Geodesic acceleration (Transtrum & Sethna 2012, arXiv:1201.5885, eqs. 14-16): to
    the damped Gauss-Newton step $v = -(J^TJ + \\lambda I)^{-1} J^T f$ it adds half
    of $a = -(J^TJ + \\lambda I)^{-1} J^T f_{vv}$, the second directional derivative
    $f_{vv} \\approx \\frac2h \\big(\\frac{f(z + hv) - f(z)}{h} - Jv\\big)$ by one more
    evaluation of the residuals ($h = 0.1$), when $2\\|a\\| \\le 0.75 \\|v\\|$
    (otherwise the step is $v$ alone), so the step follows the valley's curve instead
    of its tangent. `residuals(z, args)` are the residuals for that evaluation (default:
    the solver's own function; `solve_least_squares` sets the plain one, without the
    stored Jacobian). It is off by default (`geodesic=True` turns it on; another search in
    place of `NielsenDamping`, whose gain ratio leaves the acceleration out of the
    prediction, turns it off): it pays where a fit walks a long curved valley
    (`benchmarks/fit.py`: 34 -> 20 steps, about 9 -> 6 s without compilation) and costs
    where it does not (the KVLCC2 `identify` of `jaxship/studies/real_data.py`: 87 ->
    85 steps, 25 -> 30 s, most of it compiling the extra residual evaluation).

    `damping` is the first step's $\\lambda$ in the fit's internal coordinates (the
    default 1, optimistix's). A start far from the optimum needs it: from 1e-2 or 1e-3
    the 20-coefficient fit of `benchmarks/fit.py` took 88 and 96 steps instead of 34.
    A warm start, a fitted model with one term added at zero, does not: there the
    damping of 1 is far above the optimum's (about 1e-6) and Nielsen's update lowers it
    only threefold per step, so the first steps crawl: `discover`'s first three refits on
    the README's KVLCC2 case took 15, 15 and 49 steps from 1, and 8, 10 and 24 from 1e-3
    (`discover`'s `REFIT_DAMPING`), to costs equal to 1e-8 relative.

    `blockwise`: with `PredictionError(initial=EstimatedStarts())`, solve each step
    window by window (`BlockDampedNewtonDescent`, the default), not by one QR of the
    whole matrix (`False`, optimistix's `DampedNewtonDescent`): the same steps, and
    `discover`'s Esso Osaka base fit 5x faster (`benchmarks/block_descent.py`).
    """

    rtol: float
    atol: float
    ftol: float
    norm: object
    descent: optx.DampedNewtonDescent
    search: NielsenDamping
    verbose: object
    geodesic: bool
    residuals: object
    blockwise: bool

    def __init__(self, rtol: float, atol: float, ftol: float = 1e-10, norm=optx.max_norm,
                 linear_solver=None, verbose=False, geodesic: bool = False, residuals=None,
                 damping: float = 1.0, blockwise: bool = True):
        if not ftol >= 0.0:
            raise ValueError(f"`ftol` must be >= 0, got {ftol}.")
        if not 0.0 < damping < math.inf:
            raise ValueError(f"`damping` must be positive and finite, got {damping}.")
        self.rtol, self.atol, self.ftol, self.norm = rtol, atol, ftol, norm
        base = optx.LevenbergMarquardt(rtol=rtol, atol=atol, norm=norm, verbose=verbose,
                                       **({} if linear_solver is None else
                                          dict(linear_solver=linear_solver)))
        self.descent, self.verbose = base.descent, base.verbose
        self.search = NielsenDamping(damping=damping)
        self.geodesic, self.residuals, self.blockwise = geodesic, residuals, blockwise

    def step(self, fn, y, args, options, state, tags):
        y, new, aux = super().step(fn, y, args, options, state, tags)
        accepted = (new.num_accepted_steps > state.num_accepted_steps) & ~state.first_step
        before = 0.5 * jnp.sum(state.f_info.residual**2)
        after = 0.5 * jnp.sum(new.f_info.residual**2)
        settled = accepted & (before - after <= self.ftol * before)
        new = eqx.tree_at(lambda s: s.terminate, new, new.terminate | settled)
        if self.geodesic and isinstance(self.search, NielsenDamping):
            residuals = self.residuals or (lambda z, a: fn(z, a)[0])
            new = self._accelerate(residuals, y, args, new)
        return y, new, aux

    def _accelerate(self, residuals, y, args, state, h=0.1, alpha=0.75):
        """`state` with the proposal $y + v$ moved to $y + v + a/2$ (class docstring);
        `y` is a flat array, as in every jaxship fit."""
        info = state.f_info
        v = state.y_eval - y
        f_vv = (2 / h) * ((residuals(y + h * v, args) - info.residual) / h - info.jac.mv(v))
        # the damped Gauss-Newton step for residuals f_vv is a (the descent's own solve)
        query = self.descent.query(y, eqx.tree_at(lambda i: i.residual, info, f_vv),
                                   state.descent_state)
        a, _ = self.descent.step(state.search_state.step_size, query)
        half = 0.5 * a
        use = (jnp.all(jnp.isfinite(half))
               & (4 * jnp.linalg.norm(half) <= alpha * jnp.linalg.norm(v)))
        half = jnp.where(use, half, 0.0)
        state = eqx.tree_at(lambda s: s.search_state.correction, state, half)
        return eqx.tree_at(lambda s: s.y_eval, state, state.y_eval + half)


class SolverOutcome(eqx.Module):
    """Base of fit results: `success` and `message` from the `result` code (`RESULTS`,
    or an optimistix one)."""

    result: eqx.AbstractVar[RESULTS]

    @property
    def code(self) -> RESULTS:
        return as_code(self.result)

    @property
    def success(self) -> bool:
        return bool(self.code == RESULTS.successful)

    @property
    def code_name(self) -> str:
        """The code's name, e.g. `"successful"`, `"at_bound"` (as in `result.json`)."""
        code = self.code
        return next(n for n, item in RESULTS._name_to_item.items() if code == item)

    @property
    def message(self) -> str:
        """In plain words: "successful", or why the optimiser stopped."""
        code = self.code
        if self.success:
            return "successful"
        for name, text in _PLAIN_RESULTS.items():
            if code == getattr(RESULTS, name):
                return text
        return RESULTS[code].split("\n")[0]


# the optimistix results a fit meets, in the words of a fit (not of a root-find)
_PLAIN_RESULTS = {
    "max_steps_reached": "stopped at the maximum number of steps before converging "
                         "(raise max_steps, or start closer)",
    "nonlinear_max_steps_reached": "stopped at the maximum number of steps before "
                                   "converging (raise max_steps, or start closer)",
    "nonlinear_divergence": "diverged",
    "singular": "the least-squares step was singular or not finite (a parameter is not "
                "identifiable on these data, or the simulation blew up)",
}


def value_and_jacfwd(f, z):
    """`(f(z), J)` with $J_{...,i} = \\partial f / \\partial z_i$ by forward mode, one
    batched JVP over the unit vectors (the primal is computed once)."""
    basis = jnp.eye(z.shape[0], dtype=z.dtype)
    return jax.vmap(lambda t: jax.jvp(f, (z,), (t,)), out_axes=(None, -1))(basis)


def _compressed_basis(num_params: int, count: int, size: int) -> jax.Array:
    """The `num_params` unit vectors of the shared parameters, then k seeds, the j-th
    with a one at the j-th nuisance parameter of each of the `count` blocks (`z = (p,
    n_1, ..., n_B)`, each `n_b` of length k): `(num_params + k, size)`."""
    k = (size - num_params) // count
    seeds = jnp.zeros((k, size))
    for j in range(k):
        seeds = seeds.at[j, num_params + j::k].set(1.0)
    return jnp.concatenate([jnp.eye(num_params, size), seeds])


def blockwise_jacfwd(num_params: int, blocks: tuple[int, ...]):
    """A `value_and_jacfwd` for residuals `(..., *blocks, L)` whose last inputs are
    per-block nuisance parameters, k for each of the B = `prod(blocks)` blocks in
    block order (`z = (p, n_1, ..., n_B)`, each `n_b` of length k), where block b's
    nuisance parameters move block b's residuals only (the start corrections of
    prediction windows). Their columns have disjoint row supports, so one JVP seeded
    with the j-th nuisance parameter of every block gives all B of those columns at
    once (Curtis, Powell & Reid 1974): `num_params + k` JVPs instead of
    `num_params + k B`."""
    count = int(math.prod(blocks))

    def value_and_jac(f, z):
        k = (z.shape[0] - num_params) // count
        basis = _compressed_basis(num_params, count, z.shape[0]).astype(z.dtype)
        value, cols = jax.vmap(lambda t: jax.jvp(f, (z,), (t,)), out_axes=(None, -1))(basis)
        lead = value.ndim - len(blocks) - 1  # axes before the blocks (e.g. channels)
        # spread each seeded column back onto its own block: (..., *blocks, L, B, k)
        eye = jnp.eye(count, dtype=z.dtype).reshape((1,) * lead + blocks + (1, count, 1))
        spread = (cols[..., num_params:][..., None, :] * eye).reshape(value.shape
                                                                      + (count * k,))
        return value, jnp.concatenate([cols[..., :num_params], spread], axis=-1)

    return value_and_jac


class BlockDampedNewtonDescent(optx.AbstractDescent):
    """optimistix's damped Gauss-Newton step, $\\min_d \\|J d - f\\|^2 + \\lambda
    \\|d\\|^2$, for the residuals of `blockwise_jacfwd` (shared parameters p, then k
    nuisance parameters per block that move their own block's rows only), solved by
    eliminating each block's nuisance step first. For block b with rows
    $[J_{n,b}; \\sqrt\\lambda I_k] = Q_b R_b$ (a small QR), the shared step x solves
    the least-squares problem of the projected rows $(I - Q_b Q_b^T)[J_{p,b}; 0]$
    against $(I - Q_b Q_b^T)[f_b; 0]$ with $\\sqrt\\lambda I$ below, and then
    $y_b = R_b^{-1} Q_b^T [f_b - J_{p,b} x; 0]$: the same solution as one QR of the
    whole stacked matrix (optimistix's `DampedNewtonDescent`), in
    $O(R (n + k)^2)$ operations for R residuals instead of $O(R (n + kB)^2)$.
    `discover`'s fits with 60 s windows on 90 minutes of Esso Osaka records (288
    start corrections, 2 shared parameters) spent 0.6 s of each 0.65 s step in that
    one QR."""

    num_params: int
    blocks: tuple[int, ...]

    def init(self, y, f_info_struct):
        return optx.DampedNewtonDescent().init(y, f_info_struct)

    def query(self, y, f_info, state):
        return optx.DampedNewtonDescent().query(y, f_info, state)

    def step(self, step_size, state):
        info, n, count = state.f_info, self.num_params, int(math.prod(self.blocks))
        f = info.residual
        size = info.jac.in_structure().shape[0]
        cols = jax.vmap(info.jac.mv, out_axes=-1)(
            _compressed_basis(n, count, size).astype(f.dtype))
        lead = f.ndim - len(self.blocks) - 1

        def by_block(a):  # (..., *blocks, L, *rest) -> (B, rows of a block, *rest)
            rest = a.shape[f.ndim:]
            a = a.reshape(a.shape[:lead] + (count,) + a.shape[lead + len(self.blocks):])
            return jnp.moveaxis(a, lead, 0).reshape((count, -1) + rest)

        # optimistix's damping: lambda = 1 / step size, the largest float once that is tiny
        positive = step_size > jnp.finfo(f.dtype).eps
        root = jnp.sqrt(jnp.where(positive, 1 / jnp.where(positive, step_size, 1.0),
                                  jnp.finfo(f.dtype).max))
        jp, jn, fb = by_block(cols[..., :n]), by_block(cols[..., n:]), by_block(f)
        k = jn.shape[-1]
        pad = lambda a: jnp.concatenate([a, jnp.zeros((count, k) + a.shape[2:], a.dtype)], 1)
        q, r = jnp.linalg.qr(jnp.concatenate(
            [jn, jnp.broadcast_to(root * jnp.eye(k, dtype=f.dtype), (count, k, k))], 1))
        project = lambda a: a - q @ (jnp.swapaxes(q, 1, 2) @ a)
        jp0, fb0 = pad(jp), pad(fb[..., None])
        shared = jnp.concatenate([project(jp0).reshape(-1, n), root * jnp.eye(n, dtype=f.dtype)])
        rhs = jnp.concatenate([project(fb0).reshape(-1), jnp.zeros(n, f.dtype)])
        x = jnp.zeros(0, f.dtype)
        if n:
            q_s, r_s = jnp.linalg.qr(shared)
            x = jax.scipy.linalg.solve_triangular(r_s, q_s.T @ rhs)
        y = jax.scipy.linalg.solve_triangular(
            r, jnp.swapaxes(q, 1, 2) @ (fb0 - jp0 @ x[:, None]))[..., 0]
        return -jnp.concatenate([x, y.reshape(-1)]), optx.RESULTS.successful


@eqx.filter_jit
def _traced_once(z, fn, args, jacobian):
    """`jacobian(fn(., args), z)` under `filter_jit`: the solver's closure conversion
    calls it, then the custom JVP's rule, and the second call reuses the first trace
    (the vessel fit of `benchmarks/fit.py` traced it for 1.7 s each time)."""
    return jacobian(lambda x: fn(x, args), z)


@eqx.filter_custom_jvp
def _value_and_jacobian(z, fn, args, jacobian):
    # JAX keys its trace cache on the tracing context, and the rule's call runs with an
    # abstract mesh set where the first ran without: setting the current one (a no-op
    # for the computation) makes the two contexts equal
    with jax.sharding.use_abstract_mesh(jax.sharding.get_abstract_mesh()):
        return _traced_once(z, fn, args, jacobian)


@_value_and_jacobian.def_jvp
def _value_and_jacobian_jvp(primals, tangents):
    value, jac = _value_and_jacobian(*primals)
    return (value, jac), (jac @ tangents[0], jnp.zeros_like(jac))


def stored_jacobian(fn, jacobian=value_and_jacfwd):
    """`fn(z, args)` turned into `(f, J)`, $J$ from `value_and_jacfwd`, with a custom
    JVP $\\dot f = J \\dot z$ (see the module docstring): as a residual function with
    `has_aux=True` the solver's linearisation costs one `jacfwd` and $J$ comes back
    as the auxiliary output. (`args` is an explicit input of the custom JVP, not a
    closure: optimistix closure-converts the residual function.)"""
    return lambda z, args: _value_and_jacobian(z, fn, args, jacobian)


class Chunk(eqx.Module):
    """A part of a Levenberg-Marquardt run (`solve_least_squares(..., chunk=)`): at most
    `budget` steps (an array: every budget runs the same compiled program), from the
    start (`resume` None) or from where the last part stopped (`resume`: the arrays of
    its state, `Budgeted`'s `resume` output). The parts of a run take the steps of one
    run in one go (the state carries everything the next step reads), so the caller can
    report progress between them without a host callback in the compiled program
    (JAX's persistent cache refuses programs holding one: issue 70)."""

    resume: object
    budget: jax.Array


class Budgeted(optx.AbstractLeastSquaresSolver):
    """`solver`, a `LevenbergMarquardt`, stopped after `options["budget"]` steps and
    started from `options["resume"]`, the arrays of an earlier state (the rest of the
    state, functions and static values, is this trace's own, from `init`): its state
    is `(solver's state, steps taken in this part)`."""

    solver: LevenbergMarquardt
    rtol: float
    atol: float
    norm: object

    def __init__(self, solver):
        self.solver, self.rtol, self.atol, self.norm = (solver, solver.rtol, solver.atol,
                                                        solver.norm)

    def init(self, fn, y, args, options, f_struct, aux_struct, tags):
        state = self.solver.init(fn, y, args, options, f_struct, aux_struct, tags)
        if options["resume"] is not None:
            state = eqx.combine(options["resume"], eqx.filter(state, eqx.is_array,
                                                              inverse=True))
        return state, jnp.array(0)

    def step(self, fn, y, args, options, state, tags):
        y, inner, aux = self.solver.step(fn, y, args, options, state[0], tags)
        return y, (inner, state[1] + 1), aux

    def terminate(self, fn, y, args, options, state, tags):
        done, result = self.solver.terminate(fn, y, args, options, state[0], tags)
        return done | (state[1] >= options["budget"]), result

    def postprocess(self, fn, y, aux, args, options, state, tags, result):
        return self.solver.postprocess(fn, y, aux, args, options, state[0], tags, result)


def solve_least_squares(fn, solver, z0, args, max_steps, to_physical,
                        jacobian=value_and_jacfwd, chunk: Chunk | None = None):
    """Minimise $\\frac12\\|f(z)\\|^2$, `f = fn(z, args)`; return `(z, result, num_steps,
    q, residuals, J_q)` at the solution, with $q$ = `to_physical(z)` (an elementwise
    map) and $J_q = \\partial f / \\partial q$ (..., d). With a Gauss-Newton solver the
    residuals and Jacobian are those of its last accepted step (no second compilation
    of the forward pass); other solvers evaluate them once more.
    `jacobian(f, z)` computes `(f, J)` (default `value_and_jacfwd`; `blockwise_jacfwd`).
    `chunk`: one part of the run (`Chunk`; a `LevenbergMarquardt` only; `max_steps`
    stays the whole run's), whose outcome has two more entries: `resume` (the state's
    arrays for the next part) and `stopped` (the solver stopped: converged or failed).
    Call under jit."""
    if isinstance(solver, LevenbergMarquardt) and solver.geodesic and solver.residuals is None:
        # geodesic acceleration evaluates the plain residuals, not the stored Jacobian
        solver = eqx.tree_at(lambda s: s.residuals, solver, fn, is_leaf=lambda x: x is None)
    fn = stored_jacobian(fn, jacobian)
    if max_steps == 0:  # the start is the estimate: no optimiser state to read
        residual, jac = fn(z0, args)
        q, dq_dz = jax.jvp(to_physical, (z0,), (jnp.ones_like(z0),))
        out = (z0, RESULTS.nonlinear_max_steps_reached, jnp.array(0), q, residual, jac / dq_dz)
        return out if chunk is None else out + (None, jnp.array(True))
    options = dict(jac="fwd")
    if chunk is not None:
        solver, options = Budgeted(solver), dict(options, resume=chunk.resume,
                                                 budget=chunk.budget)
    sol = optx.least_squares(fn, solver, z0, args=args, options=options,
                             has_aux=True, max_steps=max_steps, throw=False)
    state = sol.state if chunk is None else sol.state[0]
    info = getattr(state, "f_info", None)
    if isinstance(info, optx.FunctionInfo.ResidualJac):
        residual, jac = info.residual, state.aux
    else:
        residual, jac = fn(sol.value, args)
    q, dq_dz = jax.jvp(to_physical, (sol.value,), (jnp.ones_like(sol.value),))
    out = (sol.value, sol.result, sol.stats["num_steps"], q, residual, jac / dq_dz)
    if chunk is None:
        return out
    return out + (eqx.filter(state, eqx.is_array),
                  state.terminate | (sol.result != optx.RESULTS.successful))
