"""The method-of-lines schemes (femkit.dynamics.mol) on P1 systems of femkit's meshes.

Every expected number comes from theory, never from femkit's own output: orders in time fitted
by slope against a semi-discrete reference of the same mesh (a run at 1/64 of the finest step,
whose own error is far below the fitted ones), the space order against the exact solution
``exp(-2 pi^2 t) sin(pi x) sin(pi y)``, the critical step against the closed form of the
lumped 5-point stencil, the explicit Euler threshold by running on both sides of it, exact
energy conservation of the average-acceleration rule, and scikit-fem's own M and K with SciPy's
factorisation step by step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from femkit.dynamics.mol import (HEAT_INTEGRATORS, WAVE_INTEGRATORS, LinearSystem, critical_step,
                                 get_scheme, largest_eigenvalue, march)
from femkit.fem import assemble_stiffness, error_norms
from femkit.fem.mass import mass_matrix
from femkit.mesh import boundary_nodes
from femkit.mesh.structured import structured_mesh

LAMBDA = 2.0 * math.pi ** 2


def _system(n, lumped=False, **kw):
    mesh = structured_mesh(n, n)
    M = mass_matrix(mesh, lumped=lumped)
    return mesh, LinearSystem(M, assemble_stiffness(mesh, 1.0), boundary_nodes(mesh, None),
                              lumped=lumped, **kw)


def _mode(mesh, t=0.0):
    x, y = mesh.points.T
    return math.exp(-LAMBDA * t) * np.sin(np.pi * x) * np.sin(np.pi * y)


def _slope(hs, errs):
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0])


def _final(system, name, u0, dt, steps, **options):
    return march(system, get_scheme(HEAT_INTEGRATORS, name, **options), u0, 0.0, dt, steps).frames[-1][1]


@pytest.mark.parametrize("name, order", [("implicit_euler", 1), ("crank_nicolson", 2), ("bdf2", 2)])
def test_heat_time_order_by_slope(name, order):
    mesh, s = _system(12)
    u0 = _mode(mesh)
    T = 0.05
    ref = _final(s, "crank_nicolson", u0, T / 2560, 2560)
    counts = [10, 20, 40]
    errs = [np.abs(_final(s, name, u0, T / k, k) - ref).max() for k in counts]
    assert abs(_slope([T / k for k in counts], errs) - order) < 0.15, errs


def test_heat_space_order_l2_against_the_exact_solution():
    T, errs, hs = 0.05, [], []
    for n in (8, 16, 32):
        mesh, s = _system(n)
        u = _final(s, "bdf2", _mode(mesh), T / 200, 200)
        exact = lambda x, y: math.exp(-LAMBDA * T) * np.sin(np.pi * x) * np.sin(np.pi * y)  # noqa: E731
        errs.append(error_norms(mesh, u, exact)["L2"])
        hs.append(1.0 / n)
    assert abs(_slope(hs, errs) - 2.0) < 0.1, errs


def test_crank_nicolson_equals_scikit_fem_step_by_step():
    """scikit-fem's assembled M and K on femkit's own mesh, condensed, the theta-method matrix
    factorised once by SciPy's splu: every step equal to femkit's to 1e-10."""
    skfem = pytest.importorskip("skfem")
    from scipy.sparse.linalg import splu
    from skfem.models.poisson import laplace, mass

    mesh, s = _system(10)
    m = skfem.MeshTri(mesh.points.T.copy(), mesh.cells.T.copy())
    basis = skfem.Basis(m, skfem.ElementTriP1())
    K, M = laplace.assemble(basis), mass.assemble(basis)
    D = m.boundary_nodes()
    free = np.setdiff1d(np.arange(m.p.shape[1]), D)
    dt = 0.002
    A = (M + 0.5 * dt * K).tocsc()[free][:, free]
    B = (M - 0.5 * dt * K).tocsr()[free][:, free]
    lu = splu(A.tocsc())
    u = _mode(mesh)
    ref = u[free].copy()
    result = march(s, get_scheme(HEAT_INTEGRATORS, "crank_nicolson"), u, 0.0, dt, 20)
    assert len(result.frames) == 21
    for k in range(1, 21):
        ref = lu.solve(B @ ref)
        assert np.abs(result.frames[k][1][free] - ref).max() <= 1e-10 * np.abs(ref).max()


def test_lumped_critical_step_is_the_closed_form_of_the_five_point_stencil():
    """On the uniform right-triangle grid P1's K is the 5-point Laplacian and the lumped mass is
    h^2 per interior node: lambda_max = 8 / h^2 cos^2(pi / 2n) exactly."""
    n = 16
    _, s = _system(n, lumped=True)
    h = 1.0 / n
    assert largest_eigenvalue(s) == pytest.approx(8.0 / h ** 2 * math.cos(math.pi / (2 * n)) ** 2,
                                                  rel=1e-9)
    dt, lam = critical_step(get_scheme(HEAT_INTEGRATORS, "explicit_euler"), s)
    assert dt == pytest.approx(2.0 / lam)


def test_lumped_versus_consistent_critical_steps():
    """P1: M_lumped - M_consistent is positive semidefinite and M_consistent >= M_lumped / (d + 2)
    cell by cell, so 1 <= dt_crit(lumped) / dt_crit(consistent) <= d + 2 (1D: 3, 2D: 4)."""
    scheme = get_scheme(HEAT_INTEGRATORS, "explicit_euler")
    (_, sc), (_, sl) = _system(20), _system(20, lumped=True)
    ratio = critical_step(scheme, sl)[0] / critical_step(scheme, sc)[0]
    assert 1.0 < ratio <= 4.0, ratio
    assert ratio > 2.0  # the lumped step is much larger on a uniform grid, not marginally


@pytest.mark.parametrize("lumped", [True, False])
def test_explicit_euler_threshold_within_two_percent(lumped):
    """Below the computed critical step (0.99) the norm of a random start decays, above it
    (1.01) it grows: the measured threshold lies within 1% of the computed one."""
    mesh, s = _system(12, lumped=lumped)
    scheme = get_scheme(HEAT_INTEGRATORS, "explicit_euler")
    dt_crit, _ = critical_step(scheme, s)
    u0 = np.random.default_rng(1).standard_normal(mesh.n_points)
    norms = {}
    for f in (0.99, 1.01):
        u = march(s, scheme, u0, 0.0, f * dt_crit, 1500).frames[-1][1]
        norms[f] = np.linalg.norm(u) / np.linalg.norm(u0)
    assert norms[0.99] < 1.0 and norms[1.01] > 1e3, norms


def test_adaptive_implicit_euler_meets_its_tolerance_with_fewer_steps_than_fixed():
    from femkit.dynamics.mol import march_adaptive

    mesh, s = _system(12)
    u0 = _mode(mesh)
    T = 0.1
    runs = {rtol: march_adaptive(s, get_scheme(HEAT_INTEGRATORS, "implicit_euler"), u0, 0.0, T,
                                 1e-4, rtol) for rtol in (1e-2, 1e-3)}
    ref = _final(s, "crank_nicolson", u0, T / 2000, 2000)
    for rtol, r in runs.items():
        assert r.t_reached == pytest.approx(T, abs=1e-12) and r.failure is None
        assert len(set(r.dts)) > 2  # the step did change
    e = {rtol: np.abs(r.frames[-1][1] - ref).max() for rtol, r in runs.items()}
    assert runs[1e-3].steps > runs[1e-2].steps and e[1e-3] < e[1e-2]


def test_newmark_average_acceleration_conserves_energy_over_1000_steps():
    mesh, s = _system(10)
    rng = np.random.default_rng(2)
    u0, v0 = rng.standard_normal(mesh.n_points), rng.standard_normal(mesh.n_points)
    u0[s.fixed] = 0.0
    v0[s.fixed] = 0.0
    r = march(s, get_scheme(WAVE_INTEGRATORS, "newmark"), u0, 0.0, 1e-3, 1000, v0=v0, every=100)
    E = [s.energy(u, v)["total"] for _, u, v in r.frames]
    assert len(E) == 11 and max(abs(e - E[0]) for e in E) <= 1e-10 * E[0]
    # implicit Euler on the same start dissipates (the comparison the wave study draws)
    d = march(s, get_scheme(WAVE_INTEGRATORS, "implicit_euler"), u0, 0.0, 1e-3, 100, v0=v0)
    assert s.energy(*d.frames[-1][1:])["total"] < 0.9 * E[0]


def _standing(mesh, t):
    x, y = mesh.points.T
    return math.cos(math.sqrt(2.0) * math.pi * t) * np.sin(np.pi * x) * np.sin(np.pi * y)


@pytest.mark.parametrize("name", ["central_difference", "newmark", "variational_symplectic"])
def test_wave_second_order_in_time(name):
    mesh, s = _system(10, lumped=name == "central_difference")
    u0, v0, T = _standing(mesh, 0.0), np.zeros(mesh.n_points), 0.5
    scheme = get_scheme(WAVE_INTEGRATORS, name)
    ref = march(s, get_scheme(WAVE_INTEGRATORS, "newmark"), u0, 0.0, T / 4096, 4096, v0=v0).frames[-1][1]
    counts = [40, 80, 160]  # dt_crit of central difference here ~ 0.027: all below
    errs = [np.abs(march(s, scheme, u0, 0.0, T / k, k, v0=v0).frames[-1][1] - ref).max()
            for k in counts]
    assert abs(_slope([T / k for k in counts], errs) - 2.0) < 0.15, errs


def test_standing_wave_space_order_l2():
    T, errs, hs = 0.5, [], []
    for n in (8, 16, 32):
        mesh, s = _system(n)
        u = march(s, get_scheme(WAVE_INTEGRATORS, "newmark"), _standing(mesh, 0.0), 0.0, T / 400,
                  400, v0=np.zeros(mesh.n_points)).frames[-1][1]
        exact = lambda x, y: math.cos(math.sqrt(2) * math.pi * T) * np.sin(np.pi * x) * np.sin(np.pi * y)  # noqa: E731
        errs.append(error_norms(mesh, u, exact)["L2"])
        hs.append(1.0 / n)
    assert abs(_slope(hs, errs) - 2.0) < 0.15, errs


def test_central_difference_blows_up_above_its_critical_step():
    mesh, s = _system(8, lumped=True)
    scheme = get_scheme(WAVE_INTEGRATORS, "central_difference")
    dt_crit, lam = critical_step(scheme, s)
    assert dt_crit == pytest.approx(2.0 / math.sqrt(lam))
    u0 = np.random.default_rng(3).standard_normal(mesh.n_points)
    grow = march(s, scheme, u0, 0.0, 1.02 * dt_crit, 600, v0=np.zeros_like(u0)).frames[-1][1]
    keep = march(s, scheme, u0, 0.0, 0.98 * dt_crit, 600, v0=np.zeros_like(u0)).frames[-1][1]
    assert np.linalg.norm(grow) > 1e3 * np.linalg.norm(u0) > 1e3 * np.linalg.norm(keep) / 10


def test_theta_one_is_implicit_euler_and_bad_options_are_refused():
    from femkit.errors import InputError

    mesh, s = _system(6)
    u0 = _mode(mesh)
    a = _final(s, "crank_nicolson", u0, 0.01, 5, theta=1.0)
    b = _final(s, "implicit_euler", u0, 0.01, 5)
    assert np.abs(a - b).max() <= 1e-14 * np.abs(b).max()
    with pytest.raises(InputError, match="theta must lie in"):
        get_scheme(HEAT_INTEGRATORS, "crank_nicolson", theta=1.5)
    with pytest.raises(InputError, match="beta > 0"):
        get_scheme(WAVE_INTEGRATORS, "newmark", beta=0.0)
    assert get_scheme(WAVE_INTEGRATORS, "newmark", beta=0.0 + 1e-3, gamma=0.5).stability_bound < 100


@pytest.mark.parametrize("pc,options", [("amg", {}), ("ic0", {}), ("ic0", {"ordering": "rcm"})],
                         ids=["amg", "ic0", "ic0-rcm"])
def test_iterative_steps_keep_one_preconditioner_and_match_the_rebuild_path(pc, options):
    """With a fixed dt the step matrix is constant: its preconditioner is set up once over all
    steps (as the direct solver's factor is kept), and the states equal those of the path that
    rebuilds it every step, and the kept factor's, to the solver's tolerance (``rcm``: the
    kept path solves in the permuted order, the rebuild path lets IC(0) permute)."""
    from femkit.solvers import SolverSpec

    spec = SolverSpec.from_mapping({"method": "pcg", "preconditioner": pc, "rtol": 1e-10,
                                    "preconditioner_options": options})
    mesh, kept = _system(16, solver=spec)
    _, rebuilt = _system(16, solver=spec, keep_preconditioner=False)
    _, direct = _system(16)
    u0 = _mode(mesh)
    runs = {name: march(s, get_scheme(HEAT_INTEGRATORS, "implicit_euler"), u0, 0.0, 1e-3, 12)
            for name, s in (("kept", kept), ("rebuilt", rebuilt), ("direct", direct))}
    assert kept.stats["preconditioner_setups"] == 1
    assert kept.stats["linear_solves"] == 12
    assert "preconditioner_setups" not in rebuilt.stats   # one setup inside every solve instead
    assert rebuilt.stats["linear_solves"] == 12
    ref = runs["direct"].frames[-1][1]
    scale = np.abs(ref).max()
    for name in ("kept", "rebuilt"):
        assert np.abs(runs[name].frames[-1][1] - ref).max() < 1e-8 * scale, name
    # a new step matrix (BDF2: one Crank-Nicolson start, then 3/2 M + dt K) is a new setup
    _, bdf = _system(16, solver=spec)
    march(bdf, get_scheme(HEAT_INTEGRATORS, "bdf2"), u0, 0.0, 1e-3, 6)
    assert bdf.stats["preconditioner_setups"] == 2


def test_iterative_error_history_equals_direct_below_the_time_error():
    """The rule: at the default rtol (1e-10) the algebraic error a step adds is at most
    cond(M + dt K) rtol |u| (cond about 1 + dt lambda_max / lambda_min(M^-1 M) at these steps)
    and over N steps N times that, far below the time error (here 4e-4 to 1e-2 relative). So the
    error against the exact solution is the direct solver's to 1e-6 of itself at every step."""
    from femkit.solvers import SolverSpec

    mesh, it = _system(16, solver=SolverSpec.from_mapping({"method": "pcg"}))
    _, direct = _system(16)
    u0 = _mode(mesh)
    scheme = get_scheme(HEAT_INTEGRATORS, "implicit_euler")
    a = march(it, scheme, u0, 0.0, 2e-3, 25, every=1).frames
    b = march(direct, scheme, u0, 0.0, 2e-3, 25, every=1).frames
    assert len(a) == len(b) == 26
    for (t, ua, _), (_, ub, _) in zip(a[1:], b[1:]):
        ea, eb = np.abs(ua - _mode(mesh, t)).max(), np.abs(ub - _mode(mesh, t)).max()
        assert eb > 1e-4 * np.abs(ub).max()              # the time error is there to see
        assert abs(ea - eb) < 1e-6 * eb, (t, ea, eb)


def _two_rates():
    """``u' = -diag(1, 200) u``: a slow mode and a fast transient, exact ``exp(-lambda t)``."""
    import scipy.sparse as sp

    lam = np.array([1.0, 200.0])
    s = LinearSystem(sp.identity(2, format="csr"), sp.diags(lam, format="csr"), fixed=[],
                     lumped=True)
    return s, (lambda t: np.exp(-lam * t))


@pytest.mark.parametrize("name", ["crank_nicolson", "bdf2"])
def test_adaptive_second_order_schemes_need_fewer_steps_than_fixed_on_a_fast_transient(name):
    """Adaptive Crank-Nicolson and BDF2 (Milne's device) resolve the fast transient with small
    steps and then grow them; a fixed step taking even twice as many steps misses the
    adaptive run's accuracy (max error over time against the exact solution)."""
    from femkit.dynamics.mol import march_adaptive

    s, exact = _two_rates()
    scheme = get_scheme(HEAT_INTEGRATORS, name)
    T = 2.0
    r = march_adaptive(s, scheme, np.ones(2), 0.0, T, 1e-3, 1e-4)
    assert r.failure is None and r.t_reached == pytest.approx(T, abs=1e-12)
    assert all(e <= 1.0 for e in r.errors) and max(r.dts) >= 64 * min(r.dts)

    def worst(frames):
        return max(np.abs(u - exact(t)).max() for t, u, _ in frames)

    target = worst(r.frames)
    assert target < 1e-3
    for n in (r.steps, 2 * r.steps):
        assert worst(march(s, scheme, np.ones(2), 0.0, T / n, n).frames) > 10 * target


@pytest.mark.parametrize("name", ["crank_nicolson", "bdf2"])
@pytest.mark.parametrize("ratio", [1.0, 2.0], ids=["constant-step", "step-doubled"])
def test_the_embedded_estimate_is_within_a_factor_two_of_the_true_local_error(name, ratio):
    """One step from the exact past (the local error): the estimate against the true error on
    both modes (``lambda h`` = 0.002 and 0.4), for a constant step and a doubled one (BDF2's
    variable-step coefficients and error constant)."""
    from femkit.dynamics.mol import MolState

    s, exact = _two_rates()
    scheme = get_scheme(HEAT_INTEGRATORS, name)
    h = 0.002
    hp = h / ratio
    tn = 0.01
    past = [(tn - 2 * hp, exact(tn - 2 * hp)), (tn - hp, exact(tn - hp)), (tn, exact(tn))]
    state = MolState(tn, exact(tn), aux={"estimate": True, "history": past,
                                         "previous": exact(tn - hp), "dt": hp})
    new = scheme.step(s, state, h)
    true = new.u - exact(tn + h)
    q = new.aux["error"] / true
    assert np.all((q > 0.5) & (q < 2.0)), q
