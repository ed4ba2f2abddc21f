"""A geometry is one registration: its measure lives with it and the cost layer receives numbers.

The entry of :data:`femkit.mesh.GEOMETRIES` declares the builder, the measure (area, mesh-line
length), the dimension and the tag names; these tests check each declaration against what the
builder really produces, and that a geometry registered by a user module alone is planned,
budget-checked and solved by ``femkit solve``.
"""

import inspect
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from cost_probe import child_env

from femkit.case.cost import geometry_domain
from femkit.mesh import GEOMETRIES, generate
from femkit.mesh.geometries import Geometry, register_geometry

NAMES = GEOMETRIES.names()


def _defaults(fn, skip=("h",)) -> dict:
    return {n: p.default for n, p in inspect.signature(fn).parameters.items() if n not in skip}


@pytest.mark.parametrize("name", NAMES)
def test_measure_takes_the_builders_parameters(name):
    """Same names and defaults: a case's ``params`` mean the same to the mesher and the model."""
    entry = GEOMETRIES.get(name)
    assert isinstance(entry, Geometry)
    assert _defaults(entry.measure, ()) == _defaults(entry.build)


@pytest.mark.parametrize("name", NAMES)
def test_declared_measure_and_tags_match_the_mesh(name):
    """The declared area equals the generated mesh's (2 % at h = 0.05: circles are polygons) and
    the declared tag names are exactly the mesh's."""
    entry = GEOMETRIES.get(name)
    if entry.dim == 3:  # volume and surface area of the tetrahedral mesh (5 % at h = 0.25)
        mesh = generate(name, 0.25)
        volume, surface = entry.measure()
        assert abs(float(mesh.volumes().sum()) / volume - 1) < 0.05
        faces = mesh.boundary_facets[mesh.boundary_tags == mesh.tag("boundary")]
        p = mesh.points[faces]
        got = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
        assert abs(got / surface - 1) < 0.05
        assert set(mesh.tag_names) == set(entry.boundary_tags) | set(entry.cell_tags)
        return
    dim, area, length = geometry_domain(name)
    mesh = generate(name, 0.05 * max(1.0, area ** 0.5))  # h = 0.05 on a unit-size domain (Cook's is 1,440)
    assert dim == 2 and length > 0
    assert abs(float(mesh.areas().sum()) / area - 1) < 0.02
    assert set(mesh.tag_names) == set(entry.boundary_tags) | set(entry.cell_tags)


def test_line_length_counts_interfaces_twice():
    """checkerboard n=4: outer 4 plus 6 interior unit lines counted twice = 16 (mesh edges agree)."""
    mesh = generate("checkerboard", 0.1, n=4)
    p, t = mesh.points, mesh.triangles
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    tags = mesh.cell_tags[np.tile(np.arange(len(t)), 3)]
    u, inv = np.unique(e, axis=0, return_inverse=True)
    inv = inv.ravel()
    n_tags = np.bincount(inv, minlength=len(u))       # 1: on the outer boundary
    lo = np.full(len(u), np.iinfo(np.int64).max)
    hi = np.full(len(u), np.iinfo(np.int64).min)
    np.minimum.at(lo, inv, tags)
    np.maximum.at(hi, inv, tags)
    mixed = lo != hi                                  # an interface between two regions
    seg = np.linalg.norm(p[u[:, 1]] - p[u[:, 0]], axis=1)
    measured = seg[n_tags == 1].sum() + 2 * seg[mixed].sum()
    assert abs(measured - geometry_domain("checkerboard", {"n": 4})[2]) < 1e-9


def test_a_second_registration_is_refused():
    with pytest.raises(ValueError, match="registered twice"):
        register_geometry("unit_square", measure=lambda: (1.0, 4.0))(lambda h: None)


USER_MODULE = '''
from femkit.mesh.geometries import register_geometry, rectangle


def _strip_measure(length=3.0):
    return length * 1.0, 2.0 * (length + 1.0)


@register_geometry("test_strip", measure=_strip_measure,
                   boundary_tags=("left", "right", "bottom", "top", "boundary"),
                   cell_tags=("domain",))
def strip(h, length=3.0):
    return rectangle(h, 0.0, 0.0, length, 1.0)
'''

CASE = """\
problem: poisson
mesh: {geometry: test_strip, h: %s, params: {length: 2.0}}
source: "1"
boundary:
  dirichlet: [{tags: [boundary], value: "0"}]
solver: {method: pcg, preconditioner: jacobi, rtol: 1.0e-8}
output: {dir: out, vtu: false}
"""


def _femkit(tmp_path, *argv):
    code = ("import sys, user_geometry; from femkit.cli import main; "
            f"sys.exit(main({list(argv)!r}))")
    env = child_env()
    env["PYTHONPATH"] = f"{tmp_path}:{env['PYTHONPATH']}"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=300)


def test_a_user_geometry_runs_through_femkit_solve(tmp_path):
    """One registration in a user module: ``femkit solve`` plans it from its measure, refuses a
    ruinous size from it, and solves a normal one."""
    (tmp_path / "user_geometry.py").write_text(textwrap.dedent(USER_MODULE))
    (tmp_path / "case.yaml").write_text(CASE % 0.1)
    plan = _femkit(tmp_path, "solve", "case.yaml", "--dry-run")
    assert plan.returncode == 0, plan.stderr
    assert "test_strip h=0.1 {'length': 2.0}" in plan.stdout
    # 2.326 A/h^2 + 0.4417 L/h with A = 2, L = 6: the declared measure reached the model
    triangles = 2.326 * 2.0 / 0.1 ** 2 + 0.4417 * 6.0 / 0.1
    assert f"gmsh, {triangles:,.0f} triangles" in plan.stdout
    solved = _femkit(tmp_path, "solve", "case.yaml", "--quiet")
    assert solved.returncode == 0, solved.stderr
    assert (tmp_path / "out" / "result.json").is_file()
    (tmp_path / "huge.yaml").write_text(CASE % 1e-5)
    refused = _femkit(tmp_path, "solve", "huge.yaml")
    assert refused.returncode == 2
    assert "predicted peak memory" in refused.stderr and "h >= " in refused.stderr


def test_a_3d_geometry_is_priced_by_tetrahedra_not_as_triangles():
    """A dim-3 entry (volume, surface area): the mesh guard prices its tetrahedra (volume / h^3)
    and refuses a mesh beyond the machine; a case's plan prices the same tetrahedra (9 per
    h^3 of volume), not the volume's measure as triangles."""
    import femkit
    from femkit.case.cost import check_mesh_fits
    from femkit.case.poisson.cost import plan_poisson_case
    from femkit.errors import BudgetExceededError

    register_geometry("test_cube", measure=lambda side=1.0: (side ** 3, 6 * side ** 2), dim=3,
                      boundary_tags=("boundary",), cell_tags=("domain",))(lambda h, side=1.0: None)
    try:
        assert geometry_domain("test_cube", {"side": 2.0}) == (3, 8.0, 24.0)
        assert check_mesh_fits(geometry="test_cube", h=0.1) is None
        with pytest.raises(BudgetExceededError):
            check_mesh_fits(geometry="test_cube", h=1e-6)   # ~1e19 tetrahedra
        case = femkit.load_case("cases/poisson_unit_square.yaml",
                                mesh={"geometry": "test_cube", "h": 1e-6},
                                exact={"grad": ["pi*cos(pi*x)*sin(pi*y)",
                                                "pi*sin(pi*x)*cos(pi*y)", 0]})
        plan = plan_poisson_case(case, measure=False)
        assert "triangles" not in plan.sizes
        assert plan.sizes["tetrahedra"] == pytest.approx(9.0 / 1e-18)  # volume 1 (side 1)
        assert plan.stages and plan.peak_bytes > 1e18
    finally:
        GEOMETRIES.remove("test_cube")


def test_a_case_with_parameters_the_geometry_lacks_is_refused_at_load():
    import femkit
    from femkit.errors import CaseFileError

    with pytest.raises(CaseFileError, match=r"mesh.params: \['radius'\] do not fit geometry "
                                            r"'annulus'; valid parameters: r_inner, r_outer, centre"):
        femkit.load_case("cases/poisson_unit_square.yaml",
                         mesh={"geometry": "annulus", "params": {"radius": 2.0}})
