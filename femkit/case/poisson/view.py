"""The Poisson kind's picture (:attr:`femkit.kinds.Kind.view` of ``problem: poisson``): the
solution ``u`` (or the element error indicators ``eta``, the coefficient ``kappa``, the region
``tag``) on the mesh, 2D from above, 3D clipped through the middle (or sliced, or its surface)
with the whole boundary as a ghost. Drawn from the result in memory (``result.plot()``: the
indicators are there) or from ``solution.vtu`` of a run directory. pyvista: ``femkit[view]``.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...view.core import Frame, Layer, Picture
from ...view.core.generic import field_names, surface
from ...view.core.render import pyvista
from ...view.core.source import Run, check_field

__all__ = ["poisson_view", "solution_picture", "SECTIONS"]

#: How a tetrahedral mesh is cut open -> what it shows.
SECTIONS = {"clip": "the half behind the plane through the centre normal to (1, 1, 1)",
            "slice": "three orthogonal slices through the centre",
            "surface": "the boundary surface"}

_TITLES = {"u": "u", "eta": "error indicator eta_T (log scale)", "kappa": "coefficient kappa",
           "tag": "region tag"}


def _grid(mesh, u, kappa=None, indicators=None):
    """A femkit mesh (triangles or tetrahedra) as a pyvista grid with ``u``, ``tag`` and, when
    given, ``kappa`` and ``eta``."""
    pv = pyvista()
    points = np.zeros((mesh.n_points, 3))
    points[:, :mesh.dim] = mesh.points
    kind = pv.CellType.TRIANGLE if mesh.dim == 2 else pv.CellType.TETRA
    grid = pv.UnstructuredGrid({kind: np.asarray(mesh.cells)}, points)
    grid.point_data["u"] = np.asarray(u, dtype=float)
    grid.cell_data["tag"] = np.asarray(mesh.cell_tags)
    if kappa is not None:
        kappa = np.asarray(kappa, dtype=float)
        grid.cell_data["kappa"] = np.broadcast_to(kappa, (mesh.n_cells,)).copy()
    if indicators is not None:
        grid.cell_data["eta"] = np.asarray(indicators, dtype=float)
    return grid, mesh.dim


def _grid_from_file(run: Run):
    """``solution.vtu``'s triangles (2D) or tetrahedra (3D), linear (P1) or quadratic (P2),
    without the boundary facets."""
    pv = pyvista()
    path = run.file("solution.vtu")
    grid = pv.read(path)
    c = pv.CellType
    solids = (c.TETRA, c.QUADRATIC_TETRA)
    dim = int(run.facts.get("mesh", {}).get("dim", 3 if set(solids) & set(grid.celltypes) else 2))
    kinds = solids if dim == 3 else (c.TRIANGLE, c.QUADRATIC_TRIANGLE)
    cells = grid.extract_cells_by_type(list(kinds))
    if cells.n_cells == 0:
        raise InputError(f"{path}: no {'tetrahedra' if dim == 3 else 'triangles'} in the file")
    return cells, dim


def _layers_3d(grid, scalars: str, title: str, log: bool, edges: bool, section: str) -> list:
    """The cut-open solid (coloured) and the whole boundary as a ghost."""
    centre = np.asarray(grid.center)
    ghost = Layer(surface(grid), color="grey", opacity=0.12)
    if section == "surface":
        shown = surface(grid)
        return [Layer(shown, scalars, title, log=log, edges=edges, cmap=_cmap(scalars),
                      lighting=False)]
    if section == "slice":
        shown = grid.slice_orthogonal(x=centre[0], y=centre[1], z=centre[2]).combine()
    else:
        shown = grid.clip(normal=(1.0, 1.0, 1.0), origin=centre, crinkle=scalars == "eta")
    # unlit: the colours are the colour map's, so the field reads off the colour bar
    return [Layer(shown, scalars, title, log=log, edges=edges, cmap=_cmap(scalars), lighting=False),
            ghost]


def _cmap(scalars: str) -> str:
    return {"eta": "magma", "tag": "tab10"}.get(scalars, "viridis")


def poisson_view(run: Run, field: str | None = None, edges: bool | None = None,
                 section: str = "clip") -> Picture:
    """The picture of a Poisson run.

    Parameters
    ----------
    run : Run
        The result in memory or the run directory (:func:`femkit.view.core.source.open_run`).
    field : str, optional
        ``u`` (default), ``eta`` (the estimator's indicators: a result in memory with an
        ``estimator``), ``kappa`` or ``tag``.
    edges : bool, optional
        Draw the mesh edges (default: when each cell gets 20 x 20 pixels on average).
    section : str
        3D only: one of :data:`SECTIONS`.
    """
    if run.result is not None:
        r = run.result
        grid, dim = _grid(r.mesh, r.u, r.kappa, r.indicators)
    else:
        grid, dim = _grid_from_file(run)
    return _picture(grid, dim, run.name, field, edges, section)


def solution_picture(mesh, u, name: str, edges: bool | None = None,
                     section: str = "clip") -> Picture:
    """The picture of a P1 field ``u`` on a femkit ``mesh`` (a study's solution), titled
    ``name``; as :func:`poisson_view` draws ``u``."""
    grid, dim = _grid(mesh, u)
    return _picture(grid, dim, name, "u", edges, section)


def _picture(grid, dim: int, case: str, field: str | None, edges: bool | None,
             section: str) -> Picture:
    """The picture of ``grid`` coloured by ``field`` (2D from above, 3D cut open)."""
    if section not in SECTIONS:
        raise InputError(f"unknown section {section!r}; valid sections: {', '.join(SECTIONS)}")
    fields = field_names(grid)
    name = check_field(field, fields, "u")
    log = name == "eta"
    cells = "triangles" if dim == 2 else "tetrahedra"
    title = f"{case}: {_TITLES.get(name, name).split(' (')[0]}, {grid.n_cells} {cells}"
    if dim == 2:
        layers = [Layer(grid, name, _TITLES.get(name, name), log=log, edges=edges,
                        cmap=_cmap(name))]
    else:
        layers = _layers_3d(grid, name, _TITLES.get(name, name), log, edges, section)
    return Picture([Frame(layers)], title=title, dim=dim, field=name, fields=tuple(fields))
