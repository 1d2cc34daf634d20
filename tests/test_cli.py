"""The command line: outputs with units in their names, one-line errors with non-zero exit."""

import argparse
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from weftsim.cli.commands import EXIT_USAGE, main

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


# --- one grammar: bundled scenes, --set and the shorthands, outputs per engine ----------------------------


def test_scenes_lists_the_bundled_scenes_with_their_descriptions():
    done = run_cli("scenes")
    assert done.returncode == 0, done.stderr
    lines = {line.split()[0]: line for line in done.stdout.splitlines()[1:]}
    assert "reference" in lines and "paper/clearance_0p50mm_400rpm" in lines
    assert "Reference weft insertion mechanism, c = 0.25 mm at E, 400 rpm" in lines["reference"]
    assert "c = 0.50 mm at E, 400 rpm" in lines["paper/clearance_0p50mm_400rpm"]
    assert "Rapier loom, 190 cm reed, 600 rpm" in lines["loom"]


def test_runs_of_the_two_engines_go_to_their_own_directories(tmp_path):
    """From a directory without models/: the bundled scene by name, results under out/<scene>/<engine>/."""
    run = ["run", "paper/clearance_0p50mm_400rpm", "--revolutions", "0.25", "--no-plot",
           "--set", "joint_e.restitution=0.8"]
    first = subprocess.run([sys.executable, "-m", "weftsim.cli", *run, "--engine", "reference"], cwd=tmp_path,
                           capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    # Overrides on the command line: the scene's directory is named after them (issue 25).
    from weftsim.cli.grammar import overrides_tag

    name = "clearance_0p50mm_400rpm-" + overrides_tag({"drive.revolutions": 0.25, "joint_e.restitution": 0.8})
    assert name.startswith("clearance_0p50mm_400rpm-0.25rev-set")
    reference = tmp_path / "out" / name / "reference"
    kept = {name: (reference / name).read_bytes() for name in ("channels.csv", "summary.json", "result.npz")}
    second = subprocess.run([sys.executable, "-m", "weftsim.cli", *run], cwd=tmp_path, capture_output=True, text=True)
    assert second.returncode == 0, second.stderr
    assert "engine exudyn" in second.stdout.splitlines()[0]  # --engine auto is the Exudyn engine
    exudyn = tmp_path / "out" / name / "exudyn"
    assert (exudyn / "channels.csv").exists() and (exudyn / "result.npz").exists()
    assert {name: (reference / name).read_bytes() for name in kept} == kept  # the first run is untouched
    summary = json.loads((exudyn / "summary.json").read_text())
    assert summary["scene"]["joint_e.restitution"] == 0.8 and summary["scene"]["joint_e.clearance_mm"] == 0.5
    import weftsim

    loaded = weftsim.load_result(reference / "result.npz")  # the NPZ beside the CSV is the whole run
    with open(reference / "channels.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == loaded.samples["time_s"].size
    # channels.csv holds the same samples as '%.10g': at most 5e-10 relative apart (abs for a value near 0).
    assert float(rows[-1]["rapier_displacement_m"]) == pytest.approx(loaded.samples["rapier_displacement_m"][-1],
                                                                      rel=1e-9, abs=1e-15)


def test_default_output_directories_are_under_the_scene_name(tmp_path):
    done = subprocess.run([sys.executable, "-m", "weftsim.cli", "kinematics", "reference"], cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "reference" / "kinematics" / "kinematics.csv").exists()
    for command, default in (("run", "out/<scene name>/<engine>"), ("compare", "out/<scene name>/compare"),
                             ("kinematics", "out/<scene name>/kinematics"),
                             ("sweep", "out/<scene name>/sweep-<engine>")):
        text = " ".join(run_cli(command, "--help").stdout.split())
        assert f"(default: {default})" in text, (command, text)


@pytest.mark.parametrize("args, words", [
    (["run", "reference", "--clearence-mm", "0.5"], ["unrecognized arguments", "did you mean --clearance-mm"]),
    (["compare", "reference", "--speed", "300"], ["did you mean --speed-rpm"]),
    (["rn", "reference"], ["invalid choice: 'rn'", "did you mean run?"]),
    (["run", "reference", "--engine", "exudin"], ["invalid choice: 'exudin'", "did you mean exudyn?"]),
    (["run", "reference", "--set", "clearnce_mm=0.5"], ["unknown scene key 'clearnce_mm'",
                                                       "did you mean clearance_mm"]),
    (["run", "reference", "--set", "joint_e.clearance_mm=0.4", "--clearance-mm", "0.5"],
     ["'joint_e.clearance_mm' is given twice"]),
    (["run", "referense"], ["no bundled scene has that name", "did you mean reference?"]),
    (["sweep", "reference", "--vary", "speed_rpm=300,400", "--revolutions", "1", "--set", "revolutions=2"],
     ["'drive.revolutions' is given twice"]),
])
def test_mistyped_flags_commands_and_keys_get_the_closest_spelling(args, words):
    done = run_cli(*args)
    assert done.returncode == EXIT_USAGE
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    for word in words:
        assert word in done.stderr, (word, done.stderr)


def test_every_scene_command_takes_the_same_flags():
    """--set and the shorthands on every command that loads one scene; kinematics only what it uses."""
    from weftsim.cli.commands import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
    for name in ("run", "compare", "sweep"):
        flags = {flag for action in commands[name]._actions for flag in action.option_strings}
        assert {"--set", "--revolutions", "--speed-rpm", "--clearance-mm", "--law"} <= flags, name
    flags = {flag for action in commands["kinematics"]._actions for flag in action.option_strings}
    assert {"--set", "--speed-rpm"} <= flags and not {"--law", "--clearance-mm", "--revolutions"} & flags


def test_study_and_bench_find_the_bundled_scenes_without_models():
    from weftsim.cli.commands import build_parser, models_directory
    from weftsim.input.scene import bundled_directory

    for argv in (["study", "clearance"], ["bench", "--quick"]):
        args = build_parser().parse_args(argv)
        assert models_directory(args) == bundled_directory()
        assert (models_directory(args) / "paper" / "clearance_0p50mm_400rpm.toml").is_file()
    assert models_directory(build_parser().parse_args(["study", "speed", "--models", "elsewhere"])) == Path("elsewhere")
