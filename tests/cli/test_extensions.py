"""Extending femkit from outside: a new geometry, a new force, a new problem kind and a new
study kind, each from ONE module written here, loaded through ``FEMKIT_PLUGINS`` and run by
``femkit solve`` / ``femkit study`` in a subprocess (nothing in femkit is edited).

Each check can fail on the numbers, not only on the exit code: the geometry's mesh solves a
linear exact solution to rounding, the force's momentum is ``F t`` exactly, the 1D problem's
P1 nodal values are exact (``u = x (1 - x) / 2``), and the study fits the midpoint rule's rate 2.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helper
from _plugins import ROOT, run_with_plugins, write_yaml  # noqa: E402

GEOMETRY = '''
"""A strip [0, length] x [0, 1] meshed without gmsh (structured), tags: sides and 'boundary'."""
import numpy as np

from femkit.mesh import Mesh
from femkit.mesh.geometries import GEOMETRIES
from femkit.mesh.structured import structured_mesh


def strip(h, length=2.0):
    m = structured_mesh(max(1, round(length / h)), max(1, round(1.0 / h)), length, 1.0)
    k = len(m.boundary_edges)
    names = {**m.tag_names, "boundary": 99}
    return Mesh(m.points, m.triangles,
                boundary_edges=np.concatenate([m.boundary_edges, m.boundary_edges]),
                boundary_tags=np.concatenate([m.boundary_tags, np.full(k, 99, np.int32)]),
                tag_names=names)


def strip_measure(length=2.0):
    return float(length), 2.0 * (float(length) + 1.0)


try:  # the geometry record carries its own measure (area, mesh-line length)
    from femkit.mesh.geometries import register_geometry
except ImportError:  # a registry of measures beside GEOMETRIES
    GEOMETRIES.register("strip", strip)
    from femkit.cost.geometry import MEASURES

    MEASURES.register("strip", strip_measure)
else:
    register_geometry("strip", measure=strip_measure, boundary_tags=("boundary",),
                      cell_tags=())(strip)
'''

FORCE = '''
"""A constant push: the same force vector on every free node (energy -F . x)."""
import numpy as np

from femkit.case.scene.forces import FORCES, ForceType
from femkit.dynamics.forces.base import Force


class Push(Force):
    kind = "gravity"  # the energy bucket of an external potential field (system.energies)
    constant = True

    def __init__(self, f):
        self.f = np.asarray(f, dtype=float)

    def bind(self, system):
        super().bind(system)
        self._f = np.where(system.pinned[:, None], 0.0, self.f[None, :])

    def add_force(self, x, v, t, out):
        out += self._f

    def energy(self, x):
        return float(-np.einsum("nd,nd->", self._f, x))


FORCES.register("push", ForceType(
    schema={"type": "object", "additionalProperties": False, "required": ["f"],
            "properties": {"f": {"type": "array", "items": {"type": "number"}}}},
    build=lambda p: Push(p["f"])))
'''

PROBLEM = '''
"""problem: rod -- -u'' = f on (0, 1), u(0) = u(1) = 0, P1 elements, femkit's solver spec."""
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from femkit.case.kinds import Kind, register_kind
from femkit.case.specs import SOLVER_SCHEMA, solver_spec

SCHEMA = {"type": "object", "additionalProperties": False, "required": ["problem", "n"],
          "properties": {"problem": {"const": "rod"}, "n": {"type": "integer", "minimum": 2},
                         "f": {"type": "number", "default": 1.0},
                         "solver": {**SOLVER_SCHEMA, "default": {"method": "direct"}}}}


class Result:
    def __init__(self, error, res):
        self.error, self.res, self.converged = error, res, bool(res.converged)


class Spec(NamedTuple):  # the run spec holds the solver spec (case.solver reads it)
    n: int
    f: float
    solver: object


def prepare(case):
    case.spec = Spec(int(case.data["n"]), float(case.data["f"]),
                     solver_spec(case.data["solver"], "solver"))


def run(case, output_dir=None, quiet=False, write=True, echo=None):
    n, f, _ = case.spec
    h = 1.0 / n
    A = sp.diags([-np.ones(n - 2), 2 * np.ones(n - 1), -np.ones(n - 2)], [-1, 0, 1]).tocsr() / h
    res = case.solver.solve(A, np.full(n - 1, f * h))
    x = np.linspace(h, 1 - h, n - 1)
    error = float(np.max(np.abs(res.x - f * x * (1 - x) / 2)))
    if not quiet:
        (echo or print)(f"rod n={n}: max nodal error {error:.3e}, rtol {case.solver.rtol:g}")
    return Result(error, res)


register_kind(Kind("rod", "problem", SCHEMA, prepare, run))
'''

STUDY = '''
"""kind: midpoint_rate -- the midpoint rule on sin(pi x) over [0, 1]: error against panels."""
import numpy as np

from femkit.case.kinds import Kind, register_kind
from femkit.errors import CaseFileError
from femkit.study.fit import fit_rate

SCHEMA = {"panels": {"type": "array", "items": {"type": "integer", "minimum": 1}, "minItems": 2,
                     "default": [4, 8, 16, 32]}}


def check(study):
    if sorted(set(study.data["panels"])) != sorted(study.data["panels"]):
        raise CaseFileError("panels: repeated values")


def run(study, progress_enabled=None):
    records = []
    for n in study.data["panels"]:
        x = (np.arange(n) + 0.5) / n
        records.append({"panels": n, "error": abs(np.sin(np.pi * x).sum() / n - 2 / np.pi)})
    fit = fit_rate([r["panels"] for r in records], [r["error"] for r in records])
    return {"records": records, "fits": [{"error": "midpoint", "slope": -fit.slope, "r2": fit.r2}]}


def report(rep, study, result, data, stage):
    rep.paragraph(f"rate {result.fits[0]['slope']:.4f}")


def summary(result):
    return [f"midpoint rate {result.fits[0]['slope']:.4f}"]


register_kind(Kind("midpoint_rate", "kind", SCHEMA, check, run, report=report, summary=summary))
'''


def _femkit(tmp_path: Path, plugin: str, source: str, *args: str):
    (tmp_path / f"{plugin}.py").write_text(textwrap.dedent(source))
    return run_with_plugins(tmp_path, tmp_path, plugin, *args)


_yaml = write_yaml


def test_a_plugin_geometry_runs_through_femkit_solve(tmp_path):
    case = _yaml(tmp_path, "strip.yaml", """
        problem: poisson
        mesh: {geometry: strip, h: 0.25, params: {length: 2.0}}
        source: "0"
        boundary: {dirichlet: [{tags: [boundary], value: "x + 2*y"}]}
        exact: {u: "x + 2*y"}
        solver: {method: direct}
        output: {dir: out, vtu: false}
        """)
    p = _femkit(tmp_path, "strip_geometry", GEOMETRY, "solve", case, "-q")
    assert p.returncode == 0, p.stderr
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["mesh"]["n_triangles"] == 2 * 8 * 4  # 8 x 4 cells of the 2 x 1 strip
    assert result["errors"]["max_nodal"] < 1e-12  # P1 reproduces a linear solution
    dry = _femkit(tmp_path, "strip_geometry", GEOMETRY, "solve", case, "--dry-run")
    assert dry.returncode == 0, dry.stderr


def test_a_plugin_force_runs_through_femkit_solve(tmp_path):
    scene = _yaml(tmp_path, "push.yaml", """
        problem: mass_spring
        system: {type: single_spring, k: 1.0e-12, m: 10.0}
        forces: [{type: push, f: [2.0, 0.0]}]
        integrator: symplectic_euler
        dt: 0.01
        t_end: 0.5
        output: {dir: out, vtu: false, energy_csv: false}
        """)
    p = _femkit(tmp_path, "push_force", FORCE, "solve", scene, "-q")
    assert p.returncode == 0, p.stderr
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["system"]["forces"] == ["push"]
    # the free node's momentum is F t (the spring, k = 1e-12, adds nothing measurable)
    assert result["momentum_final"][0] == pytest.approx(2.0 * 0.5, rel=1e-9)
    bad = _femkit(tmp_path, "push_force", FORCE, "solve",
                  _yaml(tmp_path, "bad.yaml", (tmp_path / scene).read_text().replace("f:", "g:")))
    assert bad.returncode == 2 and "forces[0].g: unknown key; valid keys: f, type" in bad.stderr


def test_a_plugin_problem_kind_runs_through_femkit_solve(tmp_path):
    case = _yaml(tmp_path, "rod.yaml", "problem: rod\nn: 50\nsolver: {method: cg, rtol: 1.0e-13}\n")
    p = _femkit(tmp_path, "rod_problem", PROBLEM, "solve", case)
    assert p.returncode == 0, p.stderr
    error = float(p.stdout.split("max nodal error")[1].split(",")[0])
    assert error < 1e-10  # 1D P1 nodal values are exact
    unknown = _femkit(tmp_path, "rod_problem", PROBLEM, "solve",
                      _yaml(tmp_path, "typo.yaml", "problem: rods\nn: 5\n"))
    builtin = subprocess.run(  # a fresh process's kinds (another test may register one here)
        [sys.executable, "-c", "import femkit.case; from femkit.kinds import KINDS; "
                               "print(' '.join(KINDS.names()))"],
        capture_output=True, text=True, check=True, cwd=ROOT).stdout.split()
    valid = ", ".join(sorted(builtin + ["rod"]))  # the built-in kinds and the plugin's
    assert unknown.returncode == 2 and f"valid problems: {valid}\n" in unknown.stderr


def test_a_plugin_study_kind_runs_through_femkit_study(tmp_path):
    study = _yaml(tmp_path, "rate.yaml", "kind: midpoint_rate\npanels: [8, 16, 32, 64]\n")
    p = _femkit(tmp_path, "midpoint_study", STUDY, "study", study, "-o", "report", "-q")
    assert p.returncode == 0, p.stderr
    assert "midpoint rate 2.0" in p.stdout
    results = json.loads((tmp_path / "report" / "results.json").read_text())
    assert len(results["records"]) == 4
    assert results["fits"][0]["slope"] == pytest.approx(2.0, abs=0.01)  # the midpoint rule's order


def test_a_plugin_that_cannot_be_imported_is_bad_input(tmp_path):
    env = {**os.environ, "FEMKIT_PLUGINS": "no_such_femkit_plugin",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run([sys.executable, "-m", "femkit.cli", "solve",
                        str(ROOT / "cases" / "poisson_unit_square.yaml"), "--dry-run"],
                       env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 2
    assert "plugin 'no_such_femkit_plugin' from FEMKIT_PLUGINS cannot be imported" in p.stderr


def test_a_plugin_registering_a_taken_name_is_bad_input(tmp_path):
    case = str(ROOT / "cases" / "poisson_unit_square.yaml")
    p = _femkit(tmp_path, "twice", PROBLEM.replace('Kind("rod"', 'Kind("poisson"'), "solve", case,
                "--dry-run")
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert ("plugin 'twice' from FEMKIT_PLUGINS failed while importing: ValueError: problem "
            "'poisson' registered twice") in p.stderr
