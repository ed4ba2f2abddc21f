"""Implicit integrators on a small cloth: fast mass-spring converges to Newton's implicit Euler,
its factorisation is reused, and the linear solver choice does not change a Baraff-Witkin step."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity
from femkit.dynamics.integrators import StepContext, get_integrator
from femkit.solvers import SolverSpec
from femkit.dynamics.topology import cloth_grid


def _cloth(n=8):
    return cloth_grid(n, n, 1.0, 1.0, k_structural=200.0, k_shear=50.0, k_bending=10.0,
                      total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])


def _one_step(name, system, dt, ctx=None, **opts):
    ctx = ctx or StepContext()
    integ = get_integrator(name, **opts)
    # a swinging start: every free node moves sideways, so springs stretch and rotate
    v0 = np.zeros_like(system.x0)
    v0[:, 1] = 0.5
    v0[system.pinned] = 0.0
    s = integ.start(system, system.x0, v0, 0.0, dt, ctx)
    for _ in range(3):
        s = integ.step(system, s, dt, ctx)
    return s, ctx


def test_fast_mass_spring_converges_to_newton_implicit_euler():
    system = _cloth()
    dt = 1.0 / 60.0
    ref, ctx_n = _one_step("newton", system, dt, tol=1e-13)
    fms, _ = _one_step("fast_mass_spring", system, dt, iterations=5000, tol=1e-14)
    disp = np.abs(ref.x - system.x0).max()
    assert disp > 1e-2  # the cloth did move
    np.testing.assert_allclose(fms.x, ref.x, rtol=0, atol=1e-6 * disp)
    # few iterations are a real approximation, not the converged answer
    few, _ = _one_step("fast_mass_spring", system, dt, iterations=2)
    assert np.abs(few.x - ref.x).max() > 1e-4 * disp
    assert max(ctx_n.stats["newton_iterations"]) < 20


def test_fast_mass_spring_factorises_once_while_dt_is_fixed():
    system = _cloth(6)
    ctx = StepContext()
    integ = get_integrator("fast_mass_spring", iterations=3)
    s = integ.start(system, system.x0, system.v0, 0.0, 0.01, ctx)
    for _ in range(5):
        s = integ.step(system, s, 0.01, ctx)
    assert ctx.stats["factorizations"] == 1
    s = integ.step(system, s, 0.005, ctx)  # a new dt invalidates the cached matrix
    assert ctx.stats["factorizations"] == 2


@pytest.mark.parametrize("solver,pc", [("cg", "none"), ("pcg", "jacobi"), ("pcg", "ic0")],
                         ids=["cg", "pcg-jacobi", "pcg-ic0"])
def test_implicit_euler_step_independent_of_linear_solver(solver, pc):
    system = _cloth()
    dt = 1.0 / 60.0
    ref, _ = _one_step("implicit_euler", system, dt, StepContext(SolverSpec("direct")), fix="clamp")
    got, ctx = _one_step("implicit_euler", system, dt,
                         StepContext(SolverSpec(solver, pc, rtol=1e-12)), fix="clamp")
    assert ctx.stats["linear_iterations"] > 0
    scale = np.abs(ref.v).max()
    np.testing.assert_allclose(got.v, ref.v, rtol=0, atol=1e-9 * scale)


def _liu_reference(system, x, v, dt, iterations):
    """Liu's iteration written from its definition: dense ``(M + h^2 L + h B)`` on the free
    nodes, right-hand side ``M y + h^2 (f(x, (x - x_n)/h) + L x) + h B x`` with the full force
    evaluation; ``B`` (the damping split) is written out here: viscous coefficient on the
    diagonal plus the dashpot coefficients' graph Laplacian."""
    h = dt
    free = ~system.pinned
    L = system.spring_laplacian().toarray()
    B = np.zeros_like(L)
    for f in system.forces:
        if hasattr(f, "gamma"):
            B += f.gamma * np.eye(system.n)
    c = np.broadcast_to(system.damping, (system.n_springs,))
    for (i, j), cs in zip(system.springs, c):
        B[i, i] += cs
        B[j, j] += cs
        B[i, j] -= cs
        B[j, i] -= cs
    L = L + B / h  # h^2 (L + B / h) = h^2 L + h B
    A = np.diag(system.mass) + h * h * L
    y = x + h * v
    xi = y.copy()
    xi[system.pinned] = x[system.pinned]
    for _ in range(iterations):
        rhs = system.mass[:, None] * y + h * h * (system.force(xi, (xi - x) / h, 0.0 + h) + L @ xi)
        rhs = rhs[free] - A[np.ix_(free, ~free)] @ x[~free]
        xi = xi.copy()
        xi[free] = np.linalg.solve(A[np.ix_(free, free)], rhs)
    return xi


@pytest.mark.parametrize("extra", ["gravity-only", "dashpots-viscous-contact"])
def test_fast_mass_spring_step_equals_liu_iteration_by_definition(extra):
    from femkit.dynamics.forces import GroundContact, ViscousDamping

    if extra == "gravity-only":
        system = _cloth(7)
    else:
        system = cloth_grid(7, 7, 1.0, 1.0, k_structural=200.0, k_shear=50.0, k_bending=10.0,
                            total_mass=1.0, pinned="top_corners", damping=0.5,
                            forces=[Gravity(9.81), ViscousDamping(0.3), GroundContact(300.0, height=0.2)])
        assert system.has_variable_forces
    rng = np.random.default_rng(2)
    x = system.x0 + 0.05 * rng.standard_normal(system.x0.shape)
    x[system.pinned] = system.x0[system.pinned]
    v = rng.standard_normal(system.x0.shape)
    v[system.pinned] = 0.0
    dt = 1.0 / 30.0
    integ = get_integrator("fast_mass_spring", iterations=4)
    ctx = StepContext()
    got = integ.step(system, integ.start(system, x, v, 0.0, dt, ctx), dt, ctx)
    ref = _liu_reference(system, x, v, dt, 4)
    np.testing.assert_allclose(got.x, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    np.testing.assert_allclose(got.v, (ref - x) / dt, rtol=0, atol=1e-9 * np.abs(got.v).max())


def test_fast_mass_spring_cache_follows_new_parameter_arrays():
    system = _cloth(5)
    ctx = StepContext()
    integ = get_integrator("fast_mass_spring", iterations=2)
    s = integ.start(system, system.x0, system.v0, 0.0, 0.01, ctx)
    s = integ.step(system, s, 0.01, ctx)
    s = integ.step(system, s, 0.01, ctx)
    assert ctx.stats["factorizations"] == 1
    system.k = 2.0 * system.k  # a new array: the cached factor no longer applies
    s2 = integ.step(system, s, 0.01, ctx)
    assert ctx.stats["factorizations"] == 2
    fresh = StepContext()
    s3 = integ.step(system, s, 0.01, fresh)
    np.testing.assert_array_equal(s2.x, s3.x)


@pytest.mark.parametrize("name", ["implicit_euler", "newton", "newmark"])
def test_direct_solves_reusing_the_ordering_match_plain_direct(name):
    system = _cloth(7)
    dt = 1.0 / 60.0
    opts = {"reuse_factorization": False} if name in ("newton", "implicit_euler") else {}
    ordered, ctx = _one_step(name, system, dt, StepContext(SolverSpec("direct")), **opts)
    # any ctx.options sends the solve through femkit.solvers.solve (SuperLU orders every matrix)
    plain, ctx_plain = _one_step(name, system, dt, StepContext(SolverSpec("direct", options={"spd": None})),
                                 **opts)
    assert "orderings" not in ctx_plain.stats
    assert ctx.stats["factorizations"] == ctx.stats["linear_solves"] >= 3
    # on this flat start the pattern grows while out-of-plane couplings fill in (re-ordered);
    # reuse on a fixed pattern is tested below
    assert ctx.stats.get("orderings", 0) <= ctx.stats["factorizations"]
    scale = np.abs(plain.x - system.x0).max()
    np.testing.assert_allclose(ordered.x, plain.x, rtol=0, atol=1e-10 * scale)


def test_ordering_is_reused_while_the_pattern_holds_and_redone_when_it_changes():
    system = _cloth(6)
    dt = 1.0 / 60.0
    rng = np.random.default_rng(4)
    x = system.x0 + 0.01 * rng.standard_normal(system.x0.shape)  # generic 3D state: full pattern
    x[system.pinned] = system.x0[system.pinned]
    integ = get_integrator("implicit_euler", fix="clamp", reuse_factorization=False)
    ctx = StepContext()
    s = integ.start(system, x, np.zeros_like(x), 0.0, dt, ctx)
    for _ in range(4):
        s = integ.step(system, s, dt, ctx)
    assert ctx.stats["orderings"] == 1 and ctx.stats["factorizations"] == 4
    # the flat rest state has exact zeros (axis-aligned springs, no out-of-plane coupling)
    s = integ.step(system, integ.start(system, system.x0, system.v0, 0.0, dt, ctx), dt, ctx)
    assert ctx.stats["orderings"] == 2


@pytest.mark.parametrize("name,opts", [("newton", {"tol": 1e-12}), ("implicit_euler", {"fix": "clamp"})],
                         ids=["newton", "baraff-witkin"])
def test_reusing_an_older_factorisation_gives_the_same_steps(name, opts):
    """Opt-in reuse (the default factorises every system: 'direct' means direct)."""
    system = _cloth(8)
    dt = 1.0 / 60.0
    exact, ctx_exact = _one_step(name, system, dt, StepContext(SolverSpec("direct")), **opts)
    reused, ctx = _one_step(name, system, dt, StepContext(SolverSpec("direct")),
                            reuse_factorization=True, **opts)
    scale = np.abs(exact.x - system.x0).max()
    np.testing.assert_allclose(reused.x, exact.x, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(reused.v, exact.v, rtol=0, atol=1e-8 * scale / dt)
    assert ctx_exact.stats["factorizations"] == ctx_exact.stats["linear_solves"]
    assert ctx.stats["linear_solves"] >= ctx_exact.stats["linear_solves"] - 1
    # every kept factor serves at least one PCG solve (how many more depends on measured costs)
    assert ctx.stats["factorizations"] <= (ctx.stats["linear_solves"] + 1) // 2
    assert ctx.stats["linear_iterations"] > 0  # the later directions came from PCG
