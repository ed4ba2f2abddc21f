"""Study kinds: the registry :data:`STUDY_KINDS` (``kind:`` of a study file).

Each kind declares its schema properties, the load-time check, the sweep, the report builder and
the lines ``femkit study`` prints; :func:`femkit.study.run_study`, :func:`load_study` and the
command line dispatch through this one registry. Modules are imported on first use.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..errors import CaseFileError
from ..registry import Registry

__all__ = ["StudyKind", "STUDY_KINDS"]


@dataclass(frozen=True)
class StudyKind:
    """One study kind.

    ``schema``: the kind's own top-level properties (JSON schema); ``check(study)``: load-time
    checks beyond the schema (files exist, exclusive keys); ``run(study, progress_enabled)``:
    the sweep, returning ``{"records", "fits"?, "tables"?, "notes"?, ...}``;
    ``report(report, study, result, data, stage)``: fills the report;
    ``summary(result)``: the lines ``femkit study`` prints.
    """

    schema: dict
    check: Callable
    run: Callable
    report: Callable
    summary: Callable


STUDY_KINDS: Registry = Registry("study kind")


def _r2(r2) -> str:
    """``R^2 0.9998``, or ``2 points, no R^2`` for a two-point fit (None / nan)."""
    return "2 points, no R^2" if r2 is None or r2 != r2 else f"R^2 {r2:.4f}"


def _fit_lines(result) -> list[str]:
    lines = []
    for f in result.fits[:12]:
        what = " / ".join(str(f[k]) for k in ("solver", "integrator", "quadrature", "norm", "error") if k in f)
        extra = f", dt {max(f['dt_used']):.3g}..{min(f['dt_used']):.3g}" if f.get("dt_used") else ""
        lines.append(f"rate {what}: {f['slope']:.3f} ({_r2(f['r2'])}{extra})")
    return lines


# ----------------------------------------------------------------------------- poisson_convergence

def _poisson_check(study) -> None:
    d = study.data
    if ("problem" in d) == ("base_case" in d):
        raise CaseFileError("poisson_convergence: give exactly one of 'problem' (inline) or 'base_case' (a case file)")
    lv = d.get("levels") or {}
    if "h" not in lv and not ("h0" in lv and "count" in lv):
        raise CaseFileError("levels: give either 'h' (a list of mesh sizes) or 'h0' and 'count' "
                            "(uniform refinements of one mesh)")
    if "base_case" in d:
        p = study.resolve(d["base_case"])
        if not p.is_file():
            raise CaseFileError(f"base_case: file not found: {p}")
        study.files.append(p)
    from .problem import study_problem

    study_problem(study)  # the problem's keys, names and expressions are checked now
    _check_nested(study, "h" in lv, "levels: {h: [...]} gives independent gmsh meshes, not "
                  "nested ones; use levels: {h0, count} (uniform refinements)")


def _check_nested(study, not_nested: bool, why: str) -> None:
    """Geometric multigrid (``fmg``, ``gmg``) in ``solvers:`` needs nested meshes: a one-line
    :class:`~femkit.errors.HierarchyError` at load time when the study's levels are not."""
    if not not_nested:
        return
    from ..errors import HierarchyError
    from ..solvers.preconditioners.gmg import ALTERNATIVE

    for i, s in enumerate(study.solvers):
        if s.needs_hierarchy:
            what = "method 'fmg'" if s.method == "fmg" else "preconditioner 'gmg'"
            raise HierarchyError(f"solvers[{i}]: {what} needs nested meshes, but {why}; or "
                                 f"{ALTERNATIVE.split(' or ')[0]}")


def _poisson_run(study, progress_enabled=None) -> dict:
    from .poisson import run_poisson_study

    return run_poisson_study(study, progress_enabled=progress_enabled)


def _poisson_report(*args) -> None:
    from .report_poisson import build_poisson_report

    build_poisson_report(*args)


def _poisson_summary(result) -> list[str]:
    from .report_poisson import grouped_rate_rows

    # one line per group of solvers with the same fit, like the report
    return [f"rate {who} / {rule} / {norm}: {slope:.3f} ({_r2(r2)})"
            for who, rule, norm, slope, _, r2, *_ in grouped_rate_rows(result.fits)]


# ----------------------------------------------------------------------------- dynamics_work_precision

def _dynamics_check(study) -> None:
    d = study.data
    for key in ("scene", "integrators", "dt"):
        if key not in d:
            raise CaseFileError(f"(top level): missing required key {key!r}")
    dt = d["dt"]
    if "values" not in dt and not ("k_min" in dt and "k_max" in dt and dt["k_max"] > dt["k_min"]):
        raise CaseFileError("dt: give 'values' or 'k_min' < 'k_max' (dt = 2^-k)")


def _dynamics_run(study, progress_enabled=None) -> dict:
    from .dynamics import run_dynamics_study

    return run_dynamics_study(study, progress_enabled=progress_enabled)


def _dynamics_report(*args) -> None:
    from .report_dynamics import build_dynamics_report

    build_dynamics_report(*args)


# ----------------------------------------------------------------------------- stability

def _stability_check(study) -> None:
    for i, c in enumerate(study.data["cases"]):
        if isinstance(c, str):
            p = study.resolve(c)
            if not p.is_file():
                raise CaseFileError(f"cases[{i}]: stress case file not found: {p}")
            study.files.append(p)


def _stability_run(study, progress_enabled=None) -> dict:
    from .stability import run_stability_study

    return run_stability_study(study, progress_enabled=progress_enabled)


def _stability_report(*args) -> None:
    from .report_stability import build_stability_report

    build_stability_report(*args)


# ----------------------------------------------------------------------------- adaptive

def _adaptive_check(study) -> None:
    from ..fem.adaptive import check_settings
    from ..fem.estimators import ESTIMATORS
    from ..case.names import lookup

    d = study.data
    if ("problem" in d) == ("base_case" in d):
        raise CaseFileError("adaptive: give exactly one of 'problem' (inline) or 'base_case' (a case file)")
    if "max_dofs" not in d:
        raise CaseFileError("(top level): missing required key 'max_dofs' (the budget of both refinements)")
    for i, name in enumerate(d["estimators"]):
        lookup(ESTIMATORS, name, f"estimators[{i}]")
    check_settings(theta=d["theta"], target=d.get("target"), max_dofs=d["max_dofs"],
                   max_time=d.get("max_time"), max_levels=d["max_levels"])
    if "base_case" in d:
        p = study.resolve(d["base_case"])
        if not p.is_file():
            raise CaseFileError(f"base_case: file not found: {p}")
        study.files.append(p)
    from .problem import study_problem

    study_problem(study, need_exact=False)
    _check_nested(study, True, "adaptive refinement makes graded meshes, not uniformly refined "
                  "nested ones")


def _adaptive_run(study, progress_enabled=None) -> dict:
    from .adaptive import run_adaptive_study

    return run_adaptive_study(study, progress_enabled=progress_enabled)


def _adaptive_report(*args) -> None:
    from .adaptive import build_adaptive_report

    build_adaptive_report(*args)


def _adaptive_summary(result) -> list[str]:
    from .adaptive import adaptive_summary

    return adaptive_summary(result)


def _register() -> None:
    from .schema import ADAPTIVE, DYNAMICS, POISSON, STABILITY

    STUDY_KINDS.register("poisson_convergence", StudyKind(
        POISSON, _poisson_check, _poisson_run, _poisson_report, _poisson_summary))
    STUDY_KINDS.register("dynamics_work_precision", StudyKind(
        DYNAMICS, _dynamics_check, _dynamics_run, _dynamics_report, _fit_lines))
    STUDY_KINDS.register("stability", StudyKind(
        STABILITY, _stability_check, _stability_run, _stability_report, _fit_lines))
    STUDY_KINDS.register("adaptive", StudyKind(
        ADAPTIVE, _adaptive_check, _adaptive_run, _adaptive_report, _adaptive_summary))
    from .cloth import CLOTH_KIND

    STUDY_KINDS.register("cloth_work_precision", CLOTH_KIND)


_register()
