"""The compiled spring passes equal the reference NumPy formulation (1e-12), and the integrators'
``cholesky`` path equals their SuperLU/NumPy path; Chebyshev acceleration of fast mass-spring."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.dynamics.forces import Gravity, GroundContact, RayleighDamping, ViscousDamping
from femkit.dynamics.forces.springs import hooke_forces, spring_geometry
from femkit.dynamics.integrators import StepContext, get_integrator
from femkit.solvers.operators import restrict
from femkit.dynamics.kernels.assembly import FreePattern, assemble_with_forces
from femkit.dynamics.kernels.spring_kernels import local_global_rhs, spring_forces
from femkit.dynamics.system import MassSpringSystem
from femkit.dynamics.topology import cloth_grid
from femkit.errors import InputError, NotSPDError
from femkit.solvers import SolverSpec

RNG = np.random.default_rng(7)


def _random_system(dim, n=40, s=150, damping=0.0, forces=()):
    x0 = RNG.standard_normal((n, dim))
    springs = np.array([(i, j) for i, j in RNG.integers(0, n, (3 * s, 2)) if i != j][:s])
    k = RNG.uniform(1.0, 10.0, s)
    rest = RNG.uniform(0.5, 2.0, s)
    return MassSpringSystem(x0, RNG.uniform(0.5, 2.0, n), springs, k, rest=rest,
                            damping=damping, pinned=[0, 3], forces=list(forces))


def _scale(a):
    return max(float(np.abs(a).max()), 1e-300)


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_spring_force_kernel_equals_numpy(dim):
    system = _random_system(dim)
    x = system.x0.copy()
    x[system._j[0]] = x[system._i[0]]          # one zero-length spring: it exerts nothing
    _, l, u = spring_geometry(x, system._i, system._j, system.length_floor)
    fs = hooke_forces(l, u, system.k, system.rest)
    ref = np.zeros_like(x)
    for c in range(dim):  # the reference scatter: + on end i, - on end j
        ref[:, c] = np.bincount(system._i, fs[:, c], system.n) - np.bincount(system._j, fs[:, c], system.n)
    out = np.zeros_like(x)
    spring_forces(x, system._i, system._j, system.k, system.rest, system.length_floor, out)
    assert np.abs(out - ref).max() <= 1e-12 * _scale(ref)


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_local_global_kernel_equals_sparse_products(dim):
    system = _random_system(dim)
    x = system.x0 + 0.1 * RNG.standard_normal(system.x0.shape)
    free = np.flatnonzero(~system.pinned)
    G = system.difference_operators[0]
    dx = G @ x
    d_unit = dx / np.linalg.norm(dx, axis=1)[:, None]
    ref = 0.3 * (G[:, free].T @ sp.diags(system.k * system.rest) @ d_unit)   # h^2 J d
    free_of = np.full(system.n, -1, dtype=np.int64)
    free_of[free] = np.arange(len(free))
    const = RNG.standard_normal((len(free), dim))
    out = np.zeros((len(free), dim))
    xf = x[free] + 0.0                             # the free iterate, read in place of x[free]
    x[free] = np.nan
    local_global_rhs(xf, x, system._i, system._j, free_of[system._i], free_of[system._j],
                     system.k * system.rest, system.length_floor, 0.3, const, out)
    assert np.abs(out - const - ref).max() <= 1e-12 * _scale(ref)


@pytest.mark.parametrize("fix", [None, "clamp", "regularize"], ids=["nofix", "clamp", "regularize"])
@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_one_pass_assembly_equals_reference_matrices(dim, fix):
    forces = [Gravity(9.81, axis=1), ViscousDamping(0.3), RayleighDamping(0.1, 0.01),
              GroundContact(500.0, height=0.0)]
    system = _random_system(dim, damping=0.2, forces=forces)
    x = system.x0.copy()
    v = RNG.standard_normal(x.shape)
    v[system.pinned] = 0.0
    h, kc, dc = 0.01, 0.013, 0.02
    m = np.repeat(system.mass, dim)
    pat = FreePattern(system)
    data, f, kv = assemble_with_forces(pat, system, x, v, 0.0, diagonal=m, kcoef=kc, dcoef=dc, fix=fix)
    K = system.stiffness_matrix(x, fix=fix)
    ref = restrict(system.mass_matrix() + kc * K + dc * system.damping_matrix(x), system.free_dofs)
    A = pat.matrix(data)
    assert abs(A - ref).max() <= 1e-12 * abs(ref).max()
    f_ref = system.force(x, v, 0.0, rayleigh=False)
    assert np.abs(f - f_ref).max() <= 1e-12 * _scale(f_ref)
    kv_ref = (K @ v.reshape(-1)).reshape(v.shape)
    assert np.abs(kv - kv_ref).max() <= 1e-12 * _scale(kv_ref)


def _cloth(n=8, **kw):
    return cloth_grid(n, n, 1.0, 1.0, k_structural=200.0, k_shear=50.0, k_bending=10.0,
                      total_mass=1.0, pinned="top_corners", **kw)


def _run(name, system, solver, steps=4, dt=1.0 / 60.0, x0=None, v0=None, **opts):
    ctx = StepContext(SolverSpec(solver))
    integ = get_integrator(name, **opts)
    if v0 is None:
        v0 = np.zeros_like(system.x0)
        v0[:, 1] = 0.5                       # swinging sideways: springs stretch and rotate
        v0[system.pinned] = 0.0
    s = integ.start(system, system.x0 if x0 is None else x0, v0, 0.0, dt, ctx)
    for _ in range(steps):
        s = integ.step(system, s, dt, ctx)
    return s, ctx


@pytest.mark.cholmod
@pytest.mark.parametrize("name,opts", [
    ("implicit_euler", {"fix": "clamp"}),
    ("implicit_euler", {"fix": "regularize"}),
    ("newton", {"tol": 1e-12}),
    ("fast_mass_spring", {"iterations": 7}),
], ids=["bw-clamp", "bw-regularize", "newton", "fast-mass-spring"])
def test_cholesky_path_equals_superlu_path(name, opts):
    system = _cloth(forces=[Gravity(9.81), RayleighDamping(0.1, 0.01), ViscousDamping(0.05)],
                    damping=0.2)
    ref, _ = _run(name, system, "direct", **opts)
    got, ctx = _run(name, system, "cholesky", **opts)
    disp = np.abs(ref.x - system.x0).max()
    assert disp > 1e-3
    # Newton stops at ||dx|| <= tol L: two exact-solve paths may differ at that level
    tol = 1e-9 if name == "newton" else 1e-10
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=tol * disp)
    np.testing.assert_allclose(got.v, ref.v, rtol=0, atol=100 * tol * np.abs(ref.v).max())
    assert ctx.stats["factorizations"] >= 1


@pytest.mark.cholmod
def test_symbolic_analysis_reused_every_step_of_a_3d_cloth():
    # a crumpled cloth (no spring along an axis, so no exact zero in any block): one pattern
    # for the whole run, analysed once
    system = _cloth(forces=[Gravity(9.81)])
    crumpled = system.x0 + 0.02 * np.random.default_rng(3).standard_normal(system.x0.shape)
    system = MassSpringSystem(crumpled, system.mass, system.springs, system.k, rest=system.rest,
                              pinned=system.pinned, forces=[Gravity(9.81)])
    _, ctx = _run("implicit_euler", system, "cholesky", steps=5, fix="clamp")
    assert ctx.stats["factorizations"] == 5
    assert ctx.stats["symbolic_reuses"] >= 4      # every step after the first (or all five)


@pytest.mark.cholmod
def test_fast_mass_spring_compiled_converges_to_newton_implicit_euler():
    system = _cloth(forces=[Gravity(9.81)])
    ref, _ = _run("newton", system, "cholesky", steps=3, tol=1e-13)
    fms, _ = _run("fast_mass_spring", system, "cholesky", steps=3, iterations=5000, tol=1e-14)
    disp = np.abs(ref.x - system.x0).max()
    np.testing.assert_allclose(fms.x, ref.x, rtol=0, atol=1e-6 * disp)


@pytest.mark.cholmod
def test_chebyshev_accelerates_local_global_towards_the_implicit_euler_step():
    system = _cloth(10, forces=[Gravity(9.81)])
    start, _ = _run("newton", system, "cholesky", steps=5)     # a swinging state
    one = dict(steps=1, x0=start.x, v0=start.v)
    ref, _ = _run("newton", system, "cholesky", tol=1e-13, **one)
    disp = np.abs(ref.x - start.x).max()
    plain, _ = _run("fast_mass_spring", system, "cholesky", iterations=20, **one)
    cheb, ctx = _run("fast_mass_spring", system, "cholesky", iterations=20, chebyshev=True, **one)
    rho = ctx.stats["chebyshev_rho"]
    assert 0.3 < rho < 1.0                                      # estimated, not given
    e_plain = np.abs(plain.x - ref.x).max() / disp
    e_cheb = np.abs(cheb.x - ref.x).max() / disp
    assert e_cheb < 0.5 * e_plain, (e_cheb, e_plain)
    # converged Chebyshev iterations are still the implicit Euler step
    conv, _ = _run("fast_mass_spring", system, "cholesky", iterations=3000, tol=1e-14,
                   chebyshev=True, **one)
    np.testing.assert_allclose(conv.x, ref.x, rtol=0, atol=1e-6 * disp)


@pytest.mark.cholmod
def test_compressed_cloth_without_fix_is_not_spd_for_cholesky():
    system = _cloth(forces=[Gravity(9.81)])
    x0 = system.x0 * 0.8 + 0.1 * RNG.standard_normal(system.x0.shape)   # compressed springs
    x0[system.pinned] = system.x0[system.pinned]
    integ = get_integrator("implicit_euler")
    ctx = StepContext(SolverSpec("cholesky"))
    s = integ.start(system, x0, np.zeros_like(x0), 0.0, 1.0, ctx)
    with pytest.raises(NotSPDError, match="not positive definite"):
        integ.step(system, s, 1.0, ctx)


@pytest.mark.parametrize("opts", [{"chebyshev_rho": 1.0}, {"chebyshev_delay": 0},
                                  {"chebyshev_warmup": 2}], ids=["rho", "delay", "warmup"])
def test_bad_chebyshev_options_raise(opts):
    with pytest.raises(InputError, match="chebyshev"):
        get_integrator("fast_mass_spring", chebyshev=True, **opts)


@pytest.mark.cholmod
@pytest.mark.parametrize("name,opts", [("implicit_euler", {"fix": "clamp"}), ("newton", {"tol": 1e-12})],
                         ids=["bw", "newton"])
def test_reused_cholesky_factor_preconditions_later_solves_to_the_same_step(name, opts):
    system = _cloth(forces=[Gravity(9.81)])
    exact, ctx_e = _run(name, system, "cholesky", steps=6, **opts)
    reuse, ctx_r = _run(name, system, "cholesky", steps=6, reuse_factorization=True, **opts)
    disp = np.abs(exact.x - system.x0).max()
    np.testing.assert_allclose(reuse.x, exact.x, rtol=0, atol=1e-7 * disp)
    assert ctx_r.stats["factorizations"] < ctx_e.stats["factorizations"]
    assert ctx_r.stats["linear_iterations"] > 0          # PCG with the kept factor did the rest
