"""The steady plain bearing, its oil and its heat balance (weftsim.joint.steady, .film_flow, .oil, .heat, .bearing;
``weftsim bearing``): against Raimondi and Boyd's full journal bearing, a worked example, closure of the heat
balance, and the scene keys and refusals."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from weftsim.errors import SceneError
from weftsim.input.params import ClearanceJoint, Lubrication
from weftsim.joint.film_flow import flow_variables, flows
from weftsim.joint.heat import heat_balance
from weftsim.physics.oil import ISO_VG, Oil, grade_oil, walther_kinematic
from weftsim.joint.reynolds import RAIMONDI_BOYD
from weftsim.joint.steady import steady_point

# Raimondi and Boyd (ASLE Trans. 1, 1958), full journal bearing, B/D = 1, as the machine-design textbooks reproduce
# it (Shigley's Mechanical Engineering Design, the table of dimensionless performance parameters): eccentricity
# ratio -> (friction variable (R/c) f, flow variable Q / (R c N L), side-flow ratio Qs / Q, temperature-rise
# variable rho c_p dT / P).  The rows whose four columns satisfy the table's own identity
# rho c dT / P = 4 pi (R/c) f / ((Q/RcNL)(1 - Qs/2Q)) to 0.3 %.
RB_FULL = {0.1: (26.4, 3.37, 0.150, 106.0), 0.2: (12.8, 3.59, 0.280, 52.1), 0.4: (5.79, 3.99, 0.497, 24.3),
           0.6: (3.22, 4.33, 0.680, 14.2), 0.8: (1.70, 4.62, 0.842, 8.00)}

# A bearing of the same form to evaluate them on (the variables are dimensionless: any numbers do).
RADIUS, CLEARANCE, LENGTH, ETA, OMEGA = 0.02, 2e-5, 0.04, 0.05, 100.0


def _joint(**lubrication) -> ClearanceJoint:
    """A smooth journal bearing (no asperity contact: Raimondi and Boyd's rigid smooth film)."""
    lub = {"viscosity": ETA, "roughness": 1e-9, "asperity_density_radius_roughness": 0.0, **lubrication}
    return ClearanceJoint(clearance=CLEARANCE, journal_radius=RADIUS, bearing_length=LENGTH, law="variable_kd",
                          lubrication=Lubrication(**lub))


def _load_of(sommerfeld: float) -> float:
    """W of Sommerfeld number S = (R/c)^2 eta N / P on the bearing above."""
    return (RADIUS / CLEARANCE) ** 2 * ETA * OMEGA / (2.0 * math.pi) / sommerfeld * 2.0 * RADIUS * LENGTH


def test_the_film_flows_are_raimondi_and_boyds():
    for eps, (_, inlet, side_ratio, _) in RB_FULL.items():
        q, qs = flows(eps, 1.0)
        # Measured: inlet within 0.3 %, side-flow ratio within 0.3 % (the table's 3 digits: 0.1-0.3 %).
        assert q == pytest.approx(inlet, rel=5e-3)
        assert qs / q == pytest.approx(side_ratio, rel=5e-3, abs=1e-3)
        # The interpolated table matches the direct solve (cubic in u: measured 1e-4).
        assert flow_variables(eps, 1.0) == pytest.approx((q, qs), rel=2e-3)
    assert flows(0.0, 1.0) == (math.pi, 0.0)  # Petroff's centred film: Q = pi R c N L, no side flow


def test_the_steady_bearing_carries_raimondi_and_boyds_loads_where_they_say():
    """Solving the kernel's force for the eccentricity that carries a load of Sommerfeld number S gives the table's
    eccentricity ratio and attitude angle, and its friction variable."""
    joint = _joint()
    for eps, sommerfeld, attitude in RAIMONDI_BOYD[1.0]:
        point = steady_point(joint, _load_of(sommerfeld), OMEGA, ETA)
        assert point.sommerfeld == pytest.approx(sommerfeld, rel=1e-12)
        # Measured: eps within 0.8 % (0.3967 for 0.4), attitude within 0.35 deg: the kernel's table against theirs.
        assert point.eccentricity_ratio == pytest.approx(eps, rel=0.015)
        assert point.attitude_angle_deg == pytest.approx(attitude, abs=0.6)
        assert point.regime == "hydrodynamic" and point.asperity_load_n == 0.0 and point.dry_force_n == 0.0
        if eps in RB_FULL:  # measured within 1.1 % (5.853 for 5.79 at eps 0.4)
            assert point.friction_coefficient * RADIUS / CLEARANCE == pytest.approx(RB_FULL[eps][0], rel=0.02)
        # Steady running: the drive's power is the film's dissipation, P = T omega.
        assert point.power_loss_w == pytest.approx(point.friction_torque_nm * OMEGA, rel=1e-12)


def test_raimondi_and_boyds_temperature_rise_is_reproduced():
    """The adiabatic fed bearing (all heat to the oil flow, fixed viscosity): rho c_p dT / P of the table within 5 %
    (measured 0.3-1.2 %), through the heat balance's root finder."""
    oil = Oil("custom", 100e-6, 10e-6, density_15c=870.0, heat_capacity=1900.0)
    joint = _joint()
    for eps, (_, _, _, rise) in RB_FULL.items():
        sommerfeld = next(s for e, s, _ in RAIMONDI_BOYD[1.0] if e == eps)
        load = _load_of(sommerfeld)
        balance = heat_balance(joint, load, OMEGA, viscosity=lambda t: ETA, oil=oil, ambient=20.0, housing=0.0,
                               supply="fed")
        rho = float(oil.density(balance.temperature_c))
        pressure = load / (2.0 * RADIUS * LENGTH)
        d_t = 2.0 * (balance.temperature_c - 20.0)
        assert rho * oil.heat_capacity * d_t / pressure == pytest.approx(rise, rel=0.05)
        assert abs(balance.residual) < 1e-6


def test_the_worked_example_of_shigleys_bearing():
    """The bearing of Shigley's Examples 12-1 to 12-3 (r = 0.75 in, c = 0.0015 in, l = 1.5 in, W = 500 lbf, N = 30
    rev/s, mu = 4 ureyn): the charts give S = 0.135, h_min = 0.000630 in, attitude 53 deg, (r/c) f = 3.50,
    Q = 0.217 in^3/s, Qs = 0.142 in^3/s, and with them Raimondi and Boyd's temperature rise
    dT = 0.103 P (r/c) f / ((1 - Qs/2Q) Q/(r c N l)) = 27.8 F (P in psi): weftsim within 5 % of each."""
    inch, lbf, reyn = 0.0254, 4.4482216, 6894.757
    r, c, length, load, n, mu = 0.75 * inch, 0.0015 * inch, 1.5 * inch, 500 * lbf, 30.0, 4e-6 * reyn
    joint = ClearanceJoint(clearance=c, journal_radius=r, bearing_length=length, law="variable_kd",
                           lubrication=Lubrication(viscosity=mu, roughness=1e-9, asperity_density_radius_roughness=0.0))
    point = steady_point(joint, load, 2.0 * math.pi * n, mu)
    assert point.sommerfeld == pytest.approx(0.135, rel=0.01)
    assert point.min_film_m / inch == pytest.approx(0.000630, rel=0.05)  # measured 0.000632
    assert point.attitude_angle_deg == pytest.approx(53.0, rel=0.05)
    assert point.friction_coefficient * r / c == pytest.approx(3.50, rel=0.05)
    assert point.inlet_flow_m3_s / inch**3 == pytest.approx(0.217, rel=0.05)
    assert point.side_flow_m3_s / inch**3 == pytest.approx(0.142, rel=0.05)
    # The temperature rise of the same bearing through weftsim's heat balance (adiabatic, Shigley's oil constants
    # rho c_p = 0.0311 lbf/in^3 x 0.42 Btu/(lbf F), which make his 0.103 factor).
    oil = Oil("custom", 100e-6, 10e-6, density_15c=0.0311 * lbf / inch**3 / 9.80665, heat_capacity=0.42 * 4186.8)
    balance = heat_balance(joint, load, 2.0 * math.pi * n, viscosity=lambda t: mu, oil=replace(oil),
                           ambient=15.0, housing=0.0, supply="fed")
    rho_c = 0.0311 * lbf / inch**3 / 9.80665 * 0.42 * 4186.8  # the constant Shigley's factor holds
    rise = balance.friction_power_w / (rho_c * (point.inlet_flow_m3_s - 0.5 * point.side_flow_m3_s))
    assert 1.8 * rise == pytest.approx(27.8, rel=0.05)
    assert 1.8 * 2.0 * (balance.temperature_c - 15.0) == pytest.approx(27.8, rel=0.05)


def test_the_heat_balance_closes_with_the_oils_viscosity():
    """Power in = heat out at the converged film temperature (to 1e-6; measured ~1e-14) for a grade on the loom's
    pin, fed and self-contained, and the viscosity is the oil's there."""
    from weftsim.input.scene import load_scene
    from weftsim.joint.bearing import mean_operating_point

    scene = load_scene("loom")
    mean, _, omega = mean_operating_point(scene, "e")
    for supply in ("fed", "sump"):
        lub = Lubrication(viscosity=0.0, oil="ISO VG 220", ambient_temperature=40.0, oil_supply=supply)
        joint = replace(scene.joint, lubrication=lub)
        balance = heat_balance(joint, mean, omega)
        assert abs(balance.residual) < 1e-6
        assert balance.temperature_c > 40.0
        assert balance.viscosity_pa_s == pytest.approx(float(lub.oil_model.viscosity(balance.temperature_c)),
                                                       rel=1e-12)
        assert (balance.oil_heat_w > 0.0) == (supply == "fed")
    # A hotter hall runs a hotter, thinner film.
    cool = heat_balance(replace(scene.joint, lubrication=replace(lub, ambient_temperature=20.0)), mean, omega)
    assert cool.temperature_c < balance.temperature_c and cool.viscosity_pa_s > balance.viscosity_pa_s


def test_walther_is_written_once_and_the_grades_hold_their_points():
    from weftsim.wear.uncertain import walther_viscosity

    t = np.array([25.0, 60.0, 90.0])
    oil = grade_oil("ISO VG 220")
    # The wear ensemble's walther() and the oil are one relation (same function: equal to round-off).
    assert walther_viscosity(220.0, 18.75, t) == pytest.approx(1e3 * oil.viscosity(t), rel=1e-12)
    for grade, (nu40, nu100) in ISO_VG.items():
        assert walther_kinematic(nu40, nu100, np.array([40.0, 100.0])) == pytest.approx([nu40, nu100], rel=1e-12)
    assert grade_oil("ISO_VG_220") == grade_oil("iso vg 220") == oil  # the command line's spelling
    for bad in ("ISO VG 221", "ISO VG 2", "SAE 30"):
        with pytest.raises(ValueError, match="ISO"):
            grade_oil(bad)


def test_scene_keys_name_the_oil_and_refuse_both():
    from weftsim.input.scene import apply_overrides, load_scene, scene_from_keys, to_file_keys

    oil = {"joint_e.lubrication.oil": "ISO VG 220", "joint_e.lubrication.ambient_temperature_c": 40.0}
    scene = load_scene("loom", oil)
    lub = scene.joint.lubrication
    assert lub.film_temperature > 40.0
    assert lub.viscosity == pytest.approx(float(lub.oil_model.viscosity(lub.film_temperature)), rel=1e-12)
    # The saved scene names the oil, not the viscosity it gave, and reads back to the same film.
    keys = {k: v for k, v in to_file_keys(scene).items() if v is not None}  # as a sweep cell stores its scene
    assert "joint_e.lubrication.viscosity_mpa_s" not in keys
    again = scene_from_keys(keys)
    assert again.joint.lubrication.film_temperature == pytest.approx(lub.film_temperature, rel=1e-12)
    # Another speed, another film temperature; a fixed viscosity on the command line replaces the oil.
    assert apply_overrides(scene, {"drive.speed_rpm": 300.0}).joint.lubrication.film_temperature < lub.film_temperature
    fixed = apply_overrides(scene, {"joint_e.lubrication.viscosity_mpa_s": 80.0}).joint.lubrication
    assert fixed.viscosity == 0.08 and not fixed.has_oil and fixed.film_temperature is None
    # A custom oil by its two viscosities.
    custom = load_scene("loom", {"joint_e.lubrication.oil.nu40_mm2_s": 220.0, "joint_e.lubrication.oil.nu100_mm2_s":
                                 18.75, "joint_e.lubrication.ambient_temperature_c": 40.0}).joint.lubrication
    assert custom.film_temperature == pytest.approx(lub.film_temperature, rel=1e-9)
    with pytest.raises(SceneError, match="viscosity_mpa_s' and 'joint_e.lubrication.oil' are both given"):
        scene_from_keys({**{k: v for k, v in to_file_keys(load_scene("loom")).items() if v is not None}, **oil,
                         "joint_e.lubrication.viscosity_mpa_s": 80.0})
    with pytest.raises(SceneError, match="not an ISO 3448 grade"):
        load_scene("loom", {"joint_e.lubrication.oil": "ISO VG 221"})
    with pytest.raises(SceneError, match="nu40 > nu100"):
        load_scene("loom", {"joint_e.lubrication.oil.nu40_mm2_s": 10.0, "joint_e.lubrication.oil.nu100_mm2_s": 20.0})
    with pytest.raises(SceneError, match="one way"):
        load_scene("loom", {**oil, "joint_e.lubrication.oil.nu40_mm2_s": 220.0,
                            "joint_e.lubrication.oil.nu100_mm2_s": 19.0})


def test_bearing_refuses_bad_input_in_one_line():
    import weftsim

    oiled = {"joint_e.lubrication.oil": "ISO_VG_220"}
    cases = [({}, {}, "is dry"), ({**oiled, "joint_e.clearance_mm": 0.0}, {}, "is ideal"),
             (oiled, {"joint": "f"}, "is ideal"), (oiled, {"load_kn": -1.0}, "must be a finite number > 0"),
             (oiled, {"journal_rpm": float("nan")}, "must be a finite number > 0"), (oiled, {"joint": "g"}, "'e' or 'f'")]
    for overrides, kwargs, text in cases:
        with pytest.raises(SceneError, match=text) as info:
            weftsim.bearing(weftsim.load_scene("loom", overrides), **kwargs)
        assert "\n" not in str(info.value)


def _loom_report():
    import weftsim

    scene = weftsim.load_scene("loom", {"joint_e.lubrication.oil": "ISO_VG_220",
                                        "joint_e.lubrication.ambient_temperature_c": 40.0})
    return scene, weftsim.bearing(scene)


def test_boundary_friction_is_the_boundary_coefficient():
    """At the foot of the Stribeck curve the solids carry the load: f is their boundary friction, mu_b = 0.1."""
    _, report = _loom_report()
    assert report["stribeck"]["regime"][0] == "boundary"
    assert report["stribeck"]["friction_coefficient"][0] == pytest.approx(0.1, rel=0.1)


# The loom's pin at its mean load (9.16 kN) in ISO VG 220 at its film temperature (113 mPa s), where the rough film
# thins to sigma: 15, 20 and 25 rpm put h_min at 0.70, 0.86 and 1.02 sigma (floor 0.25).
FLOOR_SPEEDS_RPM, FLOOR_LOAD_N, FLOOR_VISCOSITY = (15.0, 20.0, 25.0), 9160.0, 0.113


def _floor_points(floor: float) -> list:
    import weftsim

    joint = weftsim.load_scene("loom", {"joint_e.lubrication.viscosity_mpa_s": 113.0}).joint
    joint = replace(joint, lubrication=replace(joint.lubrication, film_floor_ratio=floor))
    return [steady_point(joint, FLOOR_LOAD_N, rpm * math.pi / 30.0, FLOOR_VISCOSITY) for rpm in FLOOR_SPEEDS_RPM]


def test_the_low_speed_friction_does_not_depend_on_a_floor_of_one_sigma():
    """The issue's check: floors 0.25-1 sigma give the low-speed friction within 2 %, where the film is thinner
    than the floor (15 and 20 rpm: h_min 0.70 and 0.86 sigma), the film continued below its floor with its slope,
    curvature and turning rate there (weftsim.physics.lubricated.film_at_floor).  Measured against floor 0.25:
    floor 0.5 equal (1e-12), floor 1 +0.50 %, +0.12 %, 0 (f = 0.00376, 0.00284, 0.00221); a held film fell through
    to the dry law here (f = 0.051, 0.034, 0.017)."""
    low = _floor_points(0.25)
    for floor in (0.5, 1.0):
        for a, b in zip(low, _floor_points(floor)):
            # The film carries > 95 % of the load, the asperities the rest with their boundary friction.
            assert a.film_ratio >= 0.5 and b.dry_force_n == 0.0 and b.asperity_load_n > 0.0
            assert b.film_force_n > 0.95 * FLOOR_LOAD_N
            assert b.friction_coefficient == pytest.approx(a.friction_coefficient, rel=0.02)


def test_bearing_report_and_stribeck_curve():
    """At the loom's mean point: the report's numbers are one steady point's, and the Stribeck curve runs from the
    boundary regime at low speed to a hydrodynamic branch whose friction rises as the film thickens."""
    import weftsim

    scene, report = _loom_report()
    mean, peak = report["points"]["mean"], report["points"]["peak"]
    assert mean["load_n"] < peak["load_n"] and mean["journal_speed_rad_s"] == peak["journal_speed_rad_s"]
    # The pre-run film temperature is the mean point's, and the peak runs in the same film.
    assert mean["film_temperature_c"] == pytest.approx(scene.joint.lubrication.film_temperature, rel=1e-9)
    assert peak["viscosity_pa_s"] == mean["viscosity_pa_s"] and peak["heat"] is None
    json.dumps(report)  # JSON-ready
    mu = np.asarray(report["stribeck"]["friction_coefficient"])
    assert report["stribeck"]["regime"][0] == "boundary" and report["stribeck"]["regime"][-1] == "hydrodynamic"
    assert np.all(np.diff(mu[-10:]) > 0.0)  # hydrodynamic: friction grows with speed
    given = weftsim.bearing(scene, load_kn=5.0, journal_rpm=600.0, stribeck=False)["points"]["given"]
    assert given["load_n"] == 5000.0 and given["journal_speed_rad_s"] == pytest.approx(20.0 * math.pi)


def test_the_command_line(tmp_path, capsys):
    from weftsim.cli.commands import main

    args = ["bearing", "loom", "--set", "joint_e.lubrication.oil=ISO_VG_220", "--set",
            "joint_e.lubrication.ambient_temperature_c=40", "-o", str(tmp_path / "b")]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "ISO VG 220 at 40 C ambient" in out and "mean: W = " in out and "Stribeck curve" in out
    assert (tmp_path / "b" / "stribeck.png").is_file()
    saved = json.loads((tmp_path / "b" / "bearing.json").read_text())
    assert main(args + ["--json", "--no-plot", "--force"]) == 0
    assert json.loads(capsys.readouterr().out)["points"] == saved["points"]
    assert main(["bearing", "loom", "-o", str(tmp_path / "dry")]) == 2
    assert "joint E is dry" in capsys.readouterr().err


def test_a_run_takes_the_oils_viscosity_at_the_film_temperature():
    """A scene built in Python with an oil (no film temperature yet) runs at the viscosity of its heat balance, as a
    loaded scene does; the design checks report the temperature (summary.json's plausibility block)."""
    import weftsim
    from weftsim.physics.joint import VISCOSITY
    from weftsim.model.dynamics import pack_parameters

    oil = {"joint_e.lubrication.oil": "ISO_VG_220", "joint_e.lubrication.ambient_temperature_c": 40.0,
           "drive.revolutions": 0.02}
    loaded = weftsim.load_scene("loom", oil)
    built = replace(loaded, joint=replace(loaded.joint, lubrication=Lubrication(viscosity=0.0, oil="ISO VG 220",
                                                                                ambient_temperature=40.0)))
    result = weftsim.simulate(built, "reference")
    lub = result.scene.joint.lubrication
    assert lub.film_temperature == pytest.approx(loaded.joint.lubrication.film_temperature, rel=1e-9)
    assert pack_parameters(result.scene)[VISCOSITY] == pytest.approx(float(lub.oil_model.viscosity(
        lub.film_temperature)), rel=1e-12)
    check = next(c for c in result.plausibility["checks"] if c["name"] == "film_temperature")
    assert check["value"] == pytest.approx(lub.film_temperature) and check["numbers"]["viscosity_pa_s"] == lub.viscosity


def test_a_bearing_that_cannot_shed_its_heat_is_refused():
    """Self-contained (no oil flow) with no heat path through the housing: no temperature balances the friction
    power, and the scene says so in one line."""
    import weftsim

    with pytest.raises(SceneError, match="has no solution below") as info:
        weftsim.load_scene("loom", {"joint_e.lubrication.oil": "ISO_VG_220", "joint_e.lubrication.oil_supply": "sump",
                                    "joint_e.lubrication.housing_heat_transfer_w_k": 0.0})
    assert "\n" not in str(info.value)


def test_the_flows_converge_with_the_grid():
    """The side flow's second-order end difference: the table's grid (120 x 16) against twice the nodes each way
    (measured 0.07 % in Q, 0.15 % in Qs/Q at eps = 0.8); the first-order difference was 4 % off."""
    from weftsim.joint import reynolds

    coarse = flows(0.8, 1.0)
    n_phi, n_zeta = reynolds.N_PHI, reynolds.N_ZETA
    try:
        reynolds.N_PHI, reynolds.N_ZETA = 2 * n_phi, 2 * n_zeta
        fine = flows(0.8, 1.0)
    finally:
        reynolds.N_PHI, reynolds.N_ZETA = n_phi, n_zeta
    assert coarse[0] == pytest.approx(fine[0], rel=2e-3)
    assert coarse[1] / coarse[0] == pytest.approx(fine[1] / fine[0], rel=3e-3)


def test_the_bearing_check_of_joint_f():
    """Joint F of the E-and-F scene with a fixed viscosity: its points carry the ideal mechanism's loads at F."""
    import weftsim
    from weftsim.mechanism.pin_loads import ideal_pin_loads

    scene = weftsim.load_scene("clearance_ef", {"joint_f.lubrication.viscosity_mpa_s": 80.0})
    report = weftsim.bearing(scene, joint="f", stribeck=False)
    loads = ideal_pin_loads(scene, "f")
    assert report["joint"] == "F" and report["oil"] is None and report["viscosity_mpa_s"] == pytest.approx(80.0)
    assert report["points"]["mean"]["load_n"] == pytest.approx(float(loads.force.mean()), rel=1e-12)
    assert report["points"]["peak"]["load_n"] == pytest.approx(float(loads.force.max()), rel=1e-12)
    assert report["points"]["mean"]["journal_speed_rad_s"] == pytest.approx(
        float(loads.sliding_speed.mean()) / scene.joint_f.journal_radius, rel=1e-12)


def test_joint_f_takes_es_lubricant_whole(tmp_path):
    """F given a clearance alone takes E's lubricant; switching E between a fixed viscosity and an oil on the command
    line switches F's with it (never a film naming neither, or both)."""
    from weftsim.input.scene import apply_overrides, load_scene

    base = {"joint_f.clearance_mm": 0.02, "joint_e.lubrication.viscosity_mpa_s": 80.0}
    scene = load_scene("loom", base)
    assert scene.joint_f.lubrication.viscosity == 0.08 and not scene.joint_f.lubrication.has_oil
    oiled = apply_overrides(scene, {"joint_e.lubrication.oil": "ISO_VG_220"})
    for lub in (oiled.joint.lubrication, oiled.joint_f.lubrication):
        assert lub.oil == "ISO_VG_220" and lub.film_temperature is not None
        assert lub.viscosity == pytest.approx(float(lub.oil_model.viscosity(lub.film_temperature)), rel=1e-12)
    back = apply_overrides(oiled, {"joint_e.lubrication.viscosity_mpa_s": 50.0})
    assert back.joint_f.lubrication.viscosity == 0.05 and not back.joint_f.lubrication.has_oil
    # A file giving the viscosity, the command line the oil: the oil replaces it, at both joints.
    (tmp_path / "oiled.toml").write_text('extends = "loom"\n[joint_f]\nclearance_mm = 0.02\n'
                                         '[joint_e.lubrication]\nviscosity_mpa_s = 80.0\n')
    again = load_scene(tmp_path / "oiled.toml", {"joint_e.lubrication.oil": "ISO_VG_220"})
    assert again.joint_f.lubrication.film_temperature == pytest.approx(oiled.joint_f.lubrication.film_temperature)
    with pytest.raises(SceneError, match="both given"):
        load_scene("loom", {**base, "joint_e.lubrication.oil": "ISO_VG_220"})  # one source naming both


# A published Stribeck test (docs/lubricated-joint.md, "Stribeck data"): Sander, Allmaier, Priebsch, Witt and Skiadas,
# Tribol. Int. 96 (2016), a conrod big end between two support bearings, the shaft's input torque against speed at
# 8 and 4 kN (tests/data/stribeck_sander2016.toml).  The issue's tolerance: 30 % on the torque.
SANDER_RIG = Path(__file__).parent / "data" / "stribeck_sander2016.toml"
STRIBECK_TOLERANCE = 0.30
# The published curve's full-film side (at and above its least torque: 500 rpm at 8 kN, 300 at 4 kN) and the mixed
# points where the rigid film still agrees (8 kN, 400 rpm: 0.81).  Below them weftsim's torque is 0.34-0.61 of the
# published (8 kN, 300-150 rpm; 4 kN, 250 and 150 rpm), and its least torque lies at 250 (8 kN) and 150 rpm (4 kN),
# not at 500 and 300: the docs' table and what was measured of the causes.
SANDER_AGREES_RPM = {8000.0: (3000.0, 1000.0, 500.0, 400.0), 4000.0: (3000.0, 1000.0, 500.0, 400.0, 300.0)}


@pytest.fixture(scope="module")
def sander():
    from weftsim.studies.stribeck_rig import comparison, load_rig

    rig = load_rig(SANDER_RIG)
    return rig, comparison(rig)


def test_the_published_stribeck_rig_where_the_film_is_full(sander):
    """weftsim's shaft torque (big end + two supports) within 30 % of the published at the full-film speeds and the
    first mixed one (measured 0.81-1.13 at 8 kN, 0.91-1.02 at 4 kN); the big end's minimum film at 3000 rpm and
    8 kN within 5 % of the source's 2.0 um (its elastohydrodynamic model; measured 2.052 um, the rigid film)."""
    rig, rows = sander
    for case in rows:
        agrees = SANDER_AGREES_RPM[case["load_n"]]
        for rpm, ratio, point in zip(case["rpm"], case["ratio"], case["points"]):
            if rpm in agrees:
                assert ratio == pytest.approx(1.0, abs=STRIBECK_TOLERANCE), (case["load_n"], rpm)
            assert point["bearings"]["support"]["film_ratio"] > 2.0  # the supports stay hydrodynamic throughout
            assert point["bearings"]["big_end"]["dry_force_n"] == 0.0  # the journal never reaches the dry law
        # The published least torque is among the points held (measured 0.94 at 8 kN, 500 rpm; 0.91 at 4 kN, 300).
        assert case["minimum_rpm"] == case["rpm"][int(np.argmin(case["torque_nm"]))]
        assert case["minimum_rpm"] in agrees
    full = rows[0]["points"][0]["bearings"]["big_end"]
    assert rows[0]["load_n"] == 8000.0 and rows[0]["rpm"][0] == 3000.0
    assert full["min_film_m"] == pytest.approx(2.0e-6, rel=0.05)  # the source gives one digit: 2e-6 m


def test_the_stribeck_comparison_is_not_the_film_floors(sander):
    """The numerical guard decides none of the points the comparison holds: at the least floor (sigma / 4) every
    point but the one below the default floor (8 kN, 150 rpm: h_min 0.31 sigma) has the same torque to 1e-9
    (measured: 3.5e-13 at most)."""
    from weftsim.studies.stribeck_rig import rig_point, with_floor

    rig, rows = sander
    low = with_floor(rig, 0.25)
    for case in rows:
        for rpm, torque, point in zip(case["rpm"], case["weftsim_nm"], case["points"]):
            if point["bearings"]["big_end"]["film_ratio"] >= 1.0:
                assert rig_point(low, case["load_n"], rpm)["torque_nm"] == pytest.approx(torque, rel=1e-9)


def test_a_bad_rig_file_is_one_line(tmp_path):
    """The rig file is input: a missing table or a bad scene key is refused in one line naming the file."""
    from weftsim.studies.stribeck_rig import load_rig

    text = SANDER_RIG.read_text()
    for name, broken in (("no_loads.toml", text.split("[[loads]]")[0].replace("[lubrication]", "[oil]")),
                         ("bad_key.toml", text.replace("clearance_mm = 0.0239", "clearance_mm = -1.0"))):
        path = tmp_path / name
        path.write_text(broken)
        with pytest.raises(SceneError) as error:
            load_rig(path)
        assert str(path) in str(error.value) and "\n" not in str(error.value)


# The elastic film (weftsim.joint.ehl, the rig's [elastic] keys: the parts' moduli, the summits' mean height 0.6 um,
# alpha = 9.5e-9 1/Pa, the surfaces' Rq and Peklenik numbers).  Measured (scripts/stribeck_sander.py): least torque
# at 526 rpm at 8 kN and 332 rpm at 4 kN on 41 speeds (published 500, 300); full-film side 0.99-1.16; mixed side
# 1.05-1.15 at 8 kN from 400 rpm down, 0.81 and 1.13 at 4 kN, 250 and 150 rpm.
ELASTIC_FULL_FILM_RPM = {8000.0: (3000.0, 1000.0, 500.0), 4000.0: (3000.0, 1000.0, 500.0, 400.0, 300.0)}
MINIMUM_TOLERANCE = 0.25  # the issue's: the least torque at the published speed within 25 %


@pytest.fixture(scope="module")
def sander_elastic(sander):
    from weftsim.studies.stribeck_rig import comparison, with_elastic

    rig = with_elastic(sander[0])
    return rig, comparison(rig)


def test_the_elastic_film_has_the_published_minimum(sander_elastic):
    """With the elastic film the rig's least torque lies within 25 % of the published speed (on 17 speeds from 200
    to 1600 rpm, steps of 14 %: measured 526 rpm at 8 kN, 332 at 4 kN on the script's 41), where the rigid film's lies
    45 and 42 % below it; the full-film side stays within 30 % (measured 1.04-1.16 at 8 kN, 0.99-1.03 at 4 kN), and
    the big end's film at 150 rpm, 8 kN is the source's 0.7 um within 10 % (measured 0.756 um; rigid 0.279)."""
    from weftsim.studies.stribeck_rig import rig_point

    rig, rows = sander_elastic
    speeds = np.geomspace(200.0, 1600.0, 17)
    for case in rows:
        curve = [rig_point(rig, case["load_n"], n)["torque_nm"] for n in speeds]
        least = speeds[int(np.argmin(curve))]
        assert least == pytest.approx(case["minimum_rpm"], rel=MINIMUM_TOLERANCE), case["load_n"]
        for rpm, ratio in zip(case["rpm"], case["ratio"]):
            if rpm in ELASTIC_FULL_FILM_RPM[case["load_n"]]:
                assert ratio == pytest.approx(1.0, abs=STRIBECK_TOLERANCE), (case["load_n"], rpm)
    slow = rows[0]["points"][-1]["bearings"]["big_end"]
    assert rows[0]["rpm"][-1] == 150.0 and slow["min_film_m"] == pytest.approx(0.7e-6, rel=0.1)


def test_the_elastic_film_mixed_side_is_within_thirty_percent(sander_elastic):
    """The issue's 30 % on the mixed side too (every published point), with the source's surfaces in the average
    flow (Rq 0.20 and 0.34 um, Peklenik numbers 4 and 12, journal first: the rig file's [elastic]): measured
    0.81-1.16 over all 15 points, the mixed side 1.05-1.15 at 8 kN from 400 rpm down, 0.81 and 1.13 at 4 kN, 250
    and 150 rpm.  With isotropic alike surfaces on the contact's sigma (the keys unset) it read 1.30-1.56 and 1.37:
    outside."""
    _, rows = sander_elastic
    for case in rows:
        for rpm, ratio in zip(case["rpm"], case["ratio"]):
            assert ratio == pytest.approx(1.0, abs=STRIBECK_TOLERANCE), (case["load_n"], rpm)


def test_a_mixed_point_of_the_rigid_film_says_what_it_was_measured_to_do():
    """A result says when it lies outside what its model reproduced: a point of the rigid film in the mixed or
    boundary regime carries a note naming the Stribeck test's 0.23-0.61 and the elastic film; a full-film point
    none (the loom's mean point in ISO VG 220 at 40 C: film ratio > 3)."""
    import weftsim

    scene, report = _loom_report()
    assert report["points"]["mean"]["regime"] == "hydrodynamic" and report["notes"] == []
    slow = weftsim.bearing(scene, load_kn=FLOOR_LOAD_N / 1e3, journal_rpm=FLOOR_SPEEDS_RPM[0], stribeck=False)
    assert slow["points"]["given"]["regime"] != "hydrodynamic"
    (note,) = slow["notes"]
    assert note.startswith("given: ") and "0.23-0.61" in note and "joint_e.lubrication.elastic_film = true" in note
