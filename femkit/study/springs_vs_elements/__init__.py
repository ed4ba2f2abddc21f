"""``kind: springs_vs_elements``: mass-spring layouts against finite elements and projective
dynamics on the same gmsh meshes (a hanging beam, a falling disk).

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`
(:class:`~.spec.SpringsStudySpec`, the methods and reference checked), :mod:`.cost`, :mod:`.run`
(every method on every scene and mesh size, the fits), :mod:`.models` (one method's body built
and integrated), :mod:`.scenes` (:data:`~.scenes.SVSE_SCENES`), :mod:`.layouts` (the spring
layouts, :data:`~.layouts.SPRING_LAYOUTS`), :mod:`.report` and :mod:`.kind`.
"""
