"""The command line: outputs with units in their names, one-line errors with non-zero exit."""

import csv
import math
import subprocess
import sys
from pathlib import Path

import pytest

from weftsim.cli import EXIT_USAGE, main

MODELS = Path(__file__).resolve().parents[1] / "models"


def run_cli(*args):
    """Run the real console entry point in a subprocess (so argparse exits and stderr are real)."""
    return subprocess.run([sys.executable, "-m", "weftsim.cli", *map(str, args)], capture_output=True, text=True)


def test_help_lists_the_commands():
    done = run_cli("--help")
    assert done.returncode == 0
    for command in ("kinematics", "run", "compare"):
        assert command in done.stdout


def test_kinematics_writes_csv_with_units_and_reproduces_spec(tmp_path):
    assert main(["kinematics", str(MODELS / "reference.toml"), "-o", str(tmp_path)]) == 0
    with open(tmp_path / "kinematics.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0])[:4] == ["crank_angle_deg", "rapier_displacement_m", "rapier_velocity_m_s",
                                 "rapier_acceleration_m_s2"]
    s = [float(r["rapier_displacement_m"]) for r in rows]
    v = [float(r["rapier_velocity_m_s"]) for r in rows]
    # docs/physics.md section 1: stroke 1.052348 m at 180 deg (on the grid: 180 deg is a grid point, so exact to 7 digits).
    assert max(s) == pytest.approx(1.052348, abs=5e-7)
    assert float(rows[s.index(max(s))]["crank_angle_deg"]) == 180.0
    # Velocity extrema fall between 0.5 deg samples; the flat top keeps the grid value within 1e-4 relative.
    assert max(v) == pytest.approx(21.754, rel=1e-4)
    assert (tmp_path / "kinematics.png").stat().st_size > 10_000


def test_speed_override_scales_velocity(tmp_path):
    main(["kinematics", str(MODELS / "reference.toml"), "-o", str(tmp_path), "--speed-rpm", "800"])
    with open(tmp_path / "kinematics.csv") as f:
        vmax = max(float(r["rapier_velocity_m_s"]) for r in csv.DictReader(f))
    # Ideal kinematics: velocity is proportional to crank speed.
    assert vmax == pytest.approx(2 * 21.754, rel=1e-4)


@pytest.mark.parametrize(
    "args, words",
    [
        (["kinematics", "no/such/scene.toml"], ["not found"]),
        (["kinematics", MODELS / "reference.toml", "--speed-rpm", "-5"], ["--speed-rpm", "> 0"]),
        (["kinematics", MODELS / "reference.toml", "--speed-rpm", "abc"], ["--speed-rpm", "number"]),
        (["run", MODELS / "reference.toml", "--clearance-mm", "-1"], ["--clearance-mm", ">= 0"]),
        (["run", MODELS / "reference.toml", "--law", "magic"], ["joint_e.law", "magic", "variable_kd"]),
        (["run", MODELS / "reference.toml", "--engine", "adams"], ["--engine", "adams"]),
        (["kinematics", MODELS / "reference.toml", "-o", "/proc/forbidden"], ["output directory"]),
    ],
)
def test_bad_input_is_one_line_on_stderr(args, words, tmp_path):
    done = run_cli(*args)
    assert done.returncode == EXIT_USAGE
    assert "Traceback" not in done.stderr
    for word in words:
        assert word in done.stderr, (word, done.stderr)
    assert len(done.stderr.strip().splitlines()) == 1


def test_output_path_that_is_a_file_is_refused(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    done = run_cli("kinematics", MODELS / "reference.toml", "-o", blocker)
    assert done.returncode == EXIT_USAGE and "not a directory" in done.stderr
    assert blocker.read_text() == "x"
