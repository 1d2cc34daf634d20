"""Plausibility checks of a scene before and after a run (issue 21; weftsim.mechanism.pin_loads, weftsim.checks.design_checks).

The ideal pin loads are checked against closed forms: the reflected mass against finite differences of the
kinematics (the rapier alone: m8 (ds/dv_E)^2), the pin forces against the power balance of the chain
behind E and against a massless rod (a two-force member), the sliding speed against finite differences of
the joint angles.  Each check fires on a scene made to cross its limit, with a message naming the scene
key, and stays silent in range.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import weftsim
from weftsim import reference
from weftsim.checks.design_checks import after_run, before_run, before_run_lines
from weftsim.errors import PlausibilityWarning
from weftsim.mechanism.kinematics import linkage_state, rapier_motion
from weftsim.mechanism.pin_loads import ideal_pin_loads, pin_forces, reflected_mass_e, reflected_mass_f, sliding_speed
from weftsim.input.scene import load_scene
from conftest import door

REFERENCE = Path(__file__).resolve().parents[1] / "models" / "reference.toml"
# Central differences of step H: truncation ~ H^2 x (third derivative) ~ 1e-10 relative, round-off ~ eps / H
# ~ 1e-11 on lengths of 0.1 m; 1e-6 is far above both and far below any error in a formula.
H = 1e-5
FD_RTOL = 1e-6


def checks_by_name(checks, stage="before"):
    return {(c.table, c.name): c for c in checks if c.stage == stage}


def fd(function, theta):
    return (function(theta + H) - function(theta - H)) / (2.0 * H)


@pytest.fixture(scope="module")
def scene():
    return load_scene(REFERENCE)


# --- Ideal pin loads ------------------------------------------------------------------------


def test_the_mass_reflected_to_f_is_the_sector_group_inertia_over_the_arm_squared(scene):
    """(J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2) / L_FG^2 = (0.025 + 0.0308 x 4.5^2 + 0.5 x 0.675^2) / 0.05^2."""
    assert reflected_mass_f(scene) == pytest.approx((0.025 + 0.0308 * 4.5**2 + 0.5 * 0.675**2) / 0.05**2, rel=1e-12)
    assert reflected_mass_f(scene) == pytest.approx(350.605, abs=1e-3)


def test_with_only_the_rapier_massive_the_mass_at_e_is_m8_times_ds_dve_squared(scene):
    """Every other member massless: m_eff,E = m8 (ds/dv_E)^2, with ds/dtheta and |dE/dtheta| from finite
    differences of the positions (rapier_motion, linkage_state), away from the rocker's reversals."""
    massless = dataclasses.replace(scene.inertia, rod_mass=0.0, rod_inertia=0.0, sector_inertia=0.0,
                                   pinion_gear_inertia=0.0, rapier_mass=0.37)
    only_rapier = dataclasses.replace(scene, inertia=massless)
    theta = np.linspace(0.0, 2.0 * np.pi, 361)[:-1]
    ds = fd(lambda t: rapier_motion(t, 1.0, scene.geometry)[0], theta)
    de = fd(lambda t: linkage_state(t, scene.geometry).point_e, theta)
    speed_e = np.hypot(*de.T)
    moving = speed_e > 0.2 * speed_e.max()
    expected = 0.37 * (ds[moving] / speed_e[moving]) ** 2
    np.testing.assert_allclose(reflected_mass_e(theta[moving], only_rapier), expected, rtol=FD_RTOL)


def test_the_mass_reflected_to_e_is_twice_the_kinetic_energy_behind_e_over_ve_squared(scene):
    """All members 4-8 massive: T = (m4 |dC4|^2 + J4 dEF^2 + J_s dFG^2) / 2 from finite differences of the
    positions and angles, over |dE|^2."""
    m = scene.inertia
    theta = np.linspace(0.0, 2.0 * np.pi, 361)[:-1]
    state = lambda t: linkage_state(t, scene.geometry, m.rocker_com)  # noqa: E731
    d_com = fd(lambda t: state(t).rod_com, theta)
    d_ef = fd(lambda t: state(t).theta_ef, theta)
    d_fg = fd(lambda t: state(t).theta_fg, theta)
    de = np.hypot(*fd(lambda t: state(t).point_e, theta).T)
    moving = de > 0.2 * de.max()
    j_s = m.sector_inertia + m.pinion_gear_inertia * 4.5**2 + m.rapier_mass * 0.675**2
    energy = m.rod_mass * np.sum(d_com**2, axis=-1) + m.rod_inertia * d_ef**2 + j_s * d_fg**2
    np.testing.assert_allclose(reflected_mass_e(theta[moving], scene), energy[moving] / de[moving] ** 2, rtol=FD_RTOL)
    assert reflected_mass_e(theta, scene).max() == pytest.approx(548.6, abs=0.1)  # reference, at 0.5 deg


def test_the_pin_force_at_e_delivers_the_power_of_the_chain_behind_it(scene):
    """F_E . v_E = dT/dt + m4 g v_C4,z at every crank angle (T of members 4-8); to round-off."""
    m, w = scene.inertia, scene.drive.speed
    theta = np.linspace(0.0, 2.0 * np.pi, 721)[:-1]
    f_e, f_s = pin_forces(theta, scene)
    st = linkage_state(theta, scene.geometry, m.rocker_com)
    j_s = m.sector_inertia + m.pinion_gear_inertia * 4.5**2 + m.rapier_mass * 0.675**2
    d_energy = w**3 * (m.rod_mass * np.sum(st.d_rod_com * st.dd_rod_com, axis=-1)
                       + m.rod_inertia * st.d_theta_ef * st.dd_theta_ef + j_s * st.d_theta_fg * st.dd_theta_fg)
    power = w * np.sum(f_e * st.d_point_e, axis=-1) - m.rod_mass * m.gravity * w * st.d_rod_com[:, 1]
    scale = np.max(np.abs(d_energy))
    assert np.max(np.abs(power - d_energy)) < 1e-12 * scale  # measured 7e-16
    # F_s . v_F = J_s omega_FG alpha_FG: the sector group takes only the power the rod gives it at F.
    np.testing.assert_allclose(w * np.sum(f_s * st.d_point_f, axis=-1),
                               j_s * w**3 * st.d_theta_fg * st.dd_theta_fg, rtol=0, atol=1e-12 * scale)


def test_a_massless_rod_is_a_two_force_member(scene):
    """No rod mass or inertia: the rod pushes along itself, the same force at E and F."""
    light = dataclasses.replace(scene, inertia=dataclasses.replace(scene.inertia, rod_mass=0.0, rod_inertia=0.0))
    theta = np.linspace(0.0, 2.0 * np.pi, 181)[:-1]
    f_e, f_s = pin_forces(theta, light)
    st = linkage_state(theta, scene.geometry)
    d = st.point_f - st.point_e
    np.testing.assert_allclose(f_e, f_s, rtol=0, atol=1e-9 * np.abs(f_s).max())
    cross = d[:, 0] * f_s[:, 1] - d[:, 1] * f_s[:, 0]
    assert np.max(np.abs(cross)) < 1e-12 * np.abs(f_s).max() * scene.geometry.l_ef


def test_the_sliding_speed_is_the_radius_times_the_relative_turn_rate(scene):
    """R_j omega |d(theta_EF - theta_OE)/dtheta| at E, R_j omega |d(theta_EF - theta_FG)/dtheta| at F."""
    theta = np.linspace(0.1, 6.2, 200)
    state = lambda t: linkage_state(t, scene.geometry)  # noqa: E731
    rel_e = fd(lambda t: state(t).theta_ef - state(t).theta_oe, theta)
    rel_f = fd(lambda t: state(t).theta_ef - state(t).theta_fg, theta)
    w = scene.drive.speed
    np.testing.assert_allclose(sliding_speed(theta, scene, "e", 0.01), 0.01 * w * np.abs(rel_e), rtol=FD_RTOL,
                               atol=1e-9)
    np.testing.assert_allclose(sliding_speed(theta, scene, "f", 0.015), 0.015 * w * np.abs(rel_f), rtol=FD_RTOL,
                               atol=1e-9)


def test_the_ideal_pin_force_grows_with_the_square_of_the_speed_less_gravity(scene):
    """Inertial loads scale as omega^2: without gravity, the peak at 800 rpm is 4 x that at 400 rpm."""
    flat = dataclasses.replace(scene, inertia=dataclasses.replace(scene.inertia, gravity=0.0))
    fast = dataclasses.replace(flat, drive=dataclasses.replace(flat.drive, speed=2.0 * flat.drive.speed))
    assert ideal_pin_loads(fast, "e").force.max() == pytest.approx(4.0 * ideal_pin_loads(flat, "e").force.max(),
                                                                   rel=1e-12)


# --- Checks before the run -------------------------------------------------------------------


def test_the_reference_scene_before_its_run(scene):
    """Numbers of the reference mechanism at 400 rpm; only its clearance (12.5 per mille) warns."""
    checks = checks_by_name(before_run(scene))
    assert checks[("joint_e", "reflected_mass")].verdict == "info"
    assert checks[("joint_e", "clearance_ratio")].value == pytest.approx(0.0125)
    assert checks[("joint_e", "pin_pressure")].numbers["peak_force_n"] == pytest.approx(38.5e3, rel=1e-3)
    assert checks[("joint_e", "pin_pressure")].verdict == "no_limit"  # the scene gives no bushing limit
    assert checks[(None, "rapier_acceleration")].value == pytest.approx(1142.0, abs=1.0)
    warned = [c for c in before_run(scene) if c.verdict == "warning"]
    assert [c.name for c in warned] == ["clearance_ratio"]
    assert "joint_e.design_clearance_per_mille" in warned[0].message and "12.5 per mille" in warned[0].message


def test_the_before_run_checks_are_each_scenes_own(scene):
    """A run reads its scene's before-run checks twice and the second reuses the first; a scene changed in
    speed (a new object) gets its own: the ideal loads scale with the speed squared (400 -> 800 rpm: 4x the
    rapier's peak acceleration, the pin force's inertial part alike), the same scene its same numbers."""
    first = checks_by_name(before_run(scene))
    fast = dataclasses.replace(scene, drive=dataclasses.replace(scene.drive, speed=2.0 * scene.drive.speed))
    quick = checks_by_name(before_run(fast))
    again = checks_by_name(before_run(scene))
    peak = (None, "rapier_acceleration")
    assert quick[peak].value == pytest.approx(4.0 * first[peak].value, rel=1e-12)
    assert {k: c.as_dict() for k, c in again.items()} == {k: c.as_dict() for k, c in first.items()}
    assert checks_by_name(before_run(fast))[peak].value == quick[peak].value


@pytest.mark.parametrize("overrides, name, key, words", [
    ({"joint_e.bearing_material.max_pressure_mpa": 50.0}, "pin_pressure",
     "joint_e.bearing_material.max_pressure_mpa", "96.33 MPa"),
    ({"joint_e.bearing_material.max_pv_mpa_m_s": 1.75}, "pv", "joint_e.bearing_material.max_pv_mpa_m_s", "1.75"),
    ({"joint_e.journal_material.yield_strength_mpa": 100.0}, "hertz_pressure",
     "joint_e.*_material.yield_strength_mpa", "first yield 167 MPa"),
    ({"limits.max_rapier_acceleration_m_s2": 1000.0}, "rapier_acceleration",
     "limits.max_rapier_acceleration_m_s2", "1142 m/s2"),
    ({"joint_e.clearance_mm": 0.005}, "clearance_ratio", "joint_e.design_clearance_per_mille", "tighter"),
    ({"joint_e.journal_radius_mm": 3.0, "joint_e.bearing_material.max_pressure_mpa": 300.0}, "pin_pressure",
     "joint_e.journal_radius_mm", "6 x 20 mm pin"),
])
def test_each_before_run_check_fires_past_its_limit_naming_the_key(overrides, name, key, words):
    checks = [c for c in before_run(load_scene(REFERENCE, overrides)) if c.verdict == "warning" and c.name == name]
    assert len(checks) == 1
    assert key in checks[0].message and words in checks[0].message, checks[0].message


@pytest.mark.parametrize("overrides", [
    {"joint_e.bearing_material.max_pressure_mpa": 200.0, "joint_e.bearing_material.max_pv_mpa_m_s": 5.0,
     "joint_e.journal_material.yield_strength_mpa": 600.0, "limits.max_rapier_acceleration_m_s2": 3000.0,
     "joint_e.clearance_mm": 0.015},
    # A bushed 30 x 30 mm pin at 20 um radial clearance (0.67 per mille of its diameter): the design range.
    {"joint_e.journal_radius_mm": 15.0, "joint_e.bearing_length_mm": 30.0, "joint_e.clearance_mm": 0.02},
])
def test_no_before_run_check_fires_in_range(overrides):
    assert [c.message for c in before_run(load_scene(REFERENCE, overrides)) if c.verdict == "warning"] == []


def test_joint_f_is_checked_when_it_has_a_clearance():
    scene = load_scene(REFERENCE.parent / "clearance_ef.toml", {"joint_f.bearing_material.max_pressure_mpa": 10.0})
    checks = checks_by_name(before_run(scene))
    assert checks[("joint_f", "reflected_mass")].value == pytest.approx(reflected_mass_f(scene))
    assert checks[("joint_f", "pin_pressure")].verdict == "warning"
    assert "joint_f.bearing_material.max_pressure_mpa" in checks[("joint_f", "pin_pressure")].message
    assert checks[("joint_e", "pin_pressure")].verdict == "no_limit"
    assert not [c for c in before_run(load_scene(REFERENCE)) if c.table == "joint_f"]  # F ideal: not judged


def test_simulate_reports_the_before_run_warnings_before_it_starts():
    scene = load_scene(REFERENCE, {"drive.revolutions": 0.02, "limits.max_rapier_acceleration_m_s2": 1000.0})
    seen = []
    result = weftsim.simulate(scene, "reference", on_warning=seen.append,
                              progress=lambda done: seen.append(f"progress {done}"))
    assert seen[0].startswith("joint_e: radial clearance") and "limits.max_rapier_acceleration_m_s2" in seen[1]
    assert all(line.startswith("progress") for line in seen[2:])
    with pytest.warns(PlausibilityWarning) as caught:
        weftsim.simulate(scene, "reference")
    assert [str(w.message) for w in caught] == seen[:2]
    in_range = load_scene(REFERENCE, {"drive.revolutions": 0.02, "joint_e.clearance_mm": 0.015})
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        weftsim.simulate(in_range, "reference")
    checks = weftsim.plausibility_checks(scene)
    assert [c["name"] for c in checks] == [c["name"] for c in result.plausibility["checks"] if c["stage"] == "before"]
    summary, *warned = before_run_lines(scene)
    assert warned == [f"warning: {c['message']}" for c in checks if c["verdict"] == "warning"]
    # One line of numbers first: the reflected mass, which no limit judges, is on stderr too.
    assert summary.startswith("design checks before the run") and "reflected mass 548.6 kg peak" in summary
    assert "rapier acceleration 1142 m/s2 peak (limit 1000)" in summary


# --- Checks after the run --------------------------------------------------------------------


@pytest.fixture(scope="module")
def run():
    """A tenth of a revolution of the reference scene: the start-up impact (132 kN at 6.6 deg)."""
    return door("reference")(load_scene(REFERENCE, {"drive.revolutions": 0.1}))


def with_scene(result, overrides):
    return dataclasses.replace(result, scene=load_scene(REFERENCE, {"drive.revolutions": 0.1, **overrides}))


def test_the_after_run_pressures_are_read_from_the_joints_load(run):
    """Pin pressure and p x v from the load the joint carries (joint_force_N: for this dry frictionless joint its
    contact force), Hertz's pressure from the dry law's contact force."""
    checks = checks_by_name(after_run(run), "after")
    np.testing.assert_array_equal(run.steps["joint_force_N"], run.steps["contact_force_N"])
    force = run.steps["joint_force_N"]
    pressure = checks[("joint_e", "pin_pressure")]
    assert pressure.numbers["peak_force_n"] == force.max()
    assert pressure.value == pytest.approx(force.max() / (0.02 * 0.02), rel=1e-12)
    assert pressure.numbers["mean_pa"] == pytest.approx(run.samples["joint_force_N"].mean() / 4e-4, rel=1e-12)
    v = sliding_speed(np.radians(run.samples["crank_angle_deg"]), run.scene, "e", 0.01)
    assert checks[("joint_e", "pv")].value == pytest.approx(np.mean(run.samples["joint_force_N"] * v) / 4e-4,
                                                            rel=1e-12)
    assert checks[(None, "rapier_acceleration")].value == np.max(np.abs(run.steps["rapier_acceleration_m_s2"]))
    assert checks[("joint_e", "penetration")].limit is None  # variable_kd: no bound on delta / c


@pytest.mark.parametrize("overrides, name, key", [
    ({"joint_e.bearing_material.max_pressure_mpa": 200.0}, "pin_pressure", "joint_e.bearing_material.max_pressure_mpa"),
    ({"joint_e.bearing_material.max_pv_mpa_m_s": 0.5}, "pv", "joint_e.bearing_material.max_pv_mpa_m_s"),
    ({"limits.max_rapier_acceleration_m_s2": 3000.0}, "rapier_acceleration", "limits.max_rapier_acceleration_m_s2"),
])
def test_each_after_run_check_fires_past_its_limit_naming_the_key(run, overrides, name, key):
    (check,) = [c for c in after_run(with_scene(run, overrides)) if c.name == name]
    assert check.verdict == "warning" and key in check.message and "the run" in check.message


def test_no_after_run_check_fires_in_range(run):
    generous = with_scene(run, {"joint_e.bearing_material.max_pressure_mpa": 1000.0,
                                "joint_e.bearing_material.max_pv_mpa_m_s": 100.0,
                                "limits.max_rapier_acceleration_m_s2": 1e4})
    assert [c.message for c in after_run(generous) if c.verdict == "warning"] == []
    assert not math.isnan(sum(c.value for c in after_run(generous)))


def test_a_run_of_two_revolutions_is_judged_on_its_second_and_the_law_on_the_whole_run():
    """Revolution 1 holds the start-up impact of the centred journal (the reference scene: 239 kN at
    6.6 deg); the machine's loads are judged from revolution 2 on, the law's range over the whole run."""
    run = door("reference")(load_scene(REFERENCE))
    period = run.scene.drive.period
    later = run.steps["time_s"] >= period
    checks = checks_by_name(after_run(run), "after")
    pressure = checks[("joint_e", "pin_pressure")]
    assert pressure.numbers["from_time_s"] >= period
    assert pressure.numbers["peak_force_n"] == run.steps["contact_force_N"][later].max()
    assert pressure.numbers["peak_force_n"] < 0.9 * run.steps["contact_force_N"].max()  # the start-up is larger
    rapier = checks[(None, "rapier_acceleration")]
    assert rapier.value == np.max(np.abs(run.steps["rapier_acceleration_m_s2"][later]))
    hertz = checks[("joint_e", "hertz_pressure")]
    assert hertz.numbers["peak_force_n"] == run.steps["contact_force_N"].max()
    assert hertz.value == run.plausibility["peak_pressure_pa"]  # the same number plausibility.assess judges
    assert checks[("joint_e", "penetration")].value == run.plausibility["max_penetration_over_clearance"]


def test_a_warning_of_a_run_shorter_than_two_revolutions_says_the_start_up_impact_counts(run):
    """The tenth of a revolution holds the start-up impact only: the warning says so and names drive.revolutions."""
    (check,) = [c for c in after_run(with_scene(run, {"limits.max_rapier_acceleration_m_s2": 3000.0}))
                if c.name == "rapier_acceleration"]
    assert check.verdict == "warning" and "start-up impact" in check.message and "drive.revolutions" in check.message


@pytest.mark.parametrize("name", ["reference", "loom"])
def test_the_interpolated_sliding_speed_is_the_linkage_s(name):
    """The after-run checks read the ideal sliding speed from a table of one revolution (0.05 deg):
    measured within 1.6e-7 of the peak against the linkage solved at each angle (pins E and F, 200 000
    angles over 20 revolutions); 2e-6 is the grid's curvature bound."""
    from weftsim.mechanism.pin_loads import sliding_speed, sliding_speed_at

    scene = load_scene(name)
    theta = np.random.default_rng(1).uniform(0.0, 40.0 * np.pi, 20000)
    for joint in ("e", "f"):
        exact = sliding_speed(theta, scene, joint, scene.joint.journal_radius)
        table = sliding_speed_at(theta, scene, joint, scene.joint.journal_radius)
        assert np.abs(table - exact).max() < 2e-6 * exact.max()
def test_the_oiled_loom_presses_its_pin_as_the_dry_loom_does():
    """Issue 30: with oil the film carries the pin's load, so the design checks read it (they read 0 MPa when
    they counted the dry law alone).  The loom at 600 rpm, c = 0.02 mm, 80 mPa s (a full film, minimum film
    ratio 8.8): the mean pin pressure over revolution 2 equals the dry loom's within 2 % (measured 10.18 against
    10.22 MPa, 0.4 %: the dry joint's impacts add a little), and the film's Hertz pressure is none (no contact)."""
    law = {"joint_e.law": "variable_kd"}  # explicit: the bundled loom's default law may change (issue 37)
    dry = weftsim.simulate(weftsim.load_scene("loom", law), engine="reference")
    oiled = weftsim.simulate(weftsim.load_scene("loom", {**law, "joint_e.lubrication.viscosity_mpa_s": 80.0}),
                             engine="reference")
    assert dry.ok and oiled.ok, (dry.message, oiled.message)
    dry_checks, oil_checks = checks_by_name(after_run(dry), "after"), checks_by_name(after_run(oiled), "after")
    dry_mean = dry_checks[("joint_e", "pin_pressure")].numbers["mean_pa"]
    oil_mean = oil_checks[("joint_e", "pin_pressure")].numbers["mean_pa"]
    assert oil_mean == pytest.approx(dry_mean, rel=0.02)
    assert oil_checks[("joint_e", "pin_pressure")].value == pytest.approx(
        dry_checks[("joint_e", "pin_pressure")].value, rel=0.02)  # peak: 12.82 against 12.99 MPa
    assert oil_checks[("joint_e", "pv")].value == pytest.approx(dry_checks[("joint_e", "pv")].value, rel=0.02)
    assert oil_checks[("joint_e", "hertz_pressure")].value == 0.0
