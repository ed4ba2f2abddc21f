"""The fused, compiled passes give the NumPy path's numbers: error norms, the residual estimate
and the energy error to 1e-12 relative, with expressions of a case file compiled by the case layer;
a non-finite value or a degenerate cell is reported by the NumPy path exactly as before."""

from __future__ import annotations

import numpy as np
import pytest

import femkit.fem.fused.kernels as fused_kernels
from femkit.case.compiled_expressions import expression_kernels
from femkit.case.expressions import Gradient, compile_expression
from femkit.errors import DegenerateMeshError, ExpressionError
from femkit.fem import energy_error, error_norms
from femkit.fem.estimators import residual_estimator
from femkit.fem.fused import kernels_for
from femkit.mesh import Mesh, structured_mesh

from ._tets import perturbed_box

V = ("x", "y", "z")

#: (u, gradient components, f) as a case file gives them
SETS = {
    "sin-2d": ("sin(pi * x) * sin(pi * y)",
               ["pi * cos(pi * x) * sin(pi * y)", "pi * sin(pi * x) * cos(pi * y)"],
               "2 * pi**2 * sin(pi * x) * sin(pi * y)"),
    "exp-poly-2d": ("exp(x) * y**2 + x", ["exp(x) * y**2 + 1", "2 * y * exp(x)"],
                    "-(exp(x) * y**2 + 2 * exp(x))"),
    "singular-no-gradient": ("hypot(x, y)**(2/3) * sin(2/3 * mod(arctan2(y, x), 2*pi))", [], "0"),
    "where-constants": ("where(x < 0.5, k * x**2, k / 4 + (x - 0.5))", [], "c * x * y"),
    "sin-3d": ("sin(pi*x) * sin(pi*y) * sin(pi*z)",
               ["pi*cos(pi*x)*sin(pi*y)*sin(pi*z)", "pi*sin(pi*x)*cos(pi*y)*sin(pi*z)",
                "pi*sin(pi*x)*sin(pi*y)*cos(pi*z)"], "3*pi**2*sin(pi*x)*sin(pi*y)*sin(pi*z)"),
    # arguments beyond the inlined kernels' range (|x| > 1e5 for sin, < -708 for exp) in some
    # blocks of points: those take the C library's functions
    "beyond-kernel-range-2d": ("1e-3 * sin(2e5 * x) + exp(720 * x - 719)",
                               ["200 * cos(2e5 * x) + 720 * exp(720 * x - 719)", "0 * y"],
                               "4e7 * sin(2e5 * x) - 518400 * exp(720 * x - 719)"),
    "exp-cos-3d": ("exp(x + 2*y - z) * cos(3*z)",
                   ["exp(x + 2*y - z) * cos(3*z)", "2 * exp(x + 2*y - z) * cos(3*z)",
                    "-exp(x + 2*y - z) * (cos(3*z) + 3 * sin(3*z))"], "exp(x + 2*y) * 0 + 1"),
}


def _mesh(name):
    # 750 tetrahedra, 312 triangles: not multiples of the passes' block of 32 cells (the last
    # block is partial)
    if name.endswith("3d"):
        return perturbed_box(5)
    m = structured_mesh(13, 12)
    rng = np.random.default_rng(3)
    p = m.points.copy()
    inner = ((p > 1e-9) & (p < 1 - 1e-9)).all(axis=1)
    p[inner] += 0.02 * rng.uniform(-1, 1, (int(inner.sum()), 2))
    return Mesh(p, m.triangles)


def _functions(name, fuse_source=True):
    u, grad, f = SETS[name]
    consts = {"k": 2.0, "c": 3.0}
    exact = compile_expression(u, V, consts)
    parts = [compile_expression(g, V, consts, check_finite=False) for g in grad]
    source = compile_expression(f, V, consts)
    kernels = expression_kernels(exact, parts, source, fuse_source=fuse_source)
    return exact, (Gradient(parts) if parts else None), source, kernels


def _numpy_and_fused(monkeypatch, run):
    """``run()`` by the NumPy path, then by the compiled one."""
    monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", 10 ** 12)
    reference = run()
    monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", 0)
    return reference, run()


@pytest.mark.parametrize("name", list(SETS))
def test_errors_estimate_and_energy_error_match_the_numpy_path(name, monkeypatch):
    mesh = _mesh(name)
    exact, grad, f, kernels = _functions(name)
    assert kernels.module.HAS_SOURCE
    pts = mesh.points.T
    u = exact(*pts) + 1e-3 * np.sin(3 * pts[0] + 2 * pts[1])     # a discrete solution's error

    def run():
        errs = error_norms(mesh, u, exact, grad)
        est = residual_estimator(mesh, u, kappa=2.0, f=f, dirichlet_nodes=np.arange(0))
        energy = energy_error(mesh, u, grad, 2.0, per_element=True) if grad is not None else None
        return errs, est, energy

    (e0, s0, g0), (e1, s1, g1) = _numpy_and_fused(monkeypatch, run)
    assert kernels_for(mesh, exact=exact, grad_exact=grad) is kernels
    for key in ("L2", "H1_semi", "max_nodal"):
        if e0[key] is None:
            assert e1[key] is None and grad is None
        else:
            assert e1[key] == pytest.approx(e0[key], rel=1e-12, abs=0), key
    np.testing.assert_allclose(s1.indicators, s0.indicators, rtol=1e-12, atol=0)
    assert s1.energy == pytest.approx(s0.energy, rel=1e-12)
    if grad is not None:
        np.testing.assert_allclose(g1, g0, rtol=1e-12, atol=0)


def test_the_source_alone_is_compiled_for_the_estimator(monkeypatch):
    """No exact solution (or a source not fused into the error pass): its own compiled pass."""
    mesh = _mesh("sin-2d")
    _, _, f, kernels = _functions("exp-poly-2d", fuse_source=False)
    assert not kernels.module.HAS_SOURCE
    u = np.cos(mesh.points[:, 0])
    s0, s1 = _numpy_and_fused(monkeypatch, lambda: residual_estimator(mesh, u, f=f))
    np.testing.assert_allclose(s1.parts["volume"], s0.parts["volume"], rtol=1e-12, atol=0)


def test_kernels_are_used_only_for_the_callables_they_stand_for(monkeypatch):
    monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", 0)
    mesh = _mesh("sin-2d")
    exact, grad, f, kernels = _functions("sin-2d")
    other = compile_expression("sin(pi * x) * sin(pi * y)", V)     # same text, not attached
    assert kernels_for(mesh, exact=exact, grad_exact=grad, source=f) is kernels
    assert kernels_for(mesh, exact=other, grad_exact=grad) is None
    assert kernels_for(mesh, exact=exact, grad_exact=lambda x, y: (x, y)) is None
    assert kernels_for(mesh, exact=f) is None                          # the source is not u
    box = perturbed_box(2)
    assert kernels_for(box, exact=exact) is kernels                    # u(x, y) on a 3D mesh: fine
    assert kernels_for(box, exact=exact, grad_exact=grad) is None      # but 3 gradient components
    swapped = Gradient(list(reversed(grad.parts)))
    assert swapped.fused is None and kernels_for(mesh, exact=exact, grad_exact=swapped) is None
    monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", mesh.n_cells + 1)
    assert kernels_for(mesh, exact=exact) is None                      # small mesh: NumPy


def test_non_finite_values_and_degenerate_cells_are_reported_as_by_numpy(monkeypatch):
    mesh = _mesh("sin-2d")
    exact = compile_expression("log(x)", V)                           # -inf on x = 0
    exact.label = "exact.u"
    expression_kernels(exact)
    u = np.zeros(mesh.n_points)
    messages = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", threshold)
        with pytest.raises(ExpressionError) as info:
            error_norms(mesh, u, exact)
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "exact.u: expression 'log(x)' gave non-finite" in messages[0]
    flat = Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]]),
                np.array([[0, 1, 2], [0, 1, 3]]))
    ok = compile_expression("x + y", V)
    expression_kernels(ok)
    with pytest.raises(DegenerateMeshError, match="1 triangle"):
        error_norms(flat, np.zeros(4), ok)


def _equilateral(n: int) -> Mesh:
    """A lattice of ``2 n^2`` equilateral triangles: every edge the same length up to rounding."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    points = np.stack([i + 0.5 * j, (np.sqrt(3) / 2) * j], axis=-1).reshape(-1, 2) / n
    v = (i[:-1, :-1] * (n + 1) + j[:-1, :-1]).ravel()
    up = np.stack([v, v + n + 1, v + 1], axis=1)
    down = np.stack([v + n + 1, v + n + 2, v + 1], axis=1)
    return Mesh(points, np.concatenate([up, down]))


def test_longest_edge_is_hypots_maximum_where_squares_order_edges_otherwise():
    """``h_T`` by hypot of the edges whose squares nearly tie equals NumPy's ``max`` of every
    edge's hypot, also for pairs of edges whose rounded squares and hypots disagree on which is
    longer (about one pair in a thousand of equal exact length)."""
    from femkit.fem.estimators._kernels import _longest

    rng = np.random.default_rng(0)
    a = rng.uniform(0.1, 1.0, (200_000, 2))
    turn = rng.uniform(-0.9, 0.9, len(a))               # < 60 degrees: the third edge is shorter
    c, s_ = np.cos(turn), np.sin(turn)
    b = np.stack([c * a[:, 0] - s_ * a[:, 1], s_ * a[:, 0] + c * a[:, 1]], axis=1)
    sq = lambda v: v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1]  # noqa: E731
    h = lambda v: np.hypot(v[:, 0], v[:, 1])  # noqa: E731
    disagree = np.flatnonzero((sq(a) > sq(b)) != (h(a) > h(b)))
    assert len(disagree) > 20
    for k in disagree[:200]:
        e = np.array([b[k] - a[k], -b[k], a[k]])
        assert _longest(e) == np.hypot(e[:, 0], e[:, 1]).max()


#: Meshes of the bit-for-bit estimator test: perturbed, equilateral (the three edges tie for the
#: longest within rounding), and scaled so far down that the squared edge lengths fall below
#: 1e-280 (the longest edge then by hypot of every edge).
ESTIMATOR_MESHES = {
    "perturbed": lambda: _mesh("sin-2d"),
    "equilateral": lambda: _equilateral(13),
    "scaled-1e-141": lambda: Mesh(1e-141 * _mesh("sin-2d").points, _mesh("sin-2d").triangles),
}


@pytest.mark.parametrize("where", list(ESTIMATOR_MESHES))
@pytest.mark.parametrize("kappa", [1.0, "regions"], ids=["kappa-1", "kappa-per-region"])
def test_compiled_residual_estimator_gives_the_same_bits(kappa, where, monkeypatch):
    """The estimator's element and edge terms compiled (large meshes) equal NumPy's exactly."""
    import femkit.fem.estimators.geometry as geometry
    import femkit.fem.estimators.residual as residual

    mesh = ESTIMATOR_MESHES[where]()
    k = (np.where(mesh.centroids()[:, 0] < 0.5 * mesh.points[:, 0].max(), 1.0, 1e3)
         if kappa == "regions" else kappa)
    x, y = (mesh.points / np.abs(mesh.points).max()).T
    u = np.sin(3 * x) * y
    bottom = np.flatnonzero(y < 1e-12)
    results = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(geometry, "NUMBA_THRESHOLD", threshold)
        monkeypatch.setattr(residual, "NUMBA_THRESHOLD", threshold)
        results.append(residual_estimator(mesh, u, kappa=k, f=1.0, dirichlet_nodes=bottom))
    for part in ("volume", "jump", "neumann"):
        np.testing.assert_array_equal(results[1].parts[part], results[0].parts[part])


@pytest.mark.parametrize("name, rule", [
    (name, rule) for name in SETS
    for rule in (("barycentric", "stroud8") if name.endswith("3d") else ("barycentric", "gauss3", "gauss7"))])
def test_load_vector_of_a_compiled_source_matches_the_numpy_path(name, rule, monkeypatch):
    """The load's source values by the compiled pass: the points of ``physical_points`` and the
    same expression, so the same load vector (bit for bit on this machine; asserted to 1e-12)."""
    from femkit.fem import assemble_load
    from femkit.fem.fused import source_values
    from femkit.fem.quadrature import get_rule

    mesh = _mesh(name)
    _, _, f, kernels = _functions(name)
    calls = []
    real = kernels.module.source_values
    monkeypatch.setattr(kernels.module, "source_values", lambda *a: calls.append(1) or real(*a))
    F0, F1 = _numpy_and_fused(monkeypatch, lambda: assemble_load(mesh, f, rule=rule))
    assert calls == [1]                                               # the compiled pass ran
    np.testing.assert_allclose(F1, F0, rtol=1e-12, atol=1e-14 * np.abs(F0).max())
    quad = get_rule(rule, dim=mesh.dim)
    fq = source_values(mesh, f, quad)
    np.testing.assert_allclose(fq, f(*quad.physical_points(mesh, mesh.cells)), rtol=1e-12, atol=0)
    assert source_values(mesh, compile_expression(SETS[name][2], V, {"k": 2.0, "c": 3.0}),
                         quad) is None                                # not the case's source


@pytest.mark.parametrize("name", list(SETS))
def test_one_pass_load_equals_the_two_passes_bit_for_bit(name, monkeypatch):
    """The one-point load in one fused pass is what the source values then the load kernel give."""
    from femkit.fem._kernels import load_kernel
    from femkit.fem.fused import barycentric_load, source_values
    from femkit.fem.quadrature import get_rule

    monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", 0)
    mesh = _mesh(name)
    _, _, f, _ = _functions(name)
    quad = get_rule("barycentric", dim=mesh.dim)
    two = load_kernel(mesh, None, source_values(mesh, f, quad)[:, 0])
    np.testing.assert_array_equal(barycentric_load(mesh, f, quad), two)


def test_one_pass_load_leaves_degenerate_cells_and_non_finite_sources_to_the_two_passes(
        monkeypatch):
    """A cell of zero area, or a source that is NaN somewhere: the pass counts them and the
    caller gets None (the two passes then name them, as the NumPy path does)."""
    from femkit.fem.fused import barycentric_load
    from femkit.fem.quadrature import get_rule

    monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", 0)
    mesh = _mesh("sin-2d")
    quad = get_rule("barycentric", dim=2)
    points = mesh.points.copy()
    points[mesh.cells[5, 0]] = points[mesh.cells[5, 1]]      # a cell of zero area
    flat = Mesh(points, mesh.cells)
    _, _, f, kernels = _functions("sin-2d")
    args = (np.ascontiguousarray(quad.points), mesh.n_points)
    assert kernels.module.barycentric_load(flat.points, flat.cells, *args)[1:] == (1, 0)
    assert barycentric_load(flat, f, quad) is None
    nan_f = compile_expression("sqrt(x - 0.5)", V, check_finite=False)   # NaN for x < 1/2
    nan_kernels = expression_kernels(None, (), nan_f)
    bad, nonfinite = nan_kernels.module.barycentric_load(mesh.points, mesh.cells, *args)[1:]
    assert bad == 0 and 0 < nonfinite < mesh.n_cells
    assert barycentric_load(mesh, nan_f, quad) is None


@pytest.mark.parametrize("rule", ["gauss3", "barycentric"])
def test_load_of_a_non_finite_compiled_source_is_refused_as_by_numpy(rule, monkeypatch):
    from femkit.errors import InputError
    from femkit.fem import assemble_load

    mesh = _mesh("sin-2d")
    f = compile_expression("sqrt(x - 0.5)", V, check_finite=False)   # NaN for x < 1/2
    expression_kernels(None, (), f)
    messages = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", threshold)
        with pytest.raises(InputError) as info:
            assemble_load(mesh, f, rule=rule)
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "source f is not finite" in messages[0]
