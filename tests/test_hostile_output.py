"""What a newcomer reads off the outputs (issue 35): figures whose labels do not collide and that say their
conditions (limit, speed, k, units), the orbit of a stiff small-clearance joint said to be at true scale, the
transmission angle in kinematics.png, a large output announced before the run and each file as it is written."""

from __future__ import annotations

import numpy as np
import pytest

import weftsim
from weftsim.cli.commands import main


def _drawn(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def _ensemble_data(hours):
    from weftsim.wear.ensemble import quantile_table

    return {"hours_to_limit": quantile_table(hours), "limit_clearance_mm": 0.1, "horizon_hours": 1e5}


@pytest.mark.parametrize("spread", [0.05, 0.3, 1.5], ids=["narrow", "medium", "wide"])
def test_the_cdf_labels_neither_collide_nor_sit_on_the_curve(spread):
    """Log-axis tick labels apart from each other at any spread of hours, and each quantile's label clear of
    the curve (it sits where the curve is not: right of the line below p, or left of it above p)."""
    from weftsim.wear.ensemble_figures import cdf_figure

    hours = 3e4 * np.exp(spread * np.random.default_rng(0).standard_normal(500))
    fig = cdf_figure(hours, _ensemble_data(hours), "t")
    renderer = _drawn(fig)
    ax = fig.axes[0]
    ticks = [t.get_window_extent(renderer) for t in ax.get_xticklabels() if t.get_text() and t.get_visible()]
    ticks = [b for b in ticks if ax.get_window_extent(renderer).x0 - 5 <= b.x0 <= ax.get_window_extent(renderer).x1]
    assert len(ticks) >= 2
    assert not any(_overlap(a, b) for i, a in enumerate(ticks) for b in ticks[i + 1:])
    x = np.sort(hours)
    curve = ax.transData.transform(np.column_stack([x, np.arange(1, x.size + 1) / x.size]))
    labels = [t for t in ax.texts if t.get_text().startswith("p")]
    assert len(labels) == 3
    for label in labels:
        box = label.get_window_extent(renderer)
        inside = (curve[:, 0] > box.x0) & (curve[:, 0] < box.x1) & (curve[:, 1] > box.y0) & (curve[:, 1] < box.y1)
        assert not inside.any(), label.get_text()


def test_the_wear_figures_say_their_conditions_and_mark_the_limit():
    from weftsim.wear.ensemble_figures import band_figure
    from weftsim.wear.figures import conditions, growth_figure

    scene = weftsim.load_scene("loom")
    text = conditions(scene)
    assert "600 rpm" in text and "k = 1e-07" in text and "MPa" in text
    columns = {"hours": np.array([0.0, 10.0, 20.0]), "effective_clearance_e_mm": np.array([0.02, 0.05, 0.09])}
    for name in ("contact_force_e_mean_N", "contact_force_e_p99_N", "rapier_acceleration_rms_m_s2",
                 "rapier_acceleration_p99_m_s2", "driving_torque_rms_Nm", "driving_torque_p99_Nm"):
        columns[name] = np.ones(3)
    fig = growth_figure(columns, "t", ("e",), limit_mm=0.1)
    assert fig.axes[-1].get_xlabel() == "operating hours [h]"
    assert "limit 0.1 mm" in fig.axes[0].get_legend_handles_labels()[1]
    band = {"clearance_e_mm": np.array([0.03, 0.05, 0.1]), "hours_p10": np.array([1.0, 5.0, 9.0]),
            "hours_p50": np.array([2.0, 6.0, 10.0]), "hours_p90": np.array([3.0, 7.0, 11.0]),
            "fraction_reaching": np.ones(3)}
    fig = band_figure(band, "t", limit_mm=0.1)
    assert "[h]" in fig.axes[0].get_xlabel()
    assert "limit 0.1 mm" in fig.axes[0].get_legend_handles_labels()[1]


def test_the_polar_labels_sit_where_the_profile_is_not():
    """Two lobes at 90 and 270 deg (the loom's bearing): the radial labels go where the profile stays near the
    centre, away from the lobes."""
    from weftsim.wear.figures import label_angle

    psi = np.linspace(0.0, 2.0 * np.pi, 361)
    radius = 0.02 + np.abs(np.sin(psi)) ** 8
    angle = label_angle(psi, radius)
    assert min(abs((angle - 90.0 + 180.0) % 360.0 - 180.0), abs((angle - 270.0 + 180.0) % 360.0 - 180.0)) > 45.0
    assert angle % 45.0 != 0.0  # off the grid lines


def test_the_orbit_of_a_stiff_small_clearance_says_it_is_at_true_scale():
    from weftsim.post.plots import plot_orbit

    new = weftsim.simulate(weftsim.load_scene("loom", revolutions=0.5), "reference", on_warning=lambda text: None)
    texts = [t.get_text() for ax in plot_orbit(new).axes for t in ax.texts]
    note = [t for t in texts if "drawn at true scale" in t and "penetration" in t]
    assert note, texts
    e = np.hypot(new.steps["eccentricity_y_m"], new.steps["eccentricity_z_m"])
    c = new.scene.joint.clearance
    assert f"= {(e.max() - c) / c:.2g} c" in note[0]  # the new loom's joint: 2.8 c (measured)


def test_kinematics_plots_the_transmission_angle(tmp_path, capsys):
    import matplotlib.image

    assert main(["kinematics", "reference", "-o", str(tmp_path / "k")]) == 0
    from weftsim.post.plots import plot_kinematics

    angle = np.linspace(0, 360, 5)
    fig = plot_kinematics(angle, angle, angle, angle, "t", transmission_deg=angle)
    assert fig.axes[-1].get_ylabel() == "transmission angle at F [deg]"
    height = matplotlib.image.imread(tmp_path / "k" / "kinematics.png").shape[0]
    assert height > 1300  # four panels of 2.7 in at 130 dpi (three were 8 in)


def test_a_large_output_is_announced_and_each_file_as_it_is_written(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr("weftsim.cli.commands.LARGE_OUTPUT_BYTES", 1.0)
    out = tmp_path / "r"
    assert main(["run", "reference", "--engine", "reference", "--revolutions", "0.2", "--no-plot", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning: the results will be ~" in err and "of channels.csv" in err
    for name in ("channels.csv", "result.npz", "summary.json"):
        assert f"writing {out / name} ..." in err, err
