"""An integrator, a material and a geometry each added as ONE module (nothing in femkit edited),
loaded through ``FEMKIT_PLUGINS`` and used by a case file that ``femkit solve`` runs.

Each is written to compute what a built-in computes (the integrator symplectic Euler's update,
the material the co-rotational energy, the geometry a unit square's structured mesh), so the
check is on the numbers: the plugin's run equals the built-in's run (the geometry's solves a linear
solution to rounding).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

INTEGRATOR = '''
"""kick_drift: v+ = v + h a(x, v), x+ = x + h v+ (symplectic Euler, written anew)."""
from dataclasses import dataclass

from femkit.dynamics.integrators.base import Integrator, StepperState
from femkit.dynamics.integrators.registry import register


@register("kick_drift")
@dataclass(frozen=True)
class KickDrift(Integrator):
    order = 1
    symplectic = True
    stability_bound = 2.0

    def step(self, system, state, dt, ctx):
        v = state.v + dt * system.acceleration(state.x, state.v, state.t)
        return StepperState(state.x + dt * v, v, state.t + dt)
'''

MATERIAL = '''
"""plugin_corotational: the co-rotational energy, written as a material of its own."""
from dataclasses import dataclass
from typing import ClassVar

from femkit.solids.energy import Energy
from femkit.solids.materials.base import StretchMaterial
from femkit.solids.materials.builtin_materials import register_material


@register_material("plugin_corotational")
@dataclass(frozen=True)
class PluginCorotational(StretchMaterial):
    energy_expression: ClassVar[Energy] = Energy(
        W="mu*((s1 - 1)**2 + (s2 - 1)**2 + (s3 - 1)**2) + lam/2*(s1 + s2 + s3 - 3)**2")
'''

GEOMETRY = '''
"""grid_square: the unit square as a structured triangle grid (no gmsh), tag 'boundary'."""
import numpy as np

from femkit.mesh import Mesh
from femkit.mesh.geometries import register_geometry
from femkit.mesh.structured import structured_mesh


def grid_square_measure():
    return 1.0, 4.0


@register_geometry("grid_square", measure=grid_square_measure, boundary_tags=("boundary",),
                   cell_tags=())
def grid_square(h):
    m = structured_mesh(max(1, round(1.0 / h)), max(1, round(1.0 / h)), 1.0, 1.0)
    k = len(m.boundary_edges)
    return Mesh(m.points, m.triangles, boundary_edges=m.boundary_edges,
                boundary_tags=np.full(k, 1, np.int32), tag_names={"boundary": 1})
'''

SCENE = """
problem: mass_spring
name: chain
system: {type: rope, n: 6, length: 1.0, dim: 2, k: 200.0, total_mass: 0.3, pinned: first}
forces: [{type: gravity, g: 9.81}]
integrator: {method: METHOD}
dt: 0.002
t_end: 0.2
output: {dir: OUT, interval: 0.05, png: false}
"""

SOLID = """
problem: solid
name: beam
mesh: {geometry: beam, h: 0.5, params: {length: 2.0, width: 1.0, height: 1.0}}
material: {model: MODEL, E: 1.0e4, nu: 0.3, density: 1.0}
boundaries:
  - {tag: clamped, type: fixed}
  - {tag: tip, type: traction, traction: [0.0, 0.0, -50.0]}
static: {load_steps: 2}
output: {dir: OUT, vtu: false, png: false, gif: false}
"""

POISSON = """
problem: poisson
mesh: {geometry: GEOMETRY, h: 0.125}
source: "0"
boundary: {dirichlet: [{tags: [boundary], value: "x + 2*y"}]}
exact: {u: "x + 2*y"}
solver: {method: direct}
output: {dir: OUT, vtu: false}
"""


def _solve(tmp_path: Path, text: str, out: str, plugins: str = "") -> dict:
    """``femkit solve`` of the case ``text`` (its ``OUT`` set to ``out``) with the plugin modules
    in ``tmp_path``; the result.json."""
    (tmp_path / f"{out}.yaml").write_text(textwrap.dedent(text).replace("OUT", out))
    env = {**os.environ, "FEMKIT_PLUGINS": plugins, "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", "solve", f"{out}.yaml", "-q"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return json.loads((tmp_path / out / "result.json").read_text())


def _plugins(tmp_path: Path) -> str:
    for name, source in (("kick_drift", INTEGRATOR), ("plugin_material", MATERIAL),
                         ("grid_square", GEOMETRY)):
        (tmp_path / f"{name}.py").write_text(textwrap.dedent(source))
    return "kick_drift,plugin_material,grid_square"


def _numbers(value, skip=("timings", "time", "seconds", "wall", "dir", "file", "name", "method",
                          "model", "geometry", "title", "cache", "version", "path")):
    """The numbers of a result.json, by key path (run-dependent and naming keys left out)."""
    if isinstance(value, dict):
        return {k: _numbers(v) for k, v in value.items()
                if not any(s in k.lower() for s in skip)}
    if isinstance(value, list):
        return [_numbers(v) for v in value]
    return value


def test_a_plugin_integrator_runs_a_scene_as_its_built_in_twin(tmp_path):
    plugins = _plugins(tmp_path)
    mine = _solve(tmp_path, SCENE.replace("METHOD", "kick_drift"), "mine", plugins)
    built_in = _solve(tmp_path, SCENE.replace("METHOD", "symplectic_euler"), "built_in")
    assert "kick_drift" in json.dumps(mine) and "kick_drift" not in json.dumps(built_in)
    assert _numbers(mine) == _numbers(built_in)   # the same update: the same bits


def test_a_plugin_geometry_runs_a_poisson_case(tmp_path):
    plugins = _plugins(tmp_path)
    result = _solve(tmp_path, POISSON.replace("GEOMETRY", "grid_square"), "square", plugins)
    assert result["mesh"]["n_triangles"] == 2 * 8 * 8
    assert result["errors"]["max_nodal"] < 1e-12   # P1 reproduces a linear solution


@pytest.mark.slow
def test_a_plugin_material_runs_a_solid_case_as_its_built_in_twin(tmp_path):
    """The plugin's energy joins the built-ins' generated module under the next ``code`` (none
    written by hand); its equilibrium is the co-rotational one."""
    plugins = _plugins(tmp_path)
    mine = _solve(tmp_path, SOLID.replace("MODEL", "plugin_corotational"), "mine", plugins)
    built_in = _solve(tmp_path, SOLID.replace("MODEL", "corotational"), "built_in")
    assert "plugin_corotational" in json.dumps(mine)
    assert _close(_numbers(mine), _numbers(built_in))


def _close(a, b) -> bool:
    """Every number of ``a`` within 1e-9 (relative) of ``b``'s, the rest equal."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float):
        return a == pytest.approx(b, rel=1e-9, abs=1e-12)
    return a == b
