"""``kind: springs_vs_elements`` (studies/springs_vs_elements.yaml, quick mode) and its spring
layouts: the study runs end to end with its figures and numbers; the elements converge on the
beam while the springs' volume error stalls on the disk; the spring layout changes the springs'
answer on the same mesh, not the elements'; Van Gelder's rule stores a dilation's energy exactly.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from femkit.errors import CaseFileError, UnknownNameError
from femkit.study.load import load_study, study_from_dict
from femkit.study.springs_vs_elements.layouts import SPRING_LAYOUTS, plane_strain_modulus

STUDY = Path(__file__).parents[2] / "studies" / "springs_vs_elements.yaml"
FIGURES = {"work_precision_hanging_beam.png", "work_precision_falling_disk.png",
           "convergence_hanging_beam.png", "convergence_falling_disk.png", "volume.png",
           "topology.png"}


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("svse") / "report"
    return load_study(STUDY, quick=True).run(out, progress=False)


def _fit(result, scene, method, key):
    return result.fit(scene=scene, method=method, fitted=key)


@pytest.mark.slow
def test_quick_study_writes_its_figures_and_numbers(quick):
    out = quick.output_dir
    assert {Path(f).name for f in quick.figures} == FIGURES
    for f in FIGURES:
        assert (out / "figures" / f).stat().st_size > 10_000
    data = json.loads((out / "results.json").read_text())
    methods = {r["method"] for r in data["records"]}
    assert len(methods) == 5 and len(data["records"]) == 5 * (3 + 2)
    for r in data["records"]:
        assert r["completed"] and r["seconds"] > 0
        for key in ("value", "value_error", "trajectory_error", "area_change_peak", "area_error"):
            assert np.isfinite(r[key]), (r["method"], key)
    md = (out / "report.md").read_text()
    assert "Van Gelder" in md and "topology" in md.lower()
    assert (out / "topology.csv").is_file() and (out / "fits.csv").is_file()


@pytest.mark.slow
def test_elements_converge_on_the_beam(quick):
    """The neo-Hookean elements' settled tip deflection approaches the finest-mesh answer at a
    fitted rate > 0.8 (fails if the elements did not converge)."""
    f = _fit(quick, "hanging_beam", "neo-Hookean (Newton)", "value_error")
    assert f["slope"] > 0.8, f
    assert f["error_finest"] < 0.5 * f["error_coarsest"], f


@pytest.mark.slow
def test_springs_volume_error_stalls_where_the_elements_converge(quick):
    """On the falling disk the springs (a lattice whose bulk modulus is fixed by its Poisson
    ratio 1/3, half the continuum's at nu = 0.4 in plane strain) change their area by about
    twice the continuum's at the impact, whatever the mesh: the error of the peak area change
    stays above 50% on every mesh, while the elements' is below 25% on the finest."""
    rows = [r for r in quick.records if r["scene"] == "falling_disk"]
    for layout in ("edges", "edges + cross"):
        errs = [r["area_error"] for r in rows if r["method"] == f"springs ({layout})"]
        assert len(errs) == 2 and min(errs) > 0.5, (layout, errs)
        f = _fit(quick, "falling_disk", f"springs ({layout})", "area_error")
        assert f["finest_over_coarsest"] > 0.5, f
    elements = sorted((r for r in rows if r["method"] == "neo-Hookean (Newton)"),
                      key=lambda r: r["h"])
    assert elements[0]["area_error"] < 0.25, elements


@pytest.mark.slow
def test_topology_changes_the_springs_answer_not_the_elements(quick):
    """Same beam mesh: the two spring layouts' settled deflections differ by more than 3% of the
    reference, on every mesh; the elements have no layout: one answer per mesh."""
    for t in (t for t in quick.tables["topology"] if t["scene"] == "hanging_beam"):
        assert t["springs_spread"] > 0.03, t
        elements = [r["value"] for r in quick.records if r["scene"] == "hanging_beam"
                    and r["h"] == t["h"] and r["method"] == "neo-Hookean (Newton)"]
        assert elements == [t["elements_value"]]


@pytest.mark.parametrize("layout", SPRING_LAYOUTS.names())
def test_layouts_use_the_same_nodes_and_differ_in_springs(layout):
    from femkit.mesh import generate

    mesh = generate("disk", 0.1, radius=0.3)
    springs, k = SPRING_LAYOUTS.get(layout).build(mesh, 1.0)
    assert springs.min() >= 0 and springs.max() < mesh.n_points
    assert np.all(springs[:, 0] < springs[:, 1]) and np.all(k > 0)
    assert len(np.unique(springs, axis=0)) == len(springs)


def test_van_gelder_stores_the_dilation_energy_of_a_nu_one_third_continuum():
    """``sum k L^2 = 3 E' area`` on any mesh (each triangle counted once per edge), so a uniform
    dilation by ``eps`` stores ``1.5 E' eps^2 area``, the plane energy ``E' eps^2 / (1 - nu)`` of
    a continuum with ``nu = 1/3``; the cross layout keeps it up to the boundary triangles."""
    from femkit.mesh import generate

    mesh = generate("disk", 0.05, radius=0.3)
    area = mesh.areas().sum()
    E = plane_strain_modulus(2.0, 0.4)
    sums = {}
    for name in SPRING_LAYOUTS.names():
        springs, k = SPRING_LAYOUTS.get(name).build(mesh, E)
        d = mesh.points[springs[:, 1]] - mesh.points[springs[:, 0]]
        sums[name] = float(np.sum(k * np.einsum("ij,ij->i", d, d)))
    assert sums["edges"] == pytest.approx(3.0 * E * area, rel=1e-12)
    assert sums["edges_cross"] == pytest.approx(3.0 * E * area, rel=0.1)
    assert sums["edges_cross"] != pytest.approx(sums["edges"], rel=1e-3)


def _data(**over):
    d = {"kind": "springs_vs_elements",
         "scenes": {"hanging_beam": {"h": [0.05, 0.035], "reference_h": 0.025}},
         "methods": [{"model": "springs", "layout": "edges"}, {"model": "elements"}]}
    d.update(over)
    return d


def test_bad_input_is_one_line_naming_the_key(tmp_path):
    with pytest.raises(UnknownNameError, match="valid spring layouts: edges, edges_cross"):
        from femkit.study.springs_vs_elements.layouts import SPRING_LAYOUTS as reg
        reg.get("lattice")
    with pytest.raises(CaseFileError, match="layout"):
        study_from_dict(_data(methods=[{"model": "springs", "layout": "grid"}]), tmp_path)
    with pytest.raises(CaseFileError, match=r"methods\[0\]: springs need a 'layout'"):
        study_from_dict(_data(methods=[{"model": "springs"}]), tmp_path)
    with pytest.raises(CaseFileError, match="elastic solids only"):
        study_from_dict(_data(methods=[{"model": "springs", "layout": "edges",
                                        "integrator": "projective"}]), tmp_path)
    with pytest.raises(CaseFileError, match="reference_h: 0.05 must be finer"):
        study_from_dict(_data(scenes={"hanging_beam": {"h": [0.05, 0.035],
                                                       "reference_h": 0.05}}), tmp_path)
    with pytest.raises(CaseFileError, match="labels must be unique"):
        study_from_dict(_data(methods=[{"model": "elements"}, {"model": "elements"}]), tmp_path)
    with pytest.raises(CaseFileError, match="unknown key"):
        study_from_dict(_data(scenes={"hanging_bean": {}}), tmp_path)


def test_plan_counts_every_run(tmp_path):
    from femkit.study.cost import plan_study

    study = study_from_dict(_data(), tmp_path)
    plan = plan_study(study)
    assert plan.sizes["runs"] == 2 * 2 + 1 and plan.seconds > 0
