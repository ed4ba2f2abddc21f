"""The Poisson problem of a study: a Poisson case (inline ``problem:`` or a ``base_case:`` file).

Shared by the study kinds that sweep one Poisson case (``poisson_convergence``, ``adaptive``):
the schema of the two keys (:data:`SOURCE_SCHEMA`), the spec fields (:class:`PoissonSource`)
and the case itself (:func:`study_problem`).

Both are one :class:`~femkit.case.Case` in the case-file language (docs/case-files.md), and
every mesh level is assembled, reduced and solved through the one Poisson pipeline
(:func:`femkit.case.poisson.run.poisson_problem`, a :class:`femkit.fem.PoissonProblem`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..errors import CaseFileError, InputError, with_prefix
from .spec import plain

__all__ = ["StudyProblem", "study_problem", "PoissonSource", "PROBLEM", "SOURCE_SCHEMA"]


@dataclass
class StudyProblem:
    """A validated Poisson case whose mesh size a sweep varies."""

    case: object

    @property
    def has_neumann(self) -> bool:
        return bool(self.case.spec.boundary.neumann)

    @property
    def pure_neumann(self) -> bool:
        """No Dirichlet condition: ``u`` fixed only up to a constant."""
        from ..case.poisson.run import is_pure_neumann

        return is_pure_neumann(self.case)

    @property
    def exact(self):
        return self.case.functions["exact.u"]

    def base_mesh(self, h: float | None):
        """The case's mesh with ``mesh.h = h`` (a mesh file is read as it is)."""
        from ..case.poisson.run import build_mesh

        return build_mesh(self.case, h=h)

    def problem(self, mesh, load_rule: str | None = None):
        """The case on ``mesh`` as a :class:`femkit.fem.PoissonProblem` (the one pipeline)."""
        from ..case.poisson.run import poisson_problem

        return poisson_problem(self.case, mesh, load_rule=load_rule)

    def errors(self, problem, u, order: int) -> dict:
        from ..case.poisson.run import compute_errors

        return compute_errors(self.case, problem, u, order=order)


def study_problem(study, *, need_exact: bool = True) -> StudyProblem:
    """The study's Poisson case: inline ``problem:`` (prefixed errors) or ``base_case:``.

    ``need_exact``: a convergence study needs ``exact``; an adaptive study measures the estimate
    without one.
    """
    from ..case import load_case
    from ..case.load import case_from_dict

    d = study.spec
    if d.base_case is not None:
        case = load_case(study.resolve(d.base_case))
        where = f"base_case: {study.resolve(d.base_case)}"
    else:
        data = {"problem": "poisson", **d.problem}
        mesh = dict(data.get("mesh") or {})
        if "geometry" in mesh and "h" not in mesh:  # the levels give the sizes
            mesh["h"] = d.mesh_h
        data["mesh"] = mesh
        try:
            case = case_from_dict(data, study.base_dir, name=study.name)
        except InputError as exc:
            raise with_prefix(exc, "problem") from None
        where = "problem"
    if case.problem != "poisson":
        raise CaseFileError(f"{where} is a {case.problem!r} case; a convergence study needs 'poisson'")
    if need_exact and "exact.u" not in case.functions:
        raise CaseFileError(f"{where} gives no exact solution; a convergence study needs 'exact'")
    return StudyProblem(case)


@dataclass(frozen=True)
class PoissonSource:
    """Where a Poisson study's problem comes from: an inline case mapping (``problem``) or a
    case file (``base_case``, as written; resolved against the study file)."""

    problem: Mapping | None
    base_case: str | None

    @staticmethod
    def source(d: Mapping) -> dict:
        return dict(problem=plain(d["problem"]) if "problem" in d else None,
                    base_case=d.get("base_case"))


#: An inline Poisson problem: a case mapping in the case-file language (docs/case-files.md),
#: validated by the Poisson case schema; ``mesh.h`` may be left out (the levels give it).
PROBLEM = {"type": "object", "x-message": "expected a Poisson case mapping (mesh, source, boundary, exact)"}

#: The two keys naming the problem of a Poisson study (exactly one given:
#: :func:`femkit.study.checks.check_problem_source`).
SOURCE_SCHEMA = {"problem": PROBLEM, "base_case": {"type": "string"}}
