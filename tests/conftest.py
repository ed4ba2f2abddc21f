"""Shared test setup: pinned BLAS threads, headless plotting."""

import os
import sys
from pathlib import Path

# benchmarks/cost_probe.py (the measuring probe, child_env) is imported by the cost tests
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_collection_modifyitems(config, items):
    """``@pytest.mark.cholmod`` tests need the optional scikit-sparse (CHOLMOD) and
    ``@pytest.mark.pardiso`` tests the optional MKL (PARDISO): they run where it is installed (CI
    installs both) and skip, saying how to install it, where it is not."""
    import pytest

    from femkit.solvers.cholesky import available as cholmod_available
    from femkit.solvers.pardiso import available as pardiso_available

    skips = {}
    if not cholmod_available():
        skips["cholmod"] = pytest.mark.skip(reason="scikit-sparse (CHOLMOD) is not installed: "
                                                   "bash scripts/install-cholesky.sh")
    if not pardiso_available():
        skips["pardiso"] = pytest.mark.skip(reason="MKL (PARDISO) is not installed: "
                                                   "pip install -e '.[pardiso]'")
    for item in items:
        for marker, skip in skips.items():
            if marker in item.keywords or (marker == "cholmod" and item.name == "femkit.solvers.cholesky"):
                item.add_marker(skip)
    _xdist_groups(config, items)
    # the long tests first: pytest-xdist hands tests out in this order, and a long one handed out
    # last keeps one worker busy while the others have finished (``slow``: tens of seconds; an
    # ``xdist_group`` shares a fixture that compiles). A stable sort: the same order on every worker.
    items.sort(key=lambda item: item.get_closest_marker("slow") is None
               and item.get_closest_marker("xdist_group") is None)


import pytest  # noqa: E402


def _xdist_groups(config, items) -> None:
    """``--dist loadgroup`` (pyproject's addopts): pytest-xdist's worker names a test of an
    ``xdist_group`` by its node id with ``@group`` appended, which its scheduler reads; with
    pytest >= 9 (node ids built from a structured id) that assignment has no effect and the
    groups are silently spread over the workers. Appended here in the structured id when the
    worker's own did not take (nothing done with a pytest where it did, or without xdist)."""
    if not getattr(config.option, "loadgroup", False):
        return
    try:
        from _pytest.nodeid import NodeId
    except ImportError:  # pytest < 9: pytest-xdist's own suffix works
        return
    for item in items:
        names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                        for m in item.iter_markers("xdist_group")})
        if names and "@" not in item.nodeid:
            item._id = NodeId.parse(f"{item.nodeid}@{'_'.join(names)}")


@pytest.fixture(scope="session")
def fresh_warmup(tmp_path_factory):
    """``femkit warmup`` run once per session into an empty femkit cache directory: what a first
    install's warm-up generates and compiles there (the case expressions' and the built-in
    materials' modules), shared by the tests that check it (each marked
    ``xdist_group("fresh_warmup")`` so that one worker runs them all and the warm-up once).
    numba's cache of femkit's own kernels is its default one. Returns ``(cache directory, the
    command's stdout, the environment in which a process sees that cache)``."""
    import subprocess

    cache = tmp_path_factory.mktemp("fresh-femkit-cache")
    env = dict(os.environ, FEMKIT_CACHE_DIR=str(cache))
    env.pop("NUMBA_CACHE_DIR", None)  # generated modules' machine code beside them, in `cache`
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", "warmup"], cwd=cache, env=env,
                          capture_output=True, text=True, timeout=1500)
    assert proc.returncode == 0, proc.stderr
    return cache, proc.stdout, env
