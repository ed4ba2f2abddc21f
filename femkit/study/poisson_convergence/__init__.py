"""``kind: poisson_convergence``: error and cost of a Poisson case over a sequence of meshes.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema` (its keys),
:mod:`.spec` (:class:`~.spec.PoissonStudySpec` and the load-time check), :mod:`.cost` (the plan
before the run), :mod:`.run` (mesh levels x solvers x quadrature rules, nested iteration, the
scikit-fem reference), :mod:`.report` (tables, figures, the printed rates) and :mod:`.kind`
(the registration). The Poisson case it sweeps: :mod:`femkit.study.problem`.
"""
