"""Checks that hold for every engine, written once and run on each (the ``engine`` fixture of conftest.py).

The way a solver library runs every solver through one convergence test: a new engine registered in
``tests/conftest.py``'s ENGINES gets these checks for free.
"""

from __future__ import annotations

import math

import pytest

import weftsim
from weftsim.post.analysis import energy_balance

# |W_drive - (dKE + dPE + E_contact + E_dissipated)| / max KE at the end of 0.3 revolution of the reference
# scene (c = 0.25 and 0.5 mm, 400 rpm, several impacts): measured 2.2e-5 and 1.9e-7 on the reference engine,
# 1.2e-4 and 1.3e-4 on the Exudyn engine (its default tree at rtol 1e-6); the bound sits ~8x above the largest.
ENERGY_TOLERANCE = 1e-3
# The first contact's time: measured to agree within 3.7e-9 s (c = 0.25 mm) and 6e-11 s (0.5 mm) here.
FIRST_CONTACT_TOLERANCE_S = 1e-7


@pytest.mark.parametrize("clearance_mm", [0.25, 0.5])
def test_the_energy_balance_closes_through_the_impacts(engine, run_of, clearance_mm):
    result = run_of("reference", engine, clearance_mm=clearance_mm, revolutions=0.3)
    assert result.ok, result.message
    assert result.events["first_contact_time_s"] is not None  # the run has impacts: the balance is not trivial
    assert abs(energy_balance(result)["relative_residual"]) < ENERGY_TOLERANCE


@pytest.mark.parametrize("clearance_mm", [0.25, 0.5])
def test_the_first_contact_is_where_the_other_engine_finds_it(engine, run_of, clearance_mm):
    """Free flight from the centred journal to the first contact is the same motion on every engine."""
    this = run_of("reference", engine, clearance_mm=clearance_mm, revolutions=0.3)
    other = run_of("reference", next(e for e in ("reference", "exudyn") if e != engine),
                   clearance_mm=clearance_mm, revolutions=0.3)
    assert this.events["first_contact_time_s"] == pytest.approx(other.events["first_contact_time_s"],
                                                                abs=FIRST_CONTACT_TOLERANCE_S)


def test_every_bundled_scene_has_a_path_and_an_estimate(engine, bundled):
    """The contract's two questions answered before a run, for each bundled scene."""
    for name in bundled:
        scene = weftsim.load_scene(name)
        path = weftsim.select_path(scene, engine)
        assert set(path) >= {"model", "method", "reason"} and all(path[k] for k in ("model", "method"))
        cost = weftsim.estimate(scene, engine)
        assert math.isfinite(cost.run_time_s) and cost.run_time_s >= 0.0 and cost.step_bytes >= 0.0


def test_the_result_is_vetted_once_by_the_door(engine, run_of):
    """Every engine's result leaves ``simulate`` with the checks before and after the run attached."""
    result = run_of("reference", engine, clearance_mm=0.25, revolutions=0.3)
    kinds = {c["name"] for c in result.plausibility["checks"]}
    assert "rapier_acceleration" in kinds and len(result.plausibility["checks"]) >= 2
