"""``kind: heat_work_precision``: error at t_end against run time for each heat integrator and dt, over two meshes.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec` (the base
case's checks), :mod:`.run` (the runs through the heat kind's pipeline), :mod:`.report`,
:mod:`.kind`. The explicit schemes' stability barrier shows as the runs above their critical
step on each mesh (run anyway, ``--force``, and marked unstable).
"""
