"""Know the cost before paying it: sizes, memory, time and output predicted before a run.

* :func:`plan_poisson`, :func:`plan_mesh`, :func:`plan_scene` make a :class:`Plan` from plain
  parameters (geometry and ``h``, refinements, solver; a scene's size and time grid);
* :func:`check_budget` refuses a plan that exceeds the available memory or a stated
  :class:`Limits` (``BudgetExceededError``, one line saying what to change);
* the constants are calibrated by ``benchmarks/calibrate_cost.py`` and overridable per machine
  (:mod:`femkit.cost.constants`); :func:`machine_speed` scales times to the machine's current
  speed; :mod:`femkit.cost.memory` reads available and peak memory; :mod:`femkit.cost.probe`
  measures real runs stage by stage.

Importing this package imports neither numpy nor scipy.
"""

from .budget import LIMIT_KEYS, Limits, check_budget, parse_bytes, parse_seconds
from .constants import load_constants
from .memory import available_memory, format_bytes, peak_rss
from .meshfile import msh_triangle_count
from .plan import Plan, Stage, format_seconds
from .poisson import plan_mesh, plan_poisson, predict_triangles
from .scene import measure_step_seconds, plan_scene
from .speed import machine_speed

__all__ = ["Plan", "Stage", "Limits", "LIMIT_KEYS", "check_budget", "parse_bytes", "parse_seconds",
           "load_constants", "available_memory", "peak_rss", "format_bytes", "format_seconds",
           "msh_triangle_count", "plan_mesh", "plan_poisson", "predict_triangles", "plan_scene",
           "measure_step_seconds", "machine_speed"]
