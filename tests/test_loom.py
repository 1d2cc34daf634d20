"""The bundled `loom` mechanism (models/loom.toml; docs/physics.md, "The loom mechanism").

The design targets of its synthesis (scripts/loom_synthesis.py) are checked on the scene as loaded:
closure of the four-bar, the stroke the reed width and the selvedge timing ask for, the transmission
angles, the ideal pin loads against the bushing's limits; then a run at the defaults against the ideal
loads, both engines against each other over the start-up impact, and no plausibility warning.
"""

import math
import warnings

import numpy as np
import pytest

import weftsim
from weftsim.mechanism import kinematics as kin
from weftsim.checks.design_checks import after_run, before_run, running
from weftsim.mechanism.pin_loads import ideal_pin_loads

# Targets of the synthesis (docs/physics.md, "The loom mechanism").
REED_WIDTH = 1.90  # m
SELVEDGE_ANGLE = math.radians(60.0)  # out of the shed for a third of the cycle
MAX_RAPIER_ACCELERATION = 3000.0  # m/s2 (limits.max_rapier_acceleration_m_s2)
GRID = np.radians(np.arange(0.0, 360.0, 0.25))


@pytest.fixture(scope="module")
def loom():
    return weftsim.load_scene("loom")


def test_the_loom_is_a_bundled_scene():
    from weftsim.input.scene import bundled_scenes

    assert "loom" in bundled_scenes() and "reference" in bundled_scenes()


def test_four_bar_closes_and_is_the_parallelogram_of_the_synthesis(loom):
    g = loom.geometry
    st = kin.linkage_state(GRID, g, loom.inertia.rocker_com)
    # Loop O-E-F-G: |F - E| = L_EF at every crank angle (round-off of lengths of 0.3 m: 1e-15 m).
    rod = np.hypot(*(st.point_f - st.point_e).T)
    assert np.max(np.abs(rod - g.l_ef)) < 1e-12
    # A parallelogram turns the sector as the rocker: theta_FG = theta_OE, the rod keeps its direction.
    assert np.max(np.abs(st.theta_fg - st.theta_oe)) < 1e-12
    assert np.max(np.abs(st.d_theta_ef)) < 1e-12
    assert kin.assembly_problem(g) is None


def test_stroke_and_selvedge_timing_meet_the_reed_width(loom):
    g = loom.geometry
    beta = g.crank_inclination
    st = kin.linkage_state(np.array([SELVEDGE_ANGLE, math.pi]), g)
    stroke, selvedge = st.rapier_displacement[1], st.rapier_displacement[0]
    # Closed form of the parallelogram: s = (d5 d7 / d6) (phi(theta) - phi(0)), phi = -atan(tan beta cos theta).
    assert stroke == pytest.approx(g.rapier_ratio * 2.0 * beta, rel=1e-12)
    phi60 = -math.atan(math.tan(beta) * math.cos(SELVEDGE_ANGLE))
    assert selvedge == pytest.approx(g.rapier_ratio * (phi60 + beta), rel=1e-12)
    # From the selvedge (60 deg) to 180 deg the head crosses half the reed; the sector's teeth are rounded
    # up, so it reaches at most one tooth's worth of stroke further (module 3 mm: d7 / d6 x 1.5 mm x 2 beta).
    reach = stroke - selvedge
    one_tooth = 2.0 * beta * g.rapier_gear_pitch_radius / g.pinion_pitch_radius * 1.5e-3 * (1.0 - selvedge / stroke)
    assert REED_WIDTH / 2.0 <= reach <= REED_WIDTH / 2.0 + one_tooth
    # Symmetric: the head leaves the shed at 300 deg where it entered at 60 deg.
    back = kin.linkage_state(np.array([2.0 * math.pi - SELVEDGE_ANGLE]), g).rapier_displacement[0]
    assert back == pytest.approx(selvedge, rel=1e-12)


def test_transmission_angles_and_peak_acceleration(loom):
    g = loom.geometry
    st = kin.linkage_state(GRID, g)
    mu = np.degrees(st.transmission_angle)
    beta = math.degrees(g.crank_inclination)
    # The parallelogram's transmission angle at F is theta_OE: 90 -/+ beta, inside 40..140 deg.
    assert mu.min() == pytest.approx(90.0 - beta, abs=1e-6) and mu.max() == pytest.approx(90.0 + beta, abs=1e-6)
    assert 40.0 <= mu.min() and mu.max() <= 140.0
    peak = np.max(np.abs(st.dd_rapier_displacement)) * loom.drive.speed**2
    assert peak < MAX_RAPIER_ACCELERATION


def test_ideal_pin_loads_are_within_the_bushing_limits_at_the_nominal_speed(loom):
    loads = ideal_pin_loads(loom, "e")
    joint = loom.joint
    area = 2.0 * joint.journal_radius * joint.bearing_length
    assert np.max(loads.force) / area < joint.bearing_material.max_pressure
    assert not [c.message for c in before_run(loom) if c.verdict == "warning"]


@pytest.fixture(scope="module")
def default_run(loom):
    return weftsim.simulate(loom, engine="exudyn")


def test_run_at_the_defaults_carries_the_ideal_mean_load_and_warns_of_its_impacts(loom, default_run):
    assert default_run.ok, default_run.message
    s = default_run.samples
    rev2 = (s["time_s"] >= loom.drive.period) & (s["time_s"] < 2.0 * loom.drive.period)
    ideal = ideal_pin_loads(loom, "e")
    # At 20 um the pin bears on its bushing all through revolution 2 but near the two force reversals: its
    # mean force is the ideal joint's (Newton-Euler of the chain behind E) plus the impacts' share, measured
    # 0.5 % (9209 N against 9160 N; 0.4 % under the former variable_kd law); 2 % is four times that.
    assert float(np.mean(s["contact_force_N"][rev2])) == pytest.approx(float(np.mean(ideal.force)), rel=0.02)
    # The law changed (issue 37): the FE-checked cylindrical law is 3-15 times stiffer than the former
    # variable_kd on this pin, so the dry new joint's impacts at the two force reversals peak at about
    # 23 kN and 4500 m/s2 of rapier acceleration (11.7 kN and 2200 m/s2 before): above the rapier's
    # 3000 m/s2 and the bushing's 27.6 MPa of projected pin pressure.  Those two, and nothing else, warn.
    warned = sorted(c.name for c in after_run(default_run) if c.verdict == "warning")
    assert warned == ["pin_pressure", "rapier_acceleration"]


def test_design_checks_after_a_run_read_revolution_two_on(default_run):
    settled = running(default_run)
    period = default_run.scene.drive.period
    assert settled.steps["time_s"].min() >= period
    # Revolution 1's start-up impact (the journal starts centred) is the run's largest force; it is not judged.
    first = default_run.steps["time_s"] < period
    assert default_run.steps["contact_force_N"][first].max() > 2.0 * settled.steps["contact_force_N"].max()
    pressure = [c for c in after_run(default_run) if c.name == "pin_pressure"][0]
    area = 2.0 * default_run.scene.joint.journal_radius * default_run.scene.joint.bearing_length
    assert pressure.value == pytest.approx(settled.steps["contact_force_N"].max() / area, rel=1e-12)


@pytest.mark.parametrize("speed_rpm, clearance_mm", [(600, 0.02), (300, 0.1), (600, 0.05), (800, 0.25)])
def test_both_engines_agree_on_the_start_up_impact(speed_rpm, clearance_mm):
    """`weftsim compare loom` over one revolution agrees: the first contact, the first-revolution maxima of
    the joint's load joint_force_N (what compare judges since issue 30: film + asperities + dry law; on this
    dry frictionless joint exactly the contact force, asserted below) and rapier acceleration (the start-up
    impact's, reproducible: docs/physics.md section 6) and the driving torque's.  Measured under the
    cylindrical law over 300/600/800 rpm x 0.02..0.25 mm: first contact within 5.7e-8 deg, load and
    acceleration maxima within 1.5e-3 (was 5.1e-5 deg and 3.5e-3 under variable_kd).

    The driving torque's first-revolution maximum is special on the loom: the start-up impact (crank angle
    1-4 deg) falls where the spherical crank is near its dead point, so it hardly reaches the crank, and the
    torque's maximum comes from later impacts (16-58 deg).  Where the two engines reach it at crank angles
    further apart than the first-contact tolerance (300 rpm at 0.1 mm: 24.9 and 21.4 deg; at 600 rpm and
    0.05 mm both now reach it at 16.8 deg, 1.0e-3 apart) they drew different impacts of the chaotic
    sequence, and compare judges the start-up impact's torque maximum instead (7.7e-4 apart at 300 rpm and
    0.1 mm), listing the first-revolution one as not compared, with both angles."""
    from weftsim.post.compare import _max_angle_deg, compare_results

    scene = weftsim.load_scene("loom", speed_rpm=speed_rpm, clearance_mm=clearance_mm, revolutions=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", weftsim.PlausibilityWarning)  # worn joints warn; judged elsewhere
        ref = weftsim.simulate(scene, engine="reference")
        exu = weftsim.simulate(scene, engine="exudyn")
    assert ref.ok and exu.ok, (ref.message, exu.message)
    report = compare_results(exu, ref)
    checks = {c["name"]: c for c in report["checks"]}
    failed = [c for c in report["checks"] if not c["passed"]]
    if (speed_rpm, clearance_mm) == (800, 0.25):
        # Under the cylindrical law (issue 37) the impacts after the start-up one are hard enough at 800 rpm and
        # 0.25 mm that the torque's first-revolution maximum is a draw of the chaotic sequence on the Exudyn
        # engine, though both engines reach it at 40.4 deg: Exudyn's chaos runs (crank speed x (1 + k 1e-9),
        # k = 0..3) give 8888, 8949, 8795 and 8870 N m (at 40.4, 40.4, 34.7 and 45.3 deg), the reference engine
        # 8982 N m (1.0e-2 from Exudyn's; on the cylinder branch before the merges the band was 8821-9063 N m).
        # Tighter tolerances draw again: Exudyn 8940 (rtol 1e-8, at 45.4 deg) and 8859 N m (1e-9, 40.4 deg), the
        # reference 8962 and 8963 N m (1e-9, 1e-10, 45.4 deg).  compare judges it because the angles coincide
        # (its rule: weftsim.post.compare.set_by_different_impacts): that one check may fail here, and the
        # start-up impact's torque maximum, the reproducible one (1835.9 and 1835.3 N m), must agree.
        from weftsim.post.compare import startup_impact_max

        if failed and [c["name"] for c in failed] == ["driving_torque_Nm: first revolution max"]:
            se, sr = (startup_impact_max(r, "driving_torque_Nm") for r in (exu, ref))
            assert se == pytest.approx(sr, rel=scene.compare.first_revolution_peaks)
            failed = []
    assert not failed, failed
    for name in ("joint_force_N", "rapier_acceleration_m_s2"):
        assert f"{name}: first revolution max" in checks
    for result in (ref, exu):  # the dry frictionless joint carries exactly its contact force (weftsim.joint.load)
        assert np.array_equal(result.steps["joint_force_N"], result.steps["contact_force_N"])
    apart = abs(_max_angle_deg(exu, "driving_torque_Nm") - _max_angle_deg(ref, "driving_torque_Nm"))
    tolerance = np.degrees(scene.compare.first_contact_angle)
    judged = "start-up impact max" if apart > tolerance else "first revolution max"
    assert f"driving_torque_Nm: {judged}" in checks
    listed = any("driving_torque_Nm" in m["what"] for m in report["not_compared"])
    assert listed == (apart > tolerance)
    # The start-up impact is the first revolution's largest force, near the crank's dead point at 0 deg: the
    # free flight across the clearance takes 1-5 deg (the larger the clearance, the longer), the impact 1-2.
    for result in (ref, exu):
        at = result.steps["crank_angle_deg"][np.argmax(result.steps["contact_force_N"])]
        assert at < 10.0


def test_compare_at_the_defaults_agrees_on_every_check():
    """`weftsim compare loom` as it runs (2 revolutions, 600 rpm, c = 0.02 mm): every check, the torque's
    too (measured 4.9e-3 against 0.01)."""
    from weftsim.post.compare import agreement_checks

    scene = weftsim.load_scene("loom")
    ref, exu = weftsim.simulate(scene, engine="reference"), weftsim.simulate(scene, engine="exudyn")
    checks = agreement_checks(exu, ref)
    assert sum("first revolution" in c["name"] for c in checks) == 3
    failed = [c for c in checks if not c["passed"]]
    assert not failed, failed
