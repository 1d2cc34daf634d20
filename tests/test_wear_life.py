"""Service life (issue 31; docs/wear.md sections 3, 5 and 12): the prediction ends at the clearance limit, the
wear regimes' coefficients, the duty cycle's stop-starts and the crank's drive law, the film's temperature and
running-in in the updates."""

from __future__ import annotations

import dataclasses as dc
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from conftest import door
from weftsim.input.scene import load_scene
from weftsim.physics import chain as kc
from weftsim.model.dynamics import pack_parameters
from weftsim.wear import predict_to_directory
from weftsim.wear.archard import run_wear
from weftsim.wear.extrapolate import predict

ROOT = Path(__file__).resolve().parents[1]
solve = door("reference")


def _wear(scene, **changes):
    return dc.replace(scene, joint=dc.replace(scene.joint, wear=dc.replace(scene.joint.wear, **changes)))


# --- the limit ------------------------------------------------------------------------------------------------

def test_reference_ends_at_the_limit_with_the_crossing_update_cut(tmp_path):
    """`weftsim wear reference --hours 10000 --limit-clearance-mm 0.3` wore on to 1.06 mm; it now ends at 0.3 mm
    (the update that crosses it cut by bisection), with every simulated update inside the limit."""
    data = predict_to_directory(load_scene("reference"), 1e4, tmp_path, limit=0.3e-3, figures=False)
    assert data["hours_reached"] == pytest.approx(data["hours_to_limit"], rel=1e-9)
    assert data["final_effective_clearance_e_mm"] == pytest.approx(0.3, rel=1e-9)
    assert 5.0 < data["hours_to_limit"] < 20.0  # 11.43 h measured (docs/wear.md section 2)
    table = np.genfromtxt(tmp_path / "wear.csv", delimiter=",", names=True)
    assert np.all(table["effective_clearance_e_mm"] < 0.3)


@pytest.mark.slow
def test_the_how_to_scene_ends_at_the_limit(tmp_path, capsys):
    """The how-to's narrow loom (its scene file read from docs/howto-own-mechanism.md): 2000 h asked, the limit
    0.1 mm reached long before (it used to wear on to 1.04 mm and fail the energy balance), the prediction ends
    there and the last line gives the hours.  The hours follow from the wear rates of the updates: the wear
    speeds up as the clearance opens (the impacts grow with it), so they lie below the first update's rate carried
    on to the limit, and above the fastest update's (measured: 37.39 h under the loom's cylindrical law, between
    6.0 and 82.9 h; 146.7 h under variable_kd, whose softer contact slid its impacts under lower peak loads:
    docs/wear.md sections 3 and 9).  Updates of 10 % of the clearance instead of the default 2 % (18 updates
    instead of 83, 28 s of CPU instead of 121 s): what is checked holds for any schedule (38.08 h, between 8.8 and
    83.3 h); the command line in this process (weftsim.cli.main), its last line read from stdout."""
    from weftsim.cli.commands import main

    page = (ROOT / "docs" / "howto-own-mechanism.md").read_text()
    toml = re.search(r"```toml\n(# narrow\.toml.*?)```", page, re.S).group(1)
    (tmp_path / "narrow.toml").write_text(toml)
    out = tmp_path / "w"
    status = main(["wear", str(tmp_path / "narrow.toml"), "--hours", "2000", "--limit-clearance-mm", "0.1", "-o",
                   str(out), "--no-plot", "--set", "joint_e.wear.max_clearance_change=0.1"])  # fmt: skip
    stdout = capsys.readouterr().out
    assert status == 0
    data = json.loads((out / "wear.json").read_text())
    assert data["final_effective_clearance_e_mm"] == pytest.approx(0.1, rel=1e-9)
    hours = data["hours_to_limit"]
    assert data["hours_reached"] == pytest.approx(hours, rel=1e-9) and hours < 2000.0  # ended at the limit
    table = np.genfromtxt(out / "wear.csv", delimiter=",", names=True)
    c, h = table["effective_clearance_e_mm"], table["hours"]
    assert len(c) > 10  # a schedule of many updates, each rate its own
    rates = np.diff(c) / np.diff(h)  # mm/h of each update
    to_go = 0.1 - c[0]
    assert to_go / rates.max() < hours < to_go / rates[0]
    assert table["contact_force_e_p99_N"][-1] > table["contact_force_e_p99_N"][0]  # why: the impacts grow
    assert f"{hours:.6g} h of running" in stdout.strip().splitlines()[-1]


def test_the_loom_ends_at_the_limit_and_goes_past_it_when_asked(tmp_path):
    """The bundled loom ends at a limit a few updates in, cut at it; with past_limit the same prediction goes on to
    the hours asked, beyond the limit, and still reports the hours to it.  (loom_dry differs from it in k alone,
    which never enters the dynamics: the 1/k tests below; loom_oiled does not reach a limit: section 12.)"""
    scene = load_scene("loom")
    ended = predict_to_directory(scene, 1e4, tmp_path / "a", limit=0.0205e-3, figures=False)
    hours = ended["hours_to_limit"]
    assert ended["hours_reached"] == pytest.approx(hours, rel=1e-9) and hours < 1e4
    assert ended["final_effective_clearance_e_mm"] == pytest.approx(0.0205, rel=1e-9)
    past = predict_to_directory(scene, 1.5 * hours, tmp_path / "b", limit=0.0205e-3, figures=False, past_limit=True)
    assert past["hours_reached"] == pytest.approx(1.5 * hours) and past["final_effective_clearance_e_mm"] > 0.0205
    assert past["hours_to_limit"] == pytest.approx(hours, rel=1e-6)  # linear between the same updates


# --- the regimes ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("regime, key", [("boundary", "boundary_wear_coefficient"), ("dry", "dry_wear_coefficient")])
def test_hours_scale_as_one_over_k_in_each_solid_regime(regime, key):
    """The regime's k never enters the dynamics: 4 k gives the same geometries in a quarter of the hours (a factor
    of 4 is exact in floating point; round-off of the sums of N / (rev/h))."""
    scene = _wear(load_scene("reference"), regime=regime, dry_wear_coefficient=1e-6)
    base = predict(scene, 2.0 if regime == "boundary" else 0.01)
    k = getattr(scene.joint.wear, key)
    fast = predict(_wear(scene, **{key: 4.0 * k}), base[-1].hours / 4.0)
    assert len(fast) == len(base)
    for a, b in zip(base, fast):
        assert b.hours == pytest.approx(a.hours / 4.0, rel=1e-12)
        np.testing.assert_allclose(b.bearing, a.bearing, rtol=1e-12, atol=0.0)


def test_the_other_regimes_key_changes_nothing():
    """A boundary-lubricated joint does not wear with the dry coefficient (nor a dry joint with the boundary one)."""
    scene = load_scene("reference")
    a = predict(scene, 1.0)
    b = predict(_wear(scene, dry_wear_coefficient=3e-3, mixed_wear_coefficient=4e-7), 1.0)
    assert [u.hours for u in a] == [u.hours for u in b]
    np.testing.assert_array_equal(a[-1].bearing, b[-1].bearing)


def test_hours_scale_as_one_over_k_in_the_mixed_regime():
    """An oiled pin whose film never lets the journal reach the wall (25 mPa s, c0 = 0.02 mm: film ratio min 2.2,
    the asperities carry load) wears with mixed_wear_coefficient alone: 4 k gives the same geometries, to the bit
    (measured), in a quarter of the hours."""
    scene = load_scene("loom", {"joint_e.lubrication.viscosity_mpa_s": 25.0,
                                "joint_e.wear.revolutions_per_update": 1})
    base = predict(scene, 2500.0)
    assert len(base) >= 2 and base[-1].bearing.max() > 0.0
    fast = predict(_wear(scene, mixed_wear_coefficient=4.0 * scene.joint.wear.mixed_wear_coefficient),
                   base[-1].hours / 4.0)
    assert len(fast) == len(base)
    for a, b in zip(base, fast):
        assert b.hours == pytest.approx(a.hours / 4.0, rel=1e-12)
        np.testing.assert_allclose(b.bearing, a.bearing, rtol=1e-12, atol=0.0)


@pytest.fixture(scope="module")
def mixed_run():
    """One update's run of the loom's pin in a thin oil film (10 mPa s at c = 0.03 mm: the asperities carry load,
    film ratio min below 1), its kernel parameters and step rows."""
    scene = load_scene("loom", {"joint_e.lubrication.viscosity_mpa_s": 10.0, "joint_e.clearance_mm": 0.03,
                                "drive.revolutions": 2.0})
    rows = {}
    result = solve(scene, observe=lambda *a: rows.update(steps=a))
    assert result.ok, result.message
    return scene, pack_parameters(scene), rows["steps"]


def test_mixed_regime_wears_the_asperity_load_with_its_own_k(mixed_run):
    """The asperities' sliding work wears with mixed_wear_coefficient, the dry law's with the solid contact's: the
    volume is exactly k_c (W - W_a) / H + k_a W_a / H; with k_a -> 0 only the dry law's part is left, and with no
    asperity load (the asperity coefficient eta beta sigma -> 0, every other part of the film on) the mixed
    regime's wear vanishes with it (linearly: F_a is proportional to eta beta sigma)."""
    scene, prm, (t, y, contact, impact) = mixed_run
    wear = run_wear(scene, prm, t, y, contact, impact)
    w = scene.joint.wear
    assert wear.asperity_work > 0.0
    one = _wear(scene, mixed_wear_coefficient=3.0 * w.boundary_wear_coefficient)
    three = run_wear(one, pack_parameters(one), t, y, contact, impact)
    k_c, k_a = w.boundary_wear_coefficient, 3.0 * w.boundary_wear_coefficient
    expected = (k_c * (wear.sliding_work - wear.asperity_work) + k_a * wear.asperity_work) / w.bearing_hardness
    assert three.bearing_volume == pytest.approx(expected, rel=1e-12)  # round-off of ~1e4 row sums
    works = []
    for s in (1.0, 0.1, 0.01):
        lub = dc.replace(scene.joint.lubrication,
                         asperity_density_radius_roughness=s * scene.joint.lubrication.asperity_density_radius_roughness)
        sc = dc.replace(scene, joint=dc.replace(scene.joint, lubrication=lub))
        rows = {}
        assert solve(sc, observe=lambda *a: rows.update(steps=a)).ok
        run = run_wear(sc, pack_parameters(sc), *rows["steps"])
        works.append(run.asperity_work * w.asperity_wear_coefficient / w.bearing_hardness)  # the mixed regime's
    # The mixed regime's worn volume falls with the asperity coefficient at least linearly (measured: as its
    # square, 49, 0.64 and 0.0064 J of asperity work at 1, 0.1, 0.01 times eta beta sigma, the dry law's share
    # 0.09 % at 1): it vanishes with the asperity load.
    assert works[0] > works[1] > works[2] > 0.0
    assert works[1] < 0.1 * works[0] and works[2] < 0.1 * works[1], works


# --- the drive law and the duty cycle -------------------------------------------------------------------------

def test_the_drive_laws_integrate_to_their_angles_and_keep_constant_speed():
    """crank_motion: theta_dot is the derivative of theta and theta_ddot of theta_dot (central differences), the
    run-down turns omega T / 2 on its ramp and the start-up reaches omega; a run-down whose ramp lies beyond the
    run gives the constant-speed run's channels bit for bit."""
    scene = load_scene("loom")
    omega, period = scene.drive.speed, scene.drive.period
    for law, t0 in (("run_down", period), ("start_up", 0.0)):
        sc = dc.replace(scene, drive=dc.replace(scene.drive, law=law, ramp_start=t0, ramp=2.0 * period))
        prm = pack_parameters(sc)
        for t in np.linspace(0.0, 4.0 * period, 37)[1:-1]:
            h = 1e-7
            (a, _, _), (b, w, acc), (c, _, _) = (kc.crank_motion(prm, x) for x in (t - h, t, t + h))
            assert (c - a) / (2 * h) == pytest.approx(w, abs=1e-6 * omega)
            dw = (kc.crank_motion(prm, t + h)[1] - kc.crank_motion(prm, t - h)[1]) / (2 * h)
            assert dw == pytest.approx(acc, abs=1e-5 * omega / period)
        end = kc.crank_motion(prm, 5.0 * period)
        if law == "run_down":
            assert end[0] == pytest.approx(omega * (t0 + period)) and end[1] == 0.0
        else:
            assert end[1] == omega
    late = dc.replace(scene, drive=dc.replace(scene.drive, law="run_down", ramp_start=10.0, ramp=0.1))
    a, b = solve(scene), solve(late)
    for name in ("contact_force_N", "driving_torque_Nm", "rapier_acceleration_m_s2", "eccentricity_y_m"):
        np.testing.assert_array_equal(a.steps[name], b.steps[name])


def test_a_stop_start_s_wear_is_archard_s_integral_over_its_transients():
    """The wear of one stop-start equals k / H times int F_N |v_T| dt over the run-down and the start-up (F_N from
    each transient's own contact-force channel, the trapezoid written out), and its energy balance closes."""
    from weftsim.wear.archard import contact_rows
    from weftsim.wear.duty import stop_start_wear, transient_scenes

    scene = load_scene("loom", {"duty.stops_per_hour": 15.0})
    down, up = stop_start_wear(scene)
    w = scene.joint.wear
    for wear, (sc, t0, t1) in zip((down, up), transient_scenes(scene)):
        rows = {}
        result = solve(sc, observe=lambda *a: rows.update(steps=a))
        assert result.ok, result.message
        t, y, contact, impact = rows["steps"]
        keep = (t >= t0) & (t <= t1)
        out = np.zeros((int(keep.sum()), 6))
        contact_rows(pack_parameters(sc), t[keep], y[keep], contact[keep], impact[keep], out)
        steps = result.steps["time_s"]
        force = np.interp(t[keep], steps, result.steps["contact_force_N"])
        assert np.all(np.isin(t[keep], steps))  # the channels are at the steps: no interpolation error
        g = force * np.abs(out[:, 1])
        integral = float(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(t[keep])))
        assert integral > 0.0
        assert wear.bearing_volume == pytest.approx(w.contact_wear_coefficient / w.bearing_hardness * integral,
                                                    rel=1e-12)
        # the transient's energy balance: driving work = energy + dissipated, to the solver's tolerance
        s = result.steps
        residual = s["driving_work_J"] - (s["kinetic_energy_J"] + s["potential_energy_J"] - s["kinetic_energy_J"][0]
                                          - s["potential_energy_J"][0] + s["contact_energy_J"]
                                          + s["dissipated_energy_J"])
        assert np.max(np.abs(residual)) < 1e-3 * np.max(s["kinetic_energy_J"]), np.max(np.abs(residual))


def test_no_stops_is_the_steady_prediction_bit_for_bit():
    """stops_per_hour = 0 simulates no transient: the prediction equals the one of the scene without [duty]."""
    scene = load_scene("reference")
    a = predict(scene, 1.0)
    b = predict(dc.replace(scene, duty=dc.replace(scene.duty, stops_per_hour=0.0, hours_per_day=16.0)), 1.0)
    assert [u.hours for u in a] == [u.hours for u in b]
    for u, v in zip(a, b):
        np.testing.assert_array_equal(u.rate_bearing, v.rate_bearing)


def test_stops_add_their_wear_per_hour_of_running():
    """With stops, an update's rate is the running rate plus stops / (rev per hour) times one stop-start's wear."""
    from weftsim.wear.duty import stop_start_wear
    from weftsim.wear.extrapolate import next_update, worn_scene

    scene = load_scene("loom", {"joint_e.clearance_mm": 0.05})
    zeros = np.zeros(scene.joint.wear.profile_points)
    steady = next_update(scene, 0.0, 0.0, zeros, zeros, 10.0)
    stopped = dc.replace(scene, duty=dc.replace(scene.duty, stops_per_hour=20.0))
    update = next_update(stopped, 0.0, 0.0, zeros, zeros, 10.0)
    down, up = stop_start_wear(worn_scene(stopped, zeros, zeros, 5))
    per_rev = 20.0 / (scene.drive.speed / (2 * math.pi) * 3600.0)
    one = down.bearing + up.bearing
    np.testing.assert_allclose(update.rate_bearing, steady.rate_bearing + per_rev * one, rtol=1e-9, atol=1e-30)
    share = update.response["stop_start_share_e"]
    assert 0.0 < share < 0.01  # a stop-start wears about as much as 2-3 revolutions at full speed


@pytest.mark.slow
def test_a_stop_start_agrees_between_the_engines():
    """One stop-start of the loom on the reference engine and on the Exudyn tree: its wear within 1 % (measured
    under the cylindrical law 0.064 % run-down, 0.070 % start-up; oiled at 0.08 mm 0.24 % and 0.024 %: one draw of
    the impacts each)."""
    from weftsim.wear.duty import stop_start_wear

    for name, overrides in (("loom", {}), ("loom_oiled", {"joint_e.clearance_mm": 0.08})):
        scene = load_scene(name, {**overrides, "duty.stops_per_hour": 15.0})
        ref = stop_start_wear(scene, "reference")
        exu = stop_start_wear(scene, "exudyn")
        for a, b in zip(ref, exu):
            assert b.bearing_volume == pytest.approx(a.bearing_volume, rel=1e-2)


def test_calendar_days_follow_the_duty():
    """Running hours to calendar days: each running hour costs 1 + stops x stop time of the scheduled hours."""
    duty = load_scene("loom_oiled").duty
    assert duty.calendar_days(1000.0) == pytest.approx(
        1000.0 * (1.0 + duty.stops_per_hour * duty.stop_minutes / 60.0) / duty.hours_per_day * 7.0 / duty.days_per_week)


# --- temperature and running-in -------------------------------------------------------------------------------

def test_an_oiled_update_runs_at_its_heat_balance_and_its_run_in_roughness():
    """An oiled joint's update: the viscosity at the film temperature of the heat balance at the update's effective
    clearance, and the roughness run in by its worn depth (sigma_ss + (sigma0 - sigma_ss) exp(-h / h_r))."""
    from weftsim.joint.bearing import mean_operating_point
    from weftsim.joint.heat import with_film_temperature
    from weftsim.wear.extrapolate import worn_scene

    scene = load_scene("loom_oiled", {"joint_e.wear.run_in_roughness_um": 0.2, "joint_e.wear.run_in_depth_um": 2.0})
    n = scene.joint.wear.profile_points
    bearing, journal = np.zeros(n), np.zeros(n)
    bearing[10] = 3e-6  # 3 um worn: c_eff = c0 + 3 um
    worn = worn_scene(scene, bearing, journal, 2)
    lub = worn.joint.lubrication
    sigma0 = scene.joint.lubrication.roughness
    assert lub.roughness == pytest.approx(0.2e-6 + (sigma0 - 0.2e-6) * math.exp(-1.5), rel=1e-12)
    mean, _, omega = mean_operating_point(scene, "e")
    joint = dc.replace(scene.joint, clearance=scene.joint.clearance + 3e-6,
                       lubrication=dc.replace(scene.joint.lubrication, roughness=lub.roughness))
    expected, balance = with_film_temperature(joint, mean, omega)
    assert lub.viscosity == expected.lubrication.viscosity and lub.film_temperature == balance.temperature_c
    assert lub.film_temperature != scene.joint.lubrication.film_temperature  # the clearance changed the balance


def test_the_life_report_turns_each_sample_s_hours_into_its_own_calendar_days():
    """Each sample's calendar days are its hours x (1 + stops x stop time / 60) / hours a day x 7 / days a week with
    its own drawn duty keys (the scene's otherwise); censored hours stay censored; the stop-starts' share of a
    prediction is the N-weighted share of its updates."""
    from types import SimpleNamespace

    from weftsim.wear.life import horizon_days, prediction_stop_share, sample_days, shift_days, stop_share_summary

    scene = load_scene("loom_oiled")
    hours = np.array([[10.0, 20.0], [100.0, np.inf], [1.0, 2.0]])
    stops = np.array([5.0, 15.0, 25.0])
    days = sample_days(scene, {"duty.stops_per_hour": stops}, hours)
    d = scene.duty
    for i, s in enumerate(stops):
        expected = hours[i] * (1.0 + s * d.stop_minutes / 60.0) / d.hours_per_day * 7.0 / d.days_per_week
        np.testing.assert_allclose(days[i], expected, rtol=1e-15)
        assert dc.replace(d, stops_per_hour=s).calendar_days(10.0) == pytest.approx(
            10.0 * (1.0 + s * d.stop_minutes / 60.0) / d.hours_per_day * 7.0 / d.days_per_week, rel=1e-15)
    assert np.isinf(days[1, 1])
    # one, two and three shifts: the same samples' days at 8, 16 and 24 h a day (the scene's 24 h: the days above)
    shifts = shift_days(scene, {"duty.stops_per_hour": stops}, hours)
    assert list(shifts) == [8.0, 16.0, 24.0]
    np.testing.assert_array_equal(shifts[24.0], days)
    np.testing.assert_allclose(shifts[8.0], 3.0 * days, rtol=1e-15)
    assert shift_days(scene, {"duty.hours_per_day": stops}, hours) is None  # drawn: the samples' own
    # a censored sample lies beyond its own horizon's days: the least of them (5 stops an hour) bounds them all
    least = 1e5 * (1.0 + 5.0 * d.stop_minutes / 60.0) / d.hours_per_day * 7.0 / d.days_per_week
    assert horizon_days(scene, {"duty.stops_per_hour": stops}, 1e5) == pytest.approx(least, rel=1e-15)
    assert horizon_days(scene, {"duty.stops_per_hour": stops}, 1e5, 8.0) == pytest.approx(3.0 * least, rel=1e-15)
    assert horizon_days(scene, {}, 1e5) == pytest.approx(d.calendar_days(1e5), rel=1e-15)

    def update(n, volume, share):
        return SimpleNamespace(step_revolutions=n, part=lambda j: SimpleNamespace(volume_rate=volume),
                               response={"stop_start_share_e": share})

    assert prediction_stop_share([update(10.0, 1.0, 0.5), update(30.0, 1.0, 0.1), update(0.0, 5.0, 0.9)]) == \
        pytest.approx((10 * 0.5 + 30 * 0.1) / 40)
    assert prediction_stop_share([update(10.0, 0.0, 0.5)]) is None
    # the summary over the design points names the centre design point's share (a job named node_1_1, not centre)
    summary = stop_share_summary({"node_0_1": {"stop_start_share": 0.1}, "node_1_1": {"stop_start_share": 0.3},
                                  "node_2_1": {"stop_start_share": 0.9}}, "node_1_1")
    assert (summary["centre"], summary["min"], summary["median"], summary["max"]) == (0.3, 0.1, 0.3, 0.9)
