"""``weftsim animate --viewer`` (weftsim.exudyn_engine.viewer): refused in one line where no window can open,
and the solution file it writes for Exudyn's viewer holds the motion of the rigid-body model: one row per
output sample, every ODE2 coordinate, the crank at omega t, the pin F closed, and for the ideal joint the
sector at the closed-form angle of docs/physics.md section 1.  No test opens a window."""

import numpy as np
import pytest
from exudyn import ConfigurationType
from exudyn.utilities import LoadSolutionFile

from weftsim.cli.commands import EXIT_USAGE, main
from weftsim.exudyn_engine.mechanism import CRANK_COORDINATE, ROTATION_2D
from weftsim.exudyn_engine.viewer import (
    SUPPRESS_VARIABLE,
    ViewerUnavailable,
    display_problem,
    expected_rows,
    record_solution,
    show_solution,
)
from weftsim.mechanism.kinematics import linkage_state
from weftsim.input.scene import load_scene

# The solution file stores 10 significant digits (Exudyn's solution.precision default): ~1e-10 rad on the
# crank angle (< 2 pi).  Measured: crank angle vs omega t within 6.4e-10 rad over a quarter revolution (the
# velocity-level drive integrated by generalized-alpha plus the rounding); the ideal joint's sector angle vs
# the closed form within 1.5e-10 rad (its position constraints hold to Newton's tolerance).  1e-8 rad sits
# 15x above both and far below a one-row shift of the grid (0.5 deg of crank = 8.7e-3 rad).
ANGLE_RAD = 1e-8
# The ideal revolute at F holds to Newton's tolerance; the stored coordinates round to 10 digits of the
# 0.22 m positions, ~1e-11 m; measured 2.2e-12 m over 0.1 revolution with c = 0.25 mm.  1e-8 m is far
# above that and far below the 0.25 mm clearance at E that a wrong coordinate index would mix in.
CLOSURE_M = 1e-8


def no_display(monkeypatch):
    for name in ("DISPLAY", "WAYLAND_DISPLAY", SUPPRESS_VARIABLE):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr("sys.platform", "linux")


@pytest.mark.parametrize("environ, platform, expected", [
    ({}, "linux", "needs a display"),
    ({"DISPLAY": ":0"}, "linux", None),
    ({"WAYLAND_DISPLAY": "wayland-0"}, "linux", None),
    ({}, "darwin", None),
    ({}, "win32", None),
    ({"DISPLAY": ":0", SUPPRESS_VARIABLE: "1"}, "linux", "suppressed"),
    ({"DISPLAY": ":0", SUPPRESS_VARIABLE: "0"}, "linux", None),
])
def test_display_problem_names_what_is_missing(environ, platform, expected):
    problem = display_problem(environ, platform)
    if expected is None:
        assert problem is None
    else:
        assert expected in problem and "writes a GIF instead" in problem and "\n" not in problem


def test_viewer_without_display_is_one_line_and_computes_nothing(monkeypatch, tmp_path, capsys):
    no_display(monkeypatch)
    target = tmp_path / "solution.txt"
    assert main(["animate", "reference", "--viewer", "-o", str(target)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "needs a display" in err and "weftsim animate SCENE" in err
    assert not target.exists()  # refused before the solve


def test_viewer_refuses_the_reference_engine(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("DISPLAY", ":0")
    assert main(["animate", "reference", "--viewer", "--engine", "reference", "-o", str(tmp_path / "s.txt")]) \
        == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "replays an Exudyn run" in err


def rows_of(recording):
    """(time, crank angle, sector angle, rod coordinates x, y, angle) per row of the recording's file."""
    solution = LoadSolutionFile(str(recording.path), verbose=False)
    mbs, nodes = recording.mbs, recording.model.nodes
    reference = mbs.systemData.GetODE2Coordinates(configuration=ConfigurationType.Reference)
    assert solution["columnsExported"][0] == recording.coordinates == len(reference)
    data = solution["data"]
    assert data.shape == (recording.rows, 1 + recording.coordinates)
    q = data[:, 1:] + np.asarray(reference)  # the file stores displacements from the reference configuration

    def column(node, coordinate):
        return q[:, mbs.GetNodeODE2Index(nodes[node]) + coordinate]

    rod = mbs.GetNodeODE2Index(nodes["rod"])
    return data[:, 0], column("crank", CRANK_COORDINATE), column("sector", ROTATION_2D), q[:, rod:rod + 3]


def check_grid_and_drive(recording, scene, time, crank):
    assert recording.rows == expected_rows(scene) == round(scene.drive.revolutions * 720) + 1  # 0.5 deg samples
    period = scene.output.sample_angle / scene.drive.speed
    assert np.abs(time - period * np.arange(recording.rows)).max() < 1e-3 * period  # samples on the grid
    assert np.abs(crank - scene.drive.speed * time).max() < ANGLE_RAD  # the drive: theta = omega t


def test_ideal_joint_recording_follows_the_closed_form(tmp_path):
    scene = load_scene("reference", {"drive.revolutions": 0.25, "joint_e.clearance_mm": 0.0})
    recording = record_solution(scene, tmp_path / "ideal.txt")
    time, crank, sector, _ = rows_of(recording)
    check_grid_and_drive(recording, scene, time, crank)
    state = linkage_state(scene.drive.speed * time, scene.geometry, scene.inertia.rocker_com)
    assert np.abs(sector - state.theta_fg).max() < ANGLE_RAD


def test_clearance_recording_keeps_the_pin_f_closed(tmp_path):
    scene = load_scene("reference", {"drive.revolutions": 0.1})  # c = 0.25 mm at E, ~1 s of solve
    recording = record_solution(scene, tmp_path / "clearance.txt")
    time, crank, sector, rod = rows_of(recording)
    check_grid_and_drive(recording, scene, time, crank)
    g = scene.geometry
    # F seen from the rod (its centre + L_EF/2 along it) and from the sector (G + L_FG along it).
    f_rod = rod[:, :2] + 0.5 * g.l_ef * np.column_stack([np.cos(rod[:, 2]), np.sin(rod[:, 2])])
    f_sector = np.column_stack([g.l_og + g.l_fg * np.cos(sector), g.l_fg * np.sin(sector)])
    assert np.abs(f_rod - f_sector).max() < CLOSURE_M
    # The journal moves in its clearance: the sector leaves the ideal joint's angle by more than the round-off
    # (measured 1.1e-2 rad in the first 36 deg, the start-up fall of the journal through the clearance).
    ideal = linkage_state(scene.drive.speed * time, g, scene.inertia.rocker_com).theta_fg
    assert np.abs(sector - ideal).max() > 1e3 * ANGLE_RAD


def test_show_solution_refuses_without_display(monkeypatch, tmp_path):
    no_display(monkeypatch)
    scene = load_scene("reference", {"drive.revolutions": 0.05, "joint_e.clearance_mm": 0.0})
    recording = record_solution(scene, tmp_path / "s.txt")
    with pytest.raises(ViewerUnavailable, match="needs a display"):
        show_solution(recording)
    assert recording.rows == expected_rows(scene)  # the recording itself stands
