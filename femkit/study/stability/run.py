"""The sweep of a ``stability`` study: the stress cases of :mod:`.cases`, after a warm-up."""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import FemkitError
from ...interrupt import active_flag
from ...mesh.structured import structured_mesh
from ...progress import progress
from .cases import STRESS_CASES, _chain, _direct, _poisson_system, _solve_row
from .schema import stress_case_schema

__all__ = ["run", "load_cases", "warm_up", "boundaries"]


def boundaries(rows) -> list[dict]:
    """Measured stability boundary per (case value, method): largest surviving and smallest failing h*omega."""
    out = []
    keys = list(dict.fromkeys((r["value"], r["method"]) for r in rows if r["type"] == "dynamics_stiffness"))
    for key in keys:
        rs = [r for r in rows if r["type"] == "dynamics_stiffness" and (r["value"], r["method"]) == key]
        ok = [r["h_omega"] for r in rs if r["survived"]]
        bad = [r["h_omega"] for r in rs if not r["survived"]]
        lo, hi = (max(ok) if ok else None), (min(bad) if bad else None)
        bound = rs[0]["bound"]
        consistent = (lo is None or lo <= bound * 1.0001) and (hi is None or hi >= bound * 0.9999)
        out.append({"value": key[0], "method": key[1], "largest_stable_h_omega": lo,
                    "smallest_unstable_h_omega": hi, "theory_h_omega": bound, "consistent_with_theory": consistent})
    return out


def load_cases(study) -> list[dict]:
    """The stress cases of the study: files read, overrides merged, validated, defaults filled."""
    from ...case.load import read_yaml
    from ...case.schema import fill_defaults, validate_against

    STRESS_CASE_SCHEMA = stress_case_schema()

    cases = []
    overrides = study.spec.case_overrides
    for i, c in enumerate(study.spec.cases):
        if isinstance(c, str):
            p = study.resolve(c)
            data = read_yaml(p)
            validate_against(data, STRESS_CASE_SCHEMA, p.name)
            data.setdefault("name", p.stem)
        else:
            data = dict(c)
            data.setdefault("name", f"{data['type']}_{i}")
        data = {**data, **(overrides.get(data["name"]) or {})}
        validate_against(data, STRESS_CASE_SCHEMA, f"cases[{i}]")
        data = fill_defaults(data, STRESS_CASE_SCHEMA)
        data.setdefault("values", list(STRESS_CASES.get(data["type"]).values))
        cases.append(data)
    unknown = sorted(set(overrides) - {c["name"] for c in cases})
    if unknown:  # a typo here would silently run that case at full size
        from ...errors import CaseFileError

        raise CaseFileError(f"case_overrides.{unknown[0]}: no such case; case names: "
                            + ", ".join(c["name"] for c in cases))
    return cases


def warm_up(solvers, integrators) -> list[str]:
    """Untimed runs on tiny problems so no timed run pays for imports or compilation.

    Each solver solves an 8 x 8 Poisson system (imports pyamg and builds a hierarchy, compiles
    the numba IC(0) kernels, loads the sparse direct solver) and each explicit integrator takes
    a few steps on the two-spring chain. Returns what was warmed (for the report's notes).
    """
    from ...dynamics.simulate import simulate

    mesh = structured_mesh(8, 8)
    _, _, sys_ = _poisson_system(mesh, np.ones(mesh.n_triangles), lambda x, y: np.ones_like(x))
    for s in solvers:
        _solve_row(sys_.A, sys_.b, s)
    _direct(sys_.A, sys_.b)
    chain = _chain(1e2, 1.0)
    x0 = chain.x0.copy()
    x0[2, 0] += 0.01
    names = []
    for spec in integrators:
        name, opts, label = spec.method, spec.options, spec.label
        if not spec.build().implicit:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    simulate(chain, name, 1e-3, 5e-3, x0=x0, **opts)
                except FemkitError:
                    pass
            names.append(label)
    return [s.label for s in solvers] + ["direct"] + names


def run(study, *, progress_enabled=None) -> dict:
    """The sweep: every stress case's rows (after the warm-up), the measured stability boundaries."""
    d = study.spec
    cases = load_cases(study)
    quick_n = 16 if study.quick else 64
    rows = []
    notes = []
    if d.warmup:
        warmed = warm_up(study.solvers, study.integrators)
        notes.append("Warm-up before timing (untimed, on an 8 x 8 Poisson system and a two-spring chain): "
                     + ", ".join(warmed) + "; no timed run includes imports, AMG module loading or compilation.")
    # one unit per stress case (a case gives one row per parameter value and method: the
    # summary counts rows)
    for case in progress(cases, total=len(cases), desc=f"{study.name} cases", unit="case",
                         enabled=progress_enabled, stop=active_flag()):
        rows += STRESS_CASES.get(case["type"]).run(case, study, quick_n)
    tables = {}
    b = boundaries(rows)
    if b:
        tables["stability_boundaries"] = b
    return {"records": rows, "tables": tables, "notes": notes}
