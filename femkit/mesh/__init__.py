"""Meshes: the record, gmsh generation, meshio I/O, validation, refinement, quality."""

from .mesh import Mesh

__all__ = ["Mesh"]
