"""``kind: adaptive``: adaptive against uniform refinement of one Poisson case.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`
(:class:`~.spec.AdaptiveStudySpec` and the load-time check), :mod:`.cost`, :mod:`.run` (the
adaptive loop per estimator and the uniform refinements), :mod:`.report` and :mod:`.kind`. The
Poisson case it refines: :mod:`femkit.study.problem`.
"""
