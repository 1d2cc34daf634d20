"""Output directories describe themselves and one scene's results never silently replace another's (issue 25).

Every command records in its directory the full resolved scene and the command line (manifest
``resolved_scene`` and ``command``, and ``scene.toml``, a scene file that loads back to the same scene);
a directory holding the results of another scene is refused before anything runs, naming the keys that
differ, ``-o`` and ``--force``.
"""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import pytest

import weftsim
from weftsim.cli import commands as cli
from weftsim.errors import EngineError, OutputError
from weftsim.post.output import MANIFEST, prepare_directory
from weftsim.post.record import check_same_scene, differences, resolved_scene, scene_toml
from weftsim.input.scene import load_scene, to_file_keys
from weftsim.studies import common

MODELS = Path(__file__).resolve().parents[1] / "models"
SHORT = ("--revolutions", "0.05")  # 18 deg of crank: files and checks, not physics


def main(capsys, *args) -> tuple[int, str, str]:
    status = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


def same(a, b) -> bool:
    """Two scenes equal in every field but the file they were read from."""
    return dataclasses.replace(a, source="") == dataclasses.replace(b, source="")


def manifest(directory: Path) -> dict:
    return json.loads((directory / MANIFEST).read_text())


@pytest.mark.parametrize("name, overrides", [
    ("reference", {}),
    ("loom", {"joint_e.clearance_mm": 0.1, "drive.speed_rpm": 750.0, "joint_e.restitution": 0.8}),
    ("clearance_ef", {}),
])  # fmt: skip
def test_scene_toml_loads_back_to_the_same_scene(tmp_path, name, overrides):
    scene = load_scene(name, overrides)
    path = tmp_path / "scene.toml"
    path.write_text(scene_toml(scene))
    again = load_scene(path)
    assert to_file_keys(again) == to_file_keys(scene)
    assert same(again, scene)  # every field, SI units: the file is the scene


def test_differences_name_each_changed_key_old_and_new():
    a = resolved_scene(load_scene("reference"))
    b = resolved_scene(load_scene("reference", {"joint_e.clearance_mm": 0.5, "drive.speed_rpm": 600}))
    assert differences(a, b) == ["drive.speed_rpm 400.0 -> 600.0", "joint_e.clearance_mm 0.25 -> 0.5"]
    assert differences(a, a) == []


def test_runs_with_other_settings_go_to_their_own_directory(tmp_path, capsys, monkeypatch):
    """The issue's case: the defaults, then --clearance-mm 0.5 --speed-rpm 600.  The second run's directory
    is named after its overrides; the first run's files are untouched."""
    monkeypatch.chdir(tmp_path)
    status, out, err = main(capsys, "run", "reference", "--engine", "reference", "--no-plot")
    assert status == 0, err
    first = Path("out", "reference", "reference")  # relative, as the command names it
    before = {p.name: p.read_bytes() for p in first.iterdir()}
    record = manifest(first)
    assert record["command"] == "weftsim run reference --engine reference --no-plot"
    assert record["resolved_scene"]["joint_e.clearance_mm"] == 0.25
    assert "scene.toml" in record["files"] and f"wrote {first / 'scene.toml'}" in out

    status, out, err = main(capsys, "run", "reference", "--engine", "reference", "--no-plot",
                            "--clearance-mm", "0.5", "--speed-rpm", "600")
    assert status == 0, err
    second = Path("out", "reference-c0.5mm-600rpm", "reference")
    assert f"wrote {second / 'summary.json'}" in out
    assert {p.name: p.read_bytes() for p in first.iterdir()} == before
    assert same(load_scene(second / "scene.toml"),
                load_scene("reference", {"joint_e.clearance_mm": 0.5, "drive.speed_rpm": 600}))
    # Other keys (--set) are told apart by a digest of their values.
    status, out, err = main(capsys, "run", "reference", "--engine", "reference", "--no-plot", "--revolutions", "0.05",
                            "--set", "restitution=0.8")
    assert status == 0, err
    assert re.search(r"wrote out/reference-0\.05rev-set[0-9a-f]{8}/reference/summary\.json", out), out


def test_an_edited_scene_file_is_refused_in_its_old_directory_and_force_replaces(tmp_path, capsys, monkeypatch):
    """A scene file changed between two runs writes to the same default directory: refused before the run,
    naming the key; the same scene again replaces its own results; --force replaces the other's."""
    monkeypatch.chdir(tmp_path)
    scene = tmp_path / "mine.toml"
    scene.write_text('extends = "%s"\nname = "mine"\n\n[drive]\nrevolutions = 0.05\n' % (MODELS / "reference.toml"))
    args = ("run", scene, "--engine", "reference", "--no-plot")
    status, _, err = main(capsys, *args)
    assert status == 0, err
    target = Path("out", "mine", "reference")
    before = (target / "summary.json").read_text()
    status, _, err = main(capsys, *args)
    assert status == 0, err  # the same scene again
    scene.write_text(scene.read_text() + "\n[joint_e]\nclearance_mm = 0.5\n")
    status, out, err = main(capsys, *args)
    assert status == 2 and out == ""  # nothing ran
    assert err.strip().splitlines() == [
        f"weftsim run: error: {target} holds the results of another scene (joint_e.clearance_mm 0.25 -> 0.5); "
        "choose another directory with -o, or pass --force to replace them"]
    assert json.loads((target / "summary.json").read_text())["scene"] == json.loads(before)["scene"]
    status, _, err = main(capsys, *args, "--force")
    assert status == 0, err
    assert json.loads((target / "summary.json").read_text())["scene"]["joint_e.clearance_mm"] == 0.5


@pytest.mark.parametrize("command", [
    ("compare", "reference"),
    ("kinematics", "reference"),
    ("wear", "reference", "--hours", "1"),
    ("animate", "reference", "--engine", "reference", "--frames", "4"),
    ("run", "reference", "--engine", "exudyn"),
])  # fmt: skip
def test_every_command_refuses_a_directory_of_another_scene(tmp_path, capsys, command):
    """A directory written by a run of the reference scene at 0.05 revolutions: every command with the
    reference at 500 rpm refuses it (before solving), in one line naming the key, -o and --force."""
    target = tmp_path / "d"
    status, _, err = main(capsys, "run", "reference", "--engine", "reference", *SHORT, "--no-plot", "-o", target)
    assert status == 0, err
    before = sorted(p.name for p in target.iterdir())
    where = ("-o", target / "animation.gif") if command[0] == "animate" else ("-o", target)
    status, out, err = main(capsys, *command, "--speed-rpm", "500", *where)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "holds the results of another scene (" in lines[0]
    assert "drive.speed_rpm 400.0 -> 500.0" in lines[0]
    assert "-o" in lines[0] and "--force" in lines[0]
    assert sorted(p.name for p in target.iterdir()) == before


def test_prepare_directory_refuses_another_scene_and_force_passes(tmp_path):
    scene = load_scene("reference")
    result = weftsim.simulate(load_scene("reference", {"drive.revolutions": 0.05}), "reference")
    from weftsim.post.output import write_run

    write_run(result, tmp_path, figure=False)
    other = load_scene("reference", {"drive.revolutions": 0.05, "joint_e.law": "flores"})
    with pytest.raises(OutputError, match="joint_e.law"):
        prepare_directory(tmp_path, scene=other)
    prepare_directory(tmp_path, force=True, scene=other)
    check_same_scene(tmp_path, result.scene)  # its own scene passes
    with pytest.raises(OutputError, match=r"\(drive.revolutions 0.05 -> 2.0\)"):
        check_same_scene(tmp_path, scene)


def test_a_study_records_its_scene_overrides_and_command_and_says_what_it_wrote(tmp_path, capsys):
    out = tmp_path / "study"
    status, stdout, err = main(capsys, "study", "engines", "reference", *SHORT, "--set", "restitution=0.8", "-o", out)
    assert status == 0, err
    report = json.loads((out / "engines.json").read_text())
    assert report["base_scene"] == "reference"
    assert report["overrides"] == {"joint_e.restitution": 0.8, "drive.revolutions": 0.05}
    assert report["command"] == f"weftsim study engines reference --revolutions 0.05 --set restitution=0.8 -o {out}"
    record = manifest(out)
    assert record["resolved_scene"]["joint_e.restitution"] == 0.8
    assert record["command"] == report["command"]
    assert same(load_scene(out / "scene.toml"), load_scene("reference", {"joint_e.restitution": 0.8,
                                                                         "drive.revolutions": 0.05}))
    wrote = [line for line in stdout.splitlines() if line.startswith("  wrote ")]
    assert set(wrote) == {f"  wrote {out / name}" for name in record["files"]}
    # Another restitution into the same directory: refused before a run.
    status, _, err = main(capsys, "study", "engines", *SHORT, "--set", "restitution=0.5", "-o", out)
    assert status == 2 and "joint_e.restitution 0.8 -> 0.5" in err and "--force" in err


def test_a_study_runs_its_cases_on_the_scene_given():
    """``weftsim study clearance loom``: each case is the loom with the keys the case file sets itself (the
    clearance), the loom's speed kept; without a scene the paper's case files run unchanged."""
    case = "paper/clearance_0p50mm_400rpm.toml"
    assert common.own_keys(MODELS / case) == {"joint_e.clearance_mm": 0.5}
    on_loom = common.load(MODELS, case, {"drive.revolutions": 2.0}, "loom")
    loom = load_scene("loom")
    assert on_loom.joint.clearance == pytest.approx(0.5e-3)
    assert on_loom.drive.speed == loom.drive.speed and on_loom.geometry == loom.geometry
    assert on_loom.name == "loom_c0.5mm"
    assert common.load(MODELS, "ideal.toml", None, "loom").joint.is_ideal
    assert same(common.load(MODELS, case), load_scene(MODELS / case))  # the default: the paper's file as it is
    speed_case = common.load(MODELS, "paper/speed_800rpm_c0p25mm.toml", None, "loom")
    assert speed_case.drive.speed * 30 / 3.141592653589793 == pytest.approx(800.0)
    assert speed_case.joint.clearance == loom.joint.clearance


def test_study_figure_titles_name_the_scene_and_overrides():
    reference, loom = load_scene("reference"), load_scene("loom")
    assert common.title_note(reference, {"drive.revolutions": 10.0}) == ""
    assert common.title_note(reference, {"mechanism.l_oe_mm": 125.0}) == "\n(scene reference; mechanism.l_oe_mm = 125)"
    assert common.title_note(loom, {}) == "\n(scene loom)"


def test_simulate_suggests_the_engine_meant():
    with pytest.raises(EngineError, match=r"got 'exudin'; did you mean exudyn\?"):
        weftsim.simulate("reference", "exudin")
    with pytest.raises(EngineError) as caught:
        weftsim.simulate("reference", "matlab")
    assert "did you mean" not in str(caught.value)


def test_animate_names_the_revolution_and_crank_angles_it_draws(tmp_path, capsys):
    target = tmp_path / "a.gif"
    status, out, err = main(capsys, "animate", "reference", "--engine", "reference", "--revolutions", "2",
                            "--frames", "6", "-o", target)
    assert status == 0, err
    assert f"wrote {target}: 6 frames of revolution 2, crank angles 0.0..300.0 deg" in out
    # A single file written anywhere (-o): it records its own resolved scene and command in its metadata, and
    # that text is a scene file that loads back to the scene animated.
    from PIL import Image

    with Image.open(target) as gif:
        recorded = gif.info["comment"].decode("utf-8")
    assert "weftsim animate reference --engine reference --revolutions 2" in recorded.splitlines()[0]
    path = tmp_path / "recorded.toml"
    path.write_text(recorded)
    assert resolved_scene(load_scene(path)) == resolved_scene(load_scene("reference", {"drive.revolutions": 2}))
