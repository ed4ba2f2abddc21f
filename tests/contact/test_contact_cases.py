"""Barrier contact through case files: a solid dropped on a plane, a small cloth on a sphere
(every written frame read back and checked by the independent numpy test), a static stack of
three solids, and the bad inputs (one line, exit 2, nothing written)."""

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ipctk")

from femkit.contact import body_surface, plane_obstacle, sphere_obstacle  # noqa: E402
from femkit.contact.barrier import BarrierModel  # noqa: E402
from femkit.contact.check import intersecting_pairs  # noqa: E402
from femkit.mesh import grid_triangles  # noqa: E402
from femkit.solids import ElasticBody, StableNeoHookean, solve_static  # noqa: E402
from femkit.solids.boundary import Dirichlet  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from _bodies import cube, merged  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

SOLID = """problem: solid
mesh: {{geometry: unit_cube, h: 1.0}}
material: {{model: stable_neo_hookean, E: 1.0e5, nu: 0.3, density: 1000.0}}
gravity: [0, 0, -9.81]
integrator: {integrator}
dt: 0.01
t_end: 0.05
velocity: [0, 0, -1.0]
contact: {contact}
output: {{vtu: true, png: false}}
"""


class _Run:
    def __init__(self, code, err):
        self.returncode, self.stderr = code, err


def _solve(tmp_path, text, capsys, name="case.yaml"):
    """``femkit solve`` in this process (its exit code and stderr) and the output directory."""
    from femkit.cli import main

    f = tmp_path / name
    f.write_text(text)
    out = tmp_path / "out"
    capsys.readouterr()
    code = main(["solve", str(f), "-o", str(out), "--quiet"])
    return _Run(code, capsys.readouterr().err), out


def _frames(out):
    import meshio

    return [meshio.read(p) for p in sorted((out / "frames").glob("frame_*.vtu"))]


def test_a_solid_dropped_on_a_plane_never_crosses_it(tmp_path, capsys):
    p, out = _solve(tmp_path, SOLID.format(
        integrator="newton", contact="{obstacles: [{type: plane, point: [0, 0, -0.01]}]}"), capsys)
    assert p.returncode == 0, p.stderr
    res = json.loads((out / "result.json").read_text())["contact"]
    assert res["intersections"] == 0 and 0.0 < res["min_distance"] < res["dhat"]
    plane = plane_obstacle([0.5, 0.5, -0.01], [0, 0, 1], 20.0, 3)
    frames = _frames(out)
    assert len(frames) == len(res["frames"]) > 3
    for m in frames:       # the written frames, read back, checked without ipctk
        x = m.points + m.point_data["displacement"]
        surf = body_surface(m.cells_dict["tetra"], 3)
        V = np.concatenate([x, plane.vertices])
        F = np.concatenate([surf, plane.faces + len(x)])
        assert len(intersecting_pairs(V, F)) == 0 and x[:, 2].min() > -0.01
    assert np.abs(frames[-1].point_data["contact_force"][:, 2]).sum() > 0


CLOTH = (ROOT / "cases/scenes/cloth_on_sphere.yaml").read_text().replace(
    "nx: 81", "nx: 9").replace("ny: 81", "ny: 9").replace("t_end: 2.0", "t_end: 0.2").replace(
    "dir: ../../runs/cloth_on_sphere", "dir: out")


def test_a_small_cloth_on_the_sphere_keeps_every_frame_intersection_free(tmp_path, capsys):
    p, out = _solve(tmp_path, CLOTH, capsys)
    assert p.returncode == 0, p.stderr
    res = json.loads((out / "result.json").read_text())["contact"]
    assert res["intersections"] == 0 and max(f["active_contacts"] for f in res["frames"]) > 0
    assert all(f["min_distance"] is None or f["min_distance"] > 0 for f in res["frames"])
    sphere = sphere_obstacle([0.5, 0.5, 0.25], 0.25, 3)
    tri = grid_triangles(9, 9)
    for m in _frames(out):
        V = np.concatenate([m.points, sphere.vertices])
        F = np.concatenate([tri, sphere.faces + len(m.points)])
        assert len(intersecting_pairs(V, F, lambda i, j: (i < len(tri)) | (j < len(tri)))) == 0


def test_a_stack_of_three_solids_rests_with_each_contact_carrying_the_weight_above():
    # offset in x, y: exactly aligned edges are CCD's worst case, not a physical one
    a, b, c = (cube(1, 0.2, (0.03 * k, 0.02 * k, z)) for k, z in enumerate((0.0, 0.2005, 0.401)))
    P, T, ranges = merged(a, b, c)
    body = ElasticBody(P, T, StableNeoHookean.from_young(1e7, 0.3, density=1000.0))
    bc = Dirichlet(len(P), 3).fix(np.flatnonzero(np.isclose(P[:, 2], 0.0)))   # the bottom face
    upper = np.r_[ranges[1], ranges[2]]
    bc.fix(upper, [0, 1])                   # the upper cubes slide along z only
    weight = body.lumped_masses()[:, None] * np.array([0.0, 0.0, -9.81])
    model = BarrierModel(P, body_surface(T, 3), dhat=1e-3, stiffness=1e5)
    res = solve_static(body, bc, weight, contact=model)
    assert res.converged
    x = res.x
    assert model.intersections(x) == 0 and 0.0 < model.min_distance(x) < model.dhat
    contact = -model.gradient(x)
    for r, above in ((ranges[2], [ranges[2]]), (ranges[1], [ranges[1], ranges[2]])):
        load = sum(weight[s, 2].sum() for s in above)
        carried = contact[r, 2].sum() + sum(contact[s, 2].sum() for s in above if s != r)
        assert carried == pytest.approx(-load, rel=1e-6)


@pytest.mark.parametrize("integrator, contact, words", [
    ("rk4", "{obstacles: [{type: plane}]}", ["integrator 'rk4'", "newton"]),
    ("newton", "{obstacles: [{type: plane, point: [0, 0, 0.5]}]}", ["intersects", "crosses"]),
    ("newton", "{dhat: 0, obstacles: [{type: plane}]}", ["dhat"]),
    ("newton", "{friction: -0.1}", ["friction"]),
    ("newton", "{obstacles: [{type: file, file: vol.msh}]}", ["not a surface", "tetra"]),
    ("newton", "{obstacles: [{type: plane, velocity: [0, 1]}]}", ["obstacles[0]", "velocity",
                                                                 "3 finite numbers"]),
    ("newton", "{obstacles: [{type: plane, angular_velocity: 1.0}]}", ["obstacles[0]",
                                                                     "angular_velocity", "3D"]),
    ("newton", "{obstacles: [{type: plane, path: [[0, 0, 0, 0], [0, 1, 0, 0]]}]}",
     ["obstacles[0]", "path", "increase strictly"]),
    ("newton", "{obstacles: [{type: plane, velocity: [0, 0, 1], path: [[0, 0, 0, 0]]}]}",
     ["obstacles[0]", "velocity or a path"]),
])
def test_bad_contact_input_is_one_line_and_writes_nothing(tmp_path, capsys, integrator, contact,
                                                        words):
    import meshio

    P, T = cube(1, 1.0, (3.0, 3.0, 3.0))
    meshio.write(tmp_path / "vol.msh", meshio.Mesh(P, [("tetra", T)]), file_format="gmsh22")
    p, out = _solve(tmp_path, SOLID.format(integrator=integrator, contact=contact), capsys)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert all(w in p.stderr for w in words), p.stderr
    assert not out.exists()


def test_the_plan_prices_contact_and_refuses_a_scene_past_its_time_budget(tmp_path, capsys):
    text = CLOTH.replace("t_end: 0.2", "t_end: 4.0") + "limits: {time: 5}\n"
    p, out = _solve(tmp_path, text, capsys)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert "time" in p.stderr and not out.exists()
    from femkit import load_case
    from femkit.case.scene.cost import plan_scene_case
    from femkit.case.scene.systems import system_size

    case = load_case(tmp_path / "case.yaml")
    stages = {s.name: s for s in plan_scene_case(case, system_size(case.spec.system),
                                                 measure=False).stages}
    assert stages["contact"].seconds > 5.0
    # contact's price is what refuses it: the same scene without contact: plans under the limit
    free = tmp_path / "free.yaml"
    free.write_text(re.sub(r"\ncontact:\n(  .*\n)+", "\n", text))
    case = load_case(free)
    assert case.spec.contact is None
    assert plan_scene_case(case, system_size(case.spec.system), measure=False).seconds < 5.0


BODIES = """problem: solid
mesh: {geometry: unit_cube, h: 1.0}
material: {model: stable_neo_hookean, E: 1.0e5, nu: 0.3, density: 1000.0}
bodies:
  - {offset: [0, 0, 0], velocity: [2.0, 0, 0]}
  - {offset: [1.02, 0.1, 0.05], velocity: [-2.0, 0, 0],
     material: {model: stable_neo_hookean, E: 1.0e5, nu: 0.3, density: 1000.0}}
integrator: newton
dt: 0.005
t_end: 0.03
contact: {self: false}
output: {vtu: true, png: false}
"""


def test_two_bodies_of_one_file_meet_head_on_without_crossing(tmp_path, capsys):
    p, out = _solve(tmp_path, BODIES, capsys)
    assert p.returncode == 0, p.stderr
    res = json.loads((out / "result.json").read_text())
    c = res["contact"]
    assert c["intersections"] == 0 and max(f["active_contacts"] for f in c["frames"]) > 0
    assert c["min_distance"] > 0
    frames = _frames(out)
    m0 = frames[0]
    tags = m0.cell_data["region"][0]
    cells = m0.cells_dict["tetra"]
    a, b = np.unique(cells[tags == 1]), np.unique(cells[tags == 2])
    assert m0.point_data["velocity"][a, 0].min() == 2.0 and m0.point_data["velocity"][b, 0].max() == -2.0
    P = m0.points
    vol = np.abs(np.einsum("ij,ij->i", np.cross(P[cells[:, 1]] - P[cells[:, 0]],
                                                P[cells[:, 2]] - P[cells[:, 0]]),
                           P[cells[:, 3]] - P[cells[:, 0]])) / 6.0
    mass = np.zeros(len(P))
    np.add.at(mass, cells.ravel(), np.repeat(1000.0 * vol / 4.0, 4))   # lumped masses
    p0 = mass @ m0.point_data["velocity"]
    v_last = frames[-1].point_data["velocity"]
    assert np.abs(mass @ v_last - p0).max() <= 1e-8 * (mass @ np.abs(m0.point_data["velocity"])).sum()
    assert v_last[a, 0].mean() < 2.0                          # they pushed each other


class _Forces:
    def __init__(self, bounded: bool):
        self.requires_bounded_steps = bounded


@pytest.mark.parametrize("bounded, expected, absent", [
    (True, "CHOLMOD", "cholespy"),
    (False, "cholespy", "CHOLMOD"),
], ids=["contact-scene-points-at-cholmod", "spring-scene-points-at-cholespy"])
def test_fast_path_hint_names_the_engine_measured_faster_for_the_scene(bounded, expected, absent):
    from types import SimpleNamespace

    from femkit.case.scene.run import FAST_PATH_DOFS, fast_path_hint

    case = SimpleNamespace(solver=SimpleNamespace(method="direct"))
    system = SimpleNamespace(ndof=FAST_PATH_DOFS, forces=[_Forces(bounded)])
    hint = fast_path_hint(case, system, SimpleNamespace(implicit=True))
    assert expected in hint and absent not in hint
    small = SimpleNamespace(ndof=FAST_PATH_DOFS - 1, forces=system.forces)
    assert fast_path_hint(case, small, SimpleNamespace(implicit=True)) is None


LID = """problem: mass_spring
name: lid
system: {type: cloth, nx: 5, ny: 5, width: 0.1, height: 0.1, plane: xy, origin: [0.0, 0.0, 0.001],
         k_structural: 200.0, total_mass: 0.01, pinned: none}
forces: {gravity: 9.81}
contact:
  obstacles:
    - {type: plane, point: [0.05, 0.05, 0.0], normal: [0, 0, 1], size: 0.2}
    - {type: plane, point: [0.05, 0.05, 0.01], normal: [0, 0, -1], size: 0.2,
       path: [[0.02, 0, 0, 0], [0.03, 0, 0, -0.05]]}
integrator: {method: newton, options: {tol: 1.0e-6}}
dt: 0.01
t_end: 0.05
stability: {check: false}
output: {frames: 5}
"""


def test_a_scene_whose_step_fails_keeps_its_frames_and_says_why(tmp_path, capsys):
    # a lid driven through the table onto a cloth lying on it (third step): no way there
    # without a crossing; the run stops at that step, exit 1, the frames before it written
    # and result.json marked solver_failed with the reason
    p, out = _solve(tmp_path, LID, capsys)
    assert p.returncode == 1
    assert "cannot make way" in p.stderr
    res = json.loads((out / "result.json").read_text())
    assert res["converged"] is False and res["steps"] == 2
    st = res["stability"]
    assert st["verdict"] == "solver_failed" and st["step"] == 3
    assert "cannot make way" in st["message"]
    assert res["contact"]["intersections"] == 0 and len(_frames(out)) == 3
