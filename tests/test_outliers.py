"""The measures of the contact-outlier study (weftsim.studies.outliers, scripts/contact_outliers.py):
peak ratios and segment bookkeeping on synthetic data, and the onset approach rates on a short real
run, checked against what the engine itself reports."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import door
solve = door("reference")
from weftsim.model.dynamics import ChainConstants, penetration
from weftsim.input.scene import load_scene
from weftsim.studies.common import StudyError
from weftsim.studies.outliers import (
    Cell,
    flores_cells,
    negative_penetration_in_contact,
    onset_rows,
    onsets,
    peak_ratios,
    study_cells,
)
from weftsim.studies.outliers_report import ensemble_ratios, markdown_report, replace_section

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"


def test_peak_ratios_leave_out_the_first_revolution():
    # Revolution 1 (start-up impact) is the largest and must not count; revolution 6 is 4.5x the median 2.
    median, worst, revolution = peak_ratios([10.0, 2.0, 2.2, 1.8, 2.0, 9.0])
    assert median == 2.0
    assert worst == 4.5
    assert revolution == 6
    # A steady run: every later revolution equals the median.
    assert peak_ratios([5.0, 3.0, 3.0, 3.0]) == (3.0, 1.0, 2)
    median, worst, revolution = peak_ratios([5.0])
    assert math.isnan(median) and math.isnan(worst) and revolution == 0


def _row(scene, rtol, peaks, status="success"):
    row = {"scene": scene, "method": "numba_DOP853", "rtol": rtol, "overrides": "", "status": status,
           "revolutions": str(len(peaks)), "steps": "1", "wall_time_s": "0.1", "onsets": "3",
           "nonpositive_onsets": "0", "contact_segments_with_negative_penetration": "0", "message": ""}  # fmt: skip
    row.update({f"peak_rev{k + 1}_N": str(p) for k, p in enumerate(peaks)})
    median, worst, rev = peak_ratios(peaks)
    row.update(median_peak_N=str(median), worst_ratio=str(worst), worst_revolution=str(rev))
    return row


def test_the_scene_ensemble_median_catches_a_run_broken_for_most_revolutions():
    # Run "b" breaks in revolution 3 and peaks at 40 from then on: against its own median (40) it looks
    # steady (1.0x), against the median of the scene's runs (revolutions 2..5 of a, b, c: 2) it is 20x.
    rows = [_row("s", "1e-05", [9, 2, 2, 2, 2]), _row("s", "1e-06", [9, 2, 40, 40, 40]),
            _row("s", "1e-07", [9, 2, 2, 3, 2]), _row("t", "1e-05", [9, 5, 5, 5, 5]),
            _row("t", "1e-06", [0, 0, 0, 0, 0], status="failed")]  # fmt: skip
    ratios = ensemble_ratios(rows)
    assert ratios[("s", "numba_DOP853", "1e-06", "")] == 20.0
    assert float(rows[1]["worst_ratio"]) == 1.0
    assert ratios[("s", "numba_DOP853", "1e-07", "")] == 1.5
    assert ratios[("t", "numba_DOP853", "1e-05", "")] == 1.0
    assert len(ratios) == 4  # the failed run has no ratio
    # c's worst is exactly 1.5x: "above" is strict, so only b counts
    text = markdown_report(rows, "cmd")
    assert "own revolutions 2..N: **0** above 1.5x, **0** above 3x (largest 1.50x)" in text
    assert "ensemble median (all its runs): **1** above 1.5x, **1** above 3x (largest 20.00x)" in text
    assert "- failed: t `numba_DOP853` rtol 1e-06" in text


def test_segment_bookkeeping_on_synthetic_rows():
    contact = np.array([0, 0, 1, 1, 1, 0, 1, 1, 0, 0, 1], dtype=bool)
    assert onset_rows(contact).tolist() == [2, 6, 10]  # a run starting in contact has no onset at row 0
    assert onset_rows(np.array([1, 1, 0], dtype=bool)).size == 0
    delta = np.array([-1, -1, 0, 2, -1, -3, 0, -2, -4, -1, 0], dtype=float)
    # Rows 4 (segment 1) and 7 (segment 2) dip below zero inside a contact; free rows 5, 8, 9 do not count.
    assert negative_penetration_in_contact(contact, delta) == (2, 2)
    delta[3] = -0.5  # a second negative row in segment 1: 3 rows, still 2 segments
    assert negative_penetration_in_contact(contact, delta) == (3, 2)


@pytest.fixture(scope="module")
def short_run():
    """0.3 revolution of the reference scene (scipy DOP853, rtol 1e-9): ~a dozen onsets, ~1 s."""
    scene = load_scene(MODELS / "reference.toml", {"drive.revolutions": 0.3, "solver.reference.method": "DOP853",
                                                   "solver.reference.rtol": 1e-9, "solver.reference.atol": 1e-12})
    raw = {}
    result = solve(scene, observe=lambda t, y, c, i: raw.update(t=t, y=y, contact=c, impact=i))
    assert result.ok, result.message
    return scene, result, raw


def test_step_states_are_the_rows_of_the_step_channels(short_run):
    scene, result, raw = short_run
    np.testing.assert_array_equal(raw["t"], result.steps["time_s"])
    p = ChainConstants.from_scene(scene)
    i = len(raw["t"]) // 2
    # the penetration channel is computed from the same state: equal to round-off (delta ~1e-4 m, eps ~1e-16 m)
    assert penetration(p, raw["t"][i], raw["y"][i])[0] == pytest.approx(result.steps["penetration_m"][i], abs=1e-15)


def test_onsets_match_what_the_engine_reports(short_run):
    scene, result, raw = short_run
    found = onsets(scene, raw["t"], raw["y"], raw["contact"], raw["impact"])
    assert found.time_s.size == result.solver_stats["impacts"] >= 3
    assert found.time_s[0] == result.events["first_contact_time_s"]
    # The engine records the largest raw onset rate; ours is the same function of the same state.
    assert found.approach_rate_m_s.max() == result.events["max_impact_velocity_m_s"]
    # A genuine onset enters the wall, and is held at its rate floored at v_min.
    assert np.all(found.approach_rate_m_s > 0.0)
    np.testing.assert_array_equal(
        found.held_impact_velocity_m_s, np.maximum(found.approach_rate_m_s, scene.joint.min_impact_velocity)
    )
    # The rate is the time derivative of the penetration: the chord over the first quarter step of the
    # contact segment (the next recorded row) agrees with it to O(h delta''/rate): the curvature of
    # delta over the ~1e-5 s to that row, largest for the slowest onsets (0.03-0.06 m/s).
    rows = np.flatnonzero(np.isin(raw["t"], found.time_s) & raw["contact"])
    t, delta = result.steps["time_s"], result.steps["penetration_m"]
    chord = (delta[rows + 1] - delta[rows]) / (t[rows + 1] - t[rows])
    # 0.1 relative: on this run the 12 chords differ from the rates by 0.03 % .. 5.8 % (measured by printing
    # chord / rate - 1); a sign error or a wrong state would be off by 100 % or more.
    np.testing.assert_allclose(chord, found.approach_rate_m_s, rtol=0.1)


def test_a_separation_taken_as_onset_has_a_negative_rate(short_run):
    # What the defect does: an "onset" accepted at a separation instant.  Marking the located
    # separation rows as onsets must give negative rates (the journal is leaving the wall).
    scene, _, raw = short_run
    c = raw["contact"]
    separations = np.flatnonzero(c[:-1] & ~c[1:]) + 1
    assert separations.size >= 2
    fake = np.zeros_like(c)
    fake[separations] = True
    found = onsets(scene, raw["t"], raw["y"], fake, raw["impact"])
    assert found.time_s.size == separations.size
    assert np.all(found.approach_rate_m_s < 0.0)


def test_study_cells_and_bad_selections():
    cells = study_cells(MODELS)
    assert len(cells) == 72  # 6 paper scenes x (5 scipy + 7 compiled tolerances)
    assert len({c.key for c in cells}) == 72
    assert all(c.atol == pytest.approx(c.rtol * 1e-3) for c in cells)
    scene = Cell(str(MODELS / "paper" / "speed_500rpm_c0p25mm.toml"), "numba_DOP853", 1e-5).scene()
    assert (scene.reference_solver.method, scene.reference_solver.rtol, scene.reference_solver.atol) == (
        "numba_DOP853", 1e-5, pytest.approx(1e-8))
    assert scene.drive.end_time == pytest.approx(10 * scene.drive.period)
    with pytest.raises(StudyError, match="unknown method"):
        study_cells(MODELS, methods=["RK45"])
    with pytest.raises(StudyError, match="matches none"):
        study_cells(MODELS, only=["no_such_scene"])


def test_flores_cells():
    cells = flores_cells(MODELS)
    assert {(dict(c.overrides)["joint_e.impact_velocity_rule"], c.method) for c in cells} == {
        (rule, m) for rule in ("onset", "max_approach") for m in ("numba_DOP853", "DOP853")}
    scene = cells[0].scene()
    assert (scene.joint.law, scene.joint.restitution) == ("flores", 0.3)
    assert scene.reference_solver.atol == pytest.approx(1e-12)
    only = flores_cells(MODELS, overrides=(("joint_e.impact_velocity_rule", "onset"),))
    assert {dict(c.overrides)["joint_e.impact_velocity_rule"] for c in only} == {"onset"} and len(only) == 2
    exudyn = flores_cells(MODELS, methods=("exudyn",))[0].scene()  # the Exudyn row keeps the scene's solver
    assert (exudyn.joint.law, exudyn.reference_solver.method) == ("flores", "auto")


def test_replace_section(tmp_path):
    doc = tmp_path / "doc.md"
    doc.write_text("head\n<!-- x:begin -->\nold\n<!-- x:end -->\ntail\n")
    replace_section(doc, "x", "new\n")
    assert doc.read_text() == "head\n<!-- x:begin -->\nnew\n<!-- x:end -->\ntail\n"
    with pytest.raises(StudyError, match="markers"):
        replace_section(doc, "y", "new\n")


@pytest.mark.parametrize("flags", [["--set", "joint_e.bogus=1"], ["--methods", "RK45"], ["--jobs", "3"],
                                   ["--revolutions", "1"], ["--flores", "--methods", "RK45"]])  # fmt: skip
def test_script_bad_input_is_one_line(tmp_path, flags):
    run = subprocess.run([sys.executable, str(ROOT / "scripts" / "contact_outliers.py"), "--csv",
                          str(tmp_path / "x.csv"), "--section", "", "--only", "speed_500", *flags],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert run.returncode == 2
    assert len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert "Traceback" not in run.stderr
