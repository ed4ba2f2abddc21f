"""``problem: mass_spring``: a mass-spring scene file, registered as a :class:`~femkit.kinds.Kind`.

Schema :func:`femkit.case.scene.schema.scene_schema` (its force and system enums come from
:data:`~femkit.case.scene.forces.FORCES` and :data:`~femkit.case.scene.systems.SYSTEMS`);
load-time checks :func:`femkit.case.scene.run.prepare_scene`; the run
:func:`femkit.case.scene.run.run_scene`; the cost plan :func:`femkit.case.scene.cost.plan_scene_case` (priced from the system's counts,
:func:`femkit.case.scene.systems.system_size`, before anything is built).
The dynamics modules are imported on first use only.
"""

from __future__ import annotations

from ...kinds import Kind, register_kind


def _schema() -> dict:
    from .schema import scene_schema

    return scene_schema()


def _prepare(case) -> None:
    from .run import prepare_scene

    prepare_scene(case)


def _run(case, **kwargs):
    from .run import run_scene

    return run_scene(case, **kwargs)


def _plan(case, measure: bool = True):
    from .cost import plan_scene_case
    from .systems import system_size

    def build():
        from .run import build_context, build_integrator, build_system

        return build_system(case)[0], build_integrator(case), build_context(case)

    # priced from the file's numbers first: nothing is allocated before the memory check
    return plan_scene_case(case, system_size(case.spec.system), build=build, measure=measure)


def _view(run, **options):
    from .view import scene_view

    return scene_view(run, **options)


KIND = register_kind(Kind("mass_spring", "problem", _schema, _prepare, _run, _plan,
                          default_solver="direct", view=_view))
