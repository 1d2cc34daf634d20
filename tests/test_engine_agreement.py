"""Exudyn against the closed-form reference engine over many revolutions (issues 4 and 11).

After the first impacts the impact sequence is chaotic: single revolutions differ between the engines
(and within one engine under any change of step or tolerance) by 5-30 %.  What is reproducible, and
checked here through the same code as ``weftsim compare``, is the first contact, the first
revolution's maxima and the statistics over revolutions 2..N (RMS, mean, 99th percentile of |x|).

Those statistics are themselves random draws: two engines solving the same equations differ by the
difference of two draws.  Their scatter within ONE engine was measured with an ensemble of 16 runs of
the reference engine whose crank speed differs by k x 1e-9 (k = 0..15; numba_DOP853, rtol 1e-8), each
giving another, equally valid impact sequence (``python scripts/statistics_scatter.py``; table in
docs/hard-cases.md).  Relative standard deviation s of one run's statistic, largest over the two scenes:

    window            RMS a   RMS T   mean F_N   p99 |a|   p99 |T|   p99 F_N
    revolutions 2..10  1.08 %  0.93 %  0.25 %     2.50 %    1.81 %    2.62 %
    revolutions 2..40  0.64 %  0.51 %  0.13 %     1.28 %    0.68 %    1.46 %

At 10 revolutions the old 3 % tolerance on RMS was 2 sigma of the difference of two draws (s sqrt 2
= 1.5 %): the test passed or failed by chance (issue 11 measured 3.3 % once).  So this test runs 40
revolutions and allows 4 s sqrt(2) of the 2..40 window: 3.6 % on RMS and mean, 8.3 % on the 99th
percentiles; a false failure needs a 4-sigma draw (6e-5 per check, normal tails).  The Exudyn side is
its default path, as ``weftsim compare`` runs it: the automatic selection takes the kinematic-tree
model (members 1-3 prescribed, the same equations in Exudyn's minimal coordinates, DOPRI5 with error
control at its default tolerance).  The rigid-body model (40 revolutions take ~7 minutes) is checked
against the reference on the first revolution in tests/test_exudyn_engine.py.  Measured on that default
path (rtol 1e-6, numba route): c = 0.25 mm: RMS a / T 0.12 % / 0.05 %, mean F_N 0.06 %, p99 <= 0.31 %,
first-revolution maxima <= 7.7e-4; c = 0.5 mm: RMS 0.50 % / 0.57 %, mean 0.07 %, p99 <= 2.3 %, maxima
<= 3.6e-4.
"""

import math
from pathlib import Path

import pytest

from weftsim.post.compare import agreement_checks, compare_results
from weftsim.input.scene import load_scene
from conftest import door

MODELS = Path(__file__).resolve().parents[1] / "models"
REVOLUTIONS = 40
SCATTER_2_40 = {"rms": 0.0064, "percentile_99": 0.0146}  # largest measured s (table above)
TOLERANCES = {name: round(4.0 * math.sqrt(2.0) * s, 3) for name, s in SCATTER_2_40.items()}  # 0.036, 0.083


@pytest.fixture(scope="module", params=["clearance_0p25mm_400rpm", "clearance_0p50mm_400rpm"])
def both_engines(request):
    from weftsim import exudyn_engine, reference

    overrides = {
        "drive.revolutions": REVOLUTIONS,
        "solver.reference.method": "numba_DOP853",
        "solver.reference.rtol": 1e-8,
        "solver.reference.atol": 1e-11,
        "compare.rms": TOLERANCES["rms"],
        "compare.percentile_99": TOLERANCES["percentile_99"],
    }
    scene = load_scene(MODELS / "paper" / f"{request.param}.toml", overrides)
    return door("reference")(scene), door("exudyn")(scene)


@pytest.mark.slow
def test_statistics_over_forty_revolutions_agree(both_engines):
    ref, exu = both_engines
    assert ref.ok and exu.ok, (ref.message, exu.message)
    assert exu.path["model"] == "kinematic_tree" and exu.path["reason"].startswith("auto")
    checks = agreement_checks(exu, ref)
    names = [c["name"] for c in checks]
    # All three kinds of reproducible quantities are present: first contact, first revolution, statistics.
    assert any("first contact" in n for n in names)
    assert sum("first revolution" in n for n in names) == 3
    assert sum(f"revolutions 2..{REVOLUTIONS}" in n for n in names) == 6
    # First contact 0.1 deg and first-revolution maxima 1 % from the scene's [compare] table (the
    # start-up impact is deterministic: engines agree to ~1e-4, docs/performance.md); statistics as above.
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
