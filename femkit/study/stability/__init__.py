"""``kind: stability``: the stress suite, one verdict row per (case, parameter, method).

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema` (the study's keys and
one stress case's), :mod:`.spec`, :mod:`.cases` (the stress-case types,
:data:`~.cases.STRESS_CASES`: each one's rows and price), :mod:`.cost`, :mod:`.run`,
:mod:`.report` and :mod:`.kind`.
"""
