"""Bey's red refinement of tetrahedra: volumes, nesting, conformity, shape, prolongation."""

import numpy as np
import pytest

from femkit.mesh import MeshHierarchy, quality, refine, structured_box, validate
from femkit.mesh.faces import boundary_faces_topological, faces
from femkit.mesh.mesh import Mesh
from femkit.mesh.refine import refine_once


def _perturbed_box(n=3, amount=0.15, state=3):
    """A box whose interior nodes are moved randomly (tetrahedra of many shapes)."""
    m = structured_box(n, n, n)
    rng = np.random.default_rng(state)
    p = m.points.copy()
    inner = ((p > 1e-12) & (p < 1 - 1e-12)).all(axis=1)
    p[inner] += amount / n * rng.uniform(-1, 1, (int(inner.sum()), 3))
    return validate(Mesh(p, m.cells, boundary_facets=m.boundary_facets,
                         boundary_tags=m.boundary_tags, tag_names=m.tag_names))


MESHES = {"kuhn-box": lambda: structured_box(2, 2, 2), "perturbed-box": _perturbed_box,
          "anisotropic-box": lambda: structured_box(2, 1, 3, (1.0, 0.3, 2.0))}


@pytest.fixture(params=list(MESHES), scope="module")
def coarse(request):
    return MESHES[request.param]()


def test_children_fill_their_parent(coarse):
    fine, _ = refine_once(coarse)
    assert fine.n_cells == 8 * coarse.n_cells
    v = fine.signed_volumes()
    assert (v > 0).all()
    np.testing.assert_allclose(v.reshape(-1, 8).sum(axis=1), coarse.volumes(), rtol=1e-12)


def test_nested(coarse):
    fine, edge_nodes = refine_once(coarse)
    np.testing.assert_array_equal(fine.points[:coarse.n_points], coarse.points)
    np.testing.assert_allclose(fine.points[coarse.n_points:], coarse.points[edge_nodes].mean(axis=1))
    # every child's centroid lies inside its parent: barycentric coordinates in (0, 1)
    c = fine.centroids().reshape(-1, 8, 3)
    p = coarse.points[coarse.cells]
    T = np.transpose(p[:, 1:] - p[:, :1], (0, 2, 1))
    lam = np.linalg.solve(T[:, None], (c - p[:, :1])[..., None])[..., 0]
    lam = np.concatenate([1 - lam.sum(-1, keepdims=True), lam], axis=-1)
    assert (lam > 0).all() and (lam < 1).all()


def test_conforming_and_boundary_kept(coarse):
    fine, _ = refine_once(coarse)
    _, tet_faces = faces(fine)
    counts = np.bincount(tet_faces.ravel())
    assert counts.max() == 2
    assert (counts == 1).sum() == 4 * len(boundary_faces_topological(coarse))
    whole = fine.boundary_facets[fine.boundary_tags == fine.tag("boundary")]
    key = lambda f: sorted(map(tuple, np.sort(f, 1)))  # noqa: E731
    assert key(whole) == key(boundary_faces_topological(fine))
    # each tagged side stays on its plane
    f = fine.boundary_facets[fine.boundary_tags == fine.tag("xmax")]
    np.testing.assert_allclose(fine.points[f][..., 0], coarse.points[:, 0].max(), atol=1e-14)


def test_shape_does_not_degrade(coarse):
    """The minimum dihedral angle after k levels stays at the first level's (bounded)."""
    angles = [quality(m)["min_dihedral"] for m in _levels(coarse, 3)]
    assert min(angles[1:]) >= angles[1] - 1e-9
    assert min(angles) > 0.5 * angles[0]


def _levels(mesh, n):
    out = [mesh]
    for _ in range(n):
        out.append(refine_once(out[-1])[0])
    return out


def test_refine_levels_and_h_halves():
    m = structured_box(1, 1, 1)
    f = refine(m, 2)
    assert f.n_cells == 64 * m.n_cells
    assert quality(f)["h_max"] <= quality(m)["h_max"] / 4 + 1e-14
    assert f.volumes().sum() == pytest.approx(1.0, rel=1e-13)


@pytest.mark.parametrize("renumber", ["none", "rcm"])
def test_hierarchy_prolongation_exact_on_linears(renumber):
    H = MeshHierarchy.from_refinement(_perturbed_box(2), 2, renumber=renumber)
    a = np.array([2.0, -1.0, 0.5])
    for lvl in range(H.n_levels - 1):
        u = H.meshes[lvl].points @ a + 0.25
        np.testing.assert_allclose(H.prolongate(u, lvl), H.meshes[lvl + 1].points @ a + 0.25,
                                   rtol=1e-13, atol=1e-13)
