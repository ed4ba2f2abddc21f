"""Shared test setup: pinned BLAS threads, headless plotting."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_collection_modifyitems(config, items):
    """``@pytest.mark.cholmod`` tests need the optional scikit-sparse (CHOLMOD): they run where it is
    installed (CI installs it) and skip, saying how to install it, where it is not."""
    import pytest

    from femkit.solvers.cholesky import available

    if available():
        return
    skip = pytest.mark.skip(reason="scikit-sparse (CHOLMOD) is not installed: "
                                   "bash scripts/install-cholesky.sh")
    for item in items:
        if "cholmod" in item.keywords or item.name == "femkit.solvers.cholesky":  # its doctest
            item.add_marker(skip)
