"""``weftsim animate`` and weftsim.post.animate: a valid GIF with the frames asked for, and drawn points that
obey the mechanism's closure (docs/physics.md section 1): the rod EF keeps its length, F stays on the
sector arm's circle, E on the rocker arm's, and for the ideal joint F is the closed-form kinematics' F."""

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from weftsim.post.animate import clearance_magnification, mechanism_frames, write_animation
from weftsim.cli.commands import EXIT_USAGE
from weftsim.mechanism.kinematics import linkage_state
from conftest import door
solve = door("reference")
from weftsim.input.scene import load_scene

REFERENCE = Path(__file__).resolve().parents[1] / "models" / "reference.toml"
# Round-off on a point of the linkage: a few ulps of its link lengths (0.27 m), ~1e-16 m. The rod-length
# residuals measured were at most 6e-17 m (reference engine, Exudyn kinematic tree) and 3e-15 m (Exudyn
# rigid-body model with an ideal joint, whose constraints close to ~1e-14 relative). 1e-12 m sits far
# above that round-off and far below the journal's travel in its clearance (1e-5..1e-4 m), which a
# wrong point would show, and below the 8e-8 m that interpolated output samples miss by.
CLOSURE_M = 1e-12


@pytest.fixture(scope="module")
def clearance_run():
    """One revolution of the reference scene (c = 0.25 mm, 400 rpm) on the reference engine (~0.5 s)."""
    result = solve(load_scene(REFERENCE, {"drive.revolutions": 1}))
    assert result.ok, result.message
    return result


def check_closure(frames, scene):
    g = scene.geometry
    assert np.abs(frames.rod_length - g.l_ef).max() <= CLOSURE_M  # the rod P_j -> F
    assert np.abs(np.hypot(*(frames.point_f - frames.point_g).T) - g.l_fg).max() <= CLOSURE_M  # F on G's circle
    assert np.abs(np.hypot(*frames.bearing.T) - g.l_oe).max() <= CLOSURE_M  # E on O's circle
    assert np.abs(frames.journal - frames.bearing - frames.eccentricity).max() <= CLOSURE_M  # P_j = P_b + e


def test_drawn_points_close_the_linkage_on_the_reference_engine(clearance_run):
    frames = mechanism_frames(clearance_run, 36)
    check_closure(frames, clearance_run.scene)
    # The journal really moves in its clearance: a wrong closure could not hide behind e = 0.
    assert np.hypot(*frames.eccentricity.T).max() > 0.5 * clearance_run.scene.joint.clearance


def test_frames_spread_evenly_over_the_last_revolution(clearance_run):
    frames = mechanism_frames(clearance_run, 36)
    # Each frame is the accepted step nearest to a multiple of 10 deg of crank: the reference engine's
    # largest step is solver.reference.max_step_deg = 0.5 deg, so a frame is within 0.25 deg of it.
    offset = (frames.crank_angle_deg - 10.0 * np.arange(36) + 180.0) % 360.0 - 180.0
    assert np.abs(offset).max() <= 0.25 + 1e-9


def test_ideal_joint_draws_the_closed_form_kinematics():
    """With c = 0 the engine's rapier displacement, turned back into the sector angle, must put F where
    the closed-form kinematics (weftsim.mechanism.kinematics, checked against docs/physics.md section 1) puts it."""
    scene = load_scene(REFERENCE, {"drive.revolutions": 1, "joint_e.clearance_mm": 0.0})
    result = solve(scene)
    frames = mechanism_frames(result, 24)
    check_closure(frames, scene)
    state = linkage_state(scene.drive.speed * frames.time_s, scene.geometry)
    assert np.abs(frames.point_f - state.point_f).max() <= CLOSURE_M
    assert np.abs(frames.bearing - state.point_e).max() <= CLOSURE_M


def test_drawn_points_close_the_linkage_on_the_exudyn_engine():
    """The Exudyn kinematic tree's steps (its output samples are interpolated between steps and
    would miss the closure by ~3e-7 L_EF)."""
    pytest.importorskip("exudyn")
    from conftest import door
    solve_exudyn = door("exudyn")

    scene = load_scene(REFERENCE, {"drive.revolutions": 0.5})
    result = solve_exudyn(scene)
    assert result.ok and result.path["model"] == "kinematic_tree", result.path
    frames = mechanism_frames(result, 18)
    check_closure(frames, scene)


def test_gif_has_the_frames_asked_for(tmp_path, clearance_run):
    target = tmp_path / "loom.gif"
    write_animation(clearance_run, target, frames=10, fps=20)
    with Image.open(target) as gif:
        assert gif.format == "GIF" and gif.n_frames == 10
        assert gif.info["duration"] == 50  # 1000 ms / 20 fps
        size = gif.size
        for k in range(gif.n_frames):
            gif.seek(k)
            assert gif.size == size
    assert [p.name for p in tmp_path.iterdir()] == ["loom.gif"]  # written atomically, nothing left over


def test_clearance_magnification_is_round_and_labelled_size():
    # 8 % of L_EF = 21.6 mm over c = 0.25 mm is 86.4: the round factor below it is 50.
    assert clearance_magnification(0.25e-3, 0.27) == 50.0
    assert clearance_magnification(0.01e-3, 0.27) == 2000.0
    assert clearance_magnification(0.0, 0.27) == 1.0
    for c in (1e-6, 3e-5, 0.25e-3, 5e-3):
        m = clearance_magnification(c, 0.27)
        assert m * c <= 0.08 * 0.27 and round(m / 10 ** math.floor(math.log10(m)), 9) in (1.0, 2.0, 5.0)


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "weftsim.cli", "animate", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, timeout=300)


def test_cli_writes_the_gif(tmp_path):
    target = tmp_path / "sub" / "loom.gif"
    done = cli(REFERENCE, "--engine", "reference", "--revolutions", "1", "--clearance-mm", "0.5", "--frames", "6",
               "-o", target)
    assert done.returncode == 0, done.stderr
    with Image.open(target) as gif:
        assert gif.n_frames == 6
    assert f"wrote {target}: 6 frames" in done.stdout


@pytest.mark.parametrize("name, words", [
    ("loom.avi", "must end in .gif or .mp4"),
    ("loom", "must end in .gif or .mp4"),
])  # fmt: skip
def test_cli_refuses_an_unknown_format_in_one_line(tmp_path, name, words):
    done = cli(REFERENCE, "--engine", "reference", "-o", tmp_path / name)
    assert done.returncode == EXIT_USAGE
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in done.stderr
    assert not any(tmp_path.iterdir())


@pytest.mark.skipif(shutil.which("ffmpeg") is not None, reason="ffmpeg is installed: MP4 is allowed")
def test_cli_refuses_mp4_without_ffmpeg_in_one_line(tmp_path):
    done = cli(REFERENCE, "--engine", "reference", "-o", tmp_path / "loom.mp4")
    assert done.returncode == EXIT_USAGE
    assert done.stderr.strip().splitlines() == [
        f"weftsim animate: error: cannot write '{tmp_path / 'loom.mp4'}': MP4 needs ffmpeg, which is not on PATH; "
        "use a .gif file"]
