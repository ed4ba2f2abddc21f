"""Meshes: the record, gmsh generation, meshio I/O, validation, refinement, quality.

Importing this package is cheap: gmsh and meshio are imported inside the functions that need
them (generation and file I/O).
"""

from .geometries import GEOMETRIES, generate, geo_file
from .io import read_mesh, write_mesh
from .mesh import Mesh
from .quality import quality
from .edges import boundary_edges_topological, boundary_nodes, edges
from .refine import refine
from .structured import grid_triangles, structured_mesh
from .validate import check_tags, orient_ccw, remove_unreferenced, validate

__all__ = [
    "Mesh", "generate", "GEOMETRIES", "geo_file", "read_mesh", "write_mesh", "validate",
    "check_tags", "remove_unreferenced", "orient_ccw", "refine", "quality", "boundary_nodes",
    "boundary_edges_topological", "edges", "structured_mesh", "grid_triangles",
]
