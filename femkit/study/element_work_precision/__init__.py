"""``kind: element_work_precision``: P1 against P2 on one Poisson case, error against unknowns and run time.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema` (its keys), :mod:`.spec`
(the load-time check), :mod:`.run` (elements x uniform refinements of one mesh, each level solved
through the one Poisson pipeline and timed), :mod:`.report` (the runs, the fitted rates, the
figures, and the crossover: from which accuracy the higher-order element is cheaper) and
:mod:`.kind` (the registration).
"""
