"""Scene files: the reference and paper scenes load to the values of docs/physics.md section 1; bad input is named precisely."""

import math
from dataclasses import replace
from pathlib import Path

import pytest

from weftsim.input.params import Scene
from weftsim.input.scene import SCHEMA, SceneError, load_scene, to_file_keys

MODELS = Path(__file__).resolve().parents[1] / "models"
PAPER_CASES = {
    "clearance_0p01mm_400rpm": (0.01e-3, 400.0),
    "clearance_0p25mm_400rpm": (0.25e-3, 400.0),
    "clearance_0p50mm_400rpm": (0.50e-3, 400.0),
    "speed_300rpm_c0p25mm": (0.25e-3, 300.0),
    "speed_500rpm_c0p25mm": (0.25e-3, 500.0),
    "speed_800rpm_c0p25mm": (0.25e-3, 800.0),
}


def _close(a, b):
    # Unit conversions (mm -> m, deg -> rad, rpm -> rad/s) cost a few ulp at most.
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-15)


def test_reference_scene_is_the_spec_reference_mechanism():
    scene = load_scene(MODELS / "reference.toml")
    expected = replace(Scene(), name="reference", source=scene.source)
    for section in ("geometry", "inertia", "joint", "drive", "reference_solver", "exudyn_solver", "output"):
        got, want = getattr(scene, section), getattr(expected, section)
        for name, value in vars(want).items():
            other = getattr(got, name)
            if isinstance(value, float):
                assert _close(other, value), (section, name, other, value)
            elif isinstance(value, tuple):
                assert all(_close(x, y) for x, y in zip(other, value)), (section, name)
            elif not hasattr(value, "__dataclass_fields__"):
                assert other == value, (section, name)


@pytest.mark.parametrize("name", sorted(PAPER_CASES))
def test_paper_scenes_extend_the_reference_and_change_only_their_case(name):
    path = MODELS / "paper" / f"{name}.toml"
    scene = load_scene(path)
    reference = load_scene(MODELS / "reference.toml")
    clearance, rpm = PAPER_CASES[name]
    assert scene.name == name
    assert _close(scene.joint.clearance, clearance)
    assert _close(scene.drive.speed, rpm * math.pi / 30)
    assert scene.geometry == reference.geometry and scene.inertia == reference.inertia
    # The scene file itself is small: it holds only what differs from the reference.
    assert len(path.read_text().splitlines()) < 15


def test_clearance_zero_means_ideal_joint():
    assert load_scene(MODELS / "ideal.toml").joint.is_ideal
    assert load_scene(MODELS / "reference.toml", {"joint_e.clearance_mm": 0.0}).joint.is_ideal


def test_round_trip_through_file_keys(tmp_path):
    scene = load_scene(MODELS / "paper" / "speed_800rpm_c0p25mm.toml")
    keys = to_file_keys(scene)
    assert set(keys) == {"name"} | {k.path for k in SCHEMA}
    lines = []
    for dotted, value in keys.items():
        if dotted == "name" or value is None:  # TOML has no null: an unset optional key is left out
            continue
        lines.append(f"{dotted} = {_toml(value)}")
    (tmp_path / "s.toml").write_text(f'name = "{scene.name}"\n' + "\n".join(lines))
    again = load_scene(tmp_path / "s.toml")
    assert _close(again.drive.speed, scene.drive.speed)
    for section in ("geometry", "inertia", "drive", "output"):
        for field, value in vars(getattr(scene, section)).items():
            other = getattr(getattr(again, section), field)
            assert other == value or _close(other, value), (section, field)


def _toml(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(repr(float(v)) for v in value) + "]"
    return repr(value)


def _write(tmp_path, body: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(f'extends = "{(MODELS / "reference.toml").as_posix()}"\n{body}\n')
    return path


# Each row: scene text added on top of the reference, and words the message must contain
# (the key, the bad value, what is allowed).
BAD_SCENES = [
    ("[joint_e]\nclearance_mm = -0.1", ["joint_e.clearance_mm", "-0.1", ">= 0"]),
    ("[joint_e]\nrestitution = 0.0", ["joint_e.restitution", "0.0", "> 0", "<= 1"]),
    ("[joint_e]\nrestitution = 1.2", ["joint_e.restitution", "1.2"]),
    ("[joint_e.bearing_material]\npoisson_ratio = 0.5", ["poisson_ratio", "0.5", "< 0.5"]),
    ("[joint_e.journal_material]\npoisson_ratio = -0.1", ["poisson_ratio", "-0.1", ">= 0"]),
    ("[drive]\nspeed_rpm = 0", ["drive.speed_rpm", "0", ">= 1"]),
    ("[drive]\nspeed_rpm = -400", ["drive.speed_rpm", "-400"]),
    ("[drive]\nspeed_rpm = nan", ["drive.speed_rpm", "nan", "finite"]),
    ("[drive]\nspeed_rpm = \"fast\"", ["drive.speed_rpm", "'fast'", "number"]),
    ("[drive]\nspeed_rpm = true", ["drive.speed_rpm", "True", "number"]),
    ("[mechanism]\nl_oe_mm = 0", ["mechanism.l_oe_mm", "> 0"]),
    ("[mechanism]\nl_ef_mm = -270", ["mechanism.l_ef_mm", "-270"]),
    ("[mechanism]\nfourbar_branch = \"up\"", ["mechanism.fourbar_branch", "'up'", "'+'", "'-'"]),
    ("[mechanism]\nl_ef_mm = 100", ["cannot be assembled", "crank angle", "deg"]),
    ("[inertia]\ncoupler_inertia_kg_m2 = [1e-3, 1e-3]", ["coupler_inertia_kg_m2", "list of 3"]),
    ("[joint_e]\nlaw = \"hertz_magic\"", ["joint_e.law", "hertz_magic", "variable_kd", "lankarani_nikravesh"]),
    ("[joint_e]\nclearence_mm = 0.1", ["unknown key", "joint_e.clearence_mm", "joint_e.clearance_mm"]),
    ("[joints]\nclearance_mm = 0.1", ["unknown key", "joints.clearance_mm"]),
    ("[joint_e]\nclearance_mm = 12.0", ["joint_e.clearance_mm", "12"]),
    ("[joint_e]\nfriction_velocities_m_s = [2e-4, 1e-4]", ["friction_velocities_m_s", "v0 < v1"]),
    ("[solver.reference]\nmethod = \"Euler\"", ["solver.reference.method", "'Euler'", "DOP853"]),
    ("[solver.exudyn]\nspectral_radius = 1.5", ["solver.exudyn.spectral_radius", "1.5", "<= 1"]),
    ("[solver.exudyn]\nnewton_max_iterations = 2.5", ["newton_max_iterations", "whole number"]),
    ("[output]\nsample_deg = 1.0", ["output.sample_deg", "<= 0.5"]),
]


@pytest.mark.parametrize("body, words", BAD_SCENES, ids=[b.split("\n")[-1] for b, _ in BAD_SCENES])
def test_bad_scene_is_one_clear_error(tmp_path, body, words):
    path = _write(tmp_path, body)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert str(path) in message
    for word in words:
        assert word in message, (word, message)


def test_missing_file_and_not_toml(tmp_path):
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("this is = = not toml")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(bad)
    with pytest.raises(SceneError, match="is a directory"):
        load_scene(tmp_path)


def test_extends_loop_is_reported(tmp_path):
    (tmp_path / "a.toml").write_text('extends = "b.toml"\n')
    (tmp_path / "b.toml").write_text('extends = "a.toml"\n')
    with pytest.raises(SceneError, match="loops back"):
        load_scene(tmp_path / "a.toml")


def test_error_names_the_file_that_holds_the_bad_key(tmp_path):
    parent = tmp_path / "parent.toml"
    parent.write_text(f'extends = "{(MODELS / "reference.toml").as_posix()}"\n[drive]\nspeed_rpm = -5\n')
    child = tmp_path / "child.toml"
    child.write_text('extends = "parent.toml"\n')
    with pytest.raises(SceneError) as info:
        load_scene(child)
    assert str(parent) in str(info.value)


def test_command_line_override_errors_say_so():
    with pytest.raises(SceneError) as info:
        load_scene(MODELS / "reference.toml", {"joint_e.clearance_mm": -1.0})
    assert "command line" in str(info.value) and "joint_e.clearance_mm" in str(info.value)
