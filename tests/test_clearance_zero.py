"""A clearance of 0 set on any scene gives the ideal joint on which both engines agree (issue 11 section 4).

The scenes' Exudyn step (2e-6 s) is chosen to resolve impacts; with the ideal joint the engine takes
0.25 deg of crank instead (weftsim.exudyn_engine.solver.IDEAL_JOINT_STEP_ANGLE), 10x inside the
tolerance on the curves' error against the closed form.  Before, `weftsim compare models/reference.toml
--clearance-mm 0` ran at 2e-6 s and differed on the torque by 8.7e-5 of the peak here (1.05e-4 on
the machine of the issue) against the 1e-4 tolerance: constraint-reaction round-off growing as 1/h^2.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from weftsim import exudyn_engine, reference
from weftsim.post.compare import agreement_checks
from weftsim.exudyn_engine.solver import IDEAL_JOINT_STEP_ANGLE, step_plan
from weftsim.input.scene import load_scene
from conftest import door

MODELS = Path(__file__).resolve().parents[1] / "models"


def test_the_ideal_joint_gets_its_own_step_and_the_clearance_joint_keeps_the_scenes():
    clearance = load_scene(MODELS / "reference.toml")
    ideal = load_scene(MODELS / "reference.toml", {"joint_e.clearance_mm": 0})
    h_clearance, _ = step_plan(clearance)
    h_ideal, _ = step_plan(ideal)
    assert h_clearance <= clearance.exudyn_solver.step_size
    # The step divides the 0.5 deg sample period: exactly 2 steps of 0.25 deg.
    aim = IDEAL_JOINT_STEP_ANGLE / ideal.drive.speed
    assert h_ideal == pytest.approx(aim, rel=1e-12)
    coarse = load_scene(MODELS / "reference.toml", {"joint_e.clearance_mm": 0, "solver.exudyn.step_size_s": 2.5e-4})
    assert step_plan(coarse)[0] > aim  # a longer step asked for is kept
    fixed = load_scene(MODELS / "reference.toml", {"joint_e.clearance_mm": 0, "solver.exudyn.step_control": "fixed"})
    assert step_plan(fixed)[0] == h_clearance  # "fixed" means the scene's step (shortened to divide a sample)


@pytest.mark.parametrize("scene", ["paper/speed_800rpm_c0p25mm.toml", "paper/clearance_0p01mm_400rpm.toml"])
def test_clearance_zero_on_a_paper_scene_agrees_far_inside_the_tolerance(scene):
    """Measured at 0.25 deg steps: 1.0e-5 of the peak (rapier acceleration; torque 4.0e-6) at 400 and
    800 rpm (two revolutions of the reference mechanism; the error depends on the crank angle of the
    step alone).  2e-5 sits 2x above it and 5x below the compare tolerance (1e-4), so the check fails
    if the step falls back to 2e-6 s (8.7e-5) or grows to 0.5 deg (6.3e-5)."""
    ideal = load_scene(MODELS / scene, {"joint_e.clearance_mm": 0})
    ex, ref = door("exudyn")(ideal), door("reference")(ideal)
    assert ex.ok and ref.ok, (ex.message, ref.message)
    checks = agreement_checks(ex, ref)
    assert len(checks) == 2 and all(c["passed"] for c in checks)
    assert max(c["difference"] for c in checks) < 2e-5, checks


def test_the_issues_command_agrees(tmp_path):
    done = subprocess.run([sys.executable, "-m", "weftsim.cli", "compare", MODELS / "reference.toml",
                           "--clearance-mm", "0", "--json", "-o", tmp_path / "out"],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["agree"]
    worst = max(c["difference"] for c in report["checks"])
    assert worst < 2e-5, report["checks"]  # as above: measured 1.0e-5 for this scene (8.7e-5 at the old 2e-6 s)
    assert report["engines"]["exudyn"]["solver"]["step_size_s"] == pytest.approx(
        math.radians(0.25) / (400 * math.pi / 30), rel=1e-12)
