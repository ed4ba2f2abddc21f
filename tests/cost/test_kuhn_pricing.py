"""The cost model counts the tetrahedra of the Kuhn geometries exactly.

A Kuhn cube of side ``h`` is cut into 6 tetrahedra, so ``kuhn_cube`` and ``kuhn_fichera`` hold
``6 V / h^3`` tetrahedra (not gmsh's measured ~9 per ``h^3``), times 8 per red refinement (Bey
1995). The plan of a case is compared with the tetrahedra of the mesh the case builds.
"""

from __future__ import annotations

import pytest
import yaml


def _case(tmp_path, geometry: str, h: float, refine: int):
    from femkit.case import load_case

    data = {"problem": "poisson", "name": "kuhn",
            "mesh": {"geometry": geometry, "h": h, "refine": refine},
            "source": "1", "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
            "solver": {"method": "direct"}, "output": {"vtu": False, "plot": False}}
    path = tmp_path / "kuhn.yaml"
    path.write_text(yaml.safe_dump(data))
    return load_case(path)


@pytest.mark.parametrize("geometry,h,refine", [
    ("kuhn_cube", 0.25, 0), ("kuhn_cube", 1 / 3, 1), ("kuhn_fichera", 0.5, 0),
    ("kuhn_fichera", 0.5, 1)],
    ids=["cube h=1/4", "cube h=1/3 refined once", "fichera h=1/2", "fichera h=1/2 refined once"])
def test_plan_prices_the_tetrahedra_the_kuhn_mesh_has(tmp_path, geometry, h, refine):
    from femkit.case.poisson.cost import plan_poisson_case
    from femkit.mesh import generate, refine as red

    plan = plan_poisson_case(_case(tmp_path, geometry, h, refine), measure=False)
    mesh = generate(geometry, h)
    for _ in range(refine):
        mesh = red(mesh)
    assert plan.sizes["tetrahedra"] == pytest.approx(mesh.n_cells, rel=1e-12)
    assert "6 per h^3" in plan.assumptions[0]


def test_gmsh_geometries_keep_the_measured_density():
    from femkit.case.cost import TETS_PER_H3, tets_per_h3

    assert tets_per_h3("unit_cube") == TETS_PER_H3 and tets_per_h3("kuhn_cube") == 6.0
