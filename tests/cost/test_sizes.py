"""Predicted sizes against generated meshes: element counts within 15 % (issue 12)."""

import math

import pytest

from cost_probe import domain

from femkit.case.cost import geometry_domain
from femkit.cost import msh_triangle_count, plan_poisson, predict_triangles
from femkit.errors import InputError, UnknownNameError
from femkit.mesh import generate, read_mesh, refine

# the bundled geometries at the sizes of the bundled cases and finer
GEOMETRY_CASES = [
    ("unit_square", 0.05, {}), ("unit_square", 0.02, {}), ("l_shape", 0.05, {}),
    ("disk", 0.04, {}), ("annulus", 0.05, {"r_inner": 0.5, "r_outer": 1.0}),
    ("annulus", 0.03, {"r_inner": 0.3, "r_outer": 1.0}), ("checkerboard", 0.03, {"n": 4}),
    ("square_with_inclusion", 0.03, {"radius": 0.25}),
    ("rectangle", 0.05, {"x0": 0.0, "y0": 0.0, "x1": 2.0, "y1": 0.5}),
]


@pytest.mark.parametrize("geometry,h,params", GEOMETRY_CASES,
                         ids=[f"{g}-h{h}" + ("-" + "-".join(map(str, p.values())) if p else "")
                              for g, h, p in GEOMETRY_CASES])
def test_triangle_count_within_15_percent(geometry, h, params):
    mesh = generate(geometry, h, **params)
    _, area, length = geometry_domain(geometry, params)
    predicted = predict_triangles(area, length, h)
    assert abs(predicted / mesh.n_triangles - 1) < 0.15, (predicted, mesh.n_triangles)


@pytest.mark.parametrize("levels", [1, 2, 3])
def test_refined_counts_and_sizes(levels):
    """Refinement multiplies by exactly 4 per level; points and nonzeros follow Euler's formula."""
    from femkit.fem import assemble_stiffness

    base = generate("unit_square", 0.1)
    mesh = refine(base, levels)
    plan = plan_poisson(**domain("unit_square"), h=0.1, refine=levels)
    assert plan.sizes["triangles"] / plan.sizes["triangles_generated"] == 4 ** levels
    assert abs(plan.sizes["triangles"] / mesh.n_triangles - 1) < 0.15
    assert abs(plan.sizes["points"] / mesh.n_points - 1) < 0.15
    assert abs(plan.sizes["nonzeros"] / assemble_stiffness(mesh).nnz - 1) < 0.15


def test_mesh_file_count_from_header():
    count, how = msh_triangle_count("meshes/plate_with_hole.msh")
    assert "header" in how
    assert abs(count / read_mesh("meshes/plate_with_hole.msh").n_triangles - 1) < 0.15


@pytest.mark.parametrize("bad", [0, -1.0, math.nan, math.inf, "x"], ids=repr)
def test_bad_h_is_an_input_error(bad):
    with pytest.raises(InputError, match="h must be"):
        plan_poisson(area=1.0, line_length=4.0, h=bad)


def test_unknown_geometry_lists_valid_ones():
    with pytest.raises(UnknownNameError, match="unit_square"):
        geometry_domain("hexagon")


def test_unknown_geometry_parameter():
    with pytest.raises(InputError, match="annulus.*valid parameters: r_inner, r_outer, centre"):
        geometry_domain("annulus", {"radius": 2})


@pytest.mark.parametrize("area, length", [(0.0, 4.0), (-1.0, 4.0), (math.nan, 4.0), (1.0, -1.0)],
                         ids=["zero-area", "negative-area", "nan-area", "negative-length"])
def test_bad_domain_numbers_are_input_errors(area, length):
    with pytest.raises(InputError, match="positive area"):
        predict_triangles(area, length, 0.1)


def test_compiled_threshold_matches_assembly():
    from femkit.cost.poisson import COMPILED_FROM
    from femkit.fem.sparsity import NUMBA_THRESHOLD

    assert COMPILED_FROM == NUMBA_THRESHOLD


def test_similar_root_bound_matches_the_quality_module():
    import sys

    import femkit.mesh.quality  # noqa: F401  (the package re-exports the function by this name)
    from femkit.cost.poisson import SIMILAR_ROOT_MAX

    assert SIMILAR_ROOT_MAX == sys.modules["femkit.mesh.quality"].SIMILAR_ROOT_MAX
