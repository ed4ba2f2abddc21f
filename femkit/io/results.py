"""Outputs of a Poisson run: ``result.json``, the solution as ``.vtu`` / ``.xdmf``, a PNG plot.

Every file is written atomically (see :mod:`femkit.io.atomic`). The keys of ``result.json``
are documented in docs/case-files.md ("Outputs").
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .atomic import atomic_path
from .writers import to_jsonable, write_json  # noqa: F401 (re-exported)

__all__ = ["to_jsonable", "write_json", "write_solution", "write_plot", "RESULT_KEYS"]

#: Top-level keys of result.json.
RESULT_KEYS = ("case", "problem", "case_file", "femkit_version", "mesh", "dofs", "nnz",
               "solver", "converged", "errors", "timings", "expressions", "files")


def write_solution(path: str | os.PathLike, mesh, u: np.ndarray, kappa: np.ndarray | None = None,
                   extra_point_data: dict | None = None) -> Path:
    """Write the mesh with point data ``u`` and cell data ``kappa`` and ``tag`` (vtu/xdmf by extension).

    Not atomic by itself (meshio may write sibling files); use it inside
    :func:`femkit.io.atomic.atomic_directory`.
    """
    from ..mesh import write_mesh

    point_data = {"u": np.asarray(u, dtype=np.float64)}
    point_data.update(extra_point_data or {})
    cell_data = {"tag": np.asarray(mesh.cell_tags, dtype=np.int32)}
    if kappa is not None:
        cell_data["kappa"] = np.asarray(kappa, dtype=np.float64)
    # Written in place: sibling files (XDMF's .h5, a tag-name sidecar) are named after the
    # file, so a temporary name would orphan them. Callers write into an atomic directory.
    target = Path(path)
    write_mesh(target, mesh, point_data=point_data, cell_data=cell_data)
    return target


def write_plot(path: str | os.PathLike, mesh, u: np.ndarray, title: str = "") -> Path:
    """Save a filled-contour PNG of ``u`` with a colour bar (matplotlib, Agg backend)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    tri = Triangulation(mesh.points[:, 0], mesh.points[:, 1], mesh.triangles)
    fig, ax = plt.subplots(figsize=(6, 5), dpi=120)
    try:
        art = ax.tripcolor(tri, np.asarray(u, dtype=np.float64), shading="gouraud", cmap="viridis")
        fig.colorbar(art, ax=ax, label="u")
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_title(title, fontsize=9)
        fig.tight_layout()
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png")
    finally:
        plt.close(fig)
    return Path(path)
