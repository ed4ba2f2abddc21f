"""``problem: solid``: elastic solids by finite elements as case files (static or dynamic).

kind.py registers the kind; schema.py (derived from the material, integrator and geometry
registries), spec.py (the frozen :class:`SolidSpec`), run.py (prepare and run), cost.py (the plan),
output.py (VTU/PVD, result.json), plot.py (PNG and GIF of the deformed body).
"""
