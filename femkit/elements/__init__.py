"""Compiled kernels of elastic elements, below both :mod:`femkit.solids` and :mod:`femkit.dynamics`.

:mod:`femkit.elements.compiled` holds the deformation gradient, the signed SVD, the nodal-force
scatter and the element pass of the elastic solids (numba, one file so that numba's per-file
cache sees every edit). :mod:`femkit.solids` builds its bodies and generated energy modules on it,
and projective dynamics' local step (:mod:`femkit.dynamics.integrators.projective_local`) uses the
same kernels; neither of those packages imports the other. This package imports no other femkit
layer.
"""
