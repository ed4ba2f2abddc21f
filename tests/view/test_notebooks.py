"""The notebooks of docs/notebooks/ run (nbclient) and draw their pictures: a notebook ends
without an error and shows a picture (a PNG, a time series' animated GIF, or the frame slider's
widget with its image) for every code cell but its first, so the gallery cannot rot.

Every notebook runs in the default test run (each a small run of a bundled case: a few seconds).
They share one kernel, started once: before each notebook its namespace is emptied (:data:`CLEAR`;
``%reset -f`` does the same plus a garbage collection that costs a second each time), so a
notebook that used a name of another fails as in a fresh kernel; what is shared is the modules
already imported, femkit's kernels already loaded and the OpenGL context (the start-up a user
pays once per session: about 5 s of the whole on 2 cores).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="the test extra installs nbformat")
pytest.importorskip("pyvista", reason="femkit[view] (pyvista) is part of the test extra")

ROOT = Path(__file__).resolve().parents[2]
HERE = ROOT / "docs" / "notebooks"
NOTEBOOKS = sorted(HERE.glob("*.ipynb"))
WIDGET = "application/vnd.jupyter.widget-view+json"
#: The cell run before each notebook: every user name goes (IPython's own stay).
CLEAR = """_ip = get_ipython()
for _name in [k for k in _ip.user_ns if not k.startswith("_") and k not in _ip.user_ns_hidden]:
    del _ip.user_ns[_name]"""


def _pictures(nb) -> int:
    """Code cells showing a picture: a PNG, an animated GIF, or a widget whose state holds
    an image (the slider's frame)."""
    state = nb.metadata.get("widgets", {}).get("application/vnd.jupyter.widget-state+json", {})
    images = [m for m in state.get("state", {}).values() if m.get("model_name") == "ImageModel"
              and any(b.get("path") == ["value"] and b.get("data") for b in m.get("buffers", []))]
    count = 0
    for cell in nb.cells:
        shown = False
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            shown |= "image/png" in data or "data:image/gif;base64" in data.get("text/html", "")
            shown |= WIDGET in data and bool(images)
        count += shown
    return count


@pytest.fixture(scope="module")
def kernel():
    """One python3 kernel in docs/notebooks/ importing this checkout's femkit."""
    from jupyter_client.manager import KernelManager

    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    km = KernelManager(kernel_name="python3")
    km.start_kernel(cwd=str(HERE), env=env)
    try:
        yield km
    finally:
        km.shutdown_kernel(now=True)


def test_the_gallery_is_there():
    names = {p.stem for p in NOTEBOOKS}
    assert {"poisson_2d_adaptive", "poisson_3d_fichera", "solid_cantilever", "cloth_scene",
            "convergence_study"} <= names


def _run(path: Path, kernel) -> str | None:
    """Execute the notebook at ``path`` in ``kernel`` (its namespace emptied first); what went
    wrong, or None."""
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    nb = nbformat.read(path, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(CLEAR))
    client = NotebookClient(nb, km=kernel, timeout=120, resources={"metadata": {"path": str(HERE)}})
    try:
        client.execute()
    except CellExecutionError as exc:
        return f"{path.name}: {exc.ename}: {exc.evalue}"
    finally:
        if client.kc is not None:
            client.kc.stop_channels()
    nb.cells.pop(0)
    code_cells = [c for c in nb.cells if c.cell_type == "code"]
    if _pictures(nb) < len(code_cells) - 1:
        return f"{path.name}: {_pictures(nb)} pictures for {len(code_cells)} code cells"
    return None


def test_every_notebook_runs_and_draws_its_pictures(kernel):
    """One test, one kernel (pytest-xdist would otherwise start a kernel per worker); every
    notebook runs, and each one's failure is reported."""
    problems = [p for p in (_run(path, kernel) for path in NOTEBOOKS) if p]
    assert not problems, "\n".join(problems)
