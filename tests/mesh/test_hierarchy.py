"""Nested mesh hierarchies: prolongation exactness, nesting, free-node bookkeeping, renumbering."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.errors import InputError, MeshError, UnknownNameError
from femkit.fem import assemble_stiffness
from femkit.mesh import (Mesh, MeshHierarchy, boundary_nodes, generate, permute_nodes,
                         rcm_permutation, refine, renumber)

SQUARE = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])


@pytest.fixture(scope="module")
def lshape():
    return generate("l_shape", 0.5)


def _linear(points, a=1.7, b=-0.6, c=0.3):
    return a * points[:, 0] + b * points[:, 1] + c


@pytest.mark.parametrize("renum", ["none", "rcm"])
@pytest.mark.parametrize("which", ["square-2-triangles", "gmsh-l_shape"])
def test_prolongation_is_exact_for_linear_functions(which, renum, lshape):
    coarse = SQUARE if which.startswith("square") else lshape
    H = MeshHierarchy.from_refinement(coarse, 3, renumber=renum)
    for lvl in range(H.n_levels - 1):
        u_c = _linear(H.meshes[lvl].points)
        np.testing.assert_allclose(H.prolongate(u_c, lvl), _linear(H.meshes[lvl + 1].points),
                                   rtol=0, atol=1e-13)


def test_prolongation_rows_are_interpolation_weights(lshape):
    H = MeshHierarchy.from_refinement(lshape, 2)
    for P in H.prolongations:
        np.testing.assert_allclose(np.asarray(P.sum(axis=1)).ravel(), 1.0)  # partition of unity
        assert set(np.unique(P.data)) <= {0.5, 1.0}
        assert np.diff(P.indptr).max() == 2


def test_finest_mesh_is_refine_of_the_coarse_mesh(lshape):
    H = MeshHierarchy.from_refinement(lshape, 3)
    ref = refine(lshape, 3)
    np.testing.assert_array_equal(H.finest.points, ref.points)
    np.testing.assert_array_equal(H.finest.triangles, ref.triangles)
    np.testing.assert_array_equal(H.finest.boundary_edges, ref.boundary_edges)
    assert [m.n_points for m in H.meshes] == [refine(lshape, k).n_points for k in range(4)]


@pytest.mark.parametrize("renum", ["none", "rcm"])
def test_level_free_matches_each_levels_boundary(renum, lshape):
    H = MeshHierarchy.from_refinement(lshape, 3, renumber=renum)
    fine_free = np.setdiff1d(np.arange(H.finest.n_points), boundary_nodes(H.finest))
    frees = H.level_free(fine_free)
    for mesh, free in zip(H.meshes, frees):
        expected = np.setdiff1d(np.arange(mesh.n_points), boundary_nodes(mesh))
        np.testing.assert_array_equal(free, expected)
    mask = np.zeros(H.finest.n_points, dtype=bool)
    mask[fine_free] = True
    for a, b in zip(H.level_free(mask), frees):
        np.testing.assert_array_equal(a, b)


def test_free_prolongation_interpolates_functions_vanishing_on_the_boundary(lshape):
    H = MeshHierarchy.from_refinement(lshape, 2)
    fine_free = np.setdiff1d(np.arange(H.finest.n_points), boundary_nodes(H.finest))
    frees = H.level_free(fine_free)
    Pf = H.free_prolongations(fine_free)
    rng = np.random.default_rng(1)
    for lvl, P in enumerate(Pf):
        assert P.shape == (len(frees[lvl + 1]), len(frees[lvl]))
        u = np.zeros(H.meshes[lvl].n_points)
        u[frees[lvl]] = rng.standard_normal(len(frees[lvl]))
        full = H.prolongate(u, lvl)
        np.testing.assert_allclose(P @ u[frees[lvl]], full[frees[lvl + 1]], atol=1e-14)
        # fixed fine nodes of a function vanishing on the coarse boundary stay zero
        fixed = np.setdiff1d(np.arange(H.meshes[lvl + 1].n_points), frees[lvl + 1])
        np.testing.assert_allclose(full[fixed], 0.0, atol=1e-14)


@pytest.mark.parametrize("renum", ["none", "rcm"])
@pytest.mark.parametrize("which", ["boundary", "random-half", "none-free", "all-free"])
def test_free_prolongations_equal_scipy_fancy_indexing(which, renum, lshape):
    # array for array (indptr, indices in their order, data): the restriction is SciPy's
    # P[free_{l+1}][:, free_l], whatever the free set (not only a boundary)
    H = MeshHierarchy.from_refinement(lshape, 3, renumber=renum)
    n = H.finest.n_points
    free = {"boundary": np.setdiff1d(np.arange(n), boundary_nodes(H.finest)),
            "random-half": np.flatnonzero(np.random.default_rng(2).random(n) < 0.5),
            "none-free": np.zeros(0, dtype=int),
            "all-free": np.arange(n)}[which]
    frees = H.level_free(free)
    for lvl, (P, Pf) in enumerate(zip(H.prolongations, H.free_prolongations(free))):
        ref = P[frees[lvl + 1]][:, frees[lvl]].tocsr()
        assert Pf.shape == ref.shape and Pf.format == "csr"
        for a, b in ((Pf.indptr, ref.indptr), (Pf.indices, ref.indices), (Pf.data, ref.data)):
            np.testing.assert_array_equal(a, b)
            assert a.dtype == b.dtype


def test_galerkin_product_equals_rediscretisation_for_piecewise_constant_kappa(lshape):
    # nested P1 spaces + kappa constant on the coarse cells: P^T K_fine P = K_coarse exactly
    H = MeshHierarchy.from_refinement(lshape, 2)
    kap = [np.where(lshape.centroids()[:, 0] > 0, 1e3, 1.0)]
    for _ in H.prolongations:
        kap.append(np.repeat(kap[-1], 4))  # children 4t..4t+3 of coarse triangle t
    for lvl, P in enumerate(H.prolongations):
        Kc = assemble_stiffness(H.meshes[lvl], kap[lvl])
        Kf = assemble_stiffness(H.meshes[lvl + 1], kap[lvl + 1])
        diff = (P.T @ Kf @ P - Kc).tocsr()
        assert abs(diff).max() <= 1e-10 * abs(Kc).max()


def test_rcm_renumbering_shrinks_the_bandwidth_and_keeps_the_mesh(lshape):
    fine = refine(lshape, 4)

    def bandwidth(m):
        K = sp.coo_matrix(assemble_stiffness(m))
        return int(np.abs(K.row - K.col).max())

    r, perm = renumber(fine, "rcm")
    assert bandwidth(r) < bandwidth(fine) / 10
    np.testing.assert_allclose(r.points, fine.points[perm])
    assert r.areas().sum() == pytest.approx(fine.areas().sum(), rel=1e-14)
    assert np.all(r.areas() > 0)                         # orientation kept
    np.testing.assert_array_equal(np.sort(r.cell_tags), np.sort(fine.cell_tags))
    np.testing.assert_array_equal(np.sort(perm), np.arange(fine.n_points))
    assert len(boundary_nodes(r)) == len(boundary_nodes(fine))


def test_bad_inputs_raise_specific_errors(lshape):
    with pytest.raises(MeshError, match="permutation"):
        permute_nodes(lshape, np.zeros(lshape.n_points, dtype=int))
    with pytest.raises(UnknownNameError, match="rcm"):
        renumber(lshape, "metis")
    with pytest.raises(InputError, match="non-negative integer"):
        MeshHierarchy.from_refinement(lshape, -1)
    with pytest.raises(InputError, match="non-negative integer"):
        MeshHierarchy.from_refinement(lshape, 1.5)
    H = MeshHierarchy.from_refinement(lshape, 1)
    with pytest.raises(InputError, match="out of range"):
        H.level_free([H.finest.n_points])
    with pytest.raises(InputError, match="shape"):
        H.level_free(np.ones(3, dtype=bool))
    assert len(rcm_permutation(lshape)) == lshape.n_points


def test_rcm_hierarchy_is_a_renumbering_of_the_plain_one(lshape):
    plain = MeshHierarchy.from_refinement(lshape, 3)
    ren = MeshHierarchy.from_refinement(lshape, 3, renumber="rcm")
    for a, b in zip(plain.meshes, ren.meshes):
        key = lambda p: np.lexsort(p.T)  # noqa: E731
        np.testing.assert_array_equal(a.points[key(a.points)], b.points[key(b.points)])
        assert b.areas().sum() == pytest.approx(a.areas().sum(), rel=1e-14) and np.all(b.areas() > 0)

    def bandwidth(m):
        K = sp.coo_matrix(assemble_stiffness(m))
        return int(np.abs(K.row - K.col).max())

    assert bandwidth(ren.finest) < bandwidth(plain.finest) / 3   # 237 vs 805
