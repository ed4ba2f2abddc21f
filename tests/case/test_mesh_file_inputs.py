"""Mesh files given to cases and scenes: refusals, dry-run pricing and dropped nodes.

What each test proves:

* a tetrahedral .msh whose physical groups leave its tetrahedra in no Physical Volume (gmsh
  ``Mesh.SaveAll``) is refused by ``femkit solve`` for a Poisson and a ``problem: solid`` case:
  exit 2, one line naming the file and the Physical Volume to add, nothing written;
* a .msh with no physical group at all is read in 2D and in 3D alike (gmsh then writes every
  element): both solve;
* ``femkit solve --dry-run`` of a tetrahedral Poisson case (a .msh file, a generated cube)
  prices tetrahedra: the sizes name ``tetrahedra`` (the file's header count, or 9 per h^3 of
  volume, x8 per refinement) and the plan's seconds are positive;
* a scene's mesh file with a node no triangle uses: the node is dropped and the run prints a
  ``note`` naming it, as a Poisson case does.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

ROOT = Path(__file__).parents[2]


def _gmsh_box(path: Path, *, dim: int = 3, groups: bool, save_all: bool = False) -> Path:
    """A unit square/cube meshed by gmsh at size 0.5; ``groups``: a physical group on two
    boundary entities only (no Physical Volume/Surface), written with ``Mesh.SaveAll``."""
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        if dim == 3:
            gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        else:
            gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
        gmsh.model.occ.synchronize()
        if groups:
            gmsh.model.addPhysicalGroup(dim - 1, [1, 2], name="sides")
        if save_all:
            gmsh.option.setNumber("Mesh.SaveAll", 1)
            gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(dim)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def _poisson_case(tmp_path: Path, msh: Path, name: str = "case") -> Path:
    data = {"problem": "poisson", "name": name, "mesh": {"file": str(msh)}, "source": 1,
            "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
            "output": {"dir": str(tmp_path / f"out-{name}")}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _solid_case(tmp_path: Path, msh: Path) -> Path:
    data = yaml.safe_load((ROOT / "cases" / "solid_block_stretch.yaml").read_text())
    data["mesh"] = {"file": str(msh)}
    data["output"] = {"dir": str(tmp_path / "out-solid")}
    path = tmp_path / "solid.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _femkit(*args) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "femkit", *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("kind", ["poisson", "solid"])
def test_volume_in_no_physical_group_is_refused(tmp_path, kind):
    msh = _gmsh_box(tmp_path / "box.msh", groups=True, save_all=True)
    case = _poisson_case(tmp_path, msh) if kind == "poisson" else _solid_case(tmp_path, msh)
    before = set(os.listdir(tmp_path))
    r = _femkit("solve", case)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert str(msh) in lines[0] and "no physical volume" in lines[0]
    assert "add them to a Physical Volume" in lines[0]
    assert set(os.listdir(tmp_path)) == before  # nothing written


@pytest.mark.parametrize("dim", [2, 3], ids=["triangles", "tetrahedra"])
def test_msh_without_any_physical_group_is_read_alike_in_2d_and_3d(tmp_path, dim):
    from femkit.cli import main
    from femkit.mesh import read_mesh

    msh = _gmsh_box(tmp_path / f"plain{dim}.msh", dim=dim, groups=False)
    assert read_mesh(msh).dim == dim
    assert main(["solve", str(_poisson_case(tmp_path, msh)), "-q"]) == 0
    assert (tmp_path / "out-case" / "result.json").is_file()


def _plan(case_path: Path):
    from femkit.case import load_case
    from femkit.case.poisson.cost import plan_poisson_case

    return plan_poisson_case(load_case(case_path), measure=False)


def test_dry_run_prices_a_tetrahedral_msh_case_as_tetrahedra(tmp_path):
    from femkit.cost import msh_triangle_count

    msh = _gmsh_box(tmp_path / "plain.msh", groups=False)
    plan = _plan(_poisson_case(tmp_path, msh))
    assert "triangles" not in plan.sizes
    assert plan.sizes["tetrahedra"] == msh_triangle_count(msh)[0]  # the $Elements header
    assert plan.seconds > 0 and plan.peak_bytes > 0
    assert "tetrahedra" in plan.size_phrase()
    r = _femkit("solve", _poisson_case(tmp_path, msh), "--dry-run")
    assert r.returncode == 0, r.stderr
    assert "sizes     tetrahedra" in r.stdout and "not costed" not in r.stdout
    assert not (tmp_path / "out-case").exists()


@pytest.mark.parametrize("refine", [1, 2], ids=["h=0.25 refined once", "h=0.25 refined twice"])
def test_dry_run_prices_a_generated_cube_as_tetrahedra(tmp_path, refine):
    data = yaml.safe_load((ROOT / "cases" / "cube.yaml").read_text())
    data["mesh"] = {"geometry": "unit_cube", "h": 0.25, "refine": refine}
    path = tmp_path / "cube.yaml"
    path.write_text(yaml.safe_dump(data))
    plan = _plan(path)
    # 9 tetrahedra per h^3 of the unit cube's volume, 8 children per red refinement (Bey 1995)
    assert plan.sizes["tetrahedra"] == pytest.approx(9.0 / 0.25 ** 3 * 8 ** refine)
    assert "triangles" not in plan.sizes and plan.seconds > 0


def test_scene_mesh_file_drops_unused_nodes_with_a_note(tmp_path, capsys):
    from femkit.cli import main
    from femkit.mesh import Mesh, read_mesh, write_mesh

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [5.0, 5.0]])
    tri = np.array([[0, 1, 3], [0, 3, 2]])
    msh = tmp_path / "square.msh"
    write_mesh(msh, Mesh(points=pts, triangles=tri))
    assert read_mesh(msh, compact=False).n_points == 5  # the unused node is in the file
    scene = {"problem": "mass_spring", "name": "sq",
             "system": {"type": "mesh", "file": str(msh), "k": 100.0, "density": 1.0},
             "forces": {"gravity": 9.81}, "integrator": {"method": "symplectic_euler"},
             "dt": 1e-3, "t_end": 0.01, "output": {"dir": str(tmp_path / "sq"), "png": False}}
    path = tmp_path / "sq.yaml"
    path.write_text(yaml.safe_dump(scene))
    assert main(["solve", str(path)]) == 0
    out = capsys.readouterr().out
    assert "note      system.file: 1 node used by no triangle dropped (node ids 4)" in out
    result = json.loads((tmp_path / "sq" / "result.json").read_text())
    assert result["system"]["particles"] == 4 and result["system"]["triangles"] == 2
