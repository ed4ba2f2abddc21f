"""``problem: solid``: elastic solids by finite elements as case files (static or dynamic).

One package: kind.py registers the kind; schema.py (derived from the material, integrator and
geometry registries), spec.py (the frozen :class:`SolidSpec`), run.py (prepare and run,
``SolidResult``, a :class:`~femkit.case.result.RunResult`), cost.py (the plan and memory guards),
output.py (VTU/PVD, result.json), plot.py (PNG and GIF of the deformed body; the GIF machinery
shared with scenes is :mod:`femkit.case.pictures`).
"""
