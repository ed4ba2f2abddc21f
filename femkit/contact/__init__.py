"""Barrier contact (Incremental Potential Contact, Li et al. 2020) through ipctk.

A library layer below :mod:`femkit.dynamics` and :mod:`femkit.solids`, importing only
:mod:`femkit.mesh` and the shared leaves:

- :mod:`.surfaces`: the contact surface of a body (boundary triangles of tetrahedra, boundary
  segments of triangles in 2D, a cloth's own triangles) and obstacle surfaces (a plane, a sphere,
  a surface mesh file read by meshio), static or in a prescribed rigid motion (:class:`Motion`);
- :mod:`.barrier`: :class:`~.barrier.BarrierModel`, the log barrier with its gradient and sparse
  Hessian on the body's dofs, continuous collision detection (the collision-free step size),
  adaptive barrier stiffness and smooth lagged Coulomb friction, all by ipctk
  (extra ``femkit[contact]``);
- :mod:`.check`: an independent intersection test in numpy (triangle-triangle, segment-segment),
  which never calls ipctk: the validation of every written frame.
"""

from .surfaces import (Motion, Obstacle, body_surface, file_obstacle, plane_obstacle, rotation,
                       sphere_obstacle)

__all__ = ["Obstacle", "Motion", "rotation", "body_surface", "plane_obstacle", "sphere_obstacle",
           "file_obstacle"]
