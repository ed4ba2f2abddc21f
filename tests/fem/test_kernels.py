"""The compiled (numba) assembly paths agree with the numpy ones (used from 200k elements on)."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError, InputError
from femkit.fem import SparsityPattern, assemble_load, assemble_stiffness
from femkit.mesh import Mesh


def _scrambled(make_square, draw=3):
    """A structured square with randomly permuted node and element numbers (far-apart vertices)."""
    base = make_square(9)
    rng = np.random.default_rng(draw)
    perm = rng.permutation(base.n_points)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    tri = inv[base.triangles][rng.permutation(base.n_triangles)]
    return Mesh(base.points[perm], tri)


def _with_unreferenced_node(make_square):
    base = make_square(4)
    pts = np.vstack([base.points[:7], [[5.0, 5.0]], base.points[7:]])
    tri = np.where(base.triangles >= 7, base.triangles + 1, base.triangles)
    return Mesh(pts, tri)


MESHES = {"scrambled": _scrambled, "unreferenced-node": _with_unreferenced_node}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_pattern_kernel_equals_numpy_pattern(make_square, name):
    mesh = MESHES[name](make_square)
    fast = SparsityPattern.from_mesh(mesh, backend="numba")
    ref = SparsityPattern.from_mesh(mesh, backend="numpy")
    assert np.array_equal(fast.indptr, ref.indptr)
    assert np.array_equal(fast.indices, ref.indices)
    assert np.array_equal(fast.slots, ref.slots)
    assert fast.slots.dtype == np.int32  # half the memory traffic of int64


@pytest.mark.parametrize("kappa", [2.5, "per-element", "callable"])
def test_stiffness_kernel_equals_numpy(make_square, kappa):
    mesh = _scrambled(make_square)
    kap = {2.5: 2.5, "per-element": np.linspace(1, 3, mesh.n_triangles),
           "callable": lambda x, y: 1 + x * y}[kappa]
    for elements in (None, np.arange(0, mesh.n_triangles, 3)):
        K = assemble_stiffness(mesh, kap, elements=elements, backend="numba")
        K_ref = assemble_stiffness(mesh, kap, elements=elements, backend="numpy")
        assert abs(K - K_ref).max() <= 1e-13 * abs(K_ref).max()


@pytest.mark.parametrize("f", [1.5, lambda x, y: np.exp(x) * np.cos(2 * y)], ids=["scalar", "callable"])
@pytest.mark.parametrize("subset", [False, True], ids=["all", "subset"])
def test_load_kernel_equals_numpy(make_square, f, subset):
    mesh = _scrambled(make_square)
    elements = np.arange(1, mesh.n_triangles, 4) if subset else None
    F = assemble_load(mesh, f, elements=elements, backend="numba")
    F_ref = assemble_load(mesh, f, elements=elements, backend="numpy")
    assert np.allclose(F, F_ref, rtol=1e-13, atol=1e-16)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_load_kernel_names_degenerate_and_bad_source():
    mesh = Mesh(np.array([[0, 0], [1, 0], [0, 1], [2, 0]], float), [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(DegenerateMeshError) as info:
        assemble_load(mesh, 1.0, backend="numba")
    assert info.value.element_ids == [1]
    good = Mesh(np.array([[0, 0], [1, 0], [0, 1]], float), [[0, 1, 2]])
    with pytest.raises(InputError, match="not finite"):
        assemble_load(good, lambda x, y: np.log(x - x), backend="numba")
    with pytest.raises(InputError, match="valid: auto, numba, numpy"):
        assemble_load(good, 1.0, backend="fortran")


def test_unknown_stiffness_backend_raises_before_any_work():
    good = Mesh(np.array([[0, 0], [1, 0], [0, 1]], float), [[0, 1, 2]])
    with pytest.raises(InputError, match="'fortran'; valid: auto, numba, numpy"):
        assemble_stiffness(good, backend="fortran")
    assert SparsityPattern.cached(good) is None


@pytest.mark.parametrize("kappa", [2.5, "per-element"])
def test_first_assembly_builds_pattern_and_stiffness_in_one_pass(make_square, kappa):
    """A first numba assembly without a pattern fuses pattern + stiffness and caches the pattern."""
    mesh = _scrambled(make_square)
    kap = 2.5 if kappa == 2.5 else np.linspace(1, 3, mesh.n_triangles)
    assert SparsityPattern.cached(mesh) is None
    K = assemble_stiffness(mesh, kap, backend="numba")
    pat = SparsityPattern.cached(mesh)
    assert pat is not None and pat.slots.dtype == np.int32
    K_ref = assemble_stiffness(mesh, kap, backend="numpy", pattern=SparsityPattern.from_mesh(mesh, backend="numpy"))
    assert abs(K - K_ref).max() <= 1e-13 * abs(K_ref).max()
    assert np.array_equal(K.indices, K_ref.indices) and np.array_equal(K.indptr, K_ref.indptr)
    K2 = assemble_stiffness(mesh, 3.0, backend="numba")  # reuses the cached pattern
    assert SparsityPattern.cached(mesh) is pat
    assert abs(K2 - 3.0 / 2.5 * assemble_stiffness(mesh, 2.5, backend="numpy")).max() < 1e-12


def test_first_assembly_degenerate_triangle_named():
    mesh = Mesh(np.array([[0, 0], [1, 0], [0, 1], [2, 0]], float), [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(DegenerateMeshError) as info:
        assemble_stiffness(mesh, backend="numba")
    assert info.value.element_ids == [1]


@pytest.mark.parametrize("kappa", [2.5, "per-element"])
def test_one_off_assembly_is_the_fused_matrix_bit_for_bit_and_caches_nothing(make_square, kappa):
    """``keep_pattern=False`` builds K row by row (no slot map): the same sums in the same
    order as the element-order scatter, so the same matrix bit for bit, and no pattern cached."""
    mesh = _scrambled(make_square)
    kap = 2.5 if kappa == 2.5 else np.linspace(1, 3, mesh.n_triangles)
    K = assemble_stiffness(mesh, kap, backend="numba", keep_pattern=False)
    assert SparsityPattern.cached(mesh) is None
    K_ref = assemble_stiffness(mesh, kap, backend="numba")
    assert SparsityPattern.cached(mesh) is not None
    assert np.array_equal(K.indptr, K_ref.indptr) and np.array_equal(K.indices, K_ref.indices)
    assert np.array_equal(K.data, K_ref.data)
    assert K.indices.dtype == K_ref.indices.dtype and K.indptr.dtype == K_ref.indptr.dtype


def test_one_off_assembly_names_a_degenerate_triangle():
    mesh = Mesh(np.array([[0, 0], [1, 0], [0, 1], [2, 0]], float), [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(DegenerateMeshError) as info:
        assemble_stiffness(mesh, backend="numba", keep_pattern=False)
    assert info.value.element_ids == [1]


@pytest.mark.parametrize("spokes", [254, 255, 400], ids=["row-of-255", "row-of-256", "row-of-401"])
def test_one_off_long_rows_take_the_element_order_pass(spokes):
    """A node in more triangles than a byte can index takes the element-order pass: the same
    matrix either way."""
    from femkit.fem._one_off_stiffness import MAX_ROW, stiffness_rows_kernel

    t = np.linspace(0.0, 2.0 * np.pi, spokes, endpoint=False)
    pts = np.vstack([[0.0, 0.0], np.stack([np.cos(t), np.sin(t)], axis=1)])
    k = 1 + np.arange(spokes)
    fan = Mesh(pts, np.stack([np.zeros(spokes, int), k, 1 + k % spokes], axis=1))
    assert (stiffness_rows_kernel(fan, 1.0) is None) == (spokes + 1 > MAX_ROW)
    K = assemble_stiffness(fan, backend="numba", keep_pattern=False)
    K_ref = assemble_stiffness(Mesh(fan.points, fan.cells), backend="numba")
    assert np.array_equal(K.indices, K_ref.indices) and np.array_equal(K.data, K_ref.data)
    assert K.indptr[1] - K.indptr[0] == spokes + 1
