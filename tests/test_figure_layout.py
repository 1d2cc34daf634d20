"""Figures read as drawn (issue 25): the sweep heat maps' axes span the values run, the wear profile's legend
lies inside the figure and its radial labels sit where the curves are not."""

from __future__ import annotations

import numpy as np
import pytest

from weftsim.input.scene import load_scene
from weftsim.sweep.plots import plot_sweep_2d
from weftsim.wear.extrapolate import Update
from weftsim.wear.figures import label_angle, profile_figure


def _rows(clearances, speeds):
    rows = []
    for c in clearances:
        for n in speeds:
            row = {"clearance_mm": c, "speed_rpm": n, "status": "success", "last_revolution": 1}
            for channel in ("driving_torque_Nm", "rapier_acceleration_m_s2", "contact_force_N"):
                row[f"{channel}_rev1_peak"] = 100.0 * c + n
            rows.append(row)
    return rows


def test_heat_map_axes_start_at_zero_not_below_the_values_run():
    """Clearances 0.01, 0.25, 0.5 mm: the mirrored first cell edge was -0.11 mm."""
    fig = plot_sweep_2d(_rows([0.01, 0.25, 0.5], [300.0, 500.0, 800.0]), "clearance_mm", "speed_rpm")
    maps = [ax for ax in fig.axes if ax.get_xlabel() == "clearance [mm]"]  # not the colour bars
    assert len(maps) == 3
    for ax in maps:
        x0, x1 = ax.get_xlim()
        y0, y1 = ax.get_ylim()
        assert x0 == 0.0 and x1 == pytest.approx(0.5 + 0.5 * (0.5 - 0.25))  # the last cell mirrored as before
        assert y0 == pytest.approx(300.0 - 0.5 * (500.0 - 300.0)) and y0 > 0.0
        assert list(ax.get_xticks()) == pytest.approx([0.01, 0.25, 0.5])  # a tick at each value run


def test_heat_map_of_values_around_zero_keeps_mirrored_cells():
    fig = plot_sweep_2d(_rows([-0.2, 0.2], [300.0, 500.0]), "clearance_mm", "speed_rpm")
    assert [ax for ax in fig.axes if ax.get_xlabel() == "clearance [mm]"][0].get_xlim() == pytest.approx((-0.4, 0.4))


def _updates():
    psi = np.arange(72) * 2 * np.pi / 72
    lobe = np.cos(psi) ** 2  # wear in two lobes along 0 and 180 deg, as the reference joint wears
    return [Update(h, 1e4 * h, 1e-6 * h * lobe, 2e-6 * h * lobe, 1e4, lobe, lobe, 1e-12, {}) for h in (0.0, 1.0, 2.0)]


def test_radial_labels_go_where_the_profile_is_smallest():
    psi = np.arange(72) * 2 * np.pi / 72
    radius = np.cos(psi) ** 2
    angle = label_angle(psi, radius)
    assert abs(np.cos(np.radians(angle))) < 0.4  # off the lobes at 0 and 180 deg (cos 67.5 deg = 0.38)


def test_wear_profile_legend_is_inside_the_figure():
    scene = load_scene("reference")
    fig = profile_figure(scene, _updates(), "reference: wear at E")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    box = fig.legends[0].get_window_extent(renderer)
    frame = fig.bbox
    assert box.x0 >= frame.x0 and box.y0 >= frame.y0 and box.x1 <= frame.x1 and box.y1 <= frame.y1
    for ax in fig.axes:  # the legend overlaps no panel
        assert not box.overlaps(ax.get_window_extent(renderer))
    journal = fig.axes[1]
    assert abs(np.cos(np.radians(journal.get_rlabel_position()))) < 0.4


def _draws(figure, target):
    """How often saving ``figure`` to ``target`` draws it (weftsim.post.output.write_figure)."""
    from weftsim.post.output import write_figure

    calls = []
    draw = type(figure).draw
    figure.draw = lambda renderer: calls.append(1) or draw(figure, renderer)
    write_figure(target, figure)
    return len(calls)


def test_a_tight_figure_is_drawn_once_when_saved_with_the_pixels_of_two_passes(tmp_path):
    """Figure.tight_layout() leaves a placeholder layout engine for which savefig drew the figure twice."""
    from PIL import Image

    from weftsim.post.plots import figure

    def tight():
        fig = figure(figsize=(4, 3))
        ax = fig.subplots()
        ax.plot([0.0, 1.0, 2.0], [0.0, 10.0, 5.0])
        ax.set_ylabel("a long label [N m]")
        fig.tight_layout()
        return fig

    assert _draws(tight(), tmp_path / "once.png") == 1
    two = tight()
    two.savefig(tmp_path / "twice.png", dpi=130, pil_kwargs={"compress_level": 3})  # matplotlib's own two passes
    assert np.array_equal(np.asarray(Image.open(tmp_path / "once.png")), np.asarray(Image.open(tmp_path / "twice.png")))


def test_a_constrained_figure_keeps_its_layout_pass(tmp_path):
    from weftsim.post.plots import figure

    fig = figure(figsize=(4, 3), constrained_layout=True)
    fig.subplots().plot([0.0, 1.0], [0.0, 1.0])
    assert _draws(fig, tmp_path / "c.png") == 2  # the layout engine runs in its own draw
    assert fig.get_layout_engine() is not None
