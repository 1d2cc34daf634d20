"""Regression guard: recompute the stored peaks of tests/regression/peaks.json.

The table holds reproducible quantities only (ideal-joint peaks, first-revolution peaks,
statistics over revolutions 2..N; docs/physics.md section 6) for both engines, each with the
tolerance measured when the table was made and the reason for it (see
weftsim/studies/regression.py).  These are not physics checks: the other tests are.
A failure names the scene, the engine and the channel.  After an intended physics
change, regenerate the table with ``python scripts/regenerate_regression.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from weftsim.studies import regression

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "tests" / "regression" / "peaks.json"
ENTRIES = json.loads(TABLE.read_text())["entries"]


def test_table_covers_every_case_and_states_its_tolerances():
    stored = {entry["case"] for entry in ENTRIES}
    assert stored == {case.name for case in regression.CASES}, "regenerate: scripts/regenerate_regression.py"
    for entry in ENTRIES:
        for name, quantity in entry["quantities"].items():
            assert ("rtol" in quantity) != ("atol" in quantity), (entry["case"], name)
            assert quantity["reason"], (entry["case"], name)


@pytest.mark.parametrize("entry", [
    pytest.param(entry, id=entry["case"], marks=[pytest.mark.slow] if entry["slow"] else [])
    for entry in ENTRIES
])
def test_peaks_match_the_stored_table(entry):
    case = regression.case_from_entry(entry)
    result = regression.run_case(case, ROOT)
    problems = regression.check_entry(entry, regression.quantities(case, result))
    assert not problems, "\n".join(problems) + "\n(intended physics change? python scripts/regenerate_regression.py)"
