"""Pictures of mass-spring runs (femkit.case.scene.plot): valid files, 3-D views, strain colours.

Small systems, few steps: every test builds its trajectory with ``simulate`` directly.
"""

from __future__ import annotations

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity
from femkit.dynamics.forces.contact import GroundContact, SphereContact
from femkit.mesh import grid_triangles
from femkit.case.scene.plot import (gif_frame_times, gif_frames, plot_frame, scene_view,
                                  spring_strain, write_final_png, write_gif)
from femkit.dynamics.simulate import simulate
from femkit.dynamics.topology import cloth_grid, rope, single_spring
from femkit.errors import InstabilityError

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def cloth3d(forces=()):
    """5 x 5 horizontal cloth (plane xy, z = 0) pinned at the two corners of its last row."""
    return cloth_grid(5, 5, 1.0, 1.0, k_structural=400.0, k_shear=100.0, total_mass=0.5,
                      plane="xy", forces=[Gravity(9.81), *forces])


SCENES = {
    "cloth-3d-surface": lambda: (cloth3d(), grid_triangles(5, 5)),
    "rope-3d-springs": lambda: (rope(6, 1.0, k=500.0, dim=3, forces=[Gravity(9.81)]), None),
    "rope-2d": lambda: (rope(6, 1.0, k=500.0, forces=[Gravity(9.81)]), None),
    "cloth-2d-ground": lambda: (cloth_grid(4, 4, 0.5, 0.5, k_structural=300.0, plane="xy", dim=2,
                                           pinned="none", origin=[0.0, 0.2],
                                           forces=[Gravity(9.81), GroundContact(1e4)]),
                                grid_triangles(4, 4)),
}


def run(system, steps=40, dt=5e-3, every=4, method="implicit_euler"):
    return simulate(system, method, dt, steps * dt, record_every=every, check_stability=False)


def unstable_run():
    """SOFA's spring made stiff (k = 1e6, m = 1, dt = 1/60): symplectic Euler blows up."""
    s = single_spring(k=1e6, m=1.0, gravity=10.0)
    with pytest.raises(InstabilityError) as info, pytest.warns(Warning):
        simulate(s, "symplectic_euler", 1 / 60, 1.0, record_every=1, check_every=1)
    return s, info.value


@pytest.fixture(scope="module")
def runs():
    out = {}
    for key, make in SCENES.items():
        system, tri = make()
        out[key] = (system, tri, run(system))
    return out


@pytest.mark.parametrize("key", list(SCENES))
def test_png_is_a_valid_picture_of_the_requested_size(runs, key, tmp_path):
    from PIL import Image

    system, tri, traj = runs[key]
    path = write_final_png(tmp_path / "final.png", system, traj, key, triangles=tri, dpi=50)
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE and len(data) > 5000
    with Image.open(path) as im:
        assert im.size == (480, 240)                       # 9.6 x 4.8 inches at 50 dpi
        pixels = np.asarray(im.convert("L"))
    assert pixels.std() > 10                               # not a blank canvas


def test_gif_has_one_frame_per_pick_all_the_same_size(runs, tmp_path):
    from PIL import Image, ImageSequence

    system, tri, traj = runs["cloth-3d-surface"]
    n = len(traj.times)
    assert n == 11                                         # 40 steps every 4 + the first
    path = write_gif(tmp_path / "a.gif", system, traj, "cloth", triangles=tri, max_frames=6,
                     dpi=30)
    assert path.read_bytes()[:6] == b"GIF89a"
    expected = gif_frames(n, 6)
    assert expected.tolist() == [0, 2, 4, 6, 8, 10]
    with Image.open(path) as im:
        frames = [f.copy() for f in ImageSequence.Iterator(im)]
        durations = []
        for i in range(im.n_frames):
            im.seek(i)
            durations.append(im.info["duration"])
    assert len(frames) == len(expected)
    assert {f.size for f in frames} == {(288, 144)}
    # 0.2 s of simulation is slowed down to the 2 s minimum playback, last frame held 1 s more
    assert sum(durations) == pytest.approx(3000, abs=30)


@pytest.mark.parametrize("n, cap, expected", [
    (101, 60, 51), (6, 60, 6), (1, 60, 1), (61, 60, 31), (200, 7, 7)],
    ids=["stride2", "all-frames", "single", "just-over", "capped"])
def test_gif_frames_are_capped_evenly_spaced_and_end_on_the_last(n, cap, expected):
    picks = gif_frames(n, cap)
    assert len(picks) == expected <= cap
    assert picks[0] == 0 and picks[-1] == n - 1
    assert len(set(np.diff(picks[:-1]).tolist())) <= 1


@pytest.mark.parametrize("t_end, playback", [(0.5, 2.0), (4.0, 4.0), (100.0, 8.0)],
                         ids=["short-slowed", "real-time", "long-sped-up"])
def test_gif_frame_times_map_simulated_time_to_a_sensible_playback(t_end, playback):
    times = np.linspace(0.0, t_end, 41)
    d = gif_frame_times(times, np.arange(0, 41, 2))
    assert len(d) == 21 and d[-1] == 1.0                  # the final state is held 1 s
    assert d[:-1].sum() == pytest.approx(playback, abs=0.05)
    assert np.all(d >= 0.02)


def test_3d_system_is_drawn_in_a_3d_axes_with_equal_aspect(runs):
    system, tri, traj = runs["cloth-3d-surface"]
    fig = plot_frame(system, traj, -1, triangles=tri, name="cloth", dpi=40)
    ax = fig.scene_axes
    assert ax.name == "3d" and hasattr(ax, "zaxis")
    # box aspect proportional to the data ranges (equal aspect): ratios of the limits
    spans = np.array([np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim()), np.ptp(ax.get_zlim())])
    box = np.asarray(ax.get_box_aspect())
    np.testing.assert_allclose(box / box.max(), np.maximum(spans, 0.05 * spans.max()) / spans.max(),
                               rtol=1e-9)
    # the cloth sagged below its pins: the z range is real, not the 5 % floor
    assert spans[2] > 0.05 * spans.max()
    # camera looks across the pins' line (along x here) 30 degrees off its normal
    assert abs(np.cos(np.radians(ax.azim))) == pytest.approx(np.sin(np.radians(30.0)), abs=1e-9)
    assert 20.0 <= ax.elev <= 30.0
    assert fig.strain_mappable is None                     # a surface, not strain lines


@pytest.mark.parametrize("key", ["rope-2d", "cloth-2d-ground"])
def test_2d_system_uses_equal_aspect_and_no_z(runs, key):
    system, tri, traj = runs[key]
    fig = plot_frame(system, traj, -1, triangles=tri, dpi=40)
    assert not hasattr(fig.scene_axes, "zaxis")
    assert fig.scene_axes.get_aspect() == 1.0


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_strain_colours_are_symmetric_about_zero_and_match_the_springs(dim):
    s = rope(4, 3.0, k=1.0, dim=dim)
    x = s.x0.copy()
    x[2:] += np.eye(dim)[0]          # spring 1 stretched from 1 to 2: strain +1
    x[3] -= 1.5 * np.eye(dim)[0]     # spring 2 compressed from 1 to -0.5 (length 0.5): -0.5
    traj = run(s, steps=1, every=1, method="symplectic_euler")
    traj.x[-1] = x
    fig = plot_frame(s, traj, -1, dpi=40)
    lc = fig.strain_mappable
    assert lc.norm.vmin == -lc.norm.vmax
    assert lc.norm.vmax == pytest.approx(1.0)              # the largest |strain| of the run
    np.testing.assert_allclose(lc.get_array(), [0.0, 1.0, -0.5])
    np.testing.assert_allclose(spring_strain(s, x), [0.0, 1.0, -0.5])


def test_final_png_colours_resolve_the_final_strains(runs, tmp_path, monkeypatch):
    import femkit.case.scene.plot as plot

    system, tri, traj = runs["rope-2d"]
    seen = {}
    real = plot.plot_frame

    def spy(*args, **kwargs):
        fig = real(*args, **kwargs)
        seen["norm"] = fig.strain_mappable.norm
        return fig

    monkeypatch.setattr(plot, "plot_frame", spy)
    plot.write_final_png(tmp_path / "r.png", system, traj, "rope", dpi=30)
    final = np.abs(spring_strain(system, traj.x[-1])).max()
    assert seen["norm"].vmax == pytest.approx(final) and seen["norm"].vmin == -seen["norm"].vmax


def test_unstable_run_still_makes_a_picture_with_the_stop_marked(tmp_path):
    from PIL import Image

    system, exc = unstable_run()
    traj = exc.partial
    assert not traj.completed
    fig = plot_frame(system, traj, -1, name="stiff", dpi=40)
    stops = [ln for ln in fig.energy_axes.get_lines() if ln.get_linestyle() == "--"]
    assert len(stops) == 1
    assert stops[0].get_xdata()[0] == pytest.approx(exc.time)
    assert f"step {exc.step}" in stops[0].get_label()
    texts = " ".join(t.get_text() for t in fig.texts)
    assert f"UNSTABLE at step {exc.step}" in texts
    assert fig.energy_axes.get_xlim()[1] > exc.time       # the mark is inside the panel
    path = write_final_png(tmp_path / "u.png", system, traj, "stiff", dpi=40)
    with Image.open(path) as im:
        assert im.size == (384, 192)


def test_completed_run_has_no_stop_mark(runs):
    system, tri, traj = runs["rope-2d"]
    fig = plot_frame(system, traj, -1, dpi=40)
    assert not [ln for ln in fig.energy_axes.get_lines() if ln.get_linestyle() == "--"]
    assert "UNSTABLE" not in " ".join(t.get_text() for t in fig.texts)


def test_declared_ground_and_sphere_are_drawn_and_framed():
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    sphere = SphereContact([0.5, 0.5, -1.0], 0.3, 1e4)
    system = cloth3d([GroundContact(1e4, height=-2.0), sphere])
    traj = run(system, steps=4, every=2)
    view = scene_view(system, traj)
    assert view.lo[2] < -2.0 and view.hi[2] > 0.0          # ground height inside the box
    fig = plot_frame(system, traj, -1, triangles=grid_triangles(5, 5), view=view, dpi=40)
    polys = [c for c in fig.scene_axes.collections if isinstance(c, Poly3DCollection)]
    # ground quad + sphere surface + cloth surface
    assert len(polys) == 3
    plain = plot_frame(cloth3d(), traj, -1, triangles=grid_triangles(5, 5), dpi=40)
    assert len([c for c in plain.scene_axes.collections if isinstance(c, Poly3DCollection)]) == 1


def test_energy_panel_shows_kinetic_potential_and_total(runs):
    system, tri, traj = runs["rope-2d"]
    fig = plot_frame(system, traj, -1, dpi=40)
    lines = {ln.get_label(): ln for ln in fig.energy_axes.get_lines()}
    e = traj.energies
    np.testing.assert_allclose(lines["kinetic"].get_ydata(), e["kinetic"])
    np.testing.assert_allclose(lines["potential"].get_ydata(),
                               e["spring"] + e["gravity"] + e["contact"])
    np.testing.assert_allclose(lines["total"].get_ydata(), e["total"])
