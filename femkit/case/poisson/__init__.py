"""``problem: poisson`` case files, one package: the registration (``kind``), schema, spec
(``PoissonSpec``), the plan (``cost``), the one Poisson pipeline (``run``, ``problem`` with
``CaseResult``, a :class:`~femkit.case.result.RunResult`), outputs, the error estimate and the
``femkit check`` cross-check against scikit-fem and pyamg (``cross_check``)."""
