"""Load-time checks shared by study kinds."""

from __future__ import annotations

from ..errors import CaseFileError

__all__ = ["check_nested", "check_problem_source", "check_base_case"]


def check_problem_source(study, kind: str) -> None:
    """Exactly one of ``problem`` (inline) or ``base_case`` (a case file, which must exist)."""
    d = study.data
    if ("problem" in d) == ("base_case" in d):
        raise CaseFileError(f"{kind}: give exactly one of 'problem' (inline) or 'base_case' (a case file)")


def check_base_case(study) -> None:
    """``base_case:`` exists; it joins the files of the fingerprint."""
    d = study.data
    if "base_case" in d:
        p = study.resolve(d["base_case"])
        if not p.is_file():
            raise CaseFileError(f"base_case: file not found: {p}")
        study.files.append(p)


def check_nested(study, not_nested: bool, why: str) -> None:
    """Geometric multigrid (``fmg``, ``gmg``) in ``solvers:`` needs nested meshes: a one-line
    :class:`~femkit.errors.HierarchyError` at load time when the study's levels are not."""
    if not not_nested:
        return
    from ..errors import HierarchyError
    from ..solvers.gmg import ALTERNATIVE

    for i, s in enumerate(study.solvers):
        if s.needs_hierarchy:
            what = "method 'fmg'" if s.method == "fmg" else "preconditioner 'gmg'"
            raise HierarchyError(f"solvers[{i}]: {what} needs nested meshes, but {why}; or "
                                 f"{ALTERNATIVE.split(' or ')[0]}")
