"""The residual estimator's compiled passes (large meshes) give the NumPy path's numbers bit for
bit, with every kind of data (kappa constant, per region or a function; a constant, Python or
compiled source; Neumann data constant or a function, Dirichlet edges), and allocate only their
outputs and a few bytes per edge (traced by tracemalloc, which sees every NumPy allocation)."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import femkit.fem.estimators.geometry as geometry
import femkit.fem.estimators.residual as residual
import femkit.fem.sparsity as sparsity
from femkit.case.compiled_expressions import expression_kernels
from femkit.case.expressions import Gradient, compile_expression
from femkit.fem import error_norms
from femkit.fem.estimators import residual_estimator
from femkit.mesh import Mesh, edges, structured_mesh

V = ("x", "y", "z")


def _mesh(n=12):
    """A perturbed structured mesh with two cell regions and tagged sides."""
    m = structured_mesh(n, n)
    rng = np.random.default_rng(3)
    p = m.points.copy()
    inner = ((p > 1e-9) & (p < 1 - 1e-9)).all(axis=1)
    p[inner] += 0.2 / n * rng.uniform(-1, 1, (int(inner.sum()), 2))
    tags = np.where(m.centroids()[:, 0] < 0.5, 11, 17)
    names = {**m.tag_names, "left_half": 11, "right_half": 17}
    return Mesh(p, m.triangles, cell_tags=tags, boundary_edges=m.boundary_edges,
                boundary_tags=m.boundary_tags, tag_names=names)


def _compiled_source():
    source = compile_expression("2 * pi**2 * sin(pi * x) * sin(pi * y)", V)
    exact = compile_expression("sin(pi * x) * sin(pi * y)", V)
    grad = [compile_expression(g, V) for g in ("pi * cos(pi * x) * sin(pi * y)",
                                               "pi * sin(pi * x) * cos(pi * y)")]
    expression_kernels(exact, grad, source, fuse_source=True)
    return source, exact, Gradient(grad)


KAPPAS = {"constant": 2.5, "regions": {"left_half": 1.0, "right_half": 1e3},
          "function": lambda x, y: 1.0 + x * y, "array-uniform": "array"}
SOURCES = ("zero", "constant", "python", "compiled", "compiled-kept")
BOUNDARY = {
    "all-dirichlet": ((), "all"),
    "neumann-constant": (((["top"], 0.5),), "bottom"),
    "neumann-function": (((["right", "top"], lambda x, y: x - y),), "left"),
    "no-dirichlet": (((["left"], -1.0),), None),
}


@pytest.mark.parametrize("boundary", list(BOUNDARY))
@pytest.mark.parametrize("source", SOURCES)
@pytest.mark.parametrize("kappa", list(KAPPAS))
def test_compiled_estimator_equals_numpy_bit_for_bit(kappa, source, boundary, monkeypatch):
    mesh = _mesh()
    k = KAPPAS[kappa]
    if k == "array":
        k = np.full(mesh.n_cells, 3.0)
    u = np.sin(3 * mesh.points[:, 0]) * mesh.points[:, 1] + mesh.points[:, 0] ** 2
    neumann, dir_side = BOUNDARY[boundary]
    dirichlet = (None if dir_side is None else np.arange(mesh.n_points) if dir_side == "all"
                 else np.unique(mesh.boundary_edges[mesh.boundary_tags == mesh.tag(dir_side)]))
    results = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(geometry, "NUMBA_THRESHOLD", threshold)
        monkeypatch.setattr(residual, "NUMBA_THRESHOLD", threshold)
        monkeypatch.setattr(sparsity, "NUMBA_THRESHOLD", threshold)   # per_region
        f = {"zero": 0.0, "constant": 4.0, "python": lambda x, y: np.exp(x) - y}.get(source)
        if f is None:
            f, exact, grad = _compiled_source()
            if source == "compiled-kept":   # the error pass keeps the source norm for the estimate
                error_norms(mesh, u, exact, grad)
        est = residual_estimator(mesh, u, kappa=k, f=f, neumann=neumann,
                                 dirichlet_nodes=dirichlet)
        results.append((est, est.per_region(mesh)))
    (ref, ref_regions), (got, got_regions) = results
    for part in ("volume", "jump", "neumann"):
        np.testing.assert_array_equal(got.parts[part], ref.parts[part], err_msg=part)
    np.testing.assert_array_equal(got.indicators, ref.indicators)
    assert got_regions == ref_regions and set(got_regions) == {"left_half", "right_half"}
    assert got.energy > 0 and (boundary == "all-dirichlet") == (not got.parts["neumann"].any())


def test_degenerate_triangles_and_bad_data_are_named_as_by_numpy(monkeypatch):
    from femkit.errors import DegenerateMeshError, InputError

    flat = Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]]),
                np.array([[0, 1, 2], [0, 1, 3]]))
    mesh = _mesh(4)
    messages = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(residual, "NUMBA_THRESHOLD", threshold)
        got = []
        for call in (lambda: residual_estimator(flat, np.zeros(4)),
                     lambda: residual_estimator(mesh, np.zeros(mesh.n_points), kappa=-1.0),
                     lambda: residual_estimator(mesh, np.zeros(3))):
            with pytest.raises((DegenerateMeshError, InputError)) as info:
                call()
            got.append(f"{type(info.value).__name__}: {info.value}")
        messages.append(got)
    assert messages[0] == messages[1]
    assert "1 triangle(s) with zero" in messages[1][0] and "kappa" in messages[1][1]


def _traced_peak(run) -> int:
    tracemalloc.start()
    try:
        run()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_compiled_estimator_allocates_its_outputs_and_a_few_bytes_per_edge():
    """Outputs: volume, jump, indicators (8 bytes per element each); scratch: 9 bytes per edge
    and the boundary's data. NumPy's path forms (m, 3, 2) edge vectors, (m, 3) lengths, fluxes
    and their products: several times more."""
    from femkit.mesh import refine

    mesh = refine(_mesh(16), 3)              # 24,576 triangles: above the compiled threshold
    m, n_edges = mesh.n_cells, len(edges(mesh)[0])   # edges cached first: the pipeline's case
    u = np.sin(3 * mesh.points[:, 0]) * mesh.points[:, 1]
    run = lambda: residual_estimator(mesh, u, kappa=1.0, f=2.0, dirichlet_nodes=np.arange(4))
    old = residual.NUMBA_THRESHOLD
    try:
        residual.NUMBA_THRESHOLD = 0
        run()                                # compiled (or loaded) before tracing
        compiled = _traced_peak(run)
        residual.NUMBA_THRESHOLD = 10 ** 12
        numpy_path = _traced_peak(run)
    finally:
        residual.NUMBA_THRESHOLD = old
    budget = 3 * 8 * m + 9 * n_edges + 16 * mesh.n_points + 200_000
    assert compiled <= budget, (compiled, budget)
    assert numpy_path > 3 * compiled, (numpy_path, compiled)


def test_compiled_estimator_equals_numpy_on_an_unperturbed_structured_mesh(monkeypatch):
    """Right isosceles triangles: two legs of exactly one length, the longest edge unique."""
    mesh = structured_mesh(9, 9)
    u = np.cos(2 * mesh.points[:, 0]) + mesh.points[:, 1] ** 3
    results = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(geometry, "NUMBA_THRESHOLD", threshold)
        monkeypatch.setattr(residual, "NUMBA_THRESHOLD", threshold)
        results.append(residual_estimator(mesh, u, kappa=1.0, f=lambda x, y: x + 2 * y,
                                          dirichlet_nodes=np.arange(mesh.n_points)))
    np.testing.assert_array_equal(results[1].indicators, results[0].indicators)


@pytest.mark.parametrize("n_tags", [1, 2, 37], ids=["one-tag", "two-tags", "37-tags"])
def test_squares_by_tag_equals_bincount_bit_for_bit(n_tags):
    """The compiled per-region sums (each tag found by bisection) are NumPy's, in the same order."""
    from femkit.fem.estimators._kernels import squares_by_tag

    rng = np.random.default_rng(n_tags)
    values = np.sort(rng.choice(np.arange(-50, 10_000), n_tags, replace=False))
    tags = values[rng.integers(0, n_tags, 5000)]
    ind = rng.uniform(0.0, 1.0, len(tags))
    uniq, inv = np.unique(tags, return_inverse=True)
    expected = np.bincount(inv, weights=ind ** 2, minlength=len(uniq))
    np.testing.assert_array_equal(squares_by_tag(tags, uniq, ind), expected)
