"""Studies: sweeps over meshes, solvers and integrators with reports of error against cost.

``femkit study STUDY.yaml`` and, from Python::

    from femkit.study import load_study, run_study
    result = run_study(load_study("studies/poisson_convergence.yaml", quick=True))
    result.fit(norm="L2", solver="direct", quadrature="barycentric")["slope"]

Each study kind is one package of this folder that owns everything about it (schema, spec
and load-time check, cost plan, sweep, report, registration: ``femkit/study/<kind>/``, declared
by :func:`femkit.study.declare.study_kind`); this package hands :data:`femkit.kinds.KINDS` the
finder that imports each package's ``kind`` module. The modules of this folder are the shared
machinery the kinds use and never a kind: loading (:mod:`~femkit.study.load`,
:mod:`~femkit.study.schema`, :mod:`~femkit.study.spec`), running and the report framework
(:mod:`~femkit.study.run`, :mod:`~femkit.study.report`, :mod:`~femkit.study.figures`), fits and
fronts (:mod:`~femkit.study.fit`, :mod:`~femkit.study.pareto`), timing, the input fingerprint,
the cost plan's dispatch and shared prices (:mod:`~femkit.study.cost`,
:mod:`~femkit.study.prices`), and the Poisson problem two kinds sweep
(:mod:`~femkit.study.problem`, :mod:`~femkit.study.checks`). See docs/studies.md and "Adding a
study kind" in docs/architecture.md.
Importing this package is cheap (numpy only); the sweeps import what they need.
"""

from __future__ import annotations

from ..kinds import KINDS as _KINDS

__all__ = ["load_study", "study_from_dict", "run_study", "Study", "StudyResult", "fit_rate", "RateFit",
           "pareto_front", "cli_main", "add_parser"]


def __getattr__(name):  # lazy: keep `import femkit.study` light
    if name in ("load_study", "study_from_dict", "Study"):
        from . import load

        return getattr(load, name)
    if name in ("run_study", "StudyResult"):
        from . import run

        return getattr(run, name)
    if name in ("fit_rate", "RateFit"):
        from . import fit

        return getattr(fit, name)
    if name == "pareto_front":
        from .pareto import pareto_front

        return pareto_front
    if name in ("cli_main", "add_parser"):
        from . import cli

        return getattr(cli, name)
    raise AttributeError(f"module 'femkit.study' has no attribute {name!r}")


def _find_study_kinds() -> None:
    """Import the ``kind`` module of every package of this folder: each registers one study kind."""
    import importlib
    import importlib.util
    import pkgutil

    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.ispkg and not info.name.startswith("_"):
            if importlib.util.find_spec(f"{__name__}.{info.name}.kind") is not None:
                importlib.import_module(f"{__name__}.{info.name}.kind")


_KINDS.add_finder("kind", _find_study_kinds)
