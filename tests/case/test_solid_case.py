"""``problem: solid`` case files: bad input (one line, exit 2, nothing written), Newton failure
(earlier frames kept), the bundled cases end to end with readable outputs, and the case layer
against the library (the same equilibrium as ``solve_static``, Clapeyron's energy balance)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

import femkit
from femkit.case.load import read_yaml
from femkit.cli import main

CASES = Path(__file__).parents[2] / "cases"

#: a small static case: unit cube (1140 tetrahedra), clamped at x = 0, a traction on x = 1
BASE = {
    "problem": "solid",
    "name": "cube",
    "mesh": {"geometry": "unit_cube", "h": 0.5},
    "material": {"model": "stable_neo_hookean", "E": 1000.0, "nu": 0.3, "density": 1.0},
    "boundaries": [{"tag": "xmin", "type": "fixed"},
                   {"tag": "xmax", "type": "traction", "traction": [0.0, 0.0, -1.0]}],
    "static": True,
    "output": {"png": False},
}


def _write(tmp_path, data, name="case.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def _edit(**changes) -> dict:
    d = copy.deepcopy(BASE)
    for key, value in changes.items():
        *head, last = key.split("__")
        node = d
        for k in head:
            node = node[k]
        if value is None:
            node.pop(last)
        else:
            node[last] = value
    return d


def _moved_centre_msh(path: Path, z: float = 1.1) -> None:
    """A 2x2x2-cube Kuhn mesh of the unit cube whose centre node is moved to ``z``: at 1.1,
    through the faces of the tetrahedra above it, which then overlap their neighbours
    (inverted), whatever vertex order the file gives them; at 1.0, onto those faces (flat)."""
    from femkit.mesh import Mesh, structured_box, write_mesh

    m = structured_box(2, 2, 2, (1.0, 1.0, 1.0))
    P = m.points.copy()
    P[np.argmin(np.linalg.norm(P - 0.5, axis=1))] = [0.5, 0.5, z]
    write_mesh(path, Mesh(points=P, cells=m.cells, cell_tags=np.full(m.n_cells, 8),
                          boundary_facets=m.boundary_facets, boundary_tags=m.boundary_tags,
                          tag_names={**m.tag_names, "domain": 8}))


BAD = {
    "young_zero": (_edit(material__E=0.0), "Young's modulus E must be > 0"),
    "young_negative": (_edit(material__E=-5.0), "Young's modulus E must be > 0"),
    "poisson_half": (_edit(material__nu=0.5), "Poisson ratio nu must lie in (-1, 0.5)"),
    "poisson_minus_one": (_edit(material__nu=-1.0), "Poisson ratio nu must lie in (-1, 0.5)"),
    "density_zero": (_edit(material__density=0.0), "density must be > 0"),
    # moduli whose products overflow (E 1e300 once ran to "E inf", von Mises inf, "converged")
    "young_overflows": (_edit(material__E=1.0e300),
                        "material: Young's modulus E = 1e+300 is larger than 1e+100"),
    "young_underflows": (_edit(material__E=1.0e-300),
                         "material: Young's modulus E = 1e-300 is smaller than 1e-100"),
    "lam_overflows": (_edit(material={"model": "stvk", "mu": 1.0, "lam": -1.0e300}),
                      "material: stvk: lambda = -1e+300 is larger than 1e+100"),
    "mu_overflows": (_edit(material={"model": "stvk", "mu": 1.0e200, "lam": 1.0}),
                     "material: stvk: shear modulus mu = 1e+200 is larger"),
    "lam_from_nu_overflows": (_edit(material__E=1.0e99, material__nu=0.49999999999),
                              "material: Poisson ratio nu = 0.49999999999 with E = 1e+99 gives "
                              "lam = 1.66667e+109, larger than 1e+100"),
    "density_overflows": (_edit(material__density=1.0e200),
                          "material: stable_neo_hookean: density = 1e+200 is larger"),
    "energy_constant_overflows": (_edit(material={"energy": {"W": "k*(s1-1)**2 + k*(s2-1)**2 "
                                                               "+ k*(s3-1)**2 + k*(J-1)**2"},
                                                  "constants": {"k": 1.0e300}}),
                                  "material: constant k = 1e+300 is larger than 1e+100"),
    "region_young_overflows": (_edit(regions={"domain": {"model": "stvk", "E": 1.0e150,
                                                         "nu": 0.3}},
                                     mesh={"geometry": "unit_cube", "h": 0.5}),
                               "E = 1e+150 is larger than 1e+100"),
    "unknown_material": (_edit(material__model="rubber"),
                         "corotational, linear, stable_neo_hookean, stvk"),
    "unknown_tag": (_edit(boundaries=[{"tag": "left", "type": "fixed"}]),
                    "unknown boundary tag 'left'"),
    "unknown_region": (_edit(regions={"core": {"model": "stvk", "E": 1.0, "nu": 0.3}}),
                       "unknown region 'core'"),
    "static_and_integrator": (_edit(integrator="newton", dt=0.1, t_end=1.0),
                              "exclude each other"),
    "neither": (_edit(static=None), "give either 'static: true'"),
    "ruinous_time_step": (_edit(static=None, integrator="newton", dt=1e-7, t_end=1.0),
                          "exceeds the default time budget 1 h; use dt >= "),
    "explicit_step_above_critical": (_edit(static=None, integrator="velocity_verlet", dt=0.05,
                                           t_end=1.0),
                                     "exceeds the critical step"),
    "gravity_2d_on_3d": (_edit(gravity=[0.0, -9.81]), "gravity: needs 3 components"),
    "no_support": (_edit(boundaries=[{"tag": "xmax", "type": "traction",
                                      "traction": [1.0, 0.0, 0.0]}]), "no fixed or roller"),
    "unknown_integrator": (_edit(static=None, integrator="rk5", dt=0.1, t_end=1.0),
                           "valid values: central_difference"),
    "ruinous_mesh": (_edit(mesh={"geometry": "unit_cube", "h": 0.001}),
                     "exceeds the available memory"),
    "fix_component": (_edit(boundaries=[{"tag": "xmin", "type": "roller", "fix": ["w"]}]),
                      "boundaries[0].fix[0]"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_input_is_one_line_exit_2_and_nothing_written(name, tmp_path, capsys):
    import time

    data, needle = BAD[name]
    out = tmp_path / "out"
    start = time.perf_counter()
    code = main(["solve", str(_write(tmp_path, data)), "--output", str(out), "--quiet"])
    took = time.perf_counter() - start
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    # the critical step is measured on the built body: its kernels may compile first (cold cache)
    assert took < 5.0 or name == "explicit_step_above_critical", took
    assert len(err.splitlines()) == 1 and needle in err, err
    assert not out.exists()


@pytest.mark.parametrize("where", ["boundary", "region"])
def test_unknown_tag_of_a_mesh_file_is_refused_before_writing(where, tmp_path, capsys):
    from femkit.mesh import Mesh, structured_box, write_mesh

    m = structured_box(2, 2, 2, (1.0, 1.0, 1.0))
    write_mesh(tmp_path / "cube.msh", Mesh(points=m.points, cells=m.cells,
                                           cell_tags=np.full(m.n_cells, 8),
                                           boundary_facets=m.boundary_facets,
                                           boundary_tags=m.boundary_tags,
                                           tag_names={**m.tag_names, "domain": 8}))
    data = _edit(mesh={"file": "cube.msh"})
    if where == "boundary":
        data["boundaries"][0]["tag"] = "clamp"
    else:
        data["regions"] = {"core": {"model": "stvk", "E": 1.0, "nu": 0.3}}
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, data)), "--output", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert ("'clamp'" if where == "boundary" else "'core'") in err and "xmin" in err
    assert not out.exists()


@pytest.mark.parametrize("z,needle", [(1.1, "inverted tetrahedron(s)"),
                                      (1.0, "degenerate tetrahedron(s) (volume <= 1e-12")],
                         ids=["inverted", "zero_volume"])
def test_inverted_or_flat_input_element_is_named(z, needle, tmp_path, capsys):
    _moved_centre_msh(tmp_path / "folded.msh", z)
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, _edit(mesh={"file": "folded.msh"}))),
                 "--output", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert needle in err and "element ids" in err
    assert not out.exists()


def test_folded_cells_finds_the_tetrahedra_pushed_through_their_faces():
    from femkit.case.solid.run import folded_cells
    from femkit.mesh import structured_box

    m = structured_box(2, 2, 2, (1.0, 1.0, 1.0))
    assert folded_cells(m.points, m.cells).size == 0
    P = m.points.copy()
    P[np.argmin(np.linalg.norm(P - 0.5, axis=1))] = [0.5, 0.5, 1.1]
    D = np.stack([P[m.cells[:, k]] - P[m.cells[:, 0]] for k in (1, 2, 3)], axis=1)
    inverted = np.flatnonzero(np.linalg.det(D) < 0)
    found = folded_cells(P, m.cells)
    assert found.size and set(found) <= set(inverted)


def test_newton_failure_keeps_the_earlier_load_steps(tmp_path, capsys):
    """StVK under uniaxial compression: its nominal stress peaks at E / (3 sqrt 3) ~ 0.19 E
    (stretch 1/sqrt 3), so a dead load of 0.3 E in three steps has an equilibrium after the
    first step (0.1 E) and none after the second (0.2 E)."""
    data = _edit(material__model="stvk", static={"load_steps": 3},
                 boundaries=[{"tag": "xmin", "type": "roller", "fix": ["x"]},
                             {"tag": "ymin", "type": "roller", "fix": ["y"]},
                             {"tag": "zmin", "type": "roller", "fix": ["z"]},
                             {"tag": "xmax", "type": "traction", "traction": [-300.0, 0.0, 0.0]}])
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, data)), "--output", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1
    assert "load step 2/3" in err
    d = json.loads((out / "result.json").read_text())
    assert d["converged"] is False and d["verdict"] == "newton_failed"
    assert d["frames"] == 2 and d["times"] == [0.0, pytest.approx(1 / 3)]
    assert len(d["residual_history"]) > 1 and len(d["load_steps"]) == 1
    assert (out / "frames" / "frame_00001.vtu").is_file()
    assert not (out / "frames" / "frame_00002.vtu").exists()


def _dynamic_collapse(**changes) -> dict:
    """A StVK cube on rollers (x = 0, y = 0, z = 0) pushed at x = 1 by a dead load of 0.2 E,
    integrated by Newton's implicit Euler with dt = 0.05, its line search allowed one trial."""
    return _edit(**{"material__model": "stvk", "material__density": 10.0, "static": None,
                    "integrator": {"method": "newton", "options": {"max_backtracks": 1}},
                    "dt": 0.05, "t_end": 1.0,
                    "boundaries": [{"tag": "xmin", "type": "roller", "fix": ["x"]},
                                   {"tag": "ymin", "type": "roller", "fix": ["y"]},
                                   {"tag": "zmin", "type": "roller", "fix": ["z"]},
                                   {"tag": "xmax", "type": "traction",
                                    "traction": [-200.0, 0.0, 0.0]}], **changes})


def test_newton_failure_in_a_time_step_keeps_the_earlier_frames(tmp_path, capsys):
    """The first step converges; in the second the full Newton step raises the objective and
    the residual (the face slams into the collapsing block): the run stops there, its first
    frames written, ``result.json`` marked failed with the residual history of that step."""
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, _dynamic_collapse())), "--output", str(out),
                 "--quiet"])
    err = capsys.readouterr().err
    assert code == 1
    assert "newton failed" in err and "from t = 0.05 to 0.1" in err
    d = json.loads((out / "result.json").read_text())
    assert d["converged"] is False and d["verdict"] == "newton_failed"
    assert "line search found no decrease" in d["failure"]
    assert d["frames"] == 2 and d["times"] == [0.0, pytest.approx(0.05)]
    assert len(d["residual_history"]) >= 2 and all(r > 0 for r in d["residual_history"])
    assert (out / "frames" / "frame_00001.vtu").is_file()
    assert not (out / "frames" / "frame_00002.vtu").exists()


def test_rollers_in_a_time_integration_hold_only_their_components(tmp_path):
    """The same cube on its three rollers, pulled at x = 1: the roller faces slide in their
    planes (x = 0 face: y and z free) and never leave them; the case equals the library's system
    with the (n, 3) pin mask."""
    data = _dynamic_collapse(integrator="newton", t_end=0.2, material__model="stable_neo_hookean")
    data["boundaries"][3]["traction"] = [100.0, 0.0, 0.0]
    res = femkit.load_case(_write(tmp_path, data)).run(write=False, quiet=True)
    assert res.converged
    X = res.problem.body.rest_positions
    x = np.array(res.x)
    for axis in range(3):
        face = np.isclose(X[:, axis], 0.0)
        assert np.all(x[:, face, axis] == 0.0)                   # held, bit for bit
        other = [a for a in range(3) if a != axis]
        moved = np.abs(x[-1][face][:, other] - X[face][:, other]).max()
        assert moved > 1e-3                                      # sliding in the plane
    assert x[-1][:, 0].max() > 1.0 + 1e-3                        # pulled out along x


# ----------------------------------------------------------------------------- end to end

BUNDLED = {
    "solid_cantilever": {"mesh": {"h": 0.5}, "output": {"gif": True}},
    "solid_beam_vibration": {"t_end": 0.05, "output": {"every": 2}},
    "solid_block_stretch": {},
    "solid_cook_membrane": {"mesh": {"h": 8.0}},       # P2 (tests/case/test_solid_p2_case.py: h = 2)
    "solid_cook_membrane_p1": {"mesh": {"h": 8.0}},
}


def test_every_bundled_solid_case_is_listed_here():
    assert {p.stem for p in CASES.glob("solid_*.yaml")} == set(BUNDLED)


@pytest.mark.parametrize("stem", sorted(BUNDLED))
def test_bundled_case_runs_with_its_outputs(stem, tmp_path):
    import meshio

    case = femkit.load_case(CASES / f"{stem}.yaml", **BUNDLED[stem])
    out = tmp_path / "out"
    result = case.run(output_dir=out)
    assert result.converged, result.failure
    d = json.loads((out / "result.json").read_text())
    assert d["frames"] == len(d["energies"]) == len(d["times"]) == len(result.x)
    for e in d["energies"]:
        assert set(e) == {"kinetic", "elastic", "gravity", "load", "total"}
        assert e["total"] == pytest.approx(e["kinetic"] + e["elastic"] + e["gravity"] + e["load"])
    assert d["energies"][-1]["elastic"] > 0.0
    assert abs(d["energies"][0]["elastic"]) <= 1e-9 * d["energies"][-1]["elastic"]
    pvd = (out / "solid.pvd").read_text()
    assert pvd.count("<DataSet") == d["frames"]
    last = meshio.read(out / "frames" / f"frame_{d['frames'] - 1:05d}.vtu")
    body = result.problem.body
    np.testing.assert_allclose(last.point_data["displacement"][:, :body.dim],
                               result.x[-1] - body.rest_positions, atol=1e-12)
    for name in ("principal_stretches", "von_mises", "J", "region"):
        assert last.cell_data[name][0].shape[0] == body.rest.n_cells
    assert (out / "deformed.png").stat().st_size > 10_000
    if d["files"].count("animation.gif"):
        from PIL import Image

        assert Image.open(out / "animation.gif").n_frames == d["frames"]


def test_block_stretch_matches_the_homogeneous_uniaxial_state(tmp_path):
    """Rollers on the symmetry faces and a free lateral contraction: the state is homogeneous,
    stretch 1.5 along x and the same lateral stretch everywhere, with zero lateral stress (solved
    here from the material's own principal stresses by bisection, independent of the mesh)."""
    case = femkit.load_case(CASES / "solid_block_stretch.yaml")
    result = case.run(write=False, quiet=True)
    mat = result.problem.body.materials[0]

    def lateral_stress(t):
        return mat.stretch_derivatives([1.5, t, t])[1][1]

    lo, hi = 0.5, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if lateral_stress(mid) < 0 else (lo, mid)
    s = result.fields(-1)["principal_stretches"]
    np.testing.assert_allclose(s[:, 0], 1.5, atol=1e-8)
    np.testing.assert_allclose(s[:, 1:], 0.5 * (lo + hi), atol=1e-8)


def test_static_tip_deflection_through_femkit_solve_equals_solve_static(tmp_path):
    """The cantilever through ``femkit solve`` (frames per load step) and through
    ``solve_static(load_steps=4)`` on the same mesh and loads: the same equilibrium."""
    from femkit.solids import Dirichlet, ElasticBody, solve_static, tagged_facets, traction_forces

    out = tmp_path / "out"
    path = _write(tmp_path, {**read_yaml(CASES / "solid_cantilever.yaml"),
                             "mesh": {"geometry": "beam", "h": 0.5,
                                      "params": {"length": 4.0, "width": 1.0, "height": 1.0}},
                             "output": {"png": False, "gif": False}})
    assert main(["solve", str(path), "--output", str(out), "--quiet"]) == 0
    d = json.loads((out / "result.json").read_text())
    from femkit.mesh import generate

    mesh = generate("beam", 0.5, length=4.0, width=1.0, height=1.0)
    body = ElasticBody.from_mesh(mesh, femkit.solids.material("stable_neo_hookean", E=1e6,
                                                              nu=0.3, density=1000.0))
    bc = Dirichlet(body.n, 3).fix(np.unique(tagged_facets(mesh, "clamped")))
    f = traction_forces(mesh.points, tagged_facets(mesh, "tip"), [0.0, 0.0, -800.0])
    ref = solve_static(body, bc, f, load_steps=4)
    tip = ref.u[np.argmax(np.linalg.norm(ref.u, axis=1))]
    np.testing.assert_allclose(d["tip_displacement"], tip, rtol=1e-8, atol=1e-12)
    assert d["tip_displacement"][2] < 0


def test_static_energies_satisfy_clapeyron(tmp_path):
    """Linear material, small dead load: at equilibrium the elastic energy is half the work of
    the load, ``E_el = f.u / 2``, i.e. ``elastic = -load / 2`` in every frame (the load
    potential is ``-f.u``), and it grows with the square of the load factor."""
    data = _edit(material__model="linear", static={"load_steps": 3})
    out = tmp_path / "out"
    assert main(["solve", str(_write(tmp_path, data)), "--output", str(out), "--quiet"]) == 0
    e = json.loads((out / "result.json").read_text())["energies"]
    for frame in e[1:]:
        assert frame["elastic"] == pytest.approx(-0.5 * frame["load"], rel=1e-8)
    assert e[1]["elastic"] * 9 == pytest.approx(e[3]["elastic"], rel=1e-8)


def test_dynamic_energy_is_conserved_by_the_variational_integrator(tmp_path):
    """A beam released under gravity, implicit midpoint (variational): kinetic + elastic +
    gravity stays constant per frame while the energy flows between them."""
    data = read_yaml(CASES / "solid_beam_vibration.yaml")
    data.update(integrator="variational_symplectic", t_end=0.1, output={"every": 1, "png": False})
    case = femkit.case.load.case_from_dict(data, tmp_path)
    result = case.run(write=False, quiet=True)
    total = np.array([e["total"] for e in result.energies])
    swing = max(abs(e["gravity"]) for e in result.energies)
    assert swing > 0 and np.abs(total - total[0]).max() <= 1e-3 * swing


def test_plane_strain_case_with_materials_per_region(tmp_path):
    """A 2D square with a stiff inclusion (plane strain): the region gets its own material and
    the whole body deforms less than with the soft matrix everywhere."""
    data = {**BASE, "mesh": {"geometry": "square_with_inclusion", "h": 0.1},
            "material": {"model": "stable_neo_hookean", "E": 100.0, "nu": 0.3},
            "boundaries": [{"tag": "left", "type": "fixed"},
                           {"tag": "right", "type": "traction", "traction": [0.0, -1.0]}],
            "output": {"png": True}}
    soft = femkit.case.load.case_from_dict(data, tmp_path).run(write=False, quiet=True)
    data["regions"] = {"inclusion": {"model": "stable_neo_hookean", "E": 1.0e4, "nu": 0.3}}
    out = tmp_path / "out"
    stiff = femkit.case.load.case_from_dict(data, tmp_path).run(output_dir=out, quiet=True)
    mesh, body = stiff.problem.mesh, stiff.problem.body
    mu = np.empty(body.rest.n_cells)
    for elems, mat in body.groups:
        mu[elems] = mat.mu
    inside = mesh.cell_tags == mesh.tag("inclusion")
    assert inside.any() and np.allclose(mu[inside], 1e4 / 2.6) and np.allclose(mu[~inside], 100 / 2.6)
    assert np.abs(stiff.tip()).max() < np.abs(soft.tip()).max()
    assert json.loads((out / "result.json").read_text())["mesh"]["cell_type"] == "triangle"
    assert (out / "deformed.png").is_file()


def test_plan_counts_tetrahedra_from_the_geometry_measure():
    from femkit.case.budget import plan_case

    case = femkit.load_case(CASES / "solid_cantilever.yaml")
    plan = plan_case(case, measure=False)
    mesh_cells = 1471  # gmsh's beam at h = 0.25 (a count, not a femkit result)
    assert 0.7 * mesh_cells < plan.sizes["tetrahedra"] < 1.4 * mesh_cells
    assert plan.peak_bytes > 0 and plan.sizes["steps"] == 4


def test_every_schema_key_is_documented():
    from femkit.case.solid.schema import solid_schema

    doc = (Path(__file__).parents[2] / "docs" / "solids.md").read_text()
    schema = solid_schema()["properties"]
    keys = set(schema) | set(schema["output"]["properties"])
    missing = sorted(k for k in keys if f"`{k}`" not in doc)
    assert not missing, f"keys missing from docs/solids.md: {missing}"


def test_a_mesh_file_with_physical_groups_runs_with_its_tags(tmp_path):
    """A .msh written with named groups: boundaries and a region by name; the material of the
    region 'domain' (every cell) replaces the default."""
    from femkit.mesh import Mesh, structured_box, write_mesh

    m = structured_box(3, 3, 3, (1.0, 1.0, 1.0))
    write_mesh(tmp_path / "cube.msh", Mesh(points=m.points, cells=m.cells,
                                           cell_tags=np.full(m.n_cells, 8),
                                           boundary_facets=m.boundary_facets,
                                           boundary_tags=m.boundary_tags,
                                           tag_names={**m.tag_names, "domain": 8}))
    data = _edit(mesh={"file": "cube.msh"},
                 regions={"domain": {"model": "linear", "E": 2000.0, "nu": 0.25}})
    result = femkit.case.load.case_from_dict(data, tmp_path).run(write=False, quiet=True)
    assert result.converged and result.problem.body.rest.n_cells == m.n_cells
    assert [mat.name for mat in result.problem.body.materials] == ["linear"]
    assert result.problem.body.materials[0].young == pytest.approx(2000.0)
    assert result.tip()[2] < 0


def _meshio_cube_msh(path: Path, flip: np.ndarray | None = None) -> int:
    """A 2x2x2-cube Kuhn mesh of the unit cube written with meshio itself (gmsh 2.2, physical
    groups ``xmin`` ... and ``domain``); the tetrahedra of ``flip`` (a boolean mask) are given
    with their last two vertices swapped (negative vertex order). Returns the tetrahedra count."""
    import meshio

    from femkit.mesh import structured_box

    m = structured_box(2, 2, 2, (1.0, 1.0, 1.0))
    tets = m.cells.copy()
    if flip is not None:
        tets[flip, 2], tets[flip, 3] = m.cells[flip, 3], m.cells[flip, 2]
    phys = [np.full(len(tets), 8), m.boundary_tags.astype(int)]
    meshio.write(path, meshio.Mesh(
        m.points, [("tetra", tets), ("triangle", m.boundary_facets)],
        cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
        field_data={**{k: np.array([v, 2]) for k, v in m.tag_names.items()},
                    "domain": np.array([8, 3])}), file_format="gmsh22", binary=False)
    return len(tets)


def test_tetrahedra_in_negative_vertex_order_are_reoriented_with_a_note(tmp_path, capsys):
    """A .msh written by meshio mixing both vertex orders (every other tetrahedron flipped,
    geometry unchanged) runs as the consistently ordered file does, and one line says how
    many cells were reoriented; a consistent file gets no note."""
    n = _meshio_cube_msh(tmp_path / "ordered.msh")
    flip = np.arange(n) % 2 == 1
    _meshio_cube_msh(tmp_path / "flipped.msh", flip)
    results = {}
    for stem in ("ordered", "flipped"):
        data = _edit(mesh={"file": f"{stem}.msh"}, name=stem)
        code = main(["solve", str(_write(tmp_path, data, f"{stem}.yaml")),
                     "--output", str(tmp_path / stem), "--quiet"])
        err = capsys.readouterr().err
        assert code == 0, err
        results[stem] = (json.loads((tmp_path / stem / "result.json").read_text()), err)
    ordered, flipped = results["ordered"], results["flipped"]
    assert ordered[1] == ""
    assert flipped[1] == (f"femkit: note: mesh.file {tmp_path / 'flipped.msh'}: {n // 2} of {n} "
                          "tetrahedron(s) listed with the opposite vertex order; re-oriented\n")
    assert flipped[0]["verdict"] == "converged"
    assert flipped[0]["tip_displacement"] == pytest.approx(ordered[0]["tip_displacement"],
                                                           rel=1e-10, abs=1e-14)
    assert flipped[0]["inverted_elements"] == 0
    assert flipped[0]["volume"]["rest"] == pytest.approx(1.0)


def test_a_dynamic_body_needs_no_support_and_keeps_its_momentum(tmp_path, capsys):
    """No ``boundaries`` at all, no gravity: a cube thrown with velocity (1, 2, 0) and stretched
    by equal and opposite tractions on xmin and xmax (no net force) flies and vibrates; its
    momentum stays ``M v0`` in every frame, and its centre of mass moves by ``v0 t``. The same
    body with ``static: true`` is refused in one line (singular)."""
    data = _edit(boundaries=[{"tag": "xmin", "type": "traction", "traction": [-50.0, 0.0, 0.0]},
                             {"tag": "xmax", "type": "traction", "traction": [50.0, 0.0, 0.0]}],
                 static=None, integrator="newton", dt=0.01, t_end=0.2, velocity=[1.0, 2.0, 0.0],
                 output={"every": 1, "png": False, "vtu": False})
    result = femkit.case.load.case_from_dict(data, tmp_path).run(write=False, quiet=True)
    assert result.converged
    m = result.problem.body.lumped_masses()
    v0 = np.array([1.0, 2.0, 0.0])
    momenta = np.array([m @ v for v in result.v])
    assert np.abs(momenta - m.sum() * v0).max() <= 1e-9 * m.sum()
    rest = result.problem.body.rest_positions
    for t, x in zip(result.times, result.x):
        assert m @ (x - rest) / m.sum() == pytest.approx(v0 * t, abs=1e-9)
    stretch = np.ptp(result.x[-1][:, 0] - rest[:, 0])
    assert stretch > 1e-3   # it deforms: the tractions act on a body with no support
    data.pop("boundaries")
    assert femkit.case.load.case_from_dict(data, tmp_path).run(write=False, quiet=True).converged
    data.update(static=True)
    for key in ("integrator", "dt", "t_end", "velocity"):
        data.pop(key)
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, data)), "--output", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "a static body with no support is singular" in err and not out.exists()


def test_moduli_near_the_bound_give_the_scaled_result(tmp_path):
    """A body moved only by prescribed displacements deforms the same whatever the scale of
    its moduli, and its stresses scale with them: E = 1e99 and 1e-99 (inside the bound on
    material constants) against E = 1, each converged with finite numbers."""
    runs = {}
    for E in (1.0, 1.0e99, 1.0e-99):
        data = _edit(material__E=E, boundaries=[
            {"tag": "xmin", "type": "fixed"},
            {"tag": "xmax", "type": "fixed", "displacement": [0.1, 0.0, 0.05]}])
        result = femkit.case.load.case_from_dict(data, tmp_path).run(write=False, quiet=True)
        assert result.converged and result.verdict == "converged"
        runs[E] = result.to_dict()
    base = runs[1.0]
    for E in (1.0e99, 1.0e-99):
        d = runs[E]
        assert d["materials"][0]["E"] == pytest.approx(E, rel=1e-12)
        assert d["tip_displacement"] == pytest.approx(base["tip_displacement"], rel=1e-8,
                                                      abs=1e-12)
        assert d["von_mises_max"] == pytest.approx(E * base["von_mises_max"], rel=1e-8)
        assert d["energies"][-1]["elastic"] == pytest.approx(E * base["energies"][-1]["elastic"],
                                                             rel=1e-8)

