"""The memory model of tetrahedral runs (femkit/cost/tetrahedra.py) against measured peaks, and
the guard it drives: a level priced beyond the machine is refused before it is built, the
912,673-node cube is admitted on a machine of 23 GB."""

from __future__ import annotations

import pytest

from femkit.errors import BudgetExceededError

GIB = 2.0 ** 30
#: ``femkit solve`` on the Kuhn cube (h = 1/3 refined 5 times; h = 1/5 refined 5 times), fmg,
#: errors and estimate: peak RSS by /usr/bin/time -v (docs/benchmarks.md, "3D Poisson").
MEASURED = {"1M": (1 / 3, 5, 2.77 * GIB), "4M": (1 / 5, 5, 11.93 * GIB)}
MACHINE = 23e9


def _cube(h, refine):
    from femkit.case import case_from_dict

    return case_from_dict({
        "problem": "poisson", "name": "cube",
        "mesh": {"geometry": "kuhn_cube", "h": h, "refine": refine},
        "source": "1", "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
        "exact": {"u": "x", "grad": ["1", "0", "0"]},
        "solver": {"method": "fmg"}, "output": {"vtu": False, "plot": False},
    })


@pytest.mark.parametrize("size", sorted(MEASURED))
def test_model_covers_the_measured_peak_within_fifteen_percent(size):
    from femkit.case.poisson.cost import plan_poisson_case

    h, refine, measured = MEASURED[size]
    predicted = plan_poisson_case(_cube(h, refine), measure=False).peak_bytes
    assert measured <= predicted <= 1.15 * measured, (predicted / GIB, measured / GIB)


#: The 2D model's memory constants when the 3D laws replaced it (constants.json before the 2D
#: refit of the costcal branch; that refit lowered the per-triangle peaks of today's pipeline, so
#: the 2D model of now would not price what the replaced model priced).
REPLACED_2D_BYTES = {
    "baseline": 68000000.0, "gmsh_import": 31200000.0, "numba_import": 53400000.0,
    "gmsh_per_triangle": 938.5, "gmsh_retained": 0.602, "refine_per_triangle": 92.0,
    "quality_per_triangle": 447.5, "assembly_per_triangle": 369.6, "boundary_per_triangle": 513.0,
    "solve_per_triangle": {"pcg+amg_rs": 477.6}, "pyamg_import": 5200000.0,
    "errors_per_triangle": 771.2, "output_per_triangle": 490.5, "estimate_per_triangle": 827.0}


def test_old_triangle_equivalent_price_was_far_above():
    """The model this replaced (16/9 triangles of the 2D model per tetrahedron, with the 2D
    constants of that time) priced the 1M cube at 2.7x its measured peak; the 3D laws are within
    the margin."""
    from femkit.case.cost import TET_AS_TRIANGLES
    from femkit.cost import load_constants, plan_poisson

    h, refine, measured = MEASURED["1M"]
    old = plan_poisson(triangles=TET_AS_TRIANGLES * 6 * 27 * 2.0 ** refine, refine=refine,
                       method="fmg",
                       constants=load_constants({"bytes": REPLACED_2D_BYTES})).peak_bytes
    assert old > 2.0 * measured


@pytest.mark.parametrize("path", ["generated", "refined"])
def test_guard_admits_the_1M_cube_on_a_23_GB_machine(path):
    from femkit.case.cost import check_mesh_fits

    if path == "generated":
        assert check_mesh_fits(geometry="kuhn_cube", h=1 / 3, refine=5, available=MACHINE) is None
    else:  # as the runner asks before refining the 162 coarse tetrahedra
        assert check_mesh_fits(triangles=162, refine=5, dim=3, available=MACHINE) is None


def test_whole_plan_admits_the_1M_cube_and_refuses_a_level_beyond_the_machine():
    from femkit.case.poisson.cost import plan_poisson_case
    from femkit.cost import check_budget

    assert check_budget(plan_poisson_case(_cube(1 / 3, 5), measure=False), available=MACHINE) == []
    with pytest.raises(BudgetExceededError, match="memory"):
        check_budget(plan_poisson_case(_cube(1 / 5, 6), measure=False), available=MACHINE)


@pytest.mark.parametrize("path", ["generated", "refined"])
def test_guard_refuses_a_refinement_level_beyond_the_machine(path):
    """h = 1/5 refined 6 times: 197M tetrahedra (~100 GB by the model), refused before any
    work; one level less (the measured 4M cube, 11.93 GiB) is admitted."""
    from femkit.case.cost import check_mesh_fits

    kw = (dict(geometry="kuhn_cube", h=1 / 5) if path == "generated"
          else dict(triangles=750, dim=3))
    with pytest.raises(BudgetExceededError):
        check_mesh_fits(refine=6, available=MACHINE, **kw)
    assert check_mesh_fits(refine=5, available=MACHINE, **kw) is None
