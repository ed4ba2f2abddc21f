"""Cost model of barrier contact (IPC): the ``contact`` stage a scene's or a solid's plan adds.

A step in contact costs more than a contact-free one in two ways (docs/benchmarks.md, "Barrier
contact"):

* more Newton iterations: ``contact.iterations_per_step`` (15; measured on the
  ``cloth_on_sphere`` scene: 11 and 19 a contact step at 21 x 21 and 41 x 41 over 40 steps,
  14 at 81 x 81 over 200 steps), where the contact-free step the other stages price takes
  ``free_iterations`` (2 for the scenes' implicit Euler, ~3 for the solids' Newton); each extra
  iteration costs what a contact-free one does (``iteration_seconds``: the measured first batch's
  step over its iterations when the scene measured one);
* contact's own work in every iteration of such a step -- the broad phase, CCD and the barrier's
  Hessian -- ``contact.seconds_per_facet_iteration`` per surface facet (cloth or boundary
  triangles and the obstacles' facets: 7e-6 s at the reference speed, from the contact seconds
  ``result.json`` records: 8.8e-6, 1.5e-5 and 1.8e-5 s wall at 21, 41 and 81 vertices a side
  with the machine 1.5-2.5x slower than the reference), times the machine's ``speed``.

Every step is priced as a contact step (the first steps of a fall are often contact-free, so a
measured first batch would miss contact entirely and the model cannot tell when it starts):
the model errs high for a scene that falls a long way before it touches.

>>> s = contact_stage(steps=100, facets=1e4, iteration_seconds=0.1, free_iterations=2)
>>> round(s.seconds)     # 100 x (13 x 0.1 + 15 x 1e4 x 7e-6)
235
"""

from __future__ import annotations

from .constants import load_constants
from .plan import Stage

__all__ = ["contact_stage", "SCENE_FREE_ITERATIONS"]

#: Newton iterations of a scene's contact-free implicit-Euler step (2.0 measured on the falling
#: cloth, docs/benchmarks.md): what a scene's measured or modelled step is made of.
SCENE_FREE_ITERATIONS = 2.0


def contact_stage(steps: int, facets: float, iteration_seconds: float,
                  free_iterations: float, speed: float = 1.0,
                  constants: dict | None = None) -> Stage:
    """The ``contact`` stage of ``steps`` steps on ``facets`` surface facets (see the module
    docstring).

    Parameters
    ----------
    steps : time (or load) steps, every one priced as in contact
    facets : surface facets of the bodies and the obstacles
    iteration_seconds : seconds of one contact-free Newton iteration (the plan's own)
    free_iterations : Newton iterations per step the plan's other stages already price
    speed : seconds multiplier of this machine now (:func:`~femkit.cost.machine_speed`)
    constants : the cost constants (default :func:`~femkit.cost.load_constants`)
    """
    c = (constants or load_constants())["contact"]
    per_step = c["iterations_per_step"]
    extra = max(per_step - float(free_iterations), 0.0) * float(iteration_seconds)
    own = per_step * float(facets) * c["seconds_per_facet_iteration"] * float(speed)
    return Stage("contact", int(steps) * (extra + own), 0.0,
                 detail=f"barrier contact: ~{facets:,.0f} facets, {per_step:g} CCD-bounded "
                 f"Newton iterations per step ({float(free_iterations):g} priced above)")
