"""``kind: cloth_work_precision``: which implicit cloth method buys the most accuracy per millisecond.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`
(:class:`~.spec.ClothStudySpec`, the solver specs and scene checks), :mod:`.cost`, :mod:`.run`
(:func:`femkit.dynamics.work_precision.cloth_work_precision` per scene), :mod:`.report` and
:mod:`.kind`.
"""
