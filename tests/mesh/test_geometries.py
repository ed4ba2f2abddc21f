"""Generated geometries: area, tags, orientation, determinism, errors."""

import math

import numpy as np
import pytest

from femkit.errors import InputError, MeshError, UnknownNameError
from femkit.mesh import GEOMETRIES, generate, geo_file, validate
from femkit.mesh.edges import boundary_edges_topological

H = 0.1

# geometry, params, exact area, polygonal (area exact up to round-off) or curved (O(h^2)),
# named edge groups, cell groups
CASES = [
    ("unit_square", {}, 1.0, True, {"left", "right", "bottom", "top"}, {"domain"}),
    ("rectangle", dict(x0=-1.0, y0=0.5, x1=2.0, y1=1.5), 3.0, True,
     {"left", "right", "bottom", "top"}, {"domain"}),
    ("l_shape", {}, 3.0, True, {"reentrant", "outer"}, {"domain"}),
    ("disk", dict(centre=(0.5, -0.5), radius=0.8), math.pi * 0.64, False, {"outer"}, {"domain"}),
    ("annulus", dict(r_inner=0.4, r_outer=1.0), math.pi * (1 - 0.16), False, {"inner", "outer"}, {"domain"}),
    ("checkerboard", dict(n=3), 1.0, True, {"left", "right", "bottom", "top"}, {"high", "low"}),
    ("square_with_inclusion", {}, 1.0, False, {"left", "right", "bottom", "top"}, {"matrix", "inclusion"}),
    ("square_with_inclusion", dict(shape="square", radius=0.2), 1.0, True,
     {"left", "right", "bottom", "top"}, {"matrix", "inclusion"}),
]
IDS = [c[0] + ("-" + "-".join(f"{k}={v}" for k, v in c[1].items()) if c[1] else "") for c in CASES]


@pytest.fixture(scope="module", params=CASES, ids=IDS)
def case(request):
    name, params, area, polygonal, edge_groups, cell_groups = request.param
    return request.param, generate(name, H, **params)


def test_area_matches_analytic(case):
    (_, _, area, polygonal, _, _), mesh = case
    err = abs(mesh.areas().sum() - area)
    assert err <= (1e-12 if polygonal else H**2), err


def test_counter_clockwise_and_valid(case):
    _, mesh = case
    assert (mesh.signed_areas() > 0).all()
    validate(mesh)


def test_tags_present_and_boundary_group_is_whole_boundary(case):
    (_, _, _, _, edge_groups, cell_groups), mesh = case
    assert edge_groups | cell_groups | {"boundary"} == set(mesh.tag_names)
    assert set(np.unique(mesh.cell_tags)) == {mesh.tag(c) for c in cell_groups}
    def edge_set(e):
        return {tuple(sorted(x)) for x in e.tolist()}
    whole = edge_set(mesh.boundary_edges[mesh.boundary_tags == mesh.tag("boundary")])
    assert whole == edge_set(boundary_edges_topological(mesh))
    parts = set().union(*(edge_set(mesh.boundary_edges[mesh.boundary_tags == mesh.tag(g)])
                          for g in edge_groups))
    assert parts == whole
    for g in edge_groups:
        assert (mesh.boundary_tags == mesh.tag(g)).sum() > 0, g


def test_tag_numbers_unique_across_groups(case):
    _, mesh = case
    assert len(set(mesh.tag_names.values())) == len(mesh.tag_names)


def test_h_controls_edge_length():
    for h in (0.2, 0.1):
        e = generate("unit_square", h)
        p = e.points[e.triangles]
        lens = np.linalg.norm(p - p[:, [1, 2, 0]], axis=2)
        assert lens.max() <= 1.5 * h


def test_generation_is_deterministic():
    a, b = generate("annulus", 0.1), generate("annulus", 0.1)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    np.testing.assert_array_equal(a.boundary_edges, b.boundary_edges)


def test_l_shape_reentrant_edges_where_singular_solution_vanishes():
    m = generate("l_shape", 0.1)
    nodes = np.unique(m.boundary_edges[m.boundary_tags == m.tag("reentrant")])
    x, y = m.points[nodes].T
    on = ((np.abs(x) < 1e-14) & (y <= 1e-14)) | ((np.abs(y) < 1e-14) & (x >= -1e-14))
    assert on.all()
    theta = np.mod(np.arctan2(y, x), 2 * np.pi)
    u = np.hypot(x, y) ** (2 / 3) * np.sin(2 * theta / 3)
    np.testing.assert_allclose(u, 0.0, atol=1e-12)
    # and no triangle lies in the removed quadrant
    c = m.centroids()
    assert not ((c[:, 0] > 0) & (c[:, 1] < 0)).any()


def test_curved_boundaries_lie_on_circles():
    m = generate("annulus", 0.1, r_inner=0.3, r_outer=0.9, centre=(1.0, 2.0))
    for name, r in (("inner", 0.3), ("outer", 0.9)):
        nodes = np.unique(m.boundary_edges[m.boundary_tags == m.tag(name)])
        np.testing.assert_allclose(np.hypot(*(m.points[nodes] - [1.0, 2.0]).T), r, rtol=1e-12)


def test_checkerboard_regions_follow_parity():
    n = 3
    m = generate("checkerboard", 0.1, n=n)
    c = m.centroids()
    i, j = np.floor(c[:, 0] * n).astype(int), np.floor(c[:, 1] * n).astype(int)
    expected = np.where((i + j) % 2 == 0, m.tag("high"), m.tag("low"))
    np.testing.assert_array_equal(m.cell_tags, expected)


def test_inclusion_region_area():
    m = generate("square_with_inclusion", 0.05, radius=0.3)
    inc = m.areas()[m.cell_tags == m.tag("inclusion")].sum()
    assert abs(inc - math.pi * 0.09) <= 0.05**2
    assert (np.hypot(*(m.centroids()[m.cell_tags == m.tag("inclusion")] - 0.5).T) < 0.3).all()


@pytest.mark.parametrize("call, exc, words", [
    (lambda: generate("unit_sqare", 0.1), UnknownNameError, ["unit_sqare", "unit_square"]),
    (lambda: generate("disk", 0.1, radius=-1), InputError, ["radius"]),
    (lambda: generate("disk", 0.1, raduis=1), InputError, ["raduis", "radius"]),
    (lambda: generate("unit_square", 0.0), InputError, ["h"]),
    (lambda: generate("annulus", 0.1, r_inner=2, r_outer=1), InputError, ["r_inner"]),
    (lambda: generate("square_with_inclusion", 0.1, radius=0.6), InputError, ["inside"]),
    (lambda: geo_file("/nonexistent/plate.geo"), MeshError, ["/nonexistent/plate.geo"]),
], ids=["unknown-geometry", "negative-radius", "misspelled-param", "zero-h", "annulus-radii",
        "inclusion-outside", "missing-geo"])
def test_bad_input(call, exc, words):
    with pytest.raises(exc) as info:
        call()
    for w in words:
        assert w in str(info.value)


def test_registry_lists_required_geometries():
    assert {"unit_square", "rectangle", "l_shape", "disk", "annulus"} <= set(GEOMETRIES)


def test_geo_file_uses_physical_groups(tmp_path):
    from pathlib import Path
    geo = Path(__file__).resolve().parents[2] / "meshes" / "plate_with_hole.geo"
    m = geo_file(geo, h=0.1)
    assert {"left", "right", "bottom", "top", "outer", "hole", "boundary", "plate"} == set(m.tag_names)
    assert abs(m.areas().sum() - (2 - math.pi / 16)) <= 0.1**2
    assert (m.signed_areas() > 0).all()
    validate(m)  # the circle-centre point is not kept as a stray node


def test_reuses_a_running_gmsh_session():
    import gmsh
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        generate("unit_square", 0.25)
        assert gmsh.isInitialized()
    finally:
        gmsh.finalize()


def test_disk_area_error_is_second_order():
    hs = np.array([0.2, 0.1, 0.05])
    err = [math.pi - generate("disk", h).areas().sum() for h in hs]
    assert all(e > 0 for e in err)  # inscribed polygon
    slope = np.polyfit(np.log(hs), np.log(err), 1)[0]
    assert abs(slope - 2) < 0.15, slope
