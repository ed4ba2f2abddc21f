"""The small cloth scene the scene-output tests run (7 x 6 particles, 11 frames)."""

CLOTH = {
    "problem": "mass_spring",
    "name": "frames",
    "system": {"type": "cloth", "nx": 7, "ny": 6, "width": 1.0, "height": 1.0, "plane": "xy",
               "k_structural": 400.0, "k_shear": 100.0, "k_bending": 10.0, "total_mass": 0.5,
               "pinned": "top_corners"},
    "forces": {"gravity": 9.81},
    "integrator": {"method": "fast_mass_spring", "options": {"iterations": 5}},
    "dt": 0.02,
    "t_end": 0.4,
    "output": {"dir": "out", "every": 2},
}
