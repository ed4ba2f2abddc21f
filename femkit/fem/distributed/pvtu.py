"""A distributed solution written as a parallel VTK file: one ``.vtu`` piece per rank and a
``.pvtu`` index (VTK file formats, "Parallel XML files"), for meshes too large to gather.

Rank ``r`` writes ``NAME_p{r}.vtu``: its own elements, the nodes they use (with ``u`` fetched
from the ranks owning them), cell data ``tag``, ``rank`` and any per-element arrays given; rank 0
writes ``NAME.pvtu`` listing the pieces with the array declarations read back from its own piece
(so the index always matches what was written). Pieces and index are written by femkit's one
VTK writer (:mod:`femkit.mesh.vtk`). ParaView opens the ``.pvtu`` as one dataset.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .assembly import values_at


def write_pvtu(directory, name: str, mesh, u_vec, layout, comm,
               cell_data: dict | None = None) -> Path:
    """Write the pieces and the index; returns the ``.pvtu`` path (on every rank).

    ``cell_data``: ``{name: (m,) array over the whole mesh}``; each rank writes its elements'.
    """
    from ...mesh import Mesh, write_mesh
    from ...mesh.vtk import write_parallel_index

    mpi = comm.tompi4py()
    directory = Path(directory)
    rank, size = layout.rank, layout.size
    own = layout.elements
    nodes, local_cells = np.unique(mesh.cells[own], return_inverse=True)
    sub = Mesh(mesh.points[nodes], local_cells.reshape(-1, mesh.cells.shape[1]),
               None if mesh.cell_tags is None else mesh.cell_tags[own])
    u = values_at(u_vec, layout, nodes, comm)
    cells = {"rank": np.full(len(own), rank, dtype=np.int32)}
    if mesh.cell_tags is not None:
        cells["tag"] = np.asarray(mesh.cell_tags[own], dtype=np.int32)
    for key, values in (cell_data or {}).items():
        cells[key] = np.asarray(values)[own]
    piece = directory / f"{name}_p{rank}.vtu"
    write_mesh(piece, sub, point_data={"u": u}, cell_data=cells)
    mpi.Barrier()
    index = directory / f"{name}.pvtu"
    if rank == 0:
        write_parallel_index(index, piece, [f"{name}_p{r}.vtu" for r in range(size)])
    mpi.Barrier()
    return index
