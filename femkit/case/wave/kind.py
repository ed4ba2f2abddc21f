"""``problem: wave``: the wave equation ``rho u_tt - div(kappa grad u) = f(x, t)`` on femkit's
meshes, registered as a :class:`~femkit.kinds.Kind`.

Schema :func:`femkit.case.wave.schema.wave_schema`; load-time checks and the spec
:func:`femkit.case.wave.run.prepare_wave`; the run :func:`femkit.case.wave.run.run_wave`; the
plan :func:`femkit.case.wave.cost.plan_wave_case`. The default linear solver is ``direct``: each
step of a fixed ``dt`` reuses one factor of ``M + beta dt^2 K`` (a pair of triangular solves per
step, docs/heat_wave.md says why).
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from .schema import wave_schema

    return wave_schema()


def _prepare(case) -> None:
    from .run import prepare_wave

    prepare_wave(case)


def _run(case, **kwargs):
    from .run import run_wave

    return run_wave(case, **kwargs)


def _plan(case, **kwargs):
    from .cost import plan_wave_case

    return plan_wave_case(case, **kwargs)


KIND = register_kind(Kind("wave", "problem", _schema, _prepare, _run, _plan,
                          default_solver="direct"))
