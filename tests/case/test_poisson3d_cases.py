"""Poisson cases on tetrahedra through the one pipeline: the same case files, commands and outputs.

What each test proves:

* the bundled cube case runs through ``femkit solve`` and writes result.json (3D mesh facts,
  errors, both estimators' effectivity), solution.vtu and a sliced PNG;
* convergence through the case layer on the unit cube, fitted by slope over 4 uniform
  refinements: L2 2 +- 0.1, H1 1 +- 0.1, effectivity of the residual and ZZ estimators in [0.5, 3]
  on every level;
* ``femkit check`` agrees with scikit-fem's MeshTet + ElementTetP1 to 1e-12 in K, F (centroid
  rule) and u (direct solves on both sides) on the cube and on a .msh volume with two regions;
* the .msh case (coefficient per region, Dirichlet and Neumann faces) reproduces its piecewise
  linear exact solution to round-off;
* 2D-only options on a 3D mesh and the reverse are one-line errors naming the option;
* the mesh guard prices tetrahedra (8 children per refinement) and refuses before any work;
* adaptive Fichera: energy error against dofs fits N^(-1/3) +- 0.05, uniform refinement is
  slower; every adaptive mesh is conforming, its smallest dihedral angle is reported.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import femkit
from femkit.cli import main
from femkit.errors import BudgetExceededError, CaseFileError, InputError, MeshError

ROOT = Path(__file__).parents[2]
CUBE = ROOT / "cases" / "cube.yaml"
BLOCK = ROOT / "cases" / "block_layers.yaml"
FICHERA = ROOT / "cases" / "fichera.yaml"


def _slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def _case_file(tmp_path, src: Path, **changes) -> Path:
    import yaml

    data = yaml.safe_load(src.read_text())
    data.update(changes)
    if "file" in data["mesh"]:
        data["mesh"]["file"] = str((src.parent / data["mesh"]["file"]).resolve())
    path = tmp_path / src.name
    path.write_text(yaml.safe_dump(data))
    return path


def test_cube_case_solves_and_writes_3d_outputs(tmp_path):
    out = tmp_path / "cube"
    path = _case_file(tmp_path, CUBE, mesh={"geometry": "unit_cube", "h": 0.25, "refine": 1})
    assert main(["solve", str(path), "-o", str(out), "-q"]) == 0
    r = json.loads((out / "result.json").read_text())
    assert r["mesh"]["dim"] == 3 and r["mesh"]["n_tetrahedra"] > 0
    assert 0 < r["mesh"]["min_dihedral"] < 70.53
    assert r["converged"] and r["errors"]["L2"] < 2e-2
    assert 0.5 <= r["effectivity"] <= 3
    assert {"solution.vtu", "solution.png", "result.json"} <= set(r["files"])
    from femkit.mesh import read_mesh

    back = read_mesh(out / "solution.vtu")
    assert back.dim == 3 and back.n_cells == r["mesh"]["n_tetrahedra"]


#: A smooth exact solution with non-zero Dirichlet data (-lap u = -1.34 u).
SMOOTH = {
    "problem": "poisson",
    "mesh": {"geometry": "kuhn_cube", "h": 0.5},
    "source": "-1.34 * exp(x + y/2 - 3*z/10)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "exp(x + y/2 - 3*z/10)"}]},
    "exact": {"u": "exp(x + y/2 - 3*z/10)",
              "grad": ["exp(x + y/2 - 3*z/10)", "exp(x + y/2 - 3*z/10) / 2",
                       "-3/10 * exp(x + y/2 - 3*z/10)"]},
    "quadrature": {"load": "gauss4"},
    "solver": {"method": "direct"},
}


@pytest.fixture(scope="module")
def cube_levels(tmp_path_factory):
    """The smooth problem on the unit cube of Kuhn cubes of side 1/2 refined 0 ... 3 times
    (27 ... 4913 nodes), through the case layer: errors and both estimators' effectivity."""
    import yaml

    from femkit.case.poisson.estimate import estimate_facts
    from femkit.case.poisson.problem import build_mesh, compute_errors, exact_gradient, poisson_problem

    path = tmp_path_factory.mktemp("cube") / "smooth.yaml"
    path.write_text(yaml.safe_dump(SMOOTH))
    rows = []
    for k in range(4):
        case = femkit.load_case(path, mesh={"refine": k})
        mesh = build_mesh(case)
        problem = poisson_problem(case, mesh)
        system = problem.assemble("direct")
        u = system.expand(case.solver.solve(system.A, system.b).x)
        errs = compute_errors(case, problem, u)
        effs = {}
        for est in ("residual", "zz"):
            variant = case.replace(spec=dataclasses.replace(case.spec, estimator=est))
            effs[est] = estimate_facts(variant, problem, u, exact_gradient(variant))[1]
        rows.append({"h": 0.5 / 2 ** k, **errs, **effs})
    return rows


def test_cube_convergence_rates_by_slope(cube_levels):
    h = [r["h"] for r in cube_levels]
    l2 = _slope(h, [r["L2"] for r in cube_levels])
    h1 = _slope(h, [r["H1_semi"] for r in cube_levels])
    print(f"cube: L2 rate {l2:.3f}, H1 rate {h1:.3f}")
    assert abs(l2 - 2) <= 0.1
    assert abs(h1 - 1) <= 0.1


@pytest.mark.parametrize("estimator", ["residual", "zz"])
def test_cube_effectivity_on_every_level(cube_levels, estimator):
    eff = [r[estimator] for r in cube_levels]
    print(f"{estimator} effectivity by level:", np.round(eff, 3).tolist())
    assert all(0.5 <= e <= 3 for e in eff)


@pytest.mark.parametrize("src", [CUBE, BLOCK], ids=["unit cube", "msh volume"])
def test_check_agrees_with_scikit_fem_meshtet(tmp_path, src):
    from femkit.case.poisson.cross_check import cross_check

    path = _case_file(tmp_path, src, source="1 + x*y - z**2", solver={"method": "direct"},
                      quadrature={"load": "barycentric"})
    case = femkit.load_case(path, mesh={"refine": 0})
    rows = {r.name: r for r in cross_check(case)}
    assert rows["stiffness K vs scikit-fem"].difference <= 1e-12
    assert rows["load F vs scikit-fem"].difference <= 1e-12
    assert rows["solution vs scikit-fem"].difference <= 1e-12
    assert "nnz" in rows["stiffness K vs scikit-fem"].detail


def test_msh_volume_case_is_exact_for_a_piecewise_linear_solution():
    result = femkit.load_case(BLOCK).run(write=False, quiet=True)
    assert result.mesh.dim == 3
    assert set(np.unique(result.kappa)) == {1.0, 10.0}
    assert result.errors["max_nodal"] <= 1e-12
    assert result.errors["H1_semi"] <= 1e-12


@pytest.mark.parametrize("change, named", [
    ({"source": "x + z"}, "source: uses z"),
    ({"exact": {"u": "x", "grad": [1, 0, 0]}}, "exact.grad: 3 components"),
    ({"quadrature": {"load": "stroud27"}}, "quadrature.load: 'stroud27'"),
], ids=["z on triangles", "3 gradient components on triangles", "tet rule on triangles"])
def test_3d_only_option_on_a_2d_mesh_is_one_line(write_case, base_case, change, named):
    base_case.update(change)
    with pytest.raises(CaseFileError) as exc:
        femkit.load_case(write_case(base_case))
    assert str(exc.value).startswith(named) and "\n" not in str(exc.value)


@pytest.mark.parametrize("change, named", [
    ({"exact": {"u": "x", "grad": [1, 0]}}, "exact.grad: 2 components"),
    ({"quadrature": {"load": "gauss3"}}, "quadrature.load: 'gauss3'"),
], ids=["2 gradient components on tetrahedra", "triangle rule on tetrahedra"])
def test_2d_only_option_on_a_3d_mesh_is_one_line(write_case, base_case, change, named):
    base_case.update(change, mesh={"geometry": "unit_cube", "h": 0.5})
    with pytest.raises(CaseFileError) as exc:
        femkit.load_case(write_case(base_case))
    msg = str(exc.value)
    assert msg.startswith(named) and "3D" in msg and "\n" not in msg


def test_2d_only_option_on_a_3d_mesh_file_is_named_when_read(tmp_path):
    path = _case_file(tmp_path, BLOCK, quadrature={"load": "gauss6"})
    case = femkit.load_case(path)                       # a file's dimension is known once read
    with pytest.raises(CaseFileError, match=r"^quadrature.load: 'gauss6' is not a rule on tetrahedra"):
        case.run(write=False, quiet=True)


def test_adaptive_on_a_non_kuhn_tetrahedral_mesh_is_refused(write_case, base_case):
    base_case.update(mesh={"geometry": "unit_cube", "h": 0.5}, source=1,
                     adaptive={"max_dofs": 1000})
    case = femkit.load_case(write_case(base_case))
    with pytest.raises(MeshError, match="Kuhn-type mesh"):
        case.run(write=False, quiet=True)


@pytest.mark.parametrize("mesh", [{"geometry": "unit_cube", "h": 0.001},
                                  {"geometry": "unit_cube", "h": 0.25, "refine": 8}],
                         ids=["generated", "refined"])
def test_mesh_guard_prices_tetrahedra_before_any_work(write_case, base_case, tmp_path, mesh):
    base_case.update(mesh=mesh)
    base_case["output"] = {"dir": str(tmp_path / "out")}
    case = femkit.load_case(write_case(base_case))
    with pytest.raises(BudgetExceededError):
        case.run(quiet=True)
    assert not (tmp_path / "out").exists()


def test_mesh_guard_counts_eight_children_per_tetrahedron():
    from femkit.case.cost import check_mesh_fits

    # 1e6 tetrahedra refined 3 times: 5.1e8 cells (8 children each), beyond this machine
    with pytest.raises(BudgetExceededError):
        check_mesh_fits(triangles=1e6, refine=3, dim=3)


# ----------------------------------------------------------------------------- adaptive Fichera

@pytest.fixture(scope="module")
def fichera_runs():
    from femkit.case.poisson.problem import build_mesh, exact_gradient, poisson_problem
    from femkit.fem.adaptive import adaptive_solve, problem_solver

    case = femkit.load_case(FICHERA)
    mesh0 = build_mesh(case)
    runs = {}
    for refinement, max_dofs in (("adaptive", 12000), ("uniform", 5000)):
        meshes = []
        inner = problem_solver(lambda m: poisson_problem(case, m), case.solver.solve,
                               case.solver.method)

        def solve_on(mesh, x0, inner=inner, meshes=meshes):
            meshes.append(mesh)
            return inner(mesh, x0)

        run = adaptive_solve(solve_on, mesh0, theta=0.3, max_dofs=max_dofs, max_levels=60,
                             refinement=refinement, grad_exact=exact_gradient(case))
        runs[refinement] = (run, meshes)
    return runs


def test_adaptive_fichera_reaches_the_optimal_rate_and_uniform_does_not(fichera_runs):
    rates = {}
    for refinement, (run, _) in fichera_runs.items():
        rows = [lv for lv in run.levels if lv.dofs >= (1000 if refinement == "adaptive" else 0)]
        rates[refinement] = _slope([lv.dofs for lv in rows], [lv.error for lv in rows])
    print("Fichera energy error vs dofs:", {k: round(v, 3) for k, v in rates.items()})
    assert abs(rates["adaptive"] + 1 / 3) <= 0.05
    assert rates["uniform"] > -1 / 3 + 0.05          # slower: u is in H^(7/4 - eps) only


def test_every_adaptive_fichera_mesh_is_conforming_with_bounded_angles(fichera_runs):
    from femkit.mesh import validate
    from femkit.mesh.faces import boundary_faces_topological

    run, meshes = fichera_runs["adaptive"]
    assert len(meshes) == len(run.levels) >= 10
    for mesh in meshes:
        validate(mesh)
        # a hanging node leaves interior faces with one tetrahedron: they would add to the
        # topological boundary, whose area is the Fichera surface, 24, exactly when conforming
        f = mesh.points[boundary_faces_topological(mesh)]
        area = 0.5 * np.linalg.norm(np.cross(f[:, 1] - f[:, 0], f[:, 2] - f[:, 0]), axis=1).sum()
        assert area == pytest.approx(24.0, rel=1e-12)
        assert mesh.volumes().sum() == pytest.approx(7.0, rel=1e-12)
    worst = min(lv.min_angle for lv in run.levels)
    print(f"smallest dihedral angle over {len(meshes)} adaptive meshes: {worst:.2f} deg")
    assert worst >= 30.0


def test_adaptive_fichera_case_reports_levels_and_worst_angle(tmp_path):
    case = femkit.load_case(FICHERA, adaptive={"theta": 0.3, "max_dofs": 800})
    result = case.run(write=False, quiet=True)
    levels = result.to_dict()["adaptive"]["levels"]
    assert len(levels) >= 3 and all(lv["min_angle"] > 0 for lv in levels)
    assert any("smallest dihedral angle on any level" in s for s in result.summary_lines())


def test_expression_of_x_y_z_is_called_with_x_y_when_z_is_unused():
    from femkit.case.expressions import compile_expression

    f = compile_expression("x*y", ("x", "y", "z"))
    assert f(np.array([2.0]), np.array([3.0]))[0] == 6.0
    g = compile_expression("x*z", ("x", "y", "z"))
    with pytest.raises(TypeError):
        g(np.array([2.0]), np.array([3.0]))
    with pytest.raises(InputError):
        compile_expression("x*w", ("x", "y", "z"))


def test_3d_convergence_study_runs_with_the_scikit_fem_reference(tmp_path):
    """``femkit study`` on tetrahedra (quick: 3 levels): every solver converges, and scikit-fem's
    ElementTetP1 with its default 4-point rule gives our gauss4 errors on every level."""
    out = tmp_path / "study"
    assert main(["study", str(ROOT / "studies" / "poisson_convergence_3d.yaml"), "--quick",
                 "--no-progress", "-o", str(out)]) == 0
    records = json.loads((out / "results.json").read_text())["records"]
    assert all(r["converged"] for r in records)
    sk = {r["level"]: r for r in records if r["source"] == "scikit-fem"}
    ours = {r["level"]: r for r in records if r["quadrature"] == "gauss4"
            and r["solver"] == "pcg+amg_sa" and r["mode"] == records[0]["mode"]}
    assert len(sk) == 3 and sorted(sk) == sorted(ours)
    assert sk[2]["elements"] == 48 * 8 ** 2
    for level, r in sk.items():
        for key in ("L2", "H1_semi"):
            assert r[key] == pytest.approx(ours[level][key], rel=1e-6), (level, key)
