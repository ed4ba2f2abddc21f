"""Maubach bisection of Kuhn tetrahedra: conforming, nested, shape kept, exact prolongation."""

import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh import refine, structured_box, quality
from femkit.mesh.bisect3d import TetBisection
from femkit.mesh.faces import boundary_faces_topological, faces


def _key(f):
    return sorted(map(tuple, np.sort(f, axis=1)))


def _run(coarse, rounds, pick):
    states = [TetBisection.start(coarse)]
    for _ in range(rounds):
        states.append(states[-1].refine(pick(states[-1].mesh)))
    return states


PICKS = {
    "corner": lambda m: np.flatnonzero(np.linalg.norm(m.centroids(), axis=1) < 0.3),
    "random-20%": lambda m: np.random.default_rng(m.n_cells).random(m.n_cells) < 0.2,
    "plane": lambda m: np.flatnonzero(np.abs(m.centroids()[:, 0] - 0.5) < 0.1),
}


@pytest.fixture(scope="module", params=list(PICKS))
def states(request):
    return _run(structured_box(2, 2, 2), 6, PICKS[request.param])


def test_conforming_and_oriented(states):
    for s in states[1:]:
        m = s.mesh
        assert (m.signed_volumes() > 0).all()
        _, tf = faces(m)
        assert np.bincount(tf.ravel()).max() == 2
        # no hanging node: the free faces are exactly the box surface
        c = m.points[boundary_faces_topological(m)].mean(axis=1)
        assert ((np.abs(c) < 1e-12) | (np.abs(c - 1) < 1e-12)).any(axis=1).all()
        assert _key(m.boundary_facets[m.boundary_tags == m.tag("boundary")]) == \
            _key(boundary_faces_topological(m))


def test_nested(states):
    for coarse, fine in zip(states, states[1:]):
        v = np.bincount(fine.parent, weights=fine.mesh.volumes(), minlength=coarse.mesh.n_cells)
        np.testing.assert_allclose(v, coarse.mesh.volumes(), rtol=1e-12)
        np.testing.assert_array_equal(fine.mesh.points[:coarse.mesh.n_points], coarse.mesh.points)
        a = np.array([1.0, -2.0, 0.5])
        np.testing.assert_allclose(fine.prolong(coarse.mesh.points @ a), fine.mesh.points @ a,
                                   atol=1e-13)


@pytest.mark.parametrize("marked", [[0], [5, 17, 30], list(range(0, 48, 3))], ids=["one", "three", "every-third"])
def test_marked_cells_are_bisected(marked):
    s0 = TetBisection.start(structured_box(2, 2, 2))
    s1 = s0.refine(marked)
    children = np.bincount(s1.parent, minlength=s0.mesh.n_cells)
    assert (children[marked] >= 2).all()
    np.testing.assert_allclose(s1.mesh.volumes()[np.isin(s1.parent, marked)].sum(),
                               s0.mesh.volumes()[marked].sum(), rtol=1e-13)
    # side tags stay on their planes
    f = s1.mesh.boundary_facets[s1.mesh.boundary_tags == s1.mesh.tag("xmax")]
    np.testing.assert_allclose(s1.mesh.points[f][..., 0], 1.0, atol=1e-14)


def test_min_dihedral_angle_bounded(states):
    """Kuhn shapes repeat under Maubach bisection: the worst angle after six rounds is the
    worst over the first round's children."""
    worst = [quality(s.mesh)["min_dihedral"] for s in states]
    assert min(worst) >= min(worst[:2]) - 1e-9 and min(worst) > 30.0


def test_works_after_red_refinement():
    s = TetBisection.start(refine(structured_box(1, 1, 1), 2))
    f = s.refine(np.arange(0, s.mesh.n_cells, 7))
    _, tf = faces(f.mesh)
    assert np.bincount(tf.ravel()).max() == 2


def test_bad_input():
    s = TetBisection.start(structured_box(1, 1, 1))
    with pytest.raises(MeshError, match="out of range"):
        s.refine([99])
    with pytest.raises(MeshError, match="needs a tetrahedral mesh"):
        from femkit.mesh import structured_mesh
        TetBisection.start(structured_mesh(2, 2))
