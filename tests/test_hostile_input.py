"""Hostile input to scenes, overrides and the Python interface (issue 35): every numeric key bounded and a
value past its bound refused naming the key, the budgets of a run named when they stop it, the TOML list
form and numpy numbers as overrides, the parameter classes raising WeftsimErrors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import weftsim
from weftsim.errors import SceneError, WeftsimError
from weftsim.input.params import ClearanceJoint, Lubrication
from weftsim.input.scene import SCHEMA, load_scene
from weftsim.sweep.grid import parse_set

NUMERIC = [k for k in SCHEMA if k.kind in ("float", "int", "floats2", "floats3")]
# Joint F's and the lubrication tables' keys need the table's joint loose (and oiled) to mean anything.
CONTEXT = {"joint_f.": {"joint_f.clearance_mm": 0.1}, "joint_e.lubrication.": {"joint_e.lubrication.viscosity_mpa_s": 80.0},
           "joint_f.lubrication.": {"joint_f.clearance_mm": 0.1, "joint_f.lubrication.viscosity_mpa_s": 80.0}}


def _context(path: str) -> dict:
    out = {}
    for prefix, keys in CONTEXT.items():
        if path.startswith(prefix):
            out.update(keys)
    return {k: v for k, v in out.items() if k != path}


@pytest.mark.parametrize("key", NUMERIC, ids=lambda k: k.path)
def test_every_numeric_key_is_bounded_and_a_value_past_it_names_the_key(key):
    """The class of "allowed but absurd" values (viscosity 1e300, atol 1e-20): every numeric key of the schema
    has a lower and an upper bound, and 10x past the upper one is refused in one line naming the key and its
    range, before any run."""
    assert key.low is not None and key.high is not None, f"{key.path} is unbounded"
    beyond = key.high * 10 if key.high > 0 else key.high + 10
    value = int(beyond) if key.kind == "int" else beyond
    if key.kind in ("floats2", "floats3"):
        value = [0.5 * key.high, beyond] if key.kind == "floats2" else [beyond] * 3
    with pytest.raises(SceneError) as err:
        load_scene("reference", {**_context(key.path), key.path: value})
    text = str(err.value)
    assert key.path in text and key.allowed() in text and "\n" not in text, text


def _below(key) -> float:
    """A value just past the key's lower bound: the bound itself where it is excluded, else a tenth of a
    positive bound (1e-9 rpm against >= 1), one below a zero or negative one."""
    if key.low_open:
        return key.low
    return key.low / 10 if key.low > 0 else key.low - 1


@pytest.mark.parametrize("key", NUMERIC, ids=lambda k: k.path)
def test_every_numeric_key_refuses_a_value_below_its_bound_naming_the_key(key):
    """The lower side of the same class (issue 35: --speed-rpm 1e-9 hung without a progress line, atol 1e-20
    collapsed the first step): a value past the lower bound is refused in one line naming the key and its
    range, before any run."""
    value = _below(key)
    if key.kind == "int":
        value = math.floor(value) if not key.low_open else int(key.low)
    if key.kind in ("floats2", "floats3"):
        value = [value, 0.5 * key.high] if key.kind == "floats2" else [value] * 3
    with pytest.raises(SceneError) as err:
        load_scene("reference", {**_context(key.path), key.path: value})
    text = str(err.value)
    assert key.path in text and key.allowed() in text and "\n" not in text, text


@pytest.mark.parametrize("key, value", [("solver.reference.atol", 1e-20), ("solver.reference.rtol", 1e-20),
                                        ("solver.exudyn.local_error_m", 1e-20),
                                        ("joint_e.lubrication.viscosity_mpa_s", 1e300),
                                        ("drive.speed_rpm", 1e-9)])
def test_the_absurd_values_of_the_issue_are_refused_naming_the_key(key, value):
    """--speed-rpm 1e-9 ran 120 s without reaching the first 1 % of its progress (issue 35): the crank
    speed is bounded below (drive.speed_rpm >= 1), refused before the run like atol 1e-20 and 1e300 mPa s."""
    with pytest.raises(SceneError, match=key.replace(".", r"\.")):
        load_scene("reference", {key: value})


def test_the_command_line_refuses_a_crank_that_would_not_turn(tmp_path, capsys):
    """The issue's own command line: one line naming the key and its bound, exit 2, nothing written."""
    from weftsim.cli.commands import main

    out = tmp_path / "slow"
    assert main(["run", "reference", "--speed-rpm", "1e-9", "--revolutions", "0.01", "-o", str(out)]) == 2
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(lines) == 1 and "drive.speed_rpm" in lines[0] and ">= 1" in lines[0], lines
    assert not out.exists()


@pytest.mark.parametrize("key, value, words", [
    ("limits.max_steps", 1, ["limits.max_steps = 1"]),
    ("limits.min_step_s", 1e-4, ["limits.min_step_s = 0.0001"]),
])
def test_a_budget_that_stops_the_run_is_named_not_blamed_on_the_materials(key, value, words):
    """A step budget or step floor that stops the compiled reference engine is reported as that budget: the
    guard took the -inf of a step out of contact for a non-finite penetration and said 'non-finite ... check
    the materials'."""
    scene = load_scene("reference", {key: value, "drive.revolutions": 0.2})
    result = weftsim.simulate(scene, "reference", on_warning=lambda text: None)
    assert result.status == "failed"
    assert "non-finite" not in result.message and "materials" not in result.message, result.message
    for word in words:
        assert word in result.message, result.message


@pytest.mark.parametrize("text, key, value", [
    ("inertia.coupler_inertia_kg_m2=[1e-3,2e-3,1e-3]", "inertia.coupler_inertia_kg_m2", [1e-3, 2e-3, 1e-3]),
    ("joint_e.friction_velocities_m_s=[1e-4, 2e-4]", "joint_e.friction_velocities_m_s", [1e-4, 2e-4]),
    ("friction_velocities_m_s=1e-4,2e-4", "joint_e.friction_velocities_m_s", [1e-4, 2e-4]),
])
def test_a_list_key_takes_the_toml_form_a_scene_file_writes(text, key, value):
    assert parse_set(text) == (key, value)


@pytest.mark.parametrize("number", [np.float64(0.3), np.float32(0.3), np.array(0.3)], ids=type)
def test_a_numpy_number_is_an_override_like_any_other(number):
    scene = load_scene("reference", {"joint_e.clearance_mm": number})
    assert scene.joint.clearance == pytest.approx(0.3e-3, rel=1e-7)  # float32: 7 digits
    vector = load_scene("reference", {"inertia.coupler_inertia_kg_m2": np.array([1e-3, 2e-3, 1e-3])})
    assert vector.inertia.coupler_inertia == pytest.approx((1e-3, 2e-3, 1e-3))


@pytest.mark.parametrize("make", [
    lambda: Lubrication(viscosity=-1.0),
    lambda: Lubrication(viscosity=0.08, model="bogus"),
    lambda: Lubrication(viscosity=math.nan),
    lambda: ClearanceJoint(clearance=math.nan, law="variable_kd"),
], ids=["viscosity -1", "model bogus", "viscosity nan", "clearance nan"])
def test_the_parameter_classes_raise_weftsim_errors(make):
    with pytest.raises(WeftsimError) as err:
        make()
    assert isinstance(err.value, ValueError) and "\n" not in str(err.value)  # still a ValueError for old code


@pytest.mark.parametrize("call, kind", [
    (lambda: weftsim.load_scene("reference", overrides=[1, 2]), "overrides must be a mapping"),
    (lambda: weftsim.simulate(weftsim.load_scene("ideal", revolutions=0.05), "reference").to_pandas("sample"),
     "which must be 'samples' or 'steps'"),
])
def test_a_wrong_argument_of_the_interface_is_a_weftsim_error(call, kind):
    with pytest.raises(WeftsimError, match=kind):
        call()
