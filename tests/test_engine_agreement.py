"""Exudyn against the closed-form reference engine over 10 revolutions (issue 4, SPEC.md section 6).

After the first impacts the impact sequence is sensitive to step and tolerance, so single
revolutions differ between the engines by 5-30%; what is reproducible, and checked here through
the same code as ``weftsim compare``, is the first contact, the first revolution's maxima and the
statistics over revolutions 2..10 (RMS, mean, 99th percentile).
"""

from pathlib import Path

import pytest

from weftsim.compare import agreement_checks, compare_results
from weftsim.scene import load_scene

MODELS = Path(__file__).resolve().parents[1] / "models"
REVOLUTIONS = 10  # the issue asks for at least 10 revolutions for the statistics


@pytest.fixture(scope="module", params=["clearance_0p25mm_400rpm", "clearance_0p50mm_400rpm"])
def both_engines(request):
    from weftsim import exudyn_engine, reference

    scene = load_scene(MODELS / "paper" / f"{request.param}.toml", {"drive.revolutions": REVOLUTIONS})
    return reference.solve(scene), exudyn_engine.solve(scene)


@pytest.mark.slow
def test_statistics_over_ten_revolutions_agree(both_engines):
    ref, exu = both_engines
    assert ref.ok and exu.ok, (ref.message, exu.message)
    checks = agreement_checks(exu, ref)
    names = [c["name"] for c in checks]
    # All three kinds of reproducible quantities are present: first contact, first revolution, statistics.
    assert any("first contact" in n for n in names)
    assert sum("first revolution" in n for n in names) == 3
    assert sum("revolutions 2..10" in n for n in names) == 6
    # Tolerances come from the scene's [compare] table: 0.1 deg, 1%, 3% (RMS, mean), 10% (99th percentiles),
    # set from SPEC.md section 6 (RMS/mean reproducible to 1-2%, 99th percentiles to ~5%).
    failed = [c for c in checks if not c["passed"]]
    assert not failed, failed


@pytest.mark.slow
def test_compare_report_has_the_side_by_side_table(both_engines):
    ref, exu = both_engines
    report = compare_results(exu, ref)
    assert report["agree"]
    for name in ("rapier_acceleration_m_s2", "driving_torque_Nm", "contact_force_N"):
        row = report["channels"][name]
        assert set(row["exudyn"]) == {"min", "max", "rms"} == set(row["reference"])
        # The ratio is information (single-revolution values after the first impacts are not
        # reproducible), but it must be the ratio of the two engines' own numbers.
        assert row["ratio_max"] == row["exudyn"]["max"] / row["reference"]["max"]
