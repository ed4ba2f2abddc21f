"""Budgets refuse ruinous runs before they start, in one line that says what to change."""

import pytest

from femkit.cost import Limits, check_budget, parse_bytes, parse_seconds, plan_mesh, plan_poisson, plan_scene
from femkit.errors import BudgetExceededError, InputError

GiB = 2 ** 30
#: the unit square as the cost model sees it: numbers only
SQUARE = dict(area=1.0, line_length=4.0, name="unit_square")


@pytest.mark.parametrize("spec,hint", [
    (dict(h=1e-5), "h >= "),
    (dict(h=0.05, refine=8), "refine <= "),
], ids=["h=1e-5", "h=0.05-refine=8"])
def test_ruinous_meshes_refused_in_one_line(spec, hint):
    plan = plan_poisson(**SQUARE, **spec)
    with pytest.raises(BudgetExceededError) as err:
        check_budget(plan, Limits(memory=16 * GiB), override="--force")
    msg = str(err.value)
    assert "\n" not in msg and "triangles" in msg and "peak memory" in msg
    assert hint in msg and "--force" in msg
    assert err.value.what == "memory" and err.value.predicted > 16 * GiB


def test_suggested_h_fits_and_is_tight():
    """The suggested h fits the limit and a 10 % smaller one does not."""
    plan = plan_poisson(**SQUARE, h=1e-4)
    limit = 4 * GiB
    tip = plan.suggest("memory", limit)
    h = float(tip.split("h >= ")[1].split()[0])
    assert plan_poisson(**SQUARE, h=h).peak_bytes <= limit
    assert plan_poisson(**SQUARE, h=0.9 * h).peak_bytes > limit


def test_mesh_generation_checked_before_gmsh():
    """plan_mesh imports no gmsh (nor numpy): the check happens before generation starts."""
    import subprocess
    import sys

    plan = plan_mesh(**SQUARE, h=1e-5)
    assert [s.name for s in plan.stages] == ["mesh"]
    with pytest.raises(BudgetExceededError, match="h >= "):
        check_budget(plan, Limits(memory=8 * GiB))
    assert plan.sizes["triangles"] > 1e10
    code = ("import sys; from femkit.cost import plan_mesh, check_budget, Limits\n"
            "try:\n    check_budget(plan_mesh(area=1, line_length=4, h=1e-5), Limits(memory=2**33))\n"
            "except Exception as e:\n    print(type(e).__name__)\n"
            "print(sorted(m for m in ('gmsh', 'numpy', 'scipy') if m in sys.modules))")
    from cost_probe import child_env

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=child_env())
    assert out.stdout.split() == ["BudgetExceededError", "[]"]


def test_scene_steps_limit():
    plan = plan_scene(n_nodes=225, n_springs=1200, dim=3, dt=1e-9, t_end=2.0, every=40_000_000,
                      method="implicit_euler", implicit=True)
    assert plan.steps == 2_000_000_000
    with pytest.raises(BudgetExceededError) as err:
        check_budget(plan, Limits(steps=1e6), override="--force")
    msg = str(err.value)
    assert "2e+09 time steps" in msg and "dt >= 2e-06" in msg and "\n" not in msg


def test_time_and_output_limits():
    plan = plan_poisson(**SQUARE, h=0.002, outputs=("vtu", "xdmf"))
    with pytest.raises(BudgetExceededError, match="predicted time") as err:
        check_budget(plan, Limits(time=1.0), available=64 * GiB)
    assert err.value.what == "time"
    with pytest.raises(BudgetExceededError, match="predicted output"):
        check_budget(plan, Limits(output=1000), available=64 * GiB)


def test_force_returns_the_messages_instead():
    plan = plan_poisson(**SQUARE, h=1e-5)
    msgs = check_budget(plan, Limits(memory=GiB, time=60), force=True)
    assert len(msgs) == 2 and msgs[0].startswith("predicted peak memory")


def test_fitting_plan_passes():
    plan = plan_poisson(**SQUARE, h=0.05)
    assert check_budget(plan, Limits(memory=8 * GiB, time=3600, output=GiB)) == []


def test_limits_from_mapping():
    lim = Limits.from_mapping({"memory": "2GiB", "time": "10min", "steps": 1e6, "output": "500MB"})
    assert (lim.memory, lim.time, lim.steps, lim.output) == (2 * GiB, 600.0, 1e6, 500e6)
    with pytest.raises(InputError, match="unknown key.*valid: memory"):
        Limits.from_mapping({"memry": "1GB"})
    with pytest.raises(InputError, match="limits.time"):
        Limits.from_mapping({"time": "soon"})


@pytest.mark.parametrize("bad", ["-1GB", "0", "1 parsec", True, float("nan")], ids=repr)
def test_bad_sizes(bad):
    with pytest.raises(InputError):
        parse_bytes(bad)


def test_units():
    assert parse_bytes("1.5k") == 1500 and parse_bytes("3 MiB") == 3 * 2 ** 20
    assert parse_seconds("1d") == 86400.0


def test_case_layer_guard_refuses_before_gmsh_starts():
    """The memory guard the case layer runs before meshing: refused from the geometry's declared
    measure, before gmsh is imported, with the h that fits."""
    import subprocess
    import sys

    code = ("import sys; from femkit.case.cost import check_mesh_fits\n"
            "try:\n    check_mesh_fits(geometry='unit_square', h=1e-5)\n"
            "except Exception as e:\n    print(type(e).__name__, '|', e)\n"
            "print('gmsh' in sys.modules)")
    from cost_probe import child_env

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=60, env=child_env())
    first, last = out.stdout.strip().splitlines()
    assert first.startswith("BudgetExceededError | unit_square h=1e-05: predicted peak memory")
    assert "use h >= " in first and "--force" in first
    assert last == "False"


def test_case_run_refuses_a_ruinous_mesh_before_meshing(monkeypatch):
    """load_case(...).run() goes through the guard (no femkit solve budget check needed); with
    options.force the guard steps aside (gmsh would then be called: stopped here)."""
    import femkit
    import femkit.mesh.geometries.planar as geometries  # the module unit_square calls rectangle in

    case = femkit.load_case("cases/poisson_unit_square.yaml", mesh={"h": 1e-5})
    called = []
    monkeypatch.setattr(geometries, "rectangle", lambda *a, **k: called.append(a) or 1 / 0)
    with pytest.raises(BudgetExceededError, match="unit_square h=1e-05"):
        case.run(write=False, quiet=True)
    assert not called


@pytest.mark.parametrize("kw", [dict(geometry="unit_square", h=1e-5), dict(triangles=1e6, refine=8)],
                         ids=["generate", "refine"])
def test_guard_forced_or_fitting_passes(kw):
    from femkit.case.cost import check_mesh_fits

    assert check_mesh_fits(**kw, force=True) is None
    with pytest.raises(BudgetExceededError):
        check_mesh_fits(**kw)
    assert check_mesh_fits(geometry="unit_square", h=0.2) is None
