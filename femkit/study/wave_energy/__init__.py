"""``kind: wave_energy``: the discrete energy's drift against the step count for each wave integrator.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`,
:mod:`.run` (the runs through the wave kind's pipeline), :mod:`.report`, :mod:`.kind`.
"""
