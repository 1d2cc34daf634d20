"""Hostile input, round three (issue 24): silent wrong answers and unclear errors of sweep, compare,
animate, wear and the clearance at F.  Each test is one row of the issue or of the further round;
runs are short (a tenth to a third of a revolution) so the file adds seconds, not minutes."""

from __future__ import annotations

import ast
import dataclasses as dc
import json
import math
from pathlib import Path

import numpy as np
import pytest

from weftsim.cli.commands import main
from weftsim.errors import SceneError, SweepError, WearError
from weftsim.input.scene import load_scene
from conftest import door

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
REFERENCE = MODELS / "reference.toml"
CLEARANCE_F = MODELS / "clearance_f.toml"


def run(capsys, *args) -> tuple[int, str, str]:
    """The command line in this process: (exit status, stdout, stderr)."""
    status = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


# --- joint F given a clearance on its own -------------------------------------------------------


def test_joint_f_clearance_alone_takes_the_pin_law_and_materials_of_e(tmp_path):
    scene = load_scene(REFERENCE, {"joint_f.clearance_mm": 0.25, "joint_e.journal_radius_mm": 6.0,
                                   "joint_e.restitution": 0.7, "joint_f.law": "flores"})
    f, e = scene.joint_f, scene.joint
    assert f.clearance == pytest.approx(0.25e-3) and not f.is_ideal
    assert f.journal_radius == e.journal_radius == pytest.approx(6e-3)  # E's pin, as overridden
    assert f.restitution == e.restitution == 0.7
    assert (f.bearing_length, f.journal_material, f.bearing_material, f.friction_velocities) == \
        (e.bearing_length, e.journal_material, e.bearing_material, e.friction_velocities)
    assert f.law == "flores" and e.law == "variable_kd"  # told otherwise: F's own
    assert "law" not in scene.joint_f_inherits and "journal_radius_mm" in scene.joint_f_inherits
    # The same from a file: [joint_f] with clearance_mm alone.
    path = tmp_path / "f.toml"
    path.write_text(f'extends = "{REFERENCE.as_posix()}"\n[joint_e]\nbearing_length_mm = 15.0\n'
                    "[joint_f]\nclearance_mm = 0.1\n")
    from_file = load_scene(path)
    assert from_file.joint_f.bearing_length == pytest.approx(15e-3) and from_file.loose_joints == ("e", "f")


def test_run_with_a_clearance_at_f_alone_says_what_f_took(capsys, tmp_path):
    status, out, err = run(capsys, "run", "reference", "--set", "joint_f.clearance_mm=0.25", "--engine", "reference",
                           "--revolutions", 0.05, "-o", tmp_path / "r")
    assert status == 0, err
    note = [line for line in err.splitlines() if "joint F (clearance 0.25 mm) takes" in line]
    assert len(note) == 1 and "journal_radius_mm" in note[0] and "joint_f.<key>" in note[0]
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["scene"]["joint_f.journal_radius_mm"] == summary["scene"]["joint_e.journal_radius_mm"]


def test_sweep_cells_move_f_with_e_where_f_takes_e_keys():
    from weftsim.sweep import plan_sweep

    plan = plan_sweep(REFERENCE, ["joint_e.journal_radius_mm=5,8"], ["joint_f.clearance_mm=0.25"])
    radii = [(plan.scene(c).joint.journal_radius, plan.scene(c).joint_f.journal_radius) for c in plan.cells]
    assert radii == [(5.0 * 1e-3,) * 2, (8.0 * 1e-3,) * 2]
    assert plan.notes and "joint F (clearance 0.25 mm)" in plan.notes[0]
    told = plan_sweep(REFERENCE, ["joint_e.journal_radius_mm=5,8"],
                      ["joint_f.clearance_mm=0.25", "joint_f.journal_radius_mm=9"])
    assert {told.scene(c).joint_f.journal_radius for c in told.cells} == {9.0 * 1e-3}  # as the scene converts mm


def test_list_valued_keys_are_settable(capsys, tmp_path):
    from weftsim.sweep.grid import parse_set

    assert parse_set("joint_e.friction_velocities_m_s=1e-4,3e-4") == ("joint_e.friction_velocities_m_s", [1e-4, 3e-4])
    assert parse_set("coupler_inertia_kg_m2=1e-3, 2e-3, 3e-3")[1] == [1e-3, 2e-3, 3e-3]
    with pytest.raises(SweepError, match="takes a list of 2 numbers"):
        parse_set("joint_e.friction_velocities_m_s=1e-4")
    with pytest.raises(SweepError, match="--set joint_e.friction_velocities_m_s=X,X"):
        from weftsim.sweep.grid import parse_vary
        parse_vary("joint_e.friction_velocities_m_s=1e-4,2e-4")
    status, _, err = run(capsys, "run", "reference", "--set", "joint_e.friction_velocities_m_s=2e-4,1e-4",
                         "--revolutions", 0.05, "-o", tmp_path / "x")
    assert status == 2 and "must have v0 < v1" in err and len(err.strip().splitlines()) == 1


# --- keys of an ideal joint: run --set and sweep --vary say the same ------------------------------


@pytest.mark.parametrize("scene, key, values", [
    ("reference", "joint_f.restitution", "0.5,0.9"),  # the row: F ideal in the reference scene
    ("reference", "joint_f.law", "flores,hertz"),
    ("clearance_f", "joint_e.restitution", "0.5,0.9"),  # further round: E ideal at clearance_f
    ("clearance_f", "joint_e.friction_coefficient", "0.1,0.2"),
    ("ideal", "joint_e.journal_radius_mm", "5,8"),
])
def test_a_key_of_an_ideal_joint_is_refused_alike_by_run_and_sweep(capsys, tmp_path, scene, key, values):
    first = values.split(",")[0]
    status_run, _, err_run = run(capsys, "run", scene, "--set", f"{key}={first}", "--revolutions", 0.05,
                                 "-o", tmp_path / "run")
    status_sweep, _, err_sweep = run(capsys, "sweep", scene, "--vary", f"{key}={values}", "--revolutions", 0.05,
                                     "-o", tmp_path / "sweep")
    assert status_run == status_sweep == 2
    message = f"key '{key}' describes the clearance joint at"
    for err in (err_run, err_sweep):
        assert message in err and "is ideal in this scene" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "sweep").exists() and not (tmp_path / "run").exists()


@pytest.mark.parametrize("command", [["run", "reference", "--set"], ["sweep", "reference", "--vary"]])
def test_a_wear_key_outside_weftsim_wear_is_refused(capsys, tmp_path, command):
    """Further round: [joint_e.wear] keys change nothing a run computes; a sweep of them made identical cells."""
    value = "1e-7,1e-6" if command[0] == "sweep" else "1e-6"
    status, _, err = run(capsys, *command, f"joint_e.wear.wear_coefficient={value}", "--revolutions", 0.05,
                         "-o", tmp_path / "x")
    assert status == 2 and "is read by `weftsim wear` only" in err and len(err.strip().splitlines()) == 1


def test_a_wear_limit_beyond_the_journal_radius_is_refused(capsys, tmp_path):
    status, _, err = run(capsys, "wear", "reference", "--hours", 1, "--limit-clearance-mm", 100, "-o", tmp_path / "w")
    assert status == 2 and "must be smaller than the journal radius 10 mm" in err


def test_a_key_that_matters_in_some_cells_of_a_sweep_is_kept():
    from weftsim.sweep import plan_sweep

    plan = plan_sweep(REFERENCE, ["joint_f.clearance_mm=0,0.25"], ["joint_f.restitution=0.5"])
    assert len(plan.cells) == 2
    with pytest.raises(SceneError, match="joint F is ideal"):  # the API's overrides: as --set
        load_scene(REFERENCE, {"joint_f.restitution": 0.5})


# --- sweep tables and figures carry each clearance joint -----------------------------------------


def test_sweep_of_the_clearance_at_f_tabulates_f(tmp_path):
    pytest.importorskip("xarray")
    from weftsim.api import load_sweep
    from weftsim.sweep import plan_sweep, run_sweep
    from weftsim.sweep.store import read_table

    plan = plan_sweep(CLEARANCE_F, ["joint_f.clearance_mm=0.1,0.25"], ["revolutions=0.1"], "reference")
    report = run_sweep(plan, tmp_path, jobs=1, progress=False)
    assert (report.succeeded, report.failed) == (2, 0)
    rows = {float(r["joint_f.clearance_mm"]): r for r in read_table(tmp_path / "sweep.csv")}
    for row in rows.values():
        assert row["contact_force_N_rev1_peak"] == ""  # E is ideal: no contact force, not 0
        assert float(row["contact_force_f_N_rev1_peak"]) > 1e3
    # Paper Fig. 12, at F: the larger clearance hits harder (the issue measured 168 and 238 kN).
    assert float(rows[0.25]["contact_force_f_N_rev1_peak"]) > float(rows[0.1]["contact_force_f_N_rev1_peak"])
    grid = load_sweep(tmp_path)
    assert np.all(grid["contact_force_f_N_rev1_peak"].values > 1e3)
    assert np.all(np.isnan(grid["contact_force_N_rev1_peak"].values))


def test_sweep_figure_draws_a_panel_per_clearance_joint():
    from weftsim.sweep.plots import plot_sweep, shown_channels

    def row(value, e, f):
        return {"clearance_mm": value, "status": "success", "last_revolution": 1,
                "driving_torque_Nm_rev1_peak": 1.0, "rapier_acceleration_m_s2_rev1_peak": 2.0,
                "contact_force_N_rev1_peak": e, "contact_force_f_N_rev1_peak": f}

    only_f = [row(0.1, None, 1e5), row(0.25, None, 2e5)]
    assert shown_channels(only_f) == ("driving_torque_Nm", "rapier_acceleration_m_s2", "contact_force_f_N")
    both = [row(0.1, 1e5, 1e5), row(0.25, 2e5, 2e5)]
    assert len(shown_channels(both)) == 4
    figure = plot_sweep(only_f, ["clearance_mm"])
    labels = [ax.get_ylabel() for ax in figure.axes]
    assert "peak contact force at F [kN]" in labels and "peak contact force at E [kN]" not in labels


# --- compare: say what was compared ---------------------------------------------------------------


def test_compare_of_less_than_a_revolution_is_partial_not_an_agreement(capsys, tmp_path):
    status, out, err = run(capsys, "compare", "reference", "--revolutions", 0.2, "-o", tmp_path / "c")
    assert status == 5, err
    assert "AGREE" not in out and "comparison PARTIAL" in out and "not compared: first-revolution maxima" in out
    assert "partial comparison" in err and "--revolutions 1" in err
    report = json.loads((tmp_path / "c" / "compare.json").read_text())
    assert report["status"] == "partial" and report["agree"] is False
    assert [c["name"] for c in report["checks"]] == ["first contact crank angle [deg]"]
    assert {m["core"] for m in report["not_compared"]} == {True, False}


# --- animate: the clearance at F --------------------------------------------------------------------


def test_animation_of_a_clearance_at_f_draws_and_captions_f():
    from weftsim import reference
    from weftsim.post.animate import animation_figure, joint_caption, mechanism_frames

    result = door("reference")(load_scene(CLEARANCE_F, {"drive.revolutions": 0.3}))
    frames = mechanism_frames(result, 12)
    assert frames.clearance == 0.0 and frames.clearance_f == pytest.approx(0.25e-3)
    assert np.hypot(*frames.eccentricity_f.T).max() > 0.5 * frames.clearance_f  # the pin moves in its eye
    # The rod is drawn to the rod's pin at F, P_jF = F + e_F: its length closes to round-off
    # (to the sector's eye F it would be off by up to c).
    assert np.abs(frames.rod_length - result.scene.geometry.l_ef).max() < 1e-9
    caption = joint_caption(frames, 50.0)
    assert caption == "c = 0.25 mm at F (E ideal), drawn x50" and "ideal joint at E" not in caption
    figure, draw, moving = animation_figure(result, frames)
    texts = [a.get_text() for a in moving if hasattr(a, "get_text")]
    assert any("clearance at F" in t for t in texts) and any("journal at F" in t for t in texts)


def test_orbit_figure_has_a_panel_per_clearance_joint(tmp_path):
    """Further round: orbit.png showed joint E alone (and nothing for a clearance at F alone)."""
    from weftsim import reference
    from weftsim.post.output import write_run
    from weftsim.post.plots import plot_orbit

    only_f = door("reference")(load_scene(CLEARANCE_F, {"drive.revolutions": 0.3}))
    figure = plot_orbit(only_f)
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert len(panels) == 1 and "orbit at F" in panels[0].get_title()
    orbit = panels[0].lines[1]  # the rod's pin in the sector's eye, every solver step, in mm
    assert np.array_equal(orbit.get_xdata(), only_f.steps["eccentricity_f_y_m"] * 1e3)
    assert "orbit" in write_run(only_f, tmp_path / "f")
    both = door("reference")(load_scene(MODELS / "clearance_ef.toml", {"drive.revolutions": 0.3}))
    titles = [ax.get_title() for ax in plot_orbit(both).axes if ax.get_title()]
    assert ["orbit at E" in titles[0], "orbit at F" in titles[1]] == [True, True]


# --- wear: geometric limits, bad inputs, failures mid-way, interrupts ------------------------------


def test_wear_ends_at_the_geometric_limits():
    from weftsim.wear.extrapolate import MAX_WALL_SLOPE, geometric_limit

    scene = load_scene(REFERENCE, {"joint_e.journal_radius_mm": 1.0, "joint_e.clearance_mm": 0.25})
    n = scene.joint.wear.profile_points
    flat = np.full(n, 0.2e-3)  # uniform wear: a round, larger clearance (no slope)
    assert geometric_limit(scene, flat, flat) is None  # c_eff = 0.65 mm < 1 mm
    worn_through = geometric_limit(scene, flat, np.full(n, 0.6e-3))  # c_eff = 1.05 mm: the row
    assert worn_through is not None and "journal radius 1 mm" in worn_through
    psi = np.arange(n) * 2 * math.pi / n
    amplitude = 1.2 * MAX_WALL_SLOPE * scene.joint.journal_radius / 4  # h = A (1 + cos 4 psi): slope 4 A / R
    lobes = amplitude * (1.0 + np.cos(4 * psi))  # 1.2 x the limit, depth 0.06 mm: within the radius
    assert "slope" in geometric_limit(scene, np.zeros(n), lobes)
    assert geometric_limit(scene, np.zeros(n), lobes / 1.5) is None


def test_wear_prediction_stops_at_the_limit_and_resumes_to_the_same_end(tmp_path):
    """Wear fast enough to leave the small-wear geometry within a few updates: the prediction ends at
    the limit with every update written; asking again adds nothing."""
    from weftsim.wear import predict_to_directory
    from weftsim.wear.extrapolate import MAX_WALL_SLOPE, advance, wall_slope

    scene = load_scene(REFERENCE, {"joint_e.journal_radius_mm": 3.0, "joint_e.wear.wear_coefficient": 1e-4,
                                   "joint_e.wear.max_clearance_change": 0.1})
    data = predict_to_directory(scene, 1e5, tmp_path, figures=False)
    assert data["ended"] is not None and "slope" in data["ended"] and not data["complete"]
    assert 0.0 < data["hours_reached"] < 1e5
    from weftsim.wear.store import load_state

    updates = load_state(tmp_path, scene)
    *_, bearing, journal = advance(updates[-1], scene)
    slope = max(wall_slope(bearing, scene.joint.bearing_radius), wall_slope(journal, scene.joint.journal_radius))
    assert slope == pytest.approx(MAX_WALL_SLOPE, rel=1e-6)  # extrapolated up to the limit, not beyond
    table = np.genfromtxt(tmp_path / "wear.csv", delimiter=",", names=True)
    assert table["hours"].size == len(updates)
    again = predict_to_directory(scene, 1e5, tmp_path, figures=False)
    assert again["updates"] == data["updates"] and again["hours_reached"] == data["hours_reached"]


@pytest.mark.parametrize("key, value, allowed", [
    ("joint_e.wear.wear_coefficient", 0.9, "<= 0.01"),
    ("joint_e.wear.bearing_hardness_mpa", 1e-310, ">= 1"),
    ("joint_e.wear.journal_hardness_mpa", 1e9, "<= 100000"),
    ("joint_e.wear.profile_points", 8, ">= 180"),  # further round: 8-120 points broke the worn contact
])
def test_wear_inputs_beyond_physics_are_refused_up_front(capsys, tmp_path, key, value, allowed):
    status, _, err = run(capsys, "wear", "reference", "--set", f"{key}={value}", "--hours", 1, "-o", tmp_path / "w")
    assert status == 2 and key in err and allowed in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "w").exists()


def test_wear_hours_beyond_any_machine_are_refused(capsys, tmp_path):
    status, _, err = run(capsys, "wear", "reference", "--hours", "1e308", "-o", tmp_path / "w")
    assert status == 2 and "--hours must be > 0 and at most 1e+06 h" in err


def test_wear_too_fast_to_extrapolate_says_so(capsys, tmp_path):
    status, _, err = run(capsys, "wear", "reference", "--set", "joint_e.wear.wear_coefficient=1e-2",
                         "--set", "joint_e.wear.bearing_hardness_mpa=1", "--hours", 10, "-o", tmp_path / "w")
    assert status == 3 and "too fast to extrapolate" in err and "joint_e.wear.max_clearance_change" in err
    assert "energy balance" not in err and "rerun" not in err


def test_a_wear_update_failing_mid_way_keeps_every_update_before_it(tmp_path, monkeypatch):
    from weftsim.wear import extrapolate, predict_to_directory

    real, calls = extrapolate.simulate_update, []

    def failing_third(scene, bearing, journal):
        calls.append(1)
        if len(calls) == 3:
            raise WearError("the simulation on the worn geometry failed: (made to fail by the test)")
        return real(scene, bearing, journal)

    monkeypatch.setattr(extrapolate, "simulate_update", failing_third)
    with pytest.raises(WearError) as error:
        predict_to_directory(load_scene(REFERENCE), 100.0, tmp_path, figures=False)
    assert "the 2 updates before it" in str(error.value) and "wear.csv" in str(error.value)
    table = np.genfromtxt(tmp_path / "wear.csv", delimiter=",", names=True)
    assert table["hours"].size == 2 and table["hours"][1] > 0.0
    data = json.loads((tmp_path / "wear.json").read_text())
    assert data["updates"] == 2 and "made to fail" in data["failure"] and not data["complete"]


def test_a_stop_during_a_wear_update_is_an_interruption_not_a_failure(capsys, tmp_path, monkeypatch):
    from weftsim.checks.guards import clear_stop, request_stop
    from weftsim.wear import extrapolate

    scene = load_scene(REFERENCE)
    try:  # a stop asked for after the first update: the second update's run ends as interrupted
        updates = extrapolate.predict(scene, 100.0, on_update=lambda done: request_stop("stopped by the user (test)"))
    finally:
        clear_stop()
    assert len(updates) == 1  # the interrupted update is dropped; no WearError "simulation failed"

    def interrupted(*args):
        raise extrapolate.WearInterrupted("stopped by the user (Ctrl-C, SIGINT)")

    monkeypatch.setattr(extrapolate, "simulate_update", interrupted)  # Ctrl-C during the first update
    status, _, err = run(capsys, "wear", "reference", "--hours", 1, "-o", tmp_path / "w", "--no-plot")
    assert status == 130 and "interrupted" in err and "failed" not in err


# --- messages name scene keys, not Python settings ---------------------------------------------------


def test_no_message_names_a_python_setting_instead_of_a_scene_key():
    """Every string of the package that is not a docstring: ``exudyn_solver.model`` is the Python
    attribute, ``solver.exudyn.model`` the key a user can set (issue 24)."""
    found = []
    for path in (ROOT / "weftsim").rglob("*.py"):
        tree = ast.parse(path.read_text())
        docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                      if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef))
                      and node.body and isinstance(node.body[0], ast.Expr)
                      and isinstance(node.body[0].value, ast.Constant)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
                if any(f"{name}." in node.value for name in ("exudyn_solver", "reference_solver")) \
                        and " " in node.value:  # a sentence, not an attribute path in code
                    found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value[:70]}")
    assert not found, found


def test_the_exudyn_model_message_names_the_scene_key(capsys, tmp_path):
    status, _, err = run(capsys, "run", "clearance_f", "--engine", "exudyn", "--set",
                         "solver.exudyn.model=kinematic_tree", "--revolutions", 0.05, "-o", tmp_path / "x")
    assert status in (2, 3) and "solver.exudyn.model" in err and "exudyn_solver" not in err


def test_a_law_range_warning_names_the_scene_key_once(capsys, tmp_path):
    """Further round: the Exudyn engine also printed the reusable joint's Python warning (a file path and
    `restitution`) beside the scene's own line naming joint_f.restitution."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:  # pytest would otherwise keep them from stderr
        warnings.simplefilter("always")
        status, _, err = run(capsys, "run", "clearance_f", "--set", "joint_f.restitution=0.3", "--engine", "exudyn",
                             "--revolutions", 0.05, "-o", tmp_path / "x")
    assert status == 0, err
    assert "joint_f.restitution = 0.3 is outside" in err
    assert not [w for w in caught if "restitution" in str(w.message)], [str(w.message) for w in caught]


def test_ctrl_c_during_wear_exits_130_saying_interrupted(tmp_path):
    """The issue's row through the real command line: SIGINT while the updates run."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "w"
    process = subprocess.Popen([sys.executable, "-m", "weftsim.cli", "wear", str(REFERENCE), "--hours", "10000",
                                "-o", str(out), "--no-plot"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for _ in range(600):  # until the first update is stored (a few seconds; the CI machine may be slower)
        if (out / "wear_state.npz").exists():
            break
        time.sleep(0.1)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "interrupted" in err and "simulation failed" not in err and "Traceback" not in err
    assert (out / "wear.csv").exists()
