"""Studies: sweeps over meshes, solvers and integrators with reports of error against cost.

``femkit study STUDY.yaml`` and, from Python::

    from femkit.study import load_study, run_study
    result = run_study(load_study("studies/poisson_convergence.yaml", quick=True))
    result.fit(norm="L2", solver="direct", quadrature="barycentric")["slope"]

Kinds: one module each in :mod:`femkit.study.kinds` (this package hands :data:`femkit.kinds.KINDS`
the finder that imports them); see docs/studies.md.
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
    """Import every module of :mod:`femkit.study.kinds`: each registers one study kind."""
    import importlib
    import pkgutil

    from . import kinds

    for info in sorted(pkgutil.iter_modules(kinds.__path__), key=lambda i: i.name):
        if not info.name.startswith("_"):
            importlib.import_module(f"{kinds.__name__}.{info.name}")


_KINDS.add_finder("kind", _find_study_kinds)
