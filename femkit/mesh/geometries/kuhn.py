"""Kuhn-type tetrahedral geometries (no gmsh): the start meshes of adaptive bisection in 3D.

Conforming bisection of tetrahedra (:class:`femkit.mesh.bisect3d.TetBisection`, Maubach 1995)
needs a start mesh whose tetrahedra are Kuhn's six per axis-aligned cube; a gmsh mesh is not.
These geometries are unions of cubes of side ``h`` (``1 / h`` a whole number) cut as in
:func:`femkit.mesh.structured_box`:

* ``kuhn_cube``: the unit cube, with the tags of the gmsh ``unit_cube`` (faces ``xmin`` ...
  ``zmax``, ``boundary``; cells ``domain``);
* ``kuhn_fichera``: the Fichera corner, the cube ``(-1, 1)^3`` minus the octant ``[0, 1]^3``
  (volume 7, surface 24), as the gmsh geometry ``l_shape_3d``, with the same tags: faces
  ``reentrant`` (the three faces of the removed octant), ``outer`` (the rest), ``boundary``
  (all); cells ``domain``.

>>> from femkit.mesh import generate
>>> m = generate("kuhn_fichera", 0.5)
>>> m.n_cells, round(float(m.volumes().sum()), 12), sorted(m.tag_names)
(336, 7.0, ['boundary', 'domain', 'outer', 'reentrant'])
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ..faces import boundary_faces_topological
from ..mesh import Mesh
from ..structured import SIDES_3D, structured_box
from .registry import register_geometry


def _cubes_per_unit(h: float) -> int:
    n = int(round(1.0 / float(h)))
    if not (n >= 1 and abs(n * float(h) - 1.0) < 1e-9):
        raise InputError(f"a Kuhn-type geometry needs 1/h to be a whole number (cubes of side h); "
                         f"got h = {h!r}, try h = {1.0 / max(n, 1):g}")
    return n


@register_geometry("kuhn_cube", dim=3, measure=lambda: (1.0, 6.0),
                   boundary_tags=("xmin", "xmax", "ymin", "ymax", "zmin", "zmax", "boundary"),
                   cell_tags=("domain",))
def kuhn_cube(h: float) -> Mesh:
    """Unit cube ``[0, 1]^3``, the origin at a corner, of Kuhn cubes of side ``h`` (``1 / h`` a
    whole number; each cube cut into six tetrahedra about its main diagonal, as
    :func:`structured_box`): a start mesh for adaptive bisection.

    Face tags: ``xmin`` (x = 0), ``xmax`` (x = 1), ``ymin``, ``ymax``, ``zmin``, ``zmax``
    likewise, ``boundary`` (all six). Cell tag: ``domain``.
    """
    n = _cubes_per_unit(h)
    box = structured_box(n, n, n)
    domain = max(SIDES_3D.values()) + 1
    return Mesh(box.points, box.cells, cell_tags=np.full(box.n_cells, domain, np.int32),
                boundary_facets=box.boundary_facets, boundary_tags=box.boundary_tags,
                tag_names={**box.tag_names, "domain": domain})


@register_geometry("kuhn_fichera", dim=3, measure=lambda: (7.0, 24.0),
                   boundary_tags=("reentrant", "outer", "boundary"), cell_tags=("domain",))
def kuhn_fichera(h: float) -> Mesh:
    """Fichera corner: the cube ``(-1, 1)^3`` minus the octant ``[0, 1]^3`` (volume 7), of Kuhn
    cubes of side ``h`` (``1 / h`` a whole number): a start mesh for adaptive bisection.

    The re-entrant vertex is the origin. Face tags: ``reentrant`` (the three faces of the
    removed octant; tag number 1), ``outer`` (the rest; 2), ``boundary`` (every face again; 3).
    Cell tag: ``domain`` (4).
    """
    n = _cubes_per_unit(h)
    box = structured_box(2 * n, 2 * n, 2 * n, (2.0, 2.0, 2.0), origin=(-1.0, -1.0, -1.0))
    centre = box.points[box.cells].mean(axis=1)
    keep = ~(centre > 0).all(axis=1)
    cells = box.cells[keep]
    used = np.zeros(box.n_points, bool)
    used[cells] = True
    new_id = np.cumsum(used) - 1
    pts, cells = box.points[used], new_id[cells]
    faces = boundary_faces_topological(Mesh(pts, cells))
    c = pts[faces].mean(axis=1)
    tol = 1e-9
    on_plane = (np.abs(c) < tol) & (c.min(axis=1, keepdims=True) > -tol)  # in [0, 1]^3 too
    tag = np.where(on_plane.any(axis=1), 1, 2)
    order = np.argsort(tag, kind="stable")
    facets = np.concatenate([faces[order], faces[order]])
    tags = np.concatenate([tag[order], np.full(len(faces), 3)]).astype(np.int32)
    names = {"reentrant": 1, "outer": 2, "boundary": 3, "domain": 4}
    return Mesh(pts, cells, cell_tags=np.full(len(cells), 4, np.int32), boundary_facets=facets,
                boundary_tags=tags, tag_names=names)
