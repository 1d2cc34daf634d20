"""The journal-centre orbit (weftsim.post.plots.plot_orbit, orbit.png of ``weftsim run``) draws the run's
eccentricity inside the clearance circle, with the impacts on that circle (docs/physics.md section 2)."""

from pathlib import Path

import numpy as np
import pytest

from weftsim.post.output import write_run
from weftsim.post.plots import contact_onsets, plot_orbit
from conftest import door
solve = door("reference")
from weftsim.input.scene import load_scene

REFERENCE = Path(__file__).resolve().parents[1] / "models" / "reference.toml"
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def half_revolution():
    """Half a revolution of the reference scene (c = 0.25 mm, 400 rpm): 20 impacts in ~0.3 s of solving."""
    result = solve(load_scene(REFERENCE, {"drive.revolutions": 0.5}))
    assert result.ok, result.message
    return result


def test_impacts_are_the_engines_own_onsets_and_lie_on_the_clearance_circle(half_revolution):
    steps, c = half_revolution.steps, half_revolution.scene.joint.clearance
    onsets = contact_onsets(steps)
    # The engine counts its impacts while it integrates (located events); the figure finds them
    # afresh in the per-step channels: the two counts must agree.
    assert onsets.size == half_revolution.solver_stats["impacts"] > 0
    radius = np.hypot(steps["eccentricity_y_m"], steps["eccentricity_z_m"])
    # The reference engine ends a step at the located onset delta = |e| - c = 0, so an impact sits on
    # the circle up to the event search's round-off: measured at most 4e-13 c over these 20 onsets;
    # 1e-9 c is far above that and far below a step's travel (the row before an onset is 1e-3..6e-2 c
    # inside the circle).
    assert np.all(np.abs(radius[onsets] - c) <= 1e-9 * c)
    assert np.all(radius[onsets - 1] < c)  # each onset comes out of free flight


def test_figure_draws_the_circle_the_orbit_and_every_impact(half_revolution):
    steps, c = half_revolution.steps, half_revolution.scene.joint.clearance
    fig = plot_orbit(half_revolution)
    ax = fig.axes[0]
    circle, orbit = ax.lines[0], ax.lines[1]
    # The circle is |e| = c in mm, to the round-off of cos/sin (1e-15 relative; 1e-12 leaves room).
    assert np.allclose(np.hypot(*circle.get_data()), c * 1e3, rtol=1e-12, atol=0.0)
    # The orbit is the eccentricity at every accepted step, unchanged but for m -> mm.
    assert np.array_equal(orbit.get_xdata(), steps["eccentricity_y_m"] * 1e3)
    assert np.array_equal(orbit.get_ydata(), steps["eccentricity_z_m"] * 1e3)
    onsets = contact_onsets(steps)
    dots = ax.collections[0]
    expected = np.column_stack([steps["eccentricity_y_m"][onsets], steps["eccentricity_z_m"][onsets]]) * 1e3
    assert np.array_equal(dots.get_offsets(), expected)
    assert np.array_equal(dots.get_array(), steps["impact_velocity_m_s"][onsets])


def test_run_writes_orbit_png_beside_channels_png_for_a_clearance_joint_only(tmp_path, half_revolution):
    written = write_run(half_revolution, tmp_path / "clearance")
    assert written["orbit"].name == "orbit.png" and written["orbit"].parent == written["figure"].parent
    assert written["orbit"].read_bytes()[:8] == PNG
    ideal = solve(load_scene(REFERENCE, {"drive.revolutions": 0.05, "joint_e.clearance_mm": 0.0}))
    written = write_run(ideal, tmp_path / "ideal")
    assert "orbit" not in written and not (tmp_path / "ideal" / "orbit.png").exists()  # e = 0: no orbit
    assert (tmp_path / "ideal" / "channels.png").exists()


def test_ideal_joint_is_refused_with_one_clear_line():
    ideal = solve(load_scene(REFERENCE, {"drive.revolutions": 0.05, "joint_e.clearance_mm": 0.0}))
    with pytest.raises(ValueError, match=r"joint_e.clearance_mm must be > 0, got 0"):
        plot_orbit(ideal)
