"""What every gmsh-built geometry does in a gmsh session: start gmsh quietly and
deterministically (:func:`gmsh_session`), set the size (:func:`set_size`), name physical groups
(:func:`physical_group`), mesh interruptibly (:func:`run_mesher`) and read the model back as a
:class:`~femkit.mesh.Mesh` (:func:`mesh_from_gmsh`); and user ``.geo`` files (:func:`geo_file`).

gmsh is imported inside the functions only, so ``import femkit.mesh`` stays cheap and a case
that reads a ``.msh`` file never loads it.
"""

from __future__ import annotations

import contextlib
import os
from typing import Iterator, Sequence

import numpy as np

from ...errors import MeshError
from ...validation import mesh_size as _check_h
from ..mesh import Mesh

__all__ = ["gmsh_session", "run_mesher", "set_size", "mesh_from_gmsh", "physical_group", "geo_file"]

#: gmsh element type numbers
_GMSH_LINE, _GMSH_TRIANGLE, _GMSH_TETRA = 1, 2, 4


#: set when a stop request abandoned gmsh's mesher in its thread (see :func:`run_mesher`)
_ABANDONED: list = []


def run_mesher(gmsh, dim: int) -> None:
    """``gmsh.model.mesh.generate(dim)``, answering SIGINT/SIGTERM within a fraction of a second
    under :func:`femkit.interrupt.stop_on_signals` (gmsh's C++ mesher never returns to Python
    until done: a large mesh used to hold a Ctrl-C for many seconds)."""
    from ...interrupt import run_interruptible

    run_interruptible(gmsh.model.mesh.generate, dim, what="meshing",
                      on_abandon=lambda: _ABANDONED.append(True))


@contextlib.contextmanager
def gmsh_session(name: str) -> Iterator[object]:
    """Initialise gmsh quietly (or reuse a live session), yield the module, clean up.

    If gmsh was already initialised by the caller, a fresh model is added and removed again
    and gmsh is left running; otherwise gmsh is finalised on exit, also on errors.
    """
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        with _python_signal_handlers():
            gmsh.initialize(argv=[], readConfigFiles=False, run=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads2D", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads3D", 1)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
        gmsh.option.setNumber("Mesh.RandomSeed", 1)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.model.add(name)
        yield gmsh
    finally:
        if _ABANDONED:  # a stop request left the mesher running in its thread: the process is
            pass        # about to exit, and finalising gmsh under it would crash
        elif owner:
            gmsh.finalize()
        else:
            with contextlib.suppress(Exception):
                gmsh.model.remove()


@contextlib.contextmanager
def _python_signal_handlers() -> Iterator[None]:
    """Put Python's SIGINT/SIGTERM handlers back after gmsh's initialisation, which installs
    its own at the C level (a SIGTERM would then kill the process instead of reaching
    :func:`femkit.interrupt.stop_on_signals`)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in saved.items():
            if handler is not None:
                signal.signal(s, handler)


def set_size(gmsh, h: float) -> None:
    """Largest element size ``h`` everywhere (no smaller size from curvature)."""
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)


def mesh_from_gmsh(gmsh, dim: int = 2) -> Mesh:
    """Turn the current gmsh model (already meshed in ``dim`` = 2 or 3) into a :class:`Mesh`.

    Cells (triangles in 2D, tetrahedra in 3D): when the model has physical groups of that
    dimension, only cells of entities in a physical group are kept (gmsh's own rule when
    saving), each tagged with its group (the first group when an entity is in several);
    otherwise all cells, tag 0. Facets (edges, triangles) of the physical groups of dimension
    ``dim - 1`` become the tagged boundary. Nodes not used by any kept cell are dropped (e.g.
    circle centres); node order follows gmsh's node tags.
    """
    model = gmsh.model
    cell_code, facet_code = (_GMSH_TRIANGLE, _GMSH_LINE) if dim == 2 else (_GMSH_TETRA, _GMSH_TRIANGLE)
    width = dim + 1
    node_tags, coords, _ = model.mesh.getNodes(-1, -1, includeBoundary=True,
                                               returnParametricCoord=False)
    node_tags = np.asarray(node_tags, dtype=np.int64)
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3)

    def blocks_of(entity_dim: int, ent: int, code: int, w: int):
        types, _, enodes = model.mesh.getElements(entity_dim, ent)
        return [np.asarray(nodes, np.int64).reshape(-1, w) for t, nodes in zip(types, enodes)
                if t == code]

    tri_blocks, tag_blocks = [], []
    names: dict[str, int] = {}
    groups = model.getPhysicalGroups(dim)
    if groups:
        seen_entities: set[int] = set()
        for gdim, ptag in groups:
            name = model.getPhysicalName(gdim, ptag)
            if name:
                names[name] = int(ptag)
            for ent in model.getEntitiesForPhysicalGroup(gdim, ptag):
                if int(ent) in seen_entities:
                    continue
                seen_entities.add(int(ent))
                for b in blocks_of(dim, int(ent), cell_code, width):
                    tri_blocks.append(b)
                    tag_blocks.append(np.full(len(b), ptag, np.int32))
    else:
        for _, ent in model.getEntities(dim):
            for b in blocks_of(dim, ent, cell_code, width):
                tri_blocks.append(b)
                tag_blocks.append(np.zeros(len(b), np.int32))
    if not tri_blocks:
        found = sorted({gmsh.model.mesh.getElementProperties(int(t))[0]
                        for t in model.mesh.getElementTypes(dim)})
        what = "linear triangles" if dim == 2 else "linear tetrahedra"
        raise MeshError(f"gmsh produced no {what}"
                        + (f" (found {dim}D element types: {', '.join(found)})" if found else ""))
    tri_gmsh = np.concatenate(tri_blocks)
    cell_tags = np.concatenate(tag_blocks)

    edge_blocks, etag_blocks = [], []
    for gdim, ptag in model.getPhysicalGroups(dim - 1):
        name = model.getPhysicalName(gdim, ptag)
        if name:
            names[name] = int(ptag)
        for ent in model.getEntitiesForPhysicalGroup(gdim, ptag):
            for b in blocks_of(dim - 1, int(ent), facet_code, dim):
                edge_blocks.append(b)
                etag_blocks.append(np.full(len(b), ptag, np.int32))
    edges_gmsh = np.concatenate(edge_blocks) if edge_blocks else np.zeros((0, dim), np.int64)
    edge_tags = np.concatenate(etag_blocks) if etag_blocks else np.zeros(0, np.int32)

    # compact numbering: keep nodes used by cells, in gmsh tag order
    order = np.argsort(node_tags, kind="stable")
    sorted_tags = node_tags[order]
    used = np.unique(tri_gmsh)
    pos = np.searchsorted(sorted_tags, used)
    if np.any(pos >= len(sorted_tags)) or np.any(sorted_tags[np.minimum(pos, len(sorted_tags) - 1)] != used):
        raise MeshError("gmsh returned cells referring to unknown nodes")
    points = xyz[order[pos], :dim]

    def renumber(arr: np.ndarray) -> np.ndarray:
        idx = np.searchsorted(used, arr)
        idx = np.minimum(idx, len(used) - 1)
        ok = used[idx] == arr
        return idx, ok

    tri, ok = renumber(tri_gmsh)
    e, eok = renumber(edges_gmsh)
    keep = eok.all(axis=1) if len(e) else np.zeros(0, bool)
    from ..validate import orient_ccw

    return orient_ccw(Mesh(points=points, cells=tri, cell_tags=cell_tags,
                           boundary_facets=e[keep], boundary_tags=edge_tags[keep],
                           tag_names=names))


def physical_group(gmsh, dim: int, entities: Sequence[int], name: str, tag: int) -> None:
    """Physical group ``tag`` named ``name`` of the ``dim``-dimensional ``entities``."""
    gmsh.model.addPhysicalGroup(dim, list(entities), tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def geo_file(path: str | os.PathLike, h: float | None = None) -> Mesh:
    """Mesh a user ``.geo`` file with gmsh (physical groups become tags): in 3D when it defines
    volumes (tetrahedra; physical surfaces become the tagged faces), else in 2D.

    Parameters
    ----------
    path : path to the ``.geo`` (or any file gmsh can open)
    h : optional maximal mesh size; ``None`` keeps the sizes the file sets.

    Tags come only from the file's physical groups (no ``"boundary"`` group is added): with
    2D physical groups only their triangles are kept (gmsh's saving rule), without any all
    triangles are kept with cell tag 0.

    Raises
    ------
    MeshError
        The file is missing, gmsh cannot open it or produces no triangles.
    """
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MeshError(f"geometry file not found: {p}")
    hv = None if h is None else _check_h(h)
    with gmsh_session("geo_file") as gmsh:
        try:
            gmsh.open(p)
            if hv is not None:
                gmsh.option.setNumber("Mesh.MeshSizeMax", hv)
            gmsh.option.setNumber("Mesh.ElementOrder", 1)
            dim = 3 if gmsh.model.getEntities(3) else 2
            run_mesher(gmsh, dim)
        except Exception as exc:  # gmsh raises bare Exception with its last error
            raise MeshError(f"gmsh could not mesh {p}: {exc}") from None
        if dim == 3:
            _refuse_unassigned_volumes(gmsh, p)
        return mesh_from_gmsh(gmsh, dim)


def _refuse_unassigned_volumes(gmsh, path: str) -> None:
    """A .geo with physical volumes that leave a volume out would lose its tetrahedra
    silently (gmsh's saving rule): refuse it in one line."""
    groups = gmsh.model.getPhysicalGroups(3)
    if not groups:
        return
    grouped = {int(e) for _, t in groups for e in gmsh.model.getEntitiesForPhysicalGroup(3, t)}
    loose = sorted(int(t) for _, t in gmsh.model.getEntities(3) if int(t) not in grouped)
    if loose:
        raise MeshError(f"{path}: volume(s) {', '.join(map(str, loose))} belong to no physical "
                        "volume; add them to a Physical Volume (gmsh would drop their tetrahedra)")

