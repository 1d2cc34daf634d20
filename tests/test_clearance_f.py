"""Clearance at F (rod 4 - sector 5), alone or with E (issue 13 section 2; docs/clearance-f.md).

The scene's [joint_f] table, the reference engine's chains (F alone: 2 DOF, the rod turning about E;
E and F: 4 DOF, the rod free), their energy balance and c -> 0 limit, the Exudyn rigid-body model with
its second clearance joint, and the agreement of the two engines on the reproducible quantities
(first contact, first-revolution maxima; docs/physics.md section 6).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from weftsim.post.analysis import time_weights
from weftsim.mechanism import kinematics as kin
from weftsim.input.params import ReferenceSolver, Scene
from conftest import door
solve = door("reference")
from weftsim.model.ideal import ideal_torque
from weftsim.post.results import CHANNELS, JOINT_F_CHANNELS
from weftsim.input.scene import SceneError, load_scene

MODELS = Path(__file__).resolve().parents[1] / "models"
BASE = dataclasses.replace(Scene(), reference_solver=ReferenceSolver(method="numba_DOP853", rtol=1e-9, atol=1e-12))
C = 0.25e-3  # m, the reference clearance


def _scene(c_e, c_f, revolutions=1.0, base=BASE):
    return dataclasses.replace(
        base,
        joint=dataclasses.replace(base.joint, clearance=c_e),
        joint_f=dataclasses.replace(base.joint, clearance=c_f),
        drive=dataclasses.replace(base.drive, revolutions=revolutions),
    )


CASES = {"F only": (0.0, C), "E and F": (C, C)}


@pytest.fixture(scope="module", params=list(CASES))
def one_revolution(request):
    return request.param, solve(_scene(*CASES[request.param]))


# --- scene ------------------------------------------------------------------------------------


def test_joint_f_table_gives_the_clearance_at_f():
    scene = load_scene(MODELS / "clearance_ef.toml")
    assert scene.loose_joints == ("e", "f") and scene.joint_f.clearance == pytest.approx(C)
    assert load_scene(MODELS / "clearance_f.toml").loose_joints == ("f",)
    # No [joint_f] table, or clearance_mm = 0 alone: the ideal joint at F, as before.
    assert load_scene(MODELS / "reference.toml").loose_joints == ("e",)
    ideal_f = load_scene(MODELS / "reference.toml", {"joint_f.clearance_mm": 0})
    assert ideal_f.joint_f.is_ideal and ideal_f.loose_joints == ("e",)


def _write(tmp_path, text):
    path = tmp_path / "scene.toml"
    path.write_text(f'extends = "{MODELS / "reference.toml"}"\n' + text)
    return path


@pytest.mark.parametrize("text, expected", [
    ("[joint_f]\nlaw = 'flores'\n", "key 'joint_f.law' describes the clearance joint at F, but joint F is ideal"),
    ("[joint_f]\nclearance_mm = -1\n", "key 'joint_f.clearance_mm' must be >= 0"),
    ("[joint_f]\nclearance_mn = 0.25\n", "unknown key 'joint_f.clearance_mn'"),
])
def test_bad_joint_f_tables_are_refused_in_one_line(tmp_path, text, expected):
    with pytest.raises(SceneError) as error:
        load_scene(_write(tmp_path, text))
    assert expected in str(error.value) and "\n" not in str(error.value)


def test_joint_f_cross_checks_name_joint_f():
    with pytest.raises(SceneError, match="key 'joint_f.law' must be one of"):
        load_scene(MODELS / "clearance_ef.toml", {"joint_f.law": "hertz"})
    with pytest.raises(SceneError, match="key 'joint_f.clearance_mm' must be smaller than the journal radius"):
        load_scene(MODELS / "clearance_ef.toml", {"joint_f.clearance_mm": 4, "joint_f.journal_radius_mm": 3})


def test_paths_that_cannot_carry_f_say_so():
    scipy = solve(_scene(0.0, C, 0.05, dataclasses.replace(BASE, reference_solver=ReferenceSolver(method="DOP853"))))
    assert scipy.status == "failed" and "cannot run a clearance at F" in scipy.message
    from weftsim import exudyn_engine
    from weftsim.exudyn_engine.selection import select_path

    scene = _scene(C, C, 0.05)
    tree = door("exudyn")(dataclasses.replace(
        scene, exudyn_solver=dataclasses.replace(scene.exudyn_solver, model="kinematic_tree")))
    assert tree.status == "failed" and "carries the clearance at E only" in tree.message
    path = select_path(scene)
    assert path["model"] == "rigid_body" and "clearance at F" in path["reason"]
    friction = _scene(C, C, 0.05)
    friction = dataclasses.replace(friction, joint_f=dataclasses.replace(friction.joint_f, friction_coefficient=0.1))
    assert "joint_f.friction_coefficient" in door("exudyn")(friction).message


# --- reference engine ------------------------------------------------------------------------


def _balance(ch):
    return (ch["driving_work_J"] - (ch["kinetic_energy_J"] - ch["kinetic_energy_J"][0])
            - (ch["potential_energy_J"] - ch["potential_energy_J"][0]) - ch["contact_energy_J"]
            - ch["dissipated_energy_J"])  # fmt: skip


def test_energy_balance_closes(one_revolution):
    """W = dKE + dPE + E_contact + D with both joints' contact energy and dissipation in the totals.

    Bound as for E alone (tests/test_reference_integrate.py): 100 rtol KE_max = 5e-5 J at rtol 1e-9
    and KE_max ~ 500 J.  Measured over one revolution: 4.1e-7 J (F only), 3.2e-8 J (E and F); a wrong
    lever, sign or missing inertia reaction of the rod at E leaves errors of the order of the
    dissipated energy (~14 J).
    """
    name, r = one_revolution
    assert r.ok, r.message
    scale = r.steps["kinetic_energy_J"].max()
    for ch in (r.steps, r.samples):
        assert np.abs(_balance(ch)).max() < 100 * r.scene.reference_solver.rtol * scale
    assert r.steps["dissipated_energy_J"][-1] > 1.0  # impacts happened and dissipated
    assert np.all(np.diff(r.steps["dissipated_energy_J"]) >= -1e-9)  # round-off of a monotone integral


def test_joint_f_channels(one_revolution):
    name, r = one_revolution
    st = r.steps
    # The joint's load of each loose joint (weftsim.joint.load) follows the contact channels.
    loads = ("joint_force_f_N",) if name == "F only" else ("joint_force_N", "joint_force_f_N")
    assert tuple(st) == CHANNELS + JOINT_F_CHANNELS + loads
    np.testing.assert_array_equal(st["joint_force_f_N"], st["contact_force_f_N"])  # dry and frictionless
    t_f = r.events["first_contact_time_f_s"]
    assert t_f is not None and 0.0 < t_f < r.scene.drive.period
    before = st["time_s"] < t_f
    assert np.all(st["penetration_f_m"][before] < 0.0) and not np.any(st["contact_force_f_N"][before])
    at = np.argmin(np.abs(st["time_s"] - t_f))
    assert abs(st["penetration_f_m"][at]) < 1e-12  # the onset located to 1e-13 s at ~0.2 m/s
    contact = st["in_contact_f"] > 0
    assert contact.any() and np.all(st["impact_velocity_f_m_s"][contact] >= r.scene.joint_f.min_impact_velocity)
    np.testing.assert_allclose(np.hypot(st["eccentricity_f_y_m"], st["eccentricity_f_z_m"]) - C,
                               st["penetration_f_m"], atol=1e-15)  # fmt: skip
    if name == "F only":  # E is ideal: its channels are zero
        assert not np.any(st["contact_force_N"]) and not np.any(st["penetration_m"])
        assert r.events["first_contact_time_e_s"] is None
    else:
        assert r.events["first_contact_time_e_s"] is not None and np.any(st["contact_force_N"] > 0.0)
    assert r.plausibility["onsets"] >= 1 and not r.plausibility["defects"]


@pytest.mark.parametrize("case", ["F only", "E and F"])
def test_friction_at_f_closes_the_energy_balance(case):
    """Modified Coulomb friction at F (mu = 0.1; reference engine only): its moments act on the rod
    (journal) and the sector (bearing), and its work enters the dissipated energy.  A moment on the wrong
    body or with the wrong arm breaks the balance by the order of the friction work (~5 J over 36 deg).
    Measured over 36 deg at rtol 1e-9: 6.5e-9 J (F only), 1.6e-9 J (E and F); bound as for E alone,
    100 rtol KE_max (2.5e-5 J).  Friction takes energy out: 9.8 J against 4.2 J without (F only)."""
    c_e, c_f = CASES[case]
    scene = _scene(c_e, c_f, 0.1)
    rough = dataclasses.replace(scene, joint_f=dataclasses.replace(scene.joint_f, friction_coefficient=0.1))
    r, smooth = solve(rough), solve(scene)
    assert r.ok and smooth.ok, (r.message, smooth.message)
    scale = r.steps["kinetic_energy_J"].max()
    assert np.abs(_balance(r.steps)).max() < 100 * r.scene.reference_solver.rtol * scale
    assert r.steps["dissipated_energy_J"][-1] > smooth.steps["dissipated_energy_J"][-1]


def test_e_only_results_have_no_joint_f_channels():
    r = solve(_scene(C, 0.0, 0.05))
    assert r.ok and tuple(r.steps) == CHANNELS + ("joint_force_N",) and "first_contact_time_f_s" not in r.events


def _errors_after_startup(result):
    """Time-weighted RMS of (acceleration, torque) minus the ideal mechanism over revolution 2."""
    st = result.steps
    theta = result.scene.drive.speed * st["time_s"]
    keep = theta >= 2.0 * math.pi
    w = time_weights(st["time_s"][keep])
    da = (st["rapier_acceleration_m_s2"] - kin.rapier_motion(theta, result.scene.drive.speed,
                                                             result.scene.geometry)[2])[keep]  # fmt: skip
    dt = (st["driving_torque_Nm"] - ideal_torque(theta, result.scene))[keep]
    return math.sqrt(np.dot(w, da * da) / w.sum()), math.sqrt(np.dot(w, dt * dt) / w.sum())


@pytest.mark.parametrize("case", ["F only", "E and F"])
def test_small_clearance_tends_to_the_ideal_mechanism(case):
    """c = 0.1, 0.01, 0.001 mm at F (E ideal), or at both: the errors against the ideal mechanism shrink.

    As for E alone (tests/test_reference_integrate.py) the limit is the compliant joint, not the ideal
    one: ~50 um of contact deflection remain as c -> 0.  Measured over revolution 2 (rtol 1e-9):
    F only 430 / 73 / 15.8 m/s^2 and 306 / 67 / 15.3 N m (E alone: 427 / 73 / 15.7 and 305 / 67 / 15.3);
    E and F 555 / 105 / 23.9 m/s^2 and 354 / 90 / 22.6 N m (two compliant joints in series).  Bounds:
    2.5 % and 5 % of the ideal amplitudes (1142.05 m/s^2, 505.43 N m), 1.2-2.2x above the floor.
    """
    errors = []
    for c in (1e-4, 1e-5, 1e-6):
        c_e, c_f = (0.0, c) if case == "F only" else (c, c)
        result = solve(_scene(c_e, c_f, 2.0))
        assert result.ok, result.message
        errors.append(_errors_after_startup(result))
    acc, torque = zip(*errors)
    assert acc[0] > acc[1] > acc[2] and torque[0] > torque[1] > torque[2]
    assert acc[2] < 0.025 * 1142.05 and torque[2] < 0.05 * 505.43


def test_e_only_kernel_path_is_unchanged_by_the_joint_f_block():
    """A scene with clearance at E alone runs through the same chain as before joint F existed: the
    kernel's topology E_ONLY calls weftsim.physics.chain.chain unchanged (bit for bit)."""
    from weftsim.physics import chain as kc
    from weftsim.physics import chain_f as kf
    from weftsim.model.dynamics import initial_state, pack_parameters

    scene = _scene(C, 0.0)
    prm = pack_parameters(scene)
    assert prm[kf.TOPOLOGY] == kf.E_ONLY
    y = initial_state(scene) + np.array([1e-4, -2e-4, 0.3, -0.2, 0.0, 0.0])
    a, b = np.empty(6), np.empty(6)
    kc.chain(prm, 0.01, y, True, 0.05, a)
    kf.rhs_any(prm, 0.01, y, 1, np.array([0.05, 0.0]), b)
    assert np.array_equal(a, b)


# --- both engines ----------------------------------------------------------------------------


def _agreement(c_e, c_f, revolutions):
    from weftsim import exudyn_engine
    from weftsim.post.compare import agreement_checks

    scene = load_scene(MODELS / "clearance_ef.toml", {"joint_e.clearance_mm": c_e * 1e3,
                                                       "drive.revolutions": revolutions})
    ref, exu = solve(scene), door("exudyn")(scene)
    assert ref.ok and exu.ok, (ref.message, exu.message)
    assert exu.path["model"] == "rigid_body"
    return ref, exu, agreement_checks(exu, ref)


@pytest.mark.parametrize("case", ["F only", "E and F"])
def test_engines_agree_on_the_first_contacts(case):
    """Both engines at their defaults over the first 36 deg (the first impacts): the first contact at
    each joint and the largest contact forces so far.  Measured: first contact 4.8e-5 deg (F only),
    2.8e-6 deg at E and 3.6e-5 deg at F (E and F); peak forces 2e-4 (F), 1.3e-5 / 1.7e-5 (E, F).  The
    bounds are the scene's [compare] tolerances (0.1 deg, 1 %), those weftsim compare decides on."""
    ref, exu, checks = _agreement(*CASES[case], 0.1)
    tol = ref.scene.compare
    assert abs(exu.first_contact_angle_deg - ref.first_contact_angle_deg) < math.degrees(tol.first_contact_angle)
    t_ref, t_exu = ref.events["first_contact_time_f_s"], exu.events["first_contact_time_f_s"]
    assert abs(t_ref - t_exu) * ref.scene.drive.speed < tol.first_contact_angle
    for name in ("contact_force_N", "contact_force_f_N") if case == "E and F" else ("contact_force_f_N",):
        a, b = exu.steps[name].max(), ref.steps[name].max()
        assert abs(a - b) < tol.first_revolution_peaks * b, name
    # Exudyn's balance with both joints' contact and dissipated energy in the totals: its trapezoid sums and
    # generalized-alpha's numerical damping, bounded as for E alone (tests/test_exudyn_engine.py) by 1e-3
    # of the dissipated energy; measured over 36 deg 3.4e-4 J of 4.2 J (F only), 2.3e-4 J of 1.5 J (E and F).
    st = exu.steps
    assert st["dissipated_energy_J"][-1] > 1.0
    assert np.max(np.abs(_balance(st))) < 1e-3 * st["dissipated_energy_J"][-1]


@pytest.mark.slow
@pytest.mark.parametrize("case", ["F only", "E and F"])
def test_engines_agree_on_the_first_revolution(case):
    """weftsim compare's checks over one revolution: first contact (at F too with E and F) and the
    first revolution's maxima of the joints' loads (joint_force_N / joint_force_f_N, what compare judges
    since issue 30; on these dry frictionless joints exactly the contact forces, asserted below), rapier
    acceleration and driving torque.  Measured (reference numba_DOP853 rtol 1e-5, Exudyn rigid-body
    adaptive 3e-10 m; unchanged by the merges): F only: first contact 4.8e-5 deg, maxima 2.0e-4 (load at
    F), 2.7e-4 (a), 2.7e-3 (T); E and F: 2.8e-6 / 3.6e-5 deg, maxima 1.3e-5 / 1.7e-5 (load at E / F),
    1.2e-4 (a), 1.5e-3 (T).  Tolerances: the scene's [compare] table."""
    ref, exu, checks = _agreement(*CASES[case], 1.0)
    names = [c["name"] for c in checks]
    assert "joint_force_f_N: first revolution max" in names
    assert ("first contact crank angle at F [deg]" in names) == (case == "E and F")
    assert ("joint_force_N: first revolution max" in names) == (case == "E and F")
    for result in (ref, exu):
        for load, contact in (("joint_force_N", "contact_force_N"), ("joint_force_f_N", "contact_force_f_N")):
            if load in result.steps:
                assert np.array_equal(result.steps[load], result.steps[contact])
    failed = [c for c in checks if not c["passed"]]
    assert not failed, failed
