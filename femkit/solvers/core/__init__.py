"""What every solver, preconditioner and backend of :mod:`femkit.solvers` shares, below them all.

``defaults`` (the one table of default tolerances, engines and preconditioners, read at call
time), ``result`` (:class:`SolveResult`), ``checks`` (input validation, verdicts, residual
replacement, the dependency boundary), ``norms`` (scaled norms), ``pairing`` (which
preconditioner goes with which method). These modules import only one another and the shared
leaves; :mod:`femkit.solvers.preconditioners`, :mod:`femkit.solvers.petsc` and the solver
modules of :mod:`femkit.solvers` build on them (no import cycle between those folders).
"""
