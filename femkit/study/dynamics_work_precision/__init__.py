"""``kind: dynamics_work_precision``: error against cost of integrators on a small scene.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`
(:class:`~.spec.DynamicsStudySpec` and the load-time check), :mod:`.cost`, :mod:`.run`
(integrators x dt against the analytic or a converged reference), :mod:`.report` (orders,
work-precision fronts, energy, stability map) and :mod:`.kind`.
"""
