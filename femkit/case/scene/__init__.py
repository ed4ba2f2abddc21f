"""The ``problem: mass_spring`` scene files: schema (:mod:`.schema`), load-time checks and the
runner (:mod:`.run`), outputs (:mod:`.output`) and pictures (:mod:`.plot`).

This is the application layer over :mod:`femkit.dynamics` (which knows nothing of files);
:data:`femkit.kinds.KINDS` dispatches ``femkit solve SCENE.yaml`` here through
:func:`femkit.case.scene.run.prepare_scene` and :func:`femkit.case.scene.run.run_scene`.
"""
