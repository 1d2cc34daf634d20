"""The weft exchange (weftsim.model.exchange, docs/rapier-tape.md section 7): the giver and taker heads at mid-shed.

Checked where the answer is known: with ideal joints on both sides the heads are the ideal mechanism's (errors zero
to round-off, the overlap the closed value 2 s_i(theta) - G); a loose giver's error is the one its journal's
eccentricity gives through the linkage's loop closure; the taker interpolation is exact for cubics; the table's
keys are refused in one line; absent or off, nothing changes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from weftsim.api import load_scene, simulate
from weftsim.errors import SceneError
from weftsim.mechanism.kinematics import linkage_state
from weftsim.model.channels import EXCHANGE_CHANNELS
from weftsim.model.exchange import gap, hermite, taker_source
from weftsim.post.analysis import summary

# 0.6 revolutions hold the first transfer window (the dead centre at 180 deg, the window 162-198 deg at 600 rpm).
SHORT = {"drive.revolutions": 0.6, "drive.speed_rpm": 600.0}
# Round-off of the ideal head position (m): the ideal engine's rapier displacement against linkage_state, measured
# 1.1e-15 m on a 1.24 m stroke (overlap 2.2e-15); 1e-12 is far above it and far below any clearance's effect.
ROUND_OFF_M = 1e-12


def _run(scene_name: str, keys: dict, engine: str = "reference"):
    return simulate(load_scene(scene_name, {**SHORT, **keys}), engine, on_warning=lambda text: None)


@pytest.fixture(scope="module")
def ideal():
    return _run("loom", {"joint_e.clearance_mm": 0.0, "exchange.taker_clearance_mm": 0.0})


@pytest.fixture(scope="module")
def worn():
    """A worn giver (c = 0.25 mm) against an ideal taker (the closed form), the rigid rapier."""
    return _run("loom", {"joint_e.clearance_mm": 0.25, "exchange.taker_clearance_mm": 0.0})


def test_ideal_joints_on_both_sides_give_the_ideal_mechanisms_exchange(ideal):
    assert ideal.ok, ideal.message
    steps = ideal.steps
    for name in ("giver_head_error_m", "taker_head_error_m"):
        assert np.max(np.abs(steps[name])) < ROUND_OFF_M
    s_i = linkage_state(np.radians(steps["crank_angle_deg"]), ideal.scene.geometry).rapier_displacement
    stroke = float(linkage_state(math.pi, ideal.scene.geometry).rapier_displacement)
    closed = 2.0 * s_i - (2.0 * stroke - 0.050)  # the default overlap, 50 mm
    assert np.max(np.abs(steps["exchange_overlap_m"] - closed)) < ROUND_OFF_M
    block = summary(ideal)["exchange"]
    assert block["head"] == "rapier tip" and block["taker"] == "giver"
    (first,) = block["transfers"]
    assert first["dead_centre_crank_deg"] == 180.0
    assert abs(first["overlap_max_m"] - 0.050) < ROUND_OFF_M
    assert abs(first["overlap_at_dead_centre_m"] - 0.050) < ROUND_OFF_M
    # The window is where the ideal heads overlap: the overlap is 0 at its edges.
    low, high = np.radians(first["window_crank_deg"])
    for edge in (low, high):
        reach = 2.0 * float(linkage_state(edge, ideal.scene.geometry).rapier_displacement)
        assert abs(reach - gap(ideal.scene)) < 1e-12
    assert abs(first["relative_speed_at_dead_centre_m_s"]) < 1e-9  # 2 v_i(pi) = 0: measured 7.9e-15 m/s


def _head_from_eccentricity(scene, theta, e_y, e_z):
    """The rigid rapier's s with the rod's end at the rocker's E plus the eccentricity (the loop closure of the
    four-bar with E moved: F on its circle about G at L_EF from the journal's centre)."""
    g = scene.geometry
    ideal = linkage_state(theta, g)
    journal_y, journal_z = ideal.point_e[..., 0] + e_y, ideal.point_e[..., 1] + e_z
    a, b = g.l_og - journal_y, -journal_z
    dist = np.hypot(a, b)
    fg = np.arctan2(b, a) + g.fourbar_branch * np.arccos((g.l_ef ** 2 - dist ** 2 - g.l_fg ** 2) / (2 * g.l_fg * dist))
    fg0 = linkage_state(0.0, g).theta_fg
    return g.rapier_ratio * (fg - fg0)


def test_a_worn_giver_errs_as_its_journals_eccentricity_moves_the_head(worn):
    assert worn.ok, worn.message
    assert taker_source(worn.scene) == "ideal"
    steps = worn.steps
    theta = np.radians(steps["crank_angle_deg"])
    s_i = linkage_state(theta, worn.scene.geometry).rapier_displacement
    # The error is the head position channel less the ideal mechanism ...
    assert np.array_equal(steps["giver_head_error_m"], steps["rapier_displacement_m"] - s_i)
    # ... and the loop closure with the journal where its eccentricity puts it gives the same head: measured to
    # 3e-13 m of a 1.45 mm error (the chain's closure in the kernel is exact to round-off).
    predicted = _head_from_eccentricity(worn.scene, theta, steps["eccentricity_y_m"], steps["eccentricity_z_m"]) - s_i
    assert np.max(np.abs(steps["giver_head_error_m"] - predicted)) < 1e-9
    (first,) = summary(worn)["exchange"]["transfers"]
    # Nonzero, beyond the clearance itself (measured 5.8 mm of head per mm of clearance: the gear train's
    # d5 d7 / (d6 L_FG) = 4.9 and the rod's transmission angle), and
    # the head runs further into the shed (the decelerating rapier pulls the journal to the bearing's far side).
    assert first["giver_error_at_dead_centre_m"] > 0.25e-3
    assert first["taker_error_min_m"] == first["taker_error_max_m"] == 0.0
    assert first["overlap_at_dead_centre_m"] == pytest.approx(0.050 + first["giver_error_at_dead_centre_m"], abs=1e-12)


def test_the_taker_is_a_second_run_with_its_own_clearance_and_a_symmetric_one_is_the_giver(worn):
    """A taker with the giver's clearance is the giver's run (no second run); the same clearance run as a second run
    of the taker's scene gives the same head: the interpolation onto the giver's steps is exact at shared times."""
    twin = _run("loom", {"joint_e.clearance_mm": 0.25, "exchange.enabled": True})
    assert twin.ok and taker_source(twin.scene) == "giver" and "taker_steps" not in twin.solver_stats
    assert np.array_equal(twin.steps["taker_head_error_m"], twin.steps["giver_head_error_m"])
    assert np.array_equal(twin.steps["rapier_displacement_m"], worn.steps["rapier_displacement_m"])  # giver as before
    other = _run("loom", {"joint_e.clearance_mm": 0.25, "exchange.taker_clearance_mm": 0.1})
    assert other.ok and taker_source(other.scene) == "run" and other.solver_stats["taker_steps"] > 0
    taker = simulate(load_scene("loom", {**SHORT, "joint_e.clearance_mm": 0.1}), "reference",
                     on_warning=lambda text: None)
    # The output grids of the two runs are the same crank angles: the taker's samples there are its own run's.
    assert np.array_equal(other.samples["taker_head_displacement_m"], taker.samples["rapier_displacement_m"])


def test_hermite_interpolation_is_exact_for_a_cubic_and_nan_outside():
    nodes = np.array([0.0, 0.3, 0.35, 1.0, 1.0, 2.0])  # a repeated node (an event's two rows) is allowed
    s, v = 1.0 - 2.0 * nodes + 0.5 * nodes ** 3, -2.0 + 1.5 * nodes ** 2
    t = np.linspace(-0.5, 2.5, 301)
    got_s, got_v = hermite(t, nodes, s, v)
    inside = (t >= 0.0) & (t <= 2.0)
    assert np.max(np.abs(got_s[inside] - (1.0 - 2.0 * t[inside] + 0.5 * t[inside] ** 3))) < 1e-14
    assert np.max(np.abs(got_v[inside] - (-2.0 + 1.5 * t[inside] ** 2))) < 1e-13
    assert np.all(np.isnan(got_s[~inside]))


def test_the_tape_head_is_the_giver_head():
    """With the flexible tape the giver's head is the tape's head (0.01 revolutions, 2 Ritz functions: the tape's
    run costs ~45 s a revolution, so no whole transfer window; the window's summary is the rigid rapier's code)."""
    tape = _run("loom_tape", {"exchange.enabled": True, "drive.revolutions": 0.01, "rapier_tape.modes": 2})
    assert tape.ok, tape.message
    steps = tape.steps
    s_i = linkage_state(np.radians(steps["crank_angle_deg"]), tape.scene.geometry).rapier_displacement
    assert np.array_equal(steps["giver_head_error_m"], steps["head_displacement_m"] - s_i)
    assert not np.array_equal(steps["head_displacement_m"], steps["rapier_displacement_m"])  # the tape stretches
    block = summary(tape)["exchange"]
    assert block["head"] == "tape head" and block["transfers"] == []


def test_no_exchange_table_or_an_exchange_that_is_off_changes_nothing(ideal):
    plain = _run("loom", {"joint_e.clearance_mm": 0.1})
    off = _run("loom", {"joint_e.clearance_mm": 0.1, "exchange.enabled": False, "exchange.overlap_mm": 80.0})
    on = _run("loom", {"joint_e.clearance_mm": 0.1, "exchange.taker_clearance_mm": 0.0})
    assert plain.scene.exchange is None and summary(plain)["exchange"] is None and summary(off)["exchange"] is None
    assert tuple(plain.steps) == tuple(off.steps) and not set(EXCHANGE_CHANNELS) & set(plain.steps)
    for name in plain.steps:
        assert np.array_equal(plain.steps[name], off.steps[name]) and np.array_equal(plain.steps[name], on.steps[name])


def test_an_exchange_result_file_reads_back(worn, tmp_path):
    from weftsim.post.result_file import read_npz
    from weftsim.post.results import save_npz

    back = read_npz(save_npz(worn, tmp_path / "result.npz"))
    for name in EXCHANGE_CHANNELS:
        assert np.array_equal(back.steps[name], worn.steps[name])


@pytest.mark.parametrize("keys, words", [
    ({"exchange.overlap_mm": 5000.0}, "'exchange.overlap_mm' must be smaller than twice the stroke"),
    ({"exchange.overlap_mm": 0.0}, "'exchange.overlap_mm' must be > 0"),
    ({"exchange.taker_clearance_mm": -0.1}, "'exchange.taker_clearance_mm' must be >= 0"),
    ({"exchange.taker_clearance_mm": 15.0}, "'exchange.taker_clearance_mm' must be smaller than the journal radius"),
    ({"exchange.window_deg": 400.0}, "'exchange.window_deg' must be > 0 and <= 360"),
    ({"exchange.enabled": "yes"}, "'exchange.enabled' must be true or false"),
    ({"exchange.taker": 1.0}, "unknown key 'exchange.taker'"),
    ({"exchange.taker_clearance_mm": 0.0, "rapier_tape.model": "flexible"}, "the flexible rapier tape cannot run"),
])
def test_bad_exchange_keys_are_one_line(keys, words):
    with pytest.raises(SceneError) as caught:
        load_scene("loom", keys)
    assert words in str(caught.value) and "\n" not in str(caught.value)


def test_the_exchange_study_runs_its_cells_on_the_sweep(tmp_path, monkeypatch):
    """One cell of the study (600 rpm, a worn giver at c = 0.25 mm) through the sweep: its taker is the loom's own
    new joint (c = 0.02 mm), run in the cell, as a run of that joint alone gives it."""
    from weftsim.studies import StudyError, exchange, run_study

    with pytest.raises(StudyError, match="sets joint_e.clearance_mm itself"):
        run_study("exchange", tmp_path / "no", overrides={"joint_e.clearance_mm": 0.1})
    monkeypatch.setattr(exchange, "SPEEDS_RPM", (600.0,))
    monkeypatch.setattr(exchange, "CLEARANCES_MM", (0.25,))
    report = run_study("exchange", tmp_path / "study", revolutions=0.56, progress=False, scene="loom")
    for name in report["files"] + ["cells"]:
        assert (tmp_path / "study" / name).exists(), name
    (worn,) = report["rows"]
    assert worn["transfer"] == 1 and report["taker_clearance_mm"] == 0.02 and report["cells_failed"] == 0
    new = _run("loom", {"exchange.enabled": True, "drive.revolutions": 0.56})
    (first,) = summary(new)["exchange"]["transfers"]
    # The cell's taker is the new joint's run, interpolated onto the worn giver's steps: measured to 5e-11 m.
    assert worn["taker_error_at_dead_centre_m"] == pytest.approx(first["giver_error_at_dead_centre_m"], abs=1e-9)
    assert worn["giver_error_at_dead_centre_m"] > 10 * first["giver_error_at_dead_centre_m"] > 0


def test_both_engines_give_the_worn_givers_exchange(worn):
    """The Exudyn engine on the worn giver's scene (its own run; the ideal taker the closed form): the overlap and
    the giver's error at the dead centre agree with the reference engine's.  Measured at 600 rpm, 2 revolutions:
    overlap 51.5812 / 51.5799 mm (2.5e-5), error 1.45222 / 1.45087 mm (9e-4); 1e-2 of the error is ten times that
    (the issue asks 1 % of the overlap)."""
    exudyn = simulate(worn.scene, "exudyn", on_warning=lambda text: None)
    assert exudyn.ok, exudyn.message
    (ours,), (theirs,) = summary(worn)["exchange"]["transfers"], summary(exudyn)["exchange"]["transfers"]
    error = ours["giver_error_at_dead_centre_m"]
    assert theirs["giver_error_at_dead_centre_m"] == pytest.approx(error, rel=1e-2)
    assert theirs["overlap_at_dead_centre_m"] == pytest.approx(ours["overlap_at_dead_centre_m"], abs=1e-2 * error)
