"""Elastic solids by P1 finite elements: energies of the principal stretches, forces and
Hessians by the SVD derivative, quasi-static equilibrium (see docs/methods.md, "Elastic solids").

Layer: library, beside :mod:`femkit.dynamics` (``solids`` uses ``mesh`` records, ``solvers`` and
the leaves; the elastic force model of the dynamics lives in
:mod:`femkit.dynamics.forces.elastic`). Compiled kernels (numba) are imported on first
evaluation only.
"""

from .body import ElasticBody, point_tangent
from .boundary import Dirichlet, body_forces, tagged_facets, tagged_nodes, traction_forces
from .kinematics import RestShape, deformation_gradients, invertible_svd, rest_shape
from .materials import (MATERIALS, Corotational, LinearElastic, Material, StableNeoHookean,
                        StretchMaterial, StVenantKirchhoff, lame_from_young, material)
from .static import LoadStepRecord, StaticResult, solve_static

__all__ = ["ElasticBody", "point_tangent", "RestShape", "rest_shape", "deformation_gradients",
           "invertible_svd", "MATERIALS", "Material", "StretchMaterial", "LinearElastic",
           "Corotational", "StVenantKirchhoff", "StableNeoHookean", "lame_from_young", "material",
           "Dirichlet", "traction_forces", "body_forces", "tagged_facets", "tagged_nodes",
           "solve_static", "StaticResult", "LoadStepRecord"]
