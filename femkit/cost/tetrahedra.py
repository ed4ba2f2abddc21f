"""Memory of a tetrahedral Poisson run: its stages' peaks per tetrahedron, calibrated in 3D.

The 2D model prices a stage per triangle; a tetrahedral run was once priced as 16/9 triangles
per tetrahedron (the 4 x 4 stiffness block against 3 x 3), which put the 912,673-node cube at
7.39 GiB against 2.77 GiB measured. Here each stage of ``femkit solve`` on tetrahedra has its own
law, fitted on ``femkit solve``'s own pipeline (``benchmarks/calibrate_cost.py --tetrahedra``:
per stage the peak resident memory above the start, at 83k, 664k and 5.3M tetrahedra)::

    peak(stage) = fixed + margin * bytes_per_tetrahedron[stage] * tetrahedra

``fixed`` holds what a run has loaded whatever its size (numba and the compiled kernels, the
case's expressions), ``bytes_per_tetrahedron`` the slope between the two largest calibration
runs and ``margin`` (> 1) covers the spread between runs and sizes (the 24.6M-tetrahedron run
measured 11.93 GiB; the model says 12.4 GiB). The mesh stage (refinement of the whole hierarchy,
renumbering, quality) is the peak of a run; the stages are named as in the 2D plan: ``refine``
and ``quality`` take the mesh law (they are one stage of a tetrahedral run), ``setup`` and
``solve`` the fmg law when the method is ``fmg``. Stages with no 3D calibration (another
solver's set-up and iterations, the output files, gmsh's generation of the coarse mesh) keep
the 2D model's price for the triangle-equivalent count.

>>> from femkit.cost.constants import load_constants
>>> b = stage_bytes("refine", 5_308_416, "fmg", load_constants())
>>> 2.5e9 < b < 3.5e9
True
"""

from __future__ import annotations

__all__ = ["stage_bytes", "LAW_OF_STAGE"]

#: The calibrated law each stage of the plan takes (None: the 2D model's price stays).
LAW_OF_STAGE = {"mesh": "mesh", "refine": "mesh", "quality": "mesh", "assembly": "assembly",
                "boundary": "boundary", "setup": "solve_fmg", "solve": "solve_fmg",
                "errors": "errors", "estimate": "estimate", "output": None}


def stage_bytes(stage: str, tetrahedra: float, method: str, constants: dict) -> float | None:
    """Peak bytes (above the plan's baseline) of ``stage`` of a tetrahedral run on
    ``tetrahedra`` cells solved by ``method``, or None when the stage has no 3D calibration
    (the caller keeps the 2D model's price)."""
    law = LAW_OF_STAGE.get(stage)
    if law == "solve_fmg" and method != "fmg":
        return None
    if law is None:
        return None
    c = constants["tetrahedra"]
    return c["fixed_bytes"] + c["margin"] * c["bytes_per_tetrahedron"][law] * float(tetrahedra)
