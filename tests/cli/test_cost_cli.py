"""Cost before the run on the command line (issue 12): ruinous inputs refused in one line within
5 s, --force, --dry-run, progress lines without a terminal, SIGTERM keeps what was computed."""

import json
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from cost_probe import child_env

ROOT = Path(__file__).parents[2]
DIRICHLET = {"dirichlet": [{"tags": ["boundary"], "value": 0}]}


def femkit(*args, cwd, timeout=60):
    """Run the femkit command in a child process (stderr is a pipe: not a terminal)."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "femkit.cli", *map(str, args)], cwd=cwd,
                         capture_output=True, text=True, timeout=timeout, env=child_env())
    return out, time.perf_counter() - t0


def femkit_main(*args, cwd, capsys, monkeypatch) -> tuple[int, str, str]:
    """The same command run in this process (``femkit.cli.main``; stderr captured, not a
    terminal), for checks that are not about the process: exit code, stdout, stderr."""
    from femkit.cli import main

    monkeypatch.chdir(cwd)
    capsys.readouterr()
    code = main([*map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


def signal_after_first_line(cwd, *args) -> tuple[str, int, str]:
    """Start femkit, wait for its first stderr line (progress: it is running), send SIGTERM;
    return that line, the exit code and the rest of stderr."""
    proc = subprocess.Popen([sys.executable, "-m", "femkit.cli", *map(str, args)], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=child_env())
    try:
        first = proc.stderr.readline()
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    return first, proc.returncode, err


def write(tmp_path, data, name="case.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


def rope_scene(**over) -> dict:
    scene = {"problem": "mass_spring", "name": "rope",
             "system": {"type": "rope", "n": 10, "length": 1.0, "dim": 2, "k": 100.0,
                        "total_mass": 1.0, "pinned": "first"},
             "forces": {"gravity": 9.81}, "integrator": "symplectic_euler",
             "dt": 1e-3, "t_end": 2.0, "output": {"frames": 20, "dir": "out"}}
    scene.update(over)
    return scene


TRUNCATED = (ROOT / "meshes" / "plate_with_hole.msh").read_bytes()[:3000]

RUINOUS = [
    ("h=1e-5", {"problem": "poisson", "mesh": {"geometry": "unit_square", "h": 1e-5},
                "boundary": DIRICHLET, "output": {"dir": "out"}},
     ["--max-memory", "2GiB"], ["predicted peak memory", "triangles", "exceeds the memory limit 2 GiB",
                                "use h >= "]),
    ("refine=8", {"problem": "poisson", "mesh": {"geometry": "unit_square", "h": 0.05, "refine": 8},
                  "boundary": DIRICHLET, "output": {"dir": "out"}},
     ["--max-memory", "8GiB"], ["predicted peak memory", "6.33e+07 triangles", "use refine <= "]),
    ("dt=1e-9", rope_scene(dt=1e-9, limits={"steps": 1e6}), [],
     ["2e+09 time steps planned", "limit of 1e+06 steps", "use dt >= 2e-06"]),
    ("truncated-msh", {"problem": "poisson", "mesh": {"file": "cut.msh"}, "boundary": DIRICHLET,
                       "output": {"dir": "out"}}, [],
     ["cut.msh: not a valid gmsh mesh", "truncated?"]),
]


@pytest.mark.parametrize("name,case,flags,pieces", RUINOUS, ids=[r[0] for r in RUINOUS])
def test_ruinous_input_ends_fast_with_one_line(tmp_path, name, case, flags, pieces):
    (tmp_path / "cut.msh").write_bytes(TRUNCATED)
    path = write(tmp_path, case)
    out, seconds = femkit("solve", path, *flags, cwd=tmp_path)
    assert out.returncode == 2 and seconds < 5.0, (out.returncode, seconds, out.stderr)
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("femkit: error: "), out.stderr
    for piece in pieces:
        assert piece in lines[0]
    assert "Error" not in lines[0] and "Traceback" not in out.stderr
    assert not (tmp_path / "out").exists()


def test_force_runs_a_budget_sized_variant(tmp_path, capsys, monkeypatch):
    """Refused under a tight budget; --force runs it (a warning names the exceeded budget)."""
    case = write(tmp_path, {"problem": "poisson", "mesh": {"geometry": "unit_square", "h": 0.1},
                            "boundary": DIRICHLET, "limits": {"memory": "40MB", "time": 3600},
                            "output": {"dir": "out"}})
    run = dict(cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    code, _, err = femkit_main("solve", case, **run)
    assert code == 2 and "exceeds the memory limit" in err
    code, _, err = femkit_main("solve", case, "--force", "--quiet", **run)
    assert code == 0, err
    assert err.startswith("femkit: warning: predicted peak memory")
    assert json.loads((tmp_path / "out" / "result.json").read_text())["converged"] is True


def test_force_runs_a_scene_over_its_step_budget(tmp_path, capsys, monkeypatch):
    scene = write(tmp_path, rope_scene(limits={"steps": 500}))
    run = dict(cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert femkit_main("solve", scene, **run)[0] == 2
    code, _, err = femkit_main("solve", scene, "--force", "--quiet", **run)
    assert code == 0, err
    assert json.loads((tmp_path / "out" / "result.json").read_text())["steps"] == 2000


def test_dry_run_prints_the_plan_and_runs_nothing(tmp_path, capsys, monkeypatch):
    case = write(tmp_path, {"problem": "poisson", "mesh": {"geometry": "l_shape", "h": 0.05, "refine": 1},
                            "boundary": DIRICHLET, "output": {"dir": "out", "plot": True}})
    code, text, _ = femkit_main("solve", case, "--dry-run", cwd=tmp_path, capsys=capsys,
                                monkeypatch=monkeypatch)
    assert code == 0 and not (tmp_path / "out").exists()
    for piece in ("plan ", "sizes     triangles", "mesh ", "refine ", "assembly ", "solve ",
                  "output ", "total ", "assumes "):
        assert piece in text
    import re

    tri = float(re.search(r"sizes     triangles ([\d,]+)", text).group(1).replace(",", ""))
    assert 10_000 < tri < 13_500  # gmsh makes 2,812 at h = 0.05, x4


def test_long_scene_prints_progress_lines_without_a_terminal(tmp_path):
    scene = write(tmp_path, rope_scene(dt=1e-4, t_end=1.0))  # 10,000 steps
    out, _ = femkit("solve", scene, cwd=tmp_path, timeout=120)
    assert out.returncode == 0, out.stderr
    lines = [ln for ln in out.stderr.splitlines() if ln.startswith("scene rope: ")]
    # one line per 10 % but at least 5 s apart, and the last always: a run of a few seconds
    # prints its last line (and one more per 5 s it took)
    elapsed = float(re.search(r"elapsed ([\d.]+) s$", lines[-1]).group(1))
    assert lines[-1].startswith("scene rope: 100% (10000/10000 steps), elapsed ")
    assert len(lines) <= 1 + elapsed // 5
    assert all("remaining ~" in ln for ln in lines[:-1])
    short = write(tmp_path, rope_scene(dt=1e-3, t_end=0.5, output={"dir": "out2"}), "short.yaml")
    quiet, _ = femkit("solve", short, "--quiet", cwd=tmp_path, timeout=120)
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_sigterm_leaves_a_loadable_partial_scene(tmp_path):
    import meshio

    scene = write(tmp_path, rope_scene(dt=1e-4, t_end=30.0, output={"every": 2000, "dir": "out"}))
    first, code, err = signal_after_first_line(tmp_path, "solve", scene)
    assert re.match(r"scene rope: \d+% ", first), first  # the run was stepping
    assert code == 143, err
    assert "interrupted by SIGTERM" in err.strip().splitlines()[-1]
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["interrupted"] is True and 0 < result["steps"] < result["steps_planned"]
    frames = sorted((tmp_path / "out" / "frames").glob("*.vtu"))
    assert len(frames) == result["frames"] >= 2
    last = meshio.read(frames[-1])
    assert last.points.shape == (10, 3)
    assert not list(tmp_path.glob("out.tmp*"))  # no half-written directory left behind


def test_study_dry_run_and_interruption_keeps_the_earlier_report(tmp_path):
    study = ROOT / "studies" / "poisson_convergence.yaml"
    out, _ = femkit("study", study, "--quick", "--dry-run", cwd=tmp_path)
    assert out.returncode == 0 and "level 0" in out.stdout and "level 2" in out.stdout
    earlier = tmp_path / "report"
    earlier.mkdir()
    (earlier / "results.json").write_text('{"earlier": true}')
    (earlier / "report.md").write_text("# the earlier report\n")
    first, code, err = signal_after_first_line(tmp_path, "study", study, "-o", earlier)
    assert first.startswith("poisson_convergence: "), first  # the sweep was running
    assert code == 143, err
    last = err.strip().splitlines()[-1]
    assert "interrupted by SIGTERM during the poisson_convergence sweep" in last
    assert "nothing written" in last
    assert sorted(p.name for p in earlier.iterdir()) == ["report.md", "results.json"]
    assert (earlier / "results.json").read_text() == '{"earlier": true}'
