"""Automatic model selection of the Exudyn engine (issue 12.1): which model for which scene, that
``solve`` runs exactly that model, and that the default path meets the issue's accuracy targets."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

pytest.importorskip("exudyn")

from weftsim import exudyn_engine  # noqa: E402
from weftsim.exudyn_engine.selection import select_path  # noqa: E402
from weftsim.exudyn_engine.solver import IDEAL_JOINT_STEP_ANGLE  # noqa: E402
from weftsim.input.params import Scene  # noqa: E402
import weftsim  # noqa: E402
from weftsim.input.scene import SceneError, load_scene  # noqa: E402
from conftest import door

MODELS = Path(__file__).resolve().parents[1] / "models"
SHORT = {"drive.revolutions": 0.02}  # 7.2 deg: through the first contact at 6.6 deg


def _with(scene: Scene, **solver) -> Scene:
    return dataclasses.replace(scene, exudyn_solver=dataclasses.replace(scene.exudyn_solver, **solver))


@pytest.mark.parametrize("overrides", [
    {},
    {"joint_e.clearance_mm": 0.01, "drive.speed_rpm": 800.0},
    {"joint_e.clearance_mm": 0.5, "joint_e.law": "flores", "joint_e.restitution": 0.3},
    {"joint_e.impact_velocity_rule": "onset", "solver.exudyn.callback": "python"},
])  # fmt: skip
def test_auto_takes_the_kinematic_tree_for_a_clearance_at_e(overrides):
    scene = load_scene(MODELS / "reference.toml", overrides)
    assert scene.exudyn_solver.model == "auto"  # the default of the scene files and of Scene()
    path = select_path(scene)
    assert path["model"] == "kinematic_tree" and path["reason"].startswith("auto")
    route = overrides.get("solver.exudyn.callback", "numba")  # auto route: numba (a dependency)
    assert path["method"] == f"DOPRI5 rtol {scene.exudyn_solver.relative_tolerance:g}, {route} callback"


def test_auto_takes_the_rigid_body_model_where_the_scene_needs_it():
    base = load_scene(MODELS / "reference.toml")
    ideal = load_scene(MODELS / "reference.toml", {"joint_e.clearance_mm": 0.0})
    path = select_path(ideal)
    # No free coordinate: generalized-alpha at the ideal joint's crank-angle step, not the contact step.
    h = IDEAL_JOINT_STEP_ANGLE / ideal.drive.speed
    assert path["model"] == "rigid_body" and "ideal joint" in path["reason"]
    assert path["method"] == f"generalized-alpha, fixed step h {h:.3g} s"
    friction = dataclasses.replace(base, joint=dataclasses.replace(base.joint, friction_coefficient=0.1))
    # The tree carries friction (force at the contact point, moments on rod and rocker): no reason to leave it.
    assert select_path(friction)["model"] == "kinematic_tree" and select_path(friction)["reason"].startswith("auto")


def test_auto_runs_the_tree_implicitly_with_friction_and_explicitly_without():
    """Issue 23: with friction the explicit tree steps at the friction ramp's ~1e-9 s stability limit, the
    implicit one does not (tests/test_friction_agreement.py); without friction DOPRI5 is the faster
    (docs/performance.md).  Both stay choices by ``solver.exudyn.tree_solver``."""
    base = load_scene(MODELS / "reference.toml")
    friction = load_scene(MODELS / "reference.toml", {"joint_e.friction_coefficient": 0.15})
    path = select_path(friction)
    assert path["model"] == "kinematic_tree"
    assert path["method"] == "generalized-alpha, adaptive step (local error 3e-10 m at E), numba callback"
    assert select_path(base)["method"].startswith("DOPRI5")
    assert select_path(_with(friction, tree_solver="explicit"))["method"].startswith("DOPRI5 rtol 1e-08")
    assert select_path(_with(base, tree_solver="implicit"))["method"].startswith("generalized-alpha")
    with pytest.raises(SceneError) as err:
        load_scene(MODELS / "reference.toml", {"solver.exudyn.tree_solver": "radau"})
    assert "solver.exudyn.tree_solver" in str(err.value) and "'implicit'" in str(err.value)


def test_explicit_models_stay_choices():
    base = load_scene(MODELS / "reference.toml")
    for model in ("rigid_body", "kinematic_tree"):
        path = select_path(_with(base, model=model))
        assert path["model"] == model and path["reason"] == "scene key solver.exudyn.model"
    with pytest.raises(SceneError) as err:
        load_scene(MODELS / "reference.toml", {"solver.exudyn.model": "magic"})
    assert "solver.exudyn.model" in str(err.value) and "'auto'" in str(err.value)


@pytest.mark.parametrize("overrides, model, method", [
    ({}, "kinematic_tree", "DOPRI5"),
    ({"joint_e.friction_coefficient": 0.15}, "kinematic_tree", "generalized_alpha"),
    ({"solver.exudyn.model": "rigid_body", "drive.revolutions": 0.03}, "rigid_body", "generalized_alpha"),
    ({"joint_e.clearance_mm": 0.0}, "rigid_body", "generalized_alpha"),
])  # fmt: skip
def test_solve_runs_what_the_selection_names(overrides, model, method):
    scene = load_scene(MODELS / "reference.toml", {**SHORT, **overrides})
    r = door("exudyn")(scene)
    assert r.ok, r.message
    assert r.path == select_path(scene)
    assert r.path["model"] == model and r.solver_stats["method"] == method
    if model == "kinematic_tree":
        assert r.solver_stats["model"] == "kinematic_tree" and r.solver_stats["callback"] == "numba"
    if overrides.get("joint_e.clearance_mm") == 0.0:
        # The ideal joint steps 0.25 deg of crank (1.04e-4 s at 400 rpm), never the contact step 2e-6 s.
        assert r.solver_stats["step_size_s"] == pytest.approx(IDEAL_JOINT_STEP_ANGLE / scene.drive.speed, rel=0.05)


def test_the_callback_override_is_part_of_the_selection():
    scene = load_scene(MODELS / "reference.toml", SHORT)
    r = door("exudyn")(scene, callback="python")
    assert r.ok and r.path["model"] == "kinematic_tree" and r.solver_stats["callback"] == "python"
    assert r.path == select_path(_with(scene, callback="python"))


@pytest.mark.slow
def test_the_default_path_meets_the_issue_targets_on_the_reference_scene():
    """Issue 12: no solver keys, 10 revolutions at 400 rpm and c = 0.25 mm: first-revolution peaks within
    1 % of the converged solution, statistics within the scene's [compare] tolerance (derived from the
    measured scatter of converged runs, 6 %).  Measured: peaks 8.2e-4 (torque), 3.8e-5 (acceleration),
    1.5e-4 (force); statistics 1.15 % (the converged ensemble's own spread is 1.24 %)."""
    from weftsim.bench.measure import converged_solution, errors, quantities

    scene = load_scene(MODELS / "reference.toml", {"drive.revolutions": 10.0})
    r = door("exudyn")(scene)
    assert r.ok and r.path["model"] == "kinematic_tree", r.message
    ref = converged_solution("c0.25mm-400rpm", MODELS, 10.0, log=lambda *a: None)
    err = errors(quantities(r), ref)
    assert err["peak_max"] < scene.compare.first_revolution_peaks, err["peak"]
    assert err["stats_max"] < scene.compare.rms, (err["rms"], err["mean"])


def test_the_default_path_runs_a_slow_drive_that_the_other_paths_run():
    """Issue 24: at 1 rpm the tree's largest step was half an output sample, 0.042 s, and its first step
    from the centred journal ended 99.7 mm deep in the wall (gravity: the journal falls through the
    clearance in 7 ms), "joint too soft".  The step is now also at most 0.1 of that fall time
    (tree_solve.largest_step): the default path runs, and as at any speed it agrees with the reference
    engine, here on the journal resting on the bearing (0.003 revolution, 0.18 s: it falls, bounces and
    settles)."""
    from weftsim import reference
    from weftsim.exudyn_engine.tree_solve import largest_step

    scene = load_scene(MODELS / "reference.toml", {"drive.speed_rpm": 1.0, "drive.revolutions": 0.003})
    assert largest_step(scene) == pytest.approx(0.1 * (2 * scene.joint.clearance / scene.inertia.gravity) ** 0.5)
    fast = load_scene(MODELS / "reference.toml")  # 400 rpm: the half sample is the bound, steps unchanged
    assert largest_step(fast) == fast.output.sample_angle / fast.drive.speed / 2
    exu, ref = door("exudyn")(scene), door("reference")(scene)
    assert exu.ok and ref.ok, (exu.message, ref.message)
    assert exu.path["model"] == "kinematic_tree" and exu.path["method"].startswith("DOPRI5")
    # At rest the journal carries its static load (3.136 N in both engines): the settled state of two
    # integrations to their tolerances, measured to agree within 1e-4.
    assert exu.steps["contact_force_N"][-1] == pytest.approx(ref.steps["contact_force_N"][-1], rel=1e-3)
    assert exu.steps["penetration_m"][-1] > 0.0


def test_the_run_time_estimate_follows_the_exudyn_trees_solver_with_friction():
    """The estimate prices friction by the path that integrates it: the implicit tree (the default with
    friction) at ~5x a dry run as measured in issue 23, the explicit tree at its stability-limited 1400x,
    and only the explicit one is announced as an explicit solver on a stiff joint."""
    from weftsim.engines import get
    from weftsim.exudyn_engine.engine import EXUDYN_IMPLICIT_STIFF_FACTOR, EXUDYN_STIFF_FACTOR

    def estimate_run_time(scene, engine):
        return get(engine).estimate(scene).run_time_s

    def stiff_explicit(scene, engines):
        return any(get(engine).estimate(scene).stiff_explicit for engine in engines)

    dry = weftsim.load_scene("reference", clearance_mm=0.5, revolutions=1)
    rough = weftsim.load_scene("reference", {"joint_e.friction_coefficient": 0.15}, clearance_mm=0.5, revolutions=1)
    explicit = weftsim.load_scene("reference", {"joint_e.friction_coefficient": 0.15,
                                               "solver.exudyn.tree_solver": "explicit"}, clearance_mm=0.5, revolutions=1)
    base = estimate_run_time(dry, "exudyn")
    assert estimate_run_time(rough, "exudyn") == pytest.approx(EXUDYN_IMPLICIT_STIFF_FACTOR * base)
    assert estimate_run_time(explicit, "exudyn") == pytest.approx(EXUDYN_STIFF_FACTOR * base)
    assert not stiff_explicit(rough, ("exudyn",)) and stiff_explicit(explicit, ("exudyn",))


def test_auto_runs_a_lubricated_tree_implicitly_at_the_films_local_error():
    """An oil film is stiff near the wall: the explicit tree took 513 065 steps for one loom revolution at
    c = 0.02 mm, 80 mPa s, generalized-alpha 2 167 (tree_solve.tree_solver); its local error is capped so the
    smallest film thickness and an impact into the film stay within 4e-4 (tree_solve.LUBRICATED_LOCAL_ERROR)."""
    from weftsim.exudyn_engine.tree_solve import LUBRICATED_LOCAL_ERROR, tree_local_error, tree_solver

    oil = load_scene(MODELS / "loom.toml", {"joint_e.lubrication.viscosity_mpa_s": 80.0})
    dry = load_scene(MODELS / "loom.toml")
    assert tree_solver(oil) == "implicit" and tree_solver(dry) == "explicit"
    assert tree_local_error(oil) == LUBRICATED_LOCAL_ERROR < tree_local_error(dry) == dry.exudyn_solver.local_error
    assert f"local error {LUBRICATED_LOCAL_ERROR:g} m" in select_path(oil)["method"]
