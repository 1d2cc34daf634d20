"""Wear on the Exudyn engine (issue 26, point 2): the kinematic tree's contact sees a worn profile exactly as
the reference engine's does (the same kernel functions), a worn scene's contact agrees between the engines
to the tolerances of ``weftsim compare``, and the Archard integral over the Exudyn run's own contact
channels (F_N, v_T, contact angles) holds the worn volume."""

from __future__ import annotations

import json
import math
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from weftsim import exudyn_engine, reference
from weftsim.physics import chain as kc
from weftsim.physics.laws import elastic_force
from weftsim.physics.wear import worn_clearance
from weftsim.model.dynamics import initial_state, pack_parameters
from weftsim.input.scene import load_scene
from weftsim.wear import WearError, check_request
from weftsim.wear.engines import engine_update, exudyn_update
from weftsim.wear.extrapolate import worn_scene
from conftest import door


def _weftsim(capsys, *args: str) -> subprocess.CompletedProcess:
    """``weftsim ARGS`` through weftsim.cli.main in this process (the console script's function): its status, stdout
    and stderr (no new process: its imports and the compiled kernels' loading are this process's)."""
    from weftsim.cli.commands import main

    status = main(list(args))
    captured = capsys.readouterr()
    return subprocess.CompletedProcess(["weftsim", *args], status, captured.out, captured.err)


def _profiles(n: int, c0: float) -> tuple[np.ndarray, np.ndarray]:
    """A worn spot on the bearing (0.5 c0 deep at 250 deg of its frame) and on the journal (0.3 c0 at 90 deg)."""
    psi = 2.0 * np.pi * np.arange(n) / n

    def spot(centre, width, depth):
        d = np.angle(np.exp(1j * (psi - centre)))
        return depth * np.exp(-0.5 * (d / width) ** 2)

    return spot(math.radians(250.0), 0.4, 0.5 * c0), spot(math.radians(90.0), 0.5, 0.3 * c0)


def _worn(scene, revolutions: float):
    bearing, journal = _profiles(scene.joint.wear.profile_points, scene.joint.clearance)
    return worn_scene(scene, bearing, journal, revolutions), bearing, journal


def test_the_tree_contact_reads_the_same_worn_clearance_as_the_reference_chain():
    """At any state, the Exudyn tree's force kernel (:func:`tree_joint_force`) and the reference chain
    (:func:`penetration`) give the same penetration and rate on a worn joint, and it is the round joint's
    less h_b(psi_b) + h_j(psi_j) read from the profiles at the contact direction in each body's frame."""
    scene = load_scene("loom")
    worn, bearing, journal = _worn(scene, 1.0)
    prm, round_prm = pack_parameters(worn), pack_parameters(scene)
    rng = np.random.default_rng(3)
    a0, psi0 = initial_state(scene)[:2]
    c0 = scene.joint.clearance
    depths = []
    for t in rng.uniform(0.0, 2e-4, 40):
        # states around the ideal one at time 0, early in the start-up: |e| = 0.07-1.7 c0, in every direction
        y = np.array([a0 + rng.normal(0.0, 3e-5), psi0 + rng.normal(0.0, 3e-5), rng.normal(0.0, 5.0),
                      rng.normal(0.0, 5.0), 0.0, 0.0])  # fmt: skip
        tree = kc.tree_joint_force(prm, t, y[0], y[1] + math.pi - y[0], y[2], y[3] - y[2], 1e-4, -1.0, 0.0)
        delta, rate = kc.penetration(prm, t, y)
        assert tree[2] == pytest.approx(delta, abs=1e-15) and tree[3] == pytest.approx(rate, rel=1e-9, abs=1e-12)
        ecc_y, ecc_z = kc.eccentricity(prm, t, y)[:2]
        direction = math.atan2(ecc_z, ecc_y)
        depth = (worn_clearance(prm, kc.WEAR_E, 0.0, direction - kc.rocker_angle(prm, t), direction - y[1], 0.0,
                                   0.0)[0])  # fmt: skip
        # the profile's own value at the direction: linear interpolation is within the table's curvature
        psi_b = (direction - kc.rocker_angle(prm, t)) % (2 * math.pi)
        psi_j = (direction - y[1]) % (2 * math.pi)
        grid = 2 * math.pi * np.arange(bearing.size + 1) / bearing.size
        near = (np.interp(psi_b, grid, np.append(bearing, bearing[0]))
                + np.interp(psi_j, grid, np.append(journal, journal[0])))
        # 1e-3 c0: a Catmull-Rom spline against linear interpolation of 1-deg cells of a spot 23-29 deg wide
        assert depth == pytest.approx(near, abs=1e-3 * c0)
        round_tree = kc.tree_joint_force(round_prm, t, y[0], y[1] + math.pi - y[0], y[2], y[3] - y[2], 1e-4, -1.0, 0.0)
        assert round_tree[2] - tree[2] == pytest.approx(depth, abs=1e-15)
        depths.append(depth)
    assert max(depths) > 0.3 * c0 and min(depths) < 0.01 * c0  # the states meet the worn spots and unworn wall


def test_the_trees_powers_on_a_worn_wall_are_the_reference_chains():
    """The drawn and dissipated powers the explicit tree integrates (W3', D' of :func:`tree_joint_force`) equal
    the reference chain's at penetrated states of a worn joint, where the wall's profile passes under the journal
    (dc/dt != 0): D' holds the radial force's work F_N dc/dt there, as the chain's does."""
    scene = load_scene("loom")
    worn = _worn(scene, 1.0)[0]
    prm = pack_parameters(worn)
    rng = np.random.default_rng(5)
    a0, psi0 = initial_state(scene)[:2]
    moving = 0
    for t in rng.uniform(0.0, 2e-4, 3000):
        y = np.array([a0 + rng.normal(0.0, 3e-5), psi0 + rng.normal(0.0, 3e-5), rng.normal(0.0, 5.0),
                      rng.normal(0.0, 5.0), 0.0, 0.0])  # fmt: skip
        delta, rate = kc.penetration(prm, t, y)
        if delta <= 0.0:
            continue
        held = max(rate, 0.05)  # one impact velocity for both (the chain's argument, the tree's held one)
        out = np.zeros(6)
        f_n = kc.chain(prm, t, y, True, held, out)[1]
        tree = kc.tree_joint_force(prm, t, y[0], y[1] + math.pi - y[0], y[2], y[3] - y[2], held, 1e-6, rate)
        ecc_y, ecc_z, v_y, v_z = kc.eccentricity(prm, t, y)[:4]
        c, c_rate = kc.local_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y)
        # the same kernel in two coordinate sets: 1e-8 (the round joint's, test_friction_agreement) of the size of
        # the terms W3' and D' are differences of, (F_N + F_el) (|e_dot| + |dc/dt|) (measured: 3.5e-9 of it; F_N
        # alone can be 0 where the damping clips it, D' = -F_el delta_dot then)
        f_el = elastic_force(prm[kc.KIND], prm[kc.COEF], c, delta)
        scale = 1e-8 * (f_n + f_el) * (math.hypot(v_y, v_z) + abs(c_rate))
        assert tree[12] == pytest.approx(out[4], rel=1e-8, abs=scale)
        assert tree[13] == pytest.approx(out[5], rel=1e-8, abs=scale)
        moving += abs(f_n * c_rate) > 0.01 * abs(out[5])  # the term the tree once left out matters here
    assert moving >= 10  # states on the worn spots with the profile moving under the journal


def test_a_worn_scene_agrees_between_the_engines_to_the_compare_tolerances():
    """The loom's start-up impact on the worn joint: the worn spots move the first contact by more than
    ``compare``'s first-contact tolerance and the peak force by more than its peak tolerance, and the
    engines agree on both within those tolerances (the round joint's criteria): the reference engine, the
    Exudyn kinematic tree and the Exudyn rigid-body model, whose joint E is the reusable clearance connector
    (:func:`weftsim.exudyn_engine.add_clearance_joint`) reading the profiles in the rocker's and the rod's
    body frames."""
    scene = load_scene("loom")
    worn = _worn(scene, 0.05)[0]
    round_scene = replace(scene, drive=replace(scene.drive, revolutions=0.05))
    tol = scene.compare
    omega = scene.drive.speed
    out = {}
    for name, s in (("round", round_scene), ("worn", worn)):
        rigid = replace(s, exudyn_solver=replace(s.exudyn_solver, model="rigid_body"))
        for engine, solve, run in (("reference", door("reference"), s), ("exudyn", door("exudyn"), s),
                                   ("rigid_body", door("exudyn"), rigid)):
            result = solve(run)
            assert result.ok, result.message
            out[name, engine] = (result.events["first_contact_time_s"], result.steps["contact_force_N"].max())
    for engine in ("reference", "exudyn", "rigid_body"):  # the wear changes the contact beyond the tolerances
        assert omega * abs(out["worn", engine][0] - out["round", engine][0]) > tol.first_contact_angle
        assert abs(out["worn", engine][1] / out["round", engine][1] - 1.0) > tol.first_revolution_peaks
    for name in ("round", "worn"):
        t_r, f_r = out[name, "reference"]
        for engine in ("exudyn", "rigid_body"):
            t_x, f_x = out[name, engine]
            assert omega * abs(t_x - t_r) < tol.first_contact_angle
            assert abs(f_x / f_r - 1.0) < tol.first_revolution_peaks


def test_the_exudyn_update_integrates_archard_over_its_own_contact_channels():
    """An update on Exudyn of a worn geometry: the profiles hold k/H times the sliding work (Archard's
    volume), the sliding work is its rows' integral of F_N |v_T| dt, and the update agrees with the
    reference engine's (the same deposit): sliding work within the reference engine's own scatter over its
    tolerances, the deepest wear at the same cell."""
    scene = load_scene("loom")
    scene = replace(scene, joint=replace(scene.joint, wear=replace(scene.joint.wear, revolutions_per_update=1)))
    bearing, journal = _profiles(scene.joint.wear.profile_points, scene.joint.clearance)
    w = scene.joint.wear
    ex, response = exudyn_update(scene, bearing, journal)
    ref = engine_update(scene, bearing, journal, "reference")[0]
    cell_b = w.bearing_hardness ** -1 * w.contact_wear_coefficient
    # the profiles' volume: sum(h) L R dpsi = (k / H) W to round-off (the deposit conserves it)
    dpsi = 2 * math.pi / w.profile_points
    volume_b = ex.bearing.sum() * scene.joint.bearing_length * scene.joint.bearing_radius * dpsi
    assert volume_b == pytest.approx(cell_b * ex.sliding_work, rel=1e-12)
    assert ex.bearing_volume == pytest.approx(cell_b * ex.sliding_work, rel=1e-15)
    assert response["sliding_work_per_rev_e_J"] == pytest.approx(ex.sliding_work, rel=1e-15)
    # The engines.  Under the loom's cylindrical law (issue 37; 3-15 times stiffer than variable_kd, under which
    # the engines agreed to 1.8e-4 here) this worn revolution is sensitive to the integration itself: the journal
    # chatters across the worn spots, and neither engine's sliding work converges with its tolerance (reference
    # at rtol 1e-5 .. 1e-11: 279.3, 291.7, 291.1, 277.9, 281.1 J; Exudyn at 1e-7 .. 1e-11: 287.0, 273.9, 278.5,
    # 277.0, 290.2 J), while the round joint's converges on both (245.84 J, engines 9e-5 apart at 1e-9).  So
    # the Exudyn update must fall within the reference engine's scatter over five of its tolerances widened by
    # that scatter's width (the criterion of the chaotic hours, test_both_engines_agree_on_the_hours_...).
    # Three tolerances (279.3, 286.5, 285.5 J) caught too little of that scatter: with the explicit tree's error
    # control restored under its power joints (tree_solve.MOTION_SHARE) Exudyn's value at the loom's
    # rtol 1e-7 is 276.1 J (291.8, 282.1, 281.2 J at 1e-8 .. 1e-10), inside the reference's own 277.9-291.7 J
    # over 1e-5 .. 1e-11 but outside the three-sample window.  Measured now: 279.3, 286.5, 284.3, 285.5, 277.4 J
    # (3.2 %), Exudyn 276.1 J, 0.73 of the width from their mean.
    # Not the sliding distance: it counts rows of any load, and where the journal crosses the worn spot under a
    # few N the engines end the light contact at different steps.
    works = [ref.sliding_work] + [engine_update(replace(scene, reference_solver=replace(
        scene.reference_solver, rtol=rtol, atol=1e-12)), bearing, journal, "reference")[0].sliding_work
        for rtol in (1e-7, 1e-8, 1e-9, 1e-10)]
    spread = max(works) - min(works)
    assert spread > 0.01 * np.mean(works)  # the scatter is there (measured 2.5 %)
    assert abs(ex.sliding_work - np.mean(works)) <= spread, (works, ex.sliding_work)
    assert int(np.argmax(ex.bearing)) == int(np.argmax(ref.bearing))
    assert int(np.argmax(ex.journal)) == int(np.argmax(ref.journal))


def test_wear_on_exudyn_refuses_what_it_cannot_run_in_one_line():
    scene = load_scene("loom")
    rigid = replace(scene, exudyn_solver=replace(scene.exudyn_solver, model="rigid_body"))
    with pytest.raises(WearError, match="kinematic tree"):
        check_request(rigid, 1.0, "exudyn", None)
    with pytest.raises(WearError, match="--engine must be one of reference, exudyn"):
        check_request(scene, 1.0, "exudin", None)
    with pytest.raises(WearError, match="covers joint E alone"):  # the tree carries the clearance at E only
        check_request(load_scene("clearance_ef"), 1.0, "exudyn", None)


def _hours_to(scene, limit: float, engine: str) -> float:
    """Hours at which the prediction of ``scene`` on ``engine`` reaches the effective clearance ``limit`` (m)."""
    from weftsim.wear.engines import simulator
    from weftsim.wear.extrapolate import MAX_HOURS, advance, effective_clearance, limit_hours, predict

    c0, latest = scene.joint.clearance, []

    def beyond() -> bool:
        return bool(latest) and effective_clearance(c0, *advance(latest[-1], scene)[2:]) >= limit

    updates = predict(scene, MAX_HOURS, on_update=lambda u: latest.__setitem__(slice(None), u), stop=beyond,
                      simulate=simulator(engine))  # fmt: skip
    end_hours, end_revolutions, bearing, journal = advance(updates[-1], scene)
    end = replace(updates[-1], hours=end_hours, revolutions=end_revolutions, bearing=bearing, journal=journal)
    return limit_hours([*updates, end], c0, limit)


@pytest.mark.slow
def test_both_engines_agree_on_the_hours_to_a_limit_within_the_chaotic_scatter():
    """The reference mechanism (c0 = 0.25 mm, 400 rpm) to 0.3 mm, ten updates: its cycle is chaotic, and
    predictions differing only in the last bits of k (the ensemble's chaos runs) scatter by percents; the
    Exudyn engine's predictions fall within that scatter of the reference engine's."""
    from weftsim.wear.ensemble_design import last_bits

    scene, limit = load_scene("reference"), 0.3e-3
    ref = np.array([_hours_to(last_bits(scene, j), limit, "reference") for j in range(4)])
    exu = np.array([_hours_to(last_bits(scene, j), limit, "exudyn") for j in range(2)])
    spread = ref.max() - ref.min()
    assert spread > 0.005 * ref.mean()  # the scatter is there (measured: 1.1-3.4 %)
    # every Exudyn prediction within the reference engine's chaos band widened by its own width
    assert np.all(np.abs(exu - ref.mean()) <= spread), (ref, exu)


def test_cli_wear_on_exudyn_writes_its_prediction_and_agrees_on_the_first_update(tmp_path, capsys):
    """``weftsim wear --engine exudyn`` runs (its own default directory, the engine in wear.json), and its first
    update (the unworn joint, before any chaos from the wear) agrees with the reference engine's."""
    out = {}
    # The tree at rtol 1e-9: the loom's 1e-7 (its cylindrical law's start-up, loom.toml: peaks within 0.1 % of
    # 1e-8) leaves 1.4e-3 in this update's deepest wear.  The hours to 0.0201 mm on the tree, measured with its
    # tolerances under the power joints' share (tree_solve.MOTION_SHARE): 0.0910765 h at rtol 1e-8 (1.1e-3 from
    # the converged value), 0.0911745 at 1e-9 (4e-5), 0.0911806 at 1e-10 (1.5e-6); the reference engine 0.0911784
    # at its default rtol 1e-5 and 0.0911807 at 1e-9
    tighter = {"exudyn": ["--set", "solver.exudyn.relative_tolerance=1e-9"], "reference": []}
    for engine in ("reference", "exudyn"):
        run = _weftsim(capsys, "wear", "loom", "--engine", engine, "--hours", "0.3", "--limit-clearance-mm", "0.0201",
                       "--no-plot", "-o", str(tmp_path / engine), *tighter[engine])  # fmt: skip
        assert run.returncode == 0, run.stderr
        assert f"on the {engine} engine" in run.stderr
        out[engine] = json.loads((tmp_path / engine / "wear.json").read_text())
        assert out[engine]["engine"] == engine
        # the result checks itself on either engine: the profiles hold Archard's volume
        assert out[engine]["profile_volume_e_mm3"] == pytest.approx(out[engine]["archard_volume_e_mm3"], rel=1e-9)
    # 0.0201 mm is reached in the first update: its wear rate alone sets the hours (0.09118 h on the reference
    # engine under the cylindrical law; 0.1462 h under variable_kd).  1e-3: 25x the engines' difference at these
    # tolerances (4e-5, above)
    assert out["exudyn"]["hours_to_limit"] == pytest.approx(out["reference"]["hours_to_limit"], rel=1e-3)
    assert out["exudyn"]["updates"] == out["reference"]["updates"]


def test_a_worn_lubricated_joint_agrees_between_the_engines():
    """The loom with oil of 20 mPa s (the film ratio falls to ~3.9, the mixed regime's edge) on the worn joint,
    half a revolution: the film sees the local clearance on both engines (the worn spots raise the smallest
    film ratio from 3.86 to 3.91 on the reference engine), and the engines agree on the smallest film ratio and
    the largest film force."""
    from weftsim.input.scene import apply_overrides

    scene = apply_overrides(load_scene("loom"), {"joint_e.lubrication.viscosity_mpa_s": 20.0})
    worn = _worn(scene, 0.5)[0]
    out = {}
    for engine, solve in (("reference", door("reference")), ("exudyn", door("exudyn"))):
        result = solve(worn)
        assert result.ok, result.message
        out[engine] = (result.steps["film_ratio"].min(), result.steps["film_force_N"].max())
    # 1e-3: 5x the measured difference of the film ratio (2.0e-4; the film force 2.3e-5)
    assert out["exudyn"][0] == pytest.approx(out["reference"][0], rel=1e-3)
    assert out["exudyn"][1] == pytest.approx(out["reference"][1], rel=1e-3)
    round_scene = replace(scene, drive=replace(scene.drive, revolutions=0.5))
    assert door("reference")(round_scene).steps["film_ratio"].min() < 0.995 * out["reference"][0]


def test_cli_wear_to_the_limit_without_hours_ends_exactly_at_it(tmp_path, capsys):
    """``weftsim wear SCENE --limit-clearance-mm X`` (no --hours) predicts until the effective clearance reaches
    X: the crossing update is cut there, so the final clearance is X and the hours at the limit are the hours
    reached; run again, it resumes and ends at the same point."""
    out = tmp_path / "w"
    runs = []
    for _ in range(2):
        run = _weftsim(capsys, "wear", "reference", "--limit-clearance-mm", "0.26", "--no-plot", "-o", str(out))
        assert run.returncode == 0, run.stderr
        assert "until the clearance reaches 0.26 mm" in run.stderr
        runs.append(json.loads((out / "wear.json").read_text()))
    for data in runs:
        assert data["final_effective_clearance_e_mm"] == pytest.approx(0.26, rel=1e-12)
        assert data["hours_to_limit"] == pytest.approx(data["hours_reached"], rel=1e-12)
        assert "reaches the limit 0.26 mm" in data["ended"]
        assert data["profile_volume_e_mm3"] == pytest.approx(data["archard_volume_e_mm3"], rel=1e-9)
    assert runs[1]["hours_reached"] == runs[0]["hours_reached"]  # the resume re-simulates the last update


def test_a_state_of_one_engine_is_not_resumed_on_the_other(tmp_path, capsys):
    out = tmp_path / "w"
    first = _weftsim(capsys, "wear", "reference", "--hours", "0.5", "--no-plot", "-o", str(out))
    assert first.returncode == 0, first.stderr
    other = _weftsim(capsys, "wear", "reference", "--hours", "1", "--engine", "exudyn", "--no-plot", "-o", str(out))
    assert other.returncode == 2 and "on the reference engine" in other.stderr and "--engine reference" in other.stderr
    assert len(other.stderr.strip().splitlines()) == 1 and "Traceback" not in other.stderr


def _free_impact(joint, law, start: float, speed: float, end_time: float = 2e-4):
    """A mass-point journal moving along +x from (start, 0) at ``speed`` into a bearing on the ground (the reusable
    connector, generalized-alpha at rho = 1, h = 1e-7 s); returns (first contact time, largest F_N, final velocity)."""
    import exudyn as exu
    from exudyn.itemInterface import (
        MarkerBodyPosition, MarkerNodePosition, NodePoint2D, ObjectMassPoint2D, SensorObject,
    )  # fmt: skip

    from weftsim.exudyn_engine import add_clearance_joint

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.CreateGround()
    node = mbs.AddNode(NodePoint2D(referenceCoordinates=[start, 0.0], initialVelocities=[speed, 0.0]))
    mbs.AddObject(ObjectMassPoint2D(nodeNumber=node, mass=1.0))
    bearing = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    model = add_clearance_joint(mbs, bearing, mbs.AddMarker(MarkerNodePosition(nodeNumber=node)), joint, law=law)
    force = mbs.AddSensor(SensorObject(objectNumber=model.connector, outputVariableType=exu.OutputVariableType.Force,
                                       storeInternal=True, writeToFile=False))  # fmt: skip
    mbs.Assemble()
    model.reset(mbs)
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime, ti.numberOfSteps = end_time, round(end_time / 1e-7)
    ti.generalizedAlpha.spectralRadius = 1.0
    ti.discontinuous.ignoreMaxIterations = False
    ti.verboseMode = 0
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.0
    ss.solution.solverInformationFileName = ""
    assert exu.MainSolverImplicitSecondOrder().SolveSystem(mbs, ss)
    f = mbs.GetSensorStoredData(force)
    velocity = mbs.GetNodeOutput(node, exu.OutputVariableType.Velocity)[0]
    return model.tracker.first_contact_time, float(np.hypot(f[:, 1], f[:, 2]).max()), velocity


def test_the_reusable_connector_sees_a_worn_spot_as_the_clearance_there():
    """``add_clearance_joint`` on a joint worn at one spot of the bearing (0.5 c0 deep at 0 deg of the ground's
    frame): a journal moving straight into the spot meets the wall at c0 + h and rebounds as from a round joint
    of clearance c0 + h with the same law, to round-off (a mass point and the ground: both frames at angle 0)."""
    from weftsim.joint.contact import make_law
    from weftsim.input.params import ClearanceJoint

    c0, speed, gap = 0.25e-3, 0.5, 1e-6
    joint = ClearanceJoint(clearance=c0, law="variable_kd")
    psi = 2.0 * np.pi * np.arange(360) / 360
    spot = 0.5 * c0 * np.exp(-0.5 * (np.angle(np.exp(1j * psi)) / 0.3) ** 2)  # h(0) = 0.5 c0 exactly
    law = make_law(joint)
    worn = _free_impact(replace(joint, bearing_wear=tuple(spot)), law, 1.5 * c0 - gap, speed)
    wider = _free_impact(replace(joint, clearance=1.5 * c0), law, 1.5 * c0 - gap, speed)
    assert worn[0] == pytest.approx(gap / speed, rel=1e-9)  # the onset interpolation is exact in free flight
    for a, b in zip(worn, wider):
        assert a == pytest.approx(b, rel=1e-9)  # Catmull-Rom at a knot returns the knot's depth to round-off
    assert worn[2] < 0.0  # the journal came back from the worn wall
