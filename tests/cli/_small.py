"""The smallest Poisson case the command-line tests run (16 triangles, CG)."""

SMALL = {
    "problem": "poisson",
    "mesh": {"geometry": "unit_square", "h": 0.25},
    "source": "1",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "solver": {"method": "cg", "rtol": 1e-10},
    "output": {"dir": "out", "vtu": True},
}
