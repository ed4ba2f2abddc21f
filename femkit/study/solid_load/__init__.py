"""``kind: solid_load``: a cantilever under a growing tip load, one curve per material.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`
(:class:`~.spec.SolidLoadStudySpec`, the base case's checks), :mod:`.cost` (each material's run
priced by the solid kind's plan), :mod:`.run` (the runs, and the elastica they are compared
with), :mod:`.report` and :mod:`.kind`.
"""
