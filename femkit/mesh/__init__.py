"""Meshes (triangles in 2D, tetrahedra in 3D): the record, gmsh generation, meshio I/O, validation, uniform and adaptive
(newest-vertex bisection) refinement, nested hierarchies, renumbering, quality.

Importing this package is cheap: gmsh and meshio are imported inside the functions that need
them (generation and file I/O).
"""

from .bisect import Bisection, bisect, label_longest_edge
from .bisect3d import TetBisection
from .edges import boundary_edges_topological, boundary_nodes, edges
from .faces import boundary_faces_topological, faces
from .geometries import GEOMETRIES, generate, geo_file
from .hierarchy import MeshHierarchy
from .io import read_mesh, write_mesh
from .mesh import Mesh
from .quality import quality
from .refine import refine, refine_once
from .renumber import permute_nodes, rcm_permutation, renumber
from .structured import grid_triangles, structured_box, structured_mesh
from .validate import check_tags, orient_ccw, remove_unreferenced, validate

__all__ = [
    "Mesh", "generate", "GEOMETRIES", "geo_file", "read_mesh", "write_mesh", "validate",
    "check_tags", "remove_unreferenced", "orient_ccw", "refine", "quality", "boundary_nodes",
    "boundary_edges_topological", "edges", "structured_mesh", "grid_triangles",
    "bisect", "label_longest_edge", "Bisection", "refine_once", "MeshHierarchy", "renumber",
    "rcm_permutation", "permute_nodes", "TetBisection", "structured_box", "faces", "boundary_faces_topological",
]
