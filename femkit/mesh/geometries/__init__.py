"""Named geometries meshed on demand: the registry and every geometry femkit bundles.

Modules: :mod:`~femkit.mesh.geometries.registry` (:class:`Geometry`, :data:`GEOMETRIES`,
:func:`register_geometry`, :func:`generate`), :mod:`~femkit.mesh.geometries.gmsh_session` (the
gmsh plumbing every gmsh-built geometry shares, and :func:`geo_file`; gmsh is imported inside
its functions only, so ``import femkit.mesh`` stays cheap and a case that reads a ``.msh``
file never loads it), :mod:`~femkit.mesh.geometries.planar` (the 2D geometries),
:mod:`~femkit.mesh.geometries.solid` (the 3D gmsh ones) and :mod:`~femkit.mesh.geometries.kuhn`
(Kuhn-cube tetrahedral meshes without gmsh, for 3D bisection) and
:mod:`~femkit.mesh.geometries.cook` (Cook's membrane, a benchmark of the elastic solids).

Every geometry is one entry of :data:`GEOMETRIES`, a :class:`Geometry` record; call it through
:func:`generate`::

    generate("l_shape", h=0.1)
    generate("annulus", h=0.05, r_inner=0.3, r_outer=1.0)

Adding a geometry is one registration, in any module (nothing else lists geometries: case
files, ``femkit solve``, its cost plan and budget checks all read this registry)::

    def _strip_measure(length=4.0):                 # same parameters and defaults as build
        return length * 1.0, 2.0 * (length + 1.0)   # (area, length of every mesh line)

    @register_geometry("strip", measure=_strip_measure,
                       boundary_tags=("boundary",), cell_tags=("domain",))
    def strip(h, length=4.0):                       # build(h, **params) -> Mesh
        return rectangle(h, 0.0, 0.0, length, 1.0)

An entry holds:

* ``build(h, **params) -> Mesh``: the mesh at target size ``h``;
* ``measure(**params) -> (measure, line_measure)``: with the same parameter names and defaults
  as ``build``; in 2D the area and the length of every mesh line (outer boundary, holes, and
  interfaces between regions counted twice, since the elements on both sides follow them); in
  3D the volume and the area of every mesh surface, counted the same way. The cost model
  predicts the element count from these two numbers (:mod:`femkit.cost.poisson`);
* ``dim``: 2 (triangles) or 3 (tetrahedra);
* ``boundary_tags``, ``cell_tags``: the tag names the generated mesh carries.

Tag conventions (names go to :attr:`Mesh.tag_names`):

* Every geometry tags its whole boundary as the edge group ``"boundary"`` **as well as** named
  parts. An edge in several groups appears once per group in ``Mesh.boundary_edges`` (the same
  node pair repeated with each tag), so ``boundary_edges[boundary_tags == mesh.tag("left")]`` and
  ``boundary_edges[boundary_tags == mesh.tag("boundary")]`` both work.
* Cell groups: single-region geometries tag every triangle ``"domain"``; multi-region geometries
  (``checkerboard``, ``square_with_inclusion``) tag each triangle with its region instead (a
  triangle carries exactly one cell tag).
* Tag numbers are unique across edge and cell groups of a generated mesh.

Generated meshes are deterministic: one gmsh thread, fixed algorithm, no random restarts
between runs; triangles are counter-clockwise.
"""

from .registry import GEOMETRIES, Geometry, generate, register_geometry
from .gmsh_session import geo_file
# the bundled geometries register themselves on import, in this order (``femkit list``'s)
from .planar import (annulus, checkerboard, disk, l_shape, rectangle, square_with_inclusion,
                     unit_square)
from . import solid  # noqa: F401  (the solid geometries)
from . import kuhn  # noqa: F401  (the Kuhn-type ones for 3D bisection)
from . import cook  # noqa: F401  (Cook's membrane, the solids' benchmark panel)

__all__ = ["GEOMETRIES", "Geometry", "register_geometry", "generate", "geo_file", "rectangle",
           "unit_square", "l_shape", "disk", "annulus", "checkerboard", "square_with_inclusion"]
