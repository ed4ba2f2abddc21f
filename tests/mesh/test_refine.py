"""Uniform red refinement, edges and boundary nodes."""

import numpy as np
import pytest

from femkit.mesh import boundary_nodes, edges, generate, quality, refine, validate
from femkit.mesh.edges import boundary_edges_topological


@pytest.fixture(scope="module", params=["l_shape", "annulus", "checkerboard"])
def coarse(request):
    return generate(request.param, 0.25)


@pytest.fixture(scope="module")
def fine(coarse):
    return refine(coarse)


def test_counts_and_area(coarse, fine):
    assert fine.n_triangles == 4 * coarse.n_triangles
    assert fine.n_points == coarse.n_points + len(edges(coarse)[0])
    assert fine.areas().sum() == pytest.approx(coarse.areas().sum(), rel=1e-13)
    # each child has a quarter of its parent's area (children 4t..4t+3 come from t)
    np.testing.assert_allclose(fine.areas().reshape(-1, 4), np.repeat(coarse.areas()[:, None] / 4, 4, 1),
                               rtol=1e-10)


def test_h_halves_and_shape_kept(coarse, fine):
    qc, qf = quality(coarse), quality(fine)
    assert qf["h_max"] == pytest.approx(qc["h_max"] / 2, rel=1e-12)
    assert qf["h_min"] == pytest.approx(qc["h_min"] / 2, rel=1e-12)
    assert qf["min_angle"] == pytest.approx(qc["min_angle"], rel=1e-9)


def test_nested_and_valid(coarse, fine):
    np.testing.assert_array_equal(fine.points[:coarse.n_points], coarse.points)
    validate(fine)
    assert (fine.signed_areas() > 0).all()
    # every fine centroid lies inside its parent (barycentric coordinates in (0, 1))
    parent = coarse.points[np.repeat(coarse.triangles, 4, axis=0)]
    c = fine.centroids()
    t = np.stack([parent[:, 1] - parent[:, 0], parent[:, 2] - parent[:, 0]], axis=2)
    lam = np.linalg.solve(t, (c - parent[:, 0])[..., None])[..., 0]
    assert (lam > 0).all() and (lam.sum(axis=1) < 1).all()


def test_tags_inherited(coarse, fine):
    np.testing.assert_array_equal(fine.cell_tags, np.repeat(coarse.cell_tags, 4))
    assert fine.tag_names == coarse.tag_names
    for name in coarse.tag_names:
        t = coarse.tag(name)
        assert (fine.boundary_tags == t).sum() == 2 * (coarse.boundary_tags == t).sum()
    # the "boundary" group still is exactly the topological boundary
    whole = fine.boundary_edges[fine.boundary_tags == fine.tag("boundary")]
    assert {tuple(sorted(e)) for e in whole.tolist()} == \
        {tuple(sorted(e)) for e in boundary_edges_topological(fine).tolist()}


def test_checkerboard_regions_after_two_levels():
    m = refine(generate("checkerboard", 0.25, n=2), levels=2)
    c = m.centroids()
    i, j = np.floor(c[:, 0] * 2).astype(int), np.floor(c[:, 1] * 2).astype(int)
    np.testing.assert_array_equal(m.cell_tags, np.where((i + j) % 2 == 0, m.tag("high"), m.tag("low")))


def test_edges_euler_characteristic():
    for name, chi in (("l_shape", 1), ("annulus", 0)):
        m = generate(name, 0.25)
        e, te = edges(m)
        assert m.n_points - len(e) + m.n_triangles == chi, name
        # edge k of each triangle is opposite vertex k
        opp = np.sort(m.triangles[:, [[1, 2], [2, 0], [0, 1]]], axis=2)
        np.testing.assert_array_equal(e[te], opp)


def test_boundary_nodes(coarse):
    all_nodes = boundary_nodes(coarse)
    np.testing.assert_array_equal(all_nodes, boundary_nodes(coarse, "boundary"))
    some = boundary_nodes(coarse, [n for n in coarse.tag_names if n not in
                                   ("boundary", "domain", "high", "low")][:1])
    assert set(some) < set(all_nodes)


def test_boundary_edges_oriented_domain_on_left():
    m = generate("disk", 0.25)
    b = boundary_edges_topological(m)
    p, q = m.points[b[:, 0]], m.points[b[:, 1]]
    # counter-clockwise around the disk: cross(p, q) > 0
    assert (p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0] > 0).all()


def test_levels_zero_and_bad_levels():
    m = generate("unit_square", 0.5)
    assert refine(m, 0) is m
    with pytest.raises(ValueError):
        refine(m, -1)
