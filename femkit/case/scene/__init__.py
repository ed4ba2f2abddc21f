"""The ``problem: mass_spring`` scene files, one package: the registration (:mod:`.kind`), schema
(:mod:`.schema`), spec (:mod:`.spec`), the plan and memory guard (:mod:`.cost`), load-time checks
and the runner with ``SceneResult`` (:mod:`.run`, a :class:`~femkit.case.result.RunResult`),
outputs (:mod:`.output`) and pictures (:mod:`.plot`).

This is the application layer over :mod:`femkit.dynamics` (which knows nothing of files);
:data:`femkit.kinds.KINDS` dispatches ``femkit solve SCENE.yaml`` here through
:func:`femkit.case.scene.run.prepare_scene` and :func:`femkit.case.scene.run.run_scene`.
"""
