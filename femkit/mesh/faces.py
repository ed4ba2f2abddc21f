"""Faces of a tetrahedral mesh and its boundary (the 3D counterpart of :mod:`.edges`).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> t = Mesh(np.eye(4, 3)[[3, 0, 1, 2]], np.array([[0, 1, 2, 3]]))
>>> faces(t)[0].tolist()
[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
>>> len(boundary_faces_topological(t))
4
"""

from __future__ import annotations

import numpy as np

from .mesh import Mesh
from ..warmup_registry import register_kernels, register_threshold

__all__ = ["LOCAL_FACES", "local_faces", "faces", "boundary_faces_topological", "unique_rows",
           "face_ids"]

#: Local face ``k`` of a tetrahedron is opposite its vertex ``k``, ordered so that its normal
#: ``(b - a) x (c - a)`` points out of a positively oriented tetrahedron.
LOCAL_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])

#: Meshes with at least this many tetrahedra find their faces with a compiled counting sort
#: (:mod:`femkit.mesh._faces_kernel`, the same numbering); smaller ones with a lexicographic sort.
NUMBA_THRESHOLD = 100_000
register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("mesh passes", "femkit.mesh._faces_kernel", "tet_faces", rank=0, tetrahedra_only=True)


def local_faces(tets: np.ndarray) -> np.ndarray:
    """(m, 4, 3) outward-oriented faces of each tetrahedron (face k opposite vertex k)."""
    return tets[:, LOCAL_FACES]


def unique_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unique rows of an int array (k, w), lexicographically sorted, and the inverse map.

    A lexicographic sort, so no packing of a row into one integer that could overflow on
    large meshes.
    """
    rows = np.asarray(rows, dtype=np.int64)
    if len(rows) == 0:
        return rows.reshape(0, rows.shape[1]), np.zeros(0, np.int64)
    order = np.lexsort(rows.T[::-1])
    s = rows[order]
    new = np.ones(len(s), bool)
    new[1:] = (s[1:] != s[:-1]).any(axis=1)
    ids = np.cumsum(new) - 1
    inverse = np.empty(len(s), np.int64)
    inverse[order] = ids
    return s[new], inverse


def faces(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Unique faces and the element -> face map (compiled from :data:`NUMBA_THRESHOLD`
    tetrahedra on).

    Returns
    -------
    face_nodes : (F, 3) int64
        Node triples, each sorted ascending, rows sorted lexicographically.
    tet_faces : (m, 4) int64
        ``tet_faces[t, k]`` is the face of tetrahedron ``t`` opposite its local vertex ``k``.
    """
    if mesh.n_cells >= NUMBA_THRESHOLD:
        from ._faces_kernel import tet_faces

        return tet_faces(np.ascontiguousarray(mesh.tetrahedra, dtype=np.int64), LOCAL_FACES,
                         max(mesh.n_points, 1))
    loc = np.sort(local_faces(mesh.tetrahedra).reshape(-1, 3), axis=1)
    face_nodes, inverse = unique_rows(loc)
    return face_nodes, inverse.reshape(-1, 4)


def boundary_faces_topological(mesh: Mesh) -> np.ndarray:
    """Faces used by exactly one tetrahedron, oriented with the outward normal.

    Found from the connectivity alone, independent of any tags.
    """
    loc = local_faces(mesh.tetrahedra).reshape(-1, 3)
    _, tet_faces = faces(mesh)
    counts = np.bincount(tet_faces.ravel(), minlength=int(tet_faces.max(initial=-1)) + 1)
    return loc[counts[tet_faces.ravel()] == 1]


def face_ids(face_nodes: np.ndarray, triples: np.ndarray) -> np.ndarray:
    """Index in ``face_nodes`` (from :func:`faces`) of each node triple (k, 3), in any order.

    Raises :class:`~femkit.errors.MeshError` when a triple is not a face of any tetrahedron.
    """
    from ..errors import MeshError

    triples = np.sort(np.asarray(triples, dtype=np.int64).reshape(-1, 3), axis=1)
    uniq, inverse = unique_rows(np.concatenate([face_nodes, triples]))
    if len(uniq) != len(face_nodes):
        known = np.zeros(len(uniq), bool)
        known[inverse[:len(face_nodes)]] = True
        bad = np.flatnonzero(~known[inverse[len(face_nodes):]])
        raise MeshError(f"{len(bad)} boundary face(s) are not faces of any tetrahedron "
                        f"(face ids {', '.join(map(str, bad[:10]))})")
    return inverse[len(face_nodes):]
