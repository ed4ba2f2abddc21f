"""The fixed costs of a ``femkit`` command: what a solve imports, the bytecode ``femkit warmup``
writes, and the process's exit (``os._exit`` after what a normal exit does that matters)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from importlib.util import cache_from_source
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared case
from _small import SMALL as CASE  # noqa: E402

#: imported by nothing a solve does (each was, before): the duplicate-node check's k-d tree, the
#: studies' timing helpers, xml.sax (and urllib.request, http.client behind it) for one escape;
#: and the pictures' pyvista and VTK (femkit[view]), imported by `femkit view` and plot() alone
LAZY = ("scipy.spatial", "femkit.study.timing", "femkit.study.load", "femkit.study.run", "xml.sax",
        "urllib.request", "http.client", "pyvista", "vtkmodules", "femkit.view")

IMPORTS = """
import sys, types
from femkit.cli import main
from femkit.cli.startup import DEFERRED_IMPORTS, defer_unused_imports
defer_unused_imports()                      # as the femkit command does (femkit.cli.entry)
code = main(["solve", sys.argv[1], "--quiet"])
print(code)
print(",".join(m for m in {lazy!r} if m in sys.modules))
# imported by scipy's array-API layer, but never executed: still Python's lazy module object
print(",".join(m for m in DEFERRED_IMPORTS if type(sys.modules.get(m, sys)) is types.ModuleType))
import numpy.testing
numpy.testing.assert_allclose(1.0, 1.0)     # usable: executed on first use
print(type(sys.modules["numpy.testing"]) is types.ModuleType)
"""


def _case(tmp_path: Path, **changes) -> Path:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(dict(CASE, **changes)))
    return path


def test_a_solve_imports_neither_spatial_nor_study_nor_xml_and_defers_unused_numpy(tmp_path):
    proc = subprocess.run([sys.executable, "-c", IMPORTS.format(lazy=LAZY), str(_case(tmp_path))],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    code, imported, executed, usable = proc.stdout.split("\n")[:4]
    assert code == "0" and (tmp_path / "out" / "solution.vtu").is_file()
    assert imported == "", f"a tiny solve imported {imported}"
    assert executed == "", f"executed although unused: {executed}"
    assert usable == "True"


def test_warmup_bytecode_is_written_and_read_under_dont_write_bytecode(tmp_path, monkeypatch):
    """``byte_compile`` (``femkit warmup``) writes a valid .pyc per module, which a process with
    ``PYTHONDONTWRITEBYTECODE=1`` then reads instead of compiling the source."""
    from femkit.cli.bytecode import byte_compile

    pkg = tmp_path / "femkit"
    shutil.copytree(Path(__file__).resolve().parents[2] / "femkit" / "mesh", pkg / "mesh",
                    ignore=shutil.ignore_patterns("__pycache__"))
    (pkg / "__init__.py").write_text("")
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    written, failed = byte_compile(str(pkg))
    sources = sorted(pkg.rglob("*.py"))
    assert (written, failed) == (len(sources), 0) and written > 10
    assert all(Path(cache_from_source(str(s))).is_file() for s in sources)
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1", PYTHONPATH=str(tmp_path))
    proc = subprocess.run([sys.executable, "-v", "-c", "import femkit.mesh.structured"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    pyc = cache_from_source(str(pkg / "mesh" / "structured.py"))
    assert f"code object from '{pyc}'" in proc.stderr  # read, not compiled from source


EXIT = """
import atexit, sys, threading, time
from pathlib import Path

def late():                                  # a non-daemon thread still working at the end
    time.sleep(0.3)
    Path("thread.txt").write_text("joined")

atexit.register(lambda: print("atexit handler ran"))
threading.Thread(target=late).start()
sys.argv = ["femkit", "solve", sys.argv[1]]
from femkit.cli import entry
entry()
print("not reached")
"""


@pytest.mark.parametrize("changes, code", [
    ({}, 0),
    ({"solver": {"method": "cg", "rtol": 1e-14, "maxiter": 1}}, 1),
    ({"source": "import os"}, 2),
], ids=["ok-0", "not-converged-1", "bad-input-2"])
def test_the_exit_joins_threads_runs_atexit_flushes_and_keeps_the_code(tmp_path, changes, code):
    proc = subprocess.run([sys.executable, "-c", EXIT, str(_case(tmp_path, **changes))], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == code, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[-1] == "atexit handler ran" and "not reached" not in proc.stdout
    assert (tmp_path / "thread.txt").read_text() == "joined"
    if code == 0:
        assert any(ln.startswith("wall") for ln in lines)  # the summary, flushed to a pipe
    if code == 2:
        assert proc.stderr.startswith("femkit: error:") and proc.stderr.count("\n") == 1


def test_python_dash_m_femkit_exits_with_the_code(tmp_path):
    path = _case(tmp_path, source="import os")
    proc = subprocess.run([sys.executable, "-m", "femkit", "solve", str(path)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_deferred_modules_are_not_deferred_when_already_imported():
    code = textwrap.dedent("""
        import sys, numpy.testing
        from femkit.cli.startup import DeferredFinder, defer_unused_imports
        defer_unused_imports()
        print(any(isinstance(f, DeferredFinder) for f in sys.meta_path))
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "False"


def test_a_profiled_command_still_writes_its_profile(tmp_path):
    """``python -m cProfile -o p.out -m femkit.cli solve ...``: cProfile writes after the command
    returns, so under a profiler the exit is the interpreter's own."""
    proc = subprocess.run([sys.executable, "-m", "cProfile", "-o", str(tmp_path / "p.out"), "-m",
                           "femkit.cli", "solve", str(_case(tmp_path)), "--quiet"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    import pstats

    assert pstats.Stats(str(tmp_path / "p.out")).total_calls > 0


def test_numba_start_up_is_its_own_stage_before_the_mesh(tmp_path):
    """A run that calls compiled kernels (fmg) books numba's import and registries in a ``numba``
    stage, once, before the mesh stage (not inside it, nor in "other"); the parts still sum."""
    import json

    path = _case(tmp_path, solver={"method": "fmg"}, mesh={"geometry": "unit_square", "h": 0.25,
                                                            "refine": 1})
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", "solve", str(path)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    res = json.loads((tmp_path / "out" / "result.json").read_text())
    stages = list(res["timings"])
    assert stages[0] == "numba" and stages.count("numba") == 1 and "mesh" in stages
    w = res["wall"]
    assert w["total"] == pytest.approx(w["startup"] + w["stages"] + w["other"], rel=1e-9)
    assert "time      numba " in proc.stdout
