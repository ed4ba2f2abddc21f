"""Memory bombs (issue 17): a scene far too large for the machine is priced from its numbers
(node and spring counts from ``nx``, ``ny``, ``n``, or the mesh geometry's measure and ``h``)
and refused in one line, exit 2, before anything is allocated, by ``femkit solve``, by its
``--dry-run`` and by the Python API.

Each child runs under an address-space limit (``RLIMIT_AS``, 2 GiB), so a regression that
builds the system before pricing it fails here (MemoryError, a traceback, exit 1) instead of
calling the machine's OOM killer.
"""

import resource
import subprocess
import sys

import pytest
import yaml

from cost_probe import child_env

LIMIT = 2 * 1024**3


def _limit_address_space() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def _scene(system: dict) -> dict:
    return {"problem": "mass_spring", "name": "bomb", "system": system,
            "forces": {"gravity": 9.81}, "integrator": "symplectic_euler",
            "dt": 1e-3, "t_end": 0.01, "output": {"frames": 2, "dir": "out"}}


BOMBS = {
    "cloth-10000x10000": {"type": "cloth", "nx": 10000, "ny": 10000, "width": 1.0, "height": 1.0,
                          "k_structural": 400.0, "k_shear": 100.0, "total_mass": 1.0},
    "rope-1e9": {"type": "rope", "n": 1_000_000_000, "length": 1.0, "k": 100.0},
    "soft-disk-h1e-5": {"type": "mesh", "geometry": "disk", "h": 1e-5, "k": 100.0},
}


def _run(tmp_path, code_or_args: list[str]):
    return subprocess.run([sys.executable, *code_or_args], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120, env=child_env(),
                          preexec_fn=_limit_address_space)


@pytest.mark.parametrize("dry_run", [False, True], ids=["solve", "dry-run"])
@pytest.mark.parametrize("name", list(BOMBS))
def test_scene_bomb_refused_before_allocating(tmp_path, name, dry_run):
    (tmp_path / "bomb.yaml").write_text(yaml.safe_dump(_scene(BOMBS[name])))
    args = ["-m", "femkit", "solve", "bomb.yaml"] + (["--dry-run"] if dry_run else [])
    out = _run(tmp_path, args)
    lines = out.stderr.strip().splitlines()
    assert out.returncode == 2, out.stderr[-2000:]
    assert len(lines) == 1 and lines[0].startswith("femkit: error: "), out.stderr[-2000:]
    assert "predicted peak memory" in lines[0] and "--force" in lines[0]
    assert "Traceback" not in out.stderr and out.stdout == ""
    assert not (tmp_path / "out").exists()


def test_scene_bomb_refused_by_the_python_api(tmp_path):
    """``load_case(...).run()`` (no budget check by the caller) is guarded the same way."""
    (tmp_path / "bomb.yaml").write_text(yaml.safe_dump(_scene(BOMBS["rope-1e9"])))
    code = ("import femkit\nfrom femkit.errors import BudgetExceededError\n"
            "try:\n    femkit.load_case('bomb.yaml').run(write=False, quiet=True)\n"
            "except BudgetExceededError as exc:\n    print(exc.what)\n")
    out = _run(tmp_path, ["-c", code])
    assert out.returncode == 0 and out.stdout.strip() == "memory", out.stderr[-2000:]


def test_counts_from_numbers_match_the_built_systems():
    """The counts the plan uses are the built systems' own (cloth families, rope, spring) and,
    for a mesh, near Euler's formula (nodes ~ T/2, edges ~ 3T/2 within 15 %)."""
    from femkit.case.scene.systems import SYSTEMS, system_size

    cases = [
        {"type": "cloth", "nx": 7, "ny": 5, "width": 1.0, "height": 1.0, "k_structural": 1.0},
        {"type": "cloth", "nx": 7, "ny": 5, "width": 1.0, "height": 1.0, "k_structural": 1.0,
         "k_shear": 1.0, "k_bending": 1.0},
        {"type": "cloth", "nx": 2, "ny": 9, "width": 1.0, "height": 1.0, "k_structural": 1.0,
         "k_bending": 1.0, "dim": 3},
        {"type": "rope", "n": 13, "length": 1.0, "k": 1.0, "dim": 3},
        {"type": "single_spring", "k": 1.0, "m": 1.0},
    ]
    for spec in cases:
        params = {k: v for k, v in spec.items() if k != "type"}
        system, *_ = SYSTEMS.get(spec["type"]).build(dict(params), None, {"forces": [], "damping": 0.0})
        size = system_size(spec)
        assert (size.nodes, size.springs, size.dim) == (system.n, system.n_springs, system.dim), spec
    mesh = {"type": "mesh", "geometry": "disk", "h": 0.05, "k": 1.0}
    params = {k: v for k, v in mesh.items() if k != "type"}
    system, *_ = SYSTEMS.get("mesh").build(dict(params), None, {"forces": [], "damping": 0.0})
    size = system_size(mesh)
    assert size.nodes == pytest.approx(system.n, rel=0.15)
    assert size.springs == pytest.approx(system.n_springs, rel=0.15)
