"""Know the cost before paying it: sizes, memory, time and output predicted before a run.

A base of pure functions of numbers (sizes in, seconds and bytes out): it imports no other
part of femkit but the leaves ``errors``, ``validation`` and ``timing``, so every layer above
may use it and nothing in it runs a mesh generator, an assembly or a solver.

* :func:`plan_poisson`, :func:`plan_mesh`, :func:`plan_scene` make a :class:`Plan` from plain
  numbers (a domain's area and line length and ``h``, or a triangle count; refinements,
  solver; a scene's node and spring counts and time grid); :func:`contact_stage` prices barrier
  contact (facets, steps, the plan's own Newton iteration);
* :func:`check_budget` refuses a plan that exceeds the available memory or a stated
  :class:`Limits` (``BudgetExceededError``, one line saying what to change);
* the constants are calibrated by ``benchmarks/calibrate_cost.py`` and overridable per machine
  (:mod:`femkit.cost.constants`); :func:`machine_speed` scales times to the machine's current
  speed; :mod:`femkit.cost.memory` reads available and peak memory.

The application turns its inputs into these numbers and runs the checks
(``femkit.case.cost``: geometry measures from ``femkit.mesh.GEOMETRIES``, the memory guard
before meshing and refining, a scene's measured seconds per step).

Importing this package imports neither numpy nor scipy.
"""

from ..timing import format_seconds
from .budget import (
    DEFAULT_TIME_BUDGET,
    LIMIT_KEYS,
    Limits,
    check_budget,
    parse_bytes,
    parse_seconds,
    with_default_time,
)
from .constants import load_constants
from .contact import SCENE_FREE_ITERATIONS, contact_stage
from .memory import available_memory, format_bytes, peak_rss
from .meshfile import msh_has_volume, msh_triangle_count
from .plan import Plan, Stage
from .poisson import plan_mesh, plan_poisson, predict_triangles
from .scene import plan_scene
from .speed import machine_speed

__all__ = ["Plan", "Stage", "Limits", "LIMIT_KEYS", "DEFAULT_TIME_BUDGET", "with_default_time", "check_budget", "parse_bytes", "parse_seconds",
           "load_constants", "available_memory", "peak_rss", "format_bytes", "format_seconds",
           "msh_has_volume", "msh_triangle_count", "plan_mesh", "plan_poisson", "predict_triangles", "plan_scene",
           "machine_speed", "contact_stage", "SCENE_FREE_ITERATIONS"]
