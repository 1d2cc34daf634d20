"""Fast paths: the compiled reference integrator against the scipy path (the same compiled right-hand
side under two integrators), the compiled kernel against its plain-Python source."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

pytest.importorskip("numba")

from weftsim.post.analysis import peaks  # noqa: E402
from weftsim.joint.contact import LAWS, make_law  # noqa: E402
from weftsim.input.params import ReferenceSolver, Scene  # noqa: E402
from conftest import door
solve = door("reference")
from weftsim.physics import laws  # noqa: E402
from weftsim.reference.compiled_channels import crank_side_eval, crank_side_table  # noqa: E402
from weftsim.model.ideal import crank_side_inertia, crank_side_potential  # noqa: E402

# The tolerances below were set for rtol 1e-9, atol 1e-12 (the reference engine's default until
# issue 12; now the automatic path runs at 1e-5): named here, so the comparisons keep their meaning.
BASE = dataclasses.replace(Scene(), reference_solver=ReferenceSolver(rtol=1e-9, atol=1e-12))
PEAK_CHANNELS = ("contact_force_N", "rapier_acceleration_m_s2", "driving_torque_Nm")


def _scene(law="variable_kd", friction=0.0, clearance=BASE.joint.clearance, revolutions=0.1, **solver):
    return dataclasses.replace(
        BASE,
        joint=dataclasses.replace(BASE.joint, law=law, friction_coefficient=friction, clearance=clearance),
        drive=dataclasses.replace(BASE.drive, revolutions=revolutions),
        reference_solver=dataclasses.replace(BASE.reference_solver, **solver),
    )


@pytest.mark.parametrize("law", sorted(LAWS))
def test_compiled_laws_equal_their_python_source(law):
    """numba's compilation (error_model="numpy", constant folding of the series) keeps the laws' values."""
    lib = make_law(_scene(law=law).joint)
    kind, coef, c, xi = lib.parameters
    c = BASE.joint.clearance
    for delta in (-1e-6, 0.0, 1e-9, 1e-6, 0.2 * c, 0.3 * c, 2.0 * c):  # both sides of the series limit c/4
        for rate in (-0.5, 0.0, 0.3):
            expect = float(lib.normal_force(delta, rate, 0.2))
            # Same source, compiled or interpreted: a few ulps at most (libm vs LLVM intrinsics).
            assert laws.normal_force(kind, coef, c, xi, delta, rate, 0.2) == pytest.approx(expect, rel=1e-14, abs=1e-300)
        assert laws.elastic_force(kind, coef, c, delta) == pytest.approx(float(lib.elastic_force(delta)), rel=1e-14,
                                                                          abs=1e-300)  # fmt: skip
        assert laws.elastic_energy(kind, coef, c, delta) == pytest.approx(float(lib.elastic_energy(delta)),
                                                                           rel=1e-14, abs=1e-300)  # fmt: skip


def test_crank_side_table_reproduces_the_closed_form():
    table = crank_side_table(BASE)
    theta = np.random.default_rng(2).uniform(-3.0, 40.0, 500)
    j13, dj13 = crank_side_inertia(theta, BASE)
    u13, du13 = crank_side_potential(theta, BASE)
    exact = np.stack([j13, dj13, u13, du13], axis=1)
    got = np.array([_eval(table, th) for th in theta])
    span = np.abs(exact).max(axis=0)
    # Periodic cubic spline, 4096 knots: h^4 error ~1e-12 of the range (measured 4e-15).
    assert np.all(np.abs(got - exact).max(axis=0) <= 1e-11 * span)


def _eval(table, theta):
    out = np.empty(4)
    crank_side_eval(table, theta, out)
    return out


@pytest.fixture(scope="module")
def start_up_runs():
    """The start-up impact (first contact at 6.6 deg) by both paths, 36 deg of crank."""
    runs = {m: solve(_scene(method=m, revolutions=0.1)) for m in ("DOP853", "numba_DOP853", "numba_RK45")}
    runs["numba_DOP853 rtol 1e-10"] = solve(_scene(method="numba_DOP853", revolutions=0.1, rtol=1e-10, atol=1e-13))
    return runs


def test_compiled_path_follows_the_scipy_path(start_up_runs):
    scipy_run, fast = start_up_runs["DOP853"], start_up_runs["numba_DOP853"]
    assert scipy_run.ok and fast.ok, fast.message
    assert fast.solver_stats["method"] == "numba_DOP853"
    # Same algorithm step for step: same step counts up to round-off-driven differences near events.
    assert fast.solver_stats["steps"] == pytest.approx(scipy_run.solver_stats["steps"], rel=0.02)
    assert fast.first_contact_angle_deg == pytest.approx(scipy_run.first_contact_angle_deg, abs=1e-9)
    # Same right-hand side and event search: the paths differ by round-off of the stage sums, which the
    # impacts amplify like any error.  They must agree within the integration error itself, estimated
    # by the same run at rtol 1e-10: measured path difference / that estimate = 0.1 (rapier
    # displacement), 0.33 (velocity), 1.1 (both eccentricities: 8.4e-11 m against 7.7e-11 m at 36 deg,
    # after four impacts); a wrong term in either path would be orders of magnitude above it.
    finer = start_up_runs["numba_DOP853 rtol 1e-10"]
    for name in ("rapier_displacement_m", "rapier_velocity_m_s", "eccentricity_y_m", "eccentricity_z_m"):
        a, b = scipy_run.samples[name], fast.samples[name]
        assert a.shape == b.shape
        integration_error = np.abs(b - finer.samples[name]).max()
        assert np.abs(a - b).max() <= max(2.0 * integration_error, 1e-7 * np.abs(a).max()), name
    pa, pb = peaks(scipy_run, 0), peaks(fast, 0)
    for name in PEAK_CHANNELS:
        # Peaks of ~0.1 ms pulses read at discrete points: 1e-5 (docs/reference-solver.md).
        assert pb[name]["max"] == pytest.approx(pa[name]["max"], rel=1e-5), name


def test_compiled_methods_agree(start_up_runs):
    a, b = start_up_runs["numba_DOP853"], start_up_runs["numba_RK45"]
    assert b.ok, b.message
    assert b.first_contact_angle_deg == pytest.approx(a.first_contact_angle_deg, abs=1e-6)
    pa, pb = peaks(a, 0), peaks(b, 0)
    for name in PEAK_CHANNELS:
        # Two methods of order 8 and 5 at rtol 1e-9: peaks within the docs' 1e-4 spread.
        assert pb[name]["max"] == pytest.approx(pa[name]["max"], rel=1e-4), name


def test_compiled_energy_balance(start_up_runs):
    r = start_up_runs["numba_DOP853"]
    s = r.steps
    residual = s["driving_work_J"] - (s["kinetic_energy_J"] - s["kinetic_energy_J"][0]) \
        - (s["potential_energy_J"] - s["potential_energy_J"][0]) - s["contact_energy_J"] - s["dissipated_energy_J"]
    # As tests/test_reference_integrate.py: 100 rtol of the largest kinetic energy.
    assert np.abs(residual).max() < 100 * r.scene.reference_solver.rtol * s["kinetic_energy_J"].max()
    assert s["dissipated_energy_J"][-1] > 1.0


def test_compiled_friction_run_closes_the_energy_balance():
    r = solve(_scene(friction=0.1, revolutions=0.05, method="numba_DOP853", rtol=1e-7, atol=1e-10))
    assert r.ok, r.message
    s = r.steps
    residual = s["driving_work_J"] - (s["kinetic_energy_J"] - s["kinetic_energy_J"][0]) \
        - (s["potential_energy_J"] - s["potential_energy_J"][0]) - s["contact_energy_J"] - s["dissipated_energy_J"]
    # Looser rtol (explicit method on the stiff friction ramp): 100 rtol of the kinetic energy.
    assert np.abs(residual).max() < 100 * 1e-7 * s["kinetic_energy_J"].max()


def test_compiled_progress_and_failure():
    calls = []
    r = solve(_scene(method="numba_DOP853", revolutions=0.05, rtol=1e-6, atol=1e-9), progress=calls.append)
    assert r.ok
    assert calls[0] == 0.0 and calls[-1] == 1.0 and calls == sorted(calls) and len(calls) > 10
    bad = solve(_scene(method="numba_DOP853", rtol=1e-30, atol=1e-300))
    # atol 1e-300 cannot be met: every step is rejected until it collapses below limits.min_step.
    assert bad.status == "failed"
    assert "crank angle" in bad.message and "numba_DOP853" in bad.message and "min_step" in bad.message
    assert bad.solver_stats["failure"] == "step_size"
    assert bad.steps["time_s"].size >= 1


def test_unknown_method_names_the_compiled_ones():
    r = solve(_scene(method="numba_Euler"))
    assert r.status == "failed" and "numba_DOP853" in r.message


@pytest.mark.parametrize(("limit", "kind"), [({"max_penetration": 0.001}, "penetration"), ({"max_steps": 50}, "steps")])
def test_compiled_path_applies_the_run_guards(limit, kind):
    scene = _scene(method="numba_DOP853")
    scene = dataclasses.replace(scene, limits=dataclasses.replace(scene.limits, **limit))
    r = solve(scene)
    assert r.status == "failed" and r.solver_stats["failure"] == kind, r.message
    assert "limits." in r.message
    if kind == "penetration":
        # Fails at the step that crosses 10 um, inside the start-up impact (first contact at 6.6 deg).
        assert r.steps["penetration_m"][-1] > 1e-5 and 6.6 < r.steps["crank_angle_deg"][-1] < 10.0
    else:
        assert r.solver_stats["steps"] == 51


# --- Exudyn: the kinematic-tree model against the rigid-body model and the reference engine ---


def _exudyn_scene(model="kinematic_tree", revolutions=0.1, rule=BASE.joint.impact_velocity_rule, **solver):
    return dataclasses.replace(
        BASE,
        joint=dataclasses.replace(BASE.joint, impact_velocity_rule=rule),
        drive=dataclasses.replace(BASE.drive, revolutions=revolutions),
        exudyn_solver=dataclasses.replace(BASE.exudyn_solver, model=model, **solver),
    )


@pytest.fixture(scope="module")
def start_up_exudyn():
    """The first revolution with both Exudyn models and the reference engine (~6 s, mostly rigid body).

    It holds the start-up impact (maxima of contact force and acceleration near 9 deg) and the
    impact sequence near 48 deg that makes the first revolution's torque maximum.  All three hold
    the impact velocity with the "onset" rule: the tolerances below were measured with it (under
    "max_approach" the rigid body's torque maximum at h = 2e-6 s is 2.8e-3 from that at 1e-6 s,
    against 6.4e-4 here; test_exudyn_engine.py compares the models under "max_approach").
    """
    pytest.importorskip("exudyn")
    from conftest import door
    exudyn_solve = door("exudyn")

    tree = exudyn_solve(_exudyn_scene(revolutions=1.0, rule="onset", relative_tolerance=1e-8, absolute_tolerance=1e-11))
    # The rigid body at the fixed 2e-6 s step the tolerances below were measured with (its default
    # adaptive step has its own tests in test_step_control.py).
    rigid = exudyn_solve(_exudyn_scene(model="rigid_body", revolutions=1.0, rule="onset", step_control="fixed"))
    ref_scene = _scene(method="numba_DOP853", rtol=1e-11, atol=1e-14, revolutions=1.0)
    ref_scene = dataclasses.replace(ref_scene, joint=dataclasses.replace(ref_scene.joint, impact_velocity_rule="onset"))
    reference = solve(ref_scene)
    return {"tree": tree, "rigid": rigid, "reference": reference}


def test_tree_model_matches_the_rigid_body_model(start_up_exudyn):
    tree, rigid = start_up_exudyn["tree"], start_up_exudyn["rigid"]
    assert tree.ok and rigid.ok, (tree.message, rigid.message)
    assert tree.solver_stats["model"] == "kinematic_tree" and tree.solver_stats["method"] == "DOPRI5"
    # Both locate the onset within their step (docs/clearance-joint.md: 2e-7 deg at h = 2e-6 s).
    assert tree.first_contact_angle_deg == pytest.approx(rigid.first_contact_angle_deg, abs=1e-4)
    pt, pr = peaks(tree, 0), peaks(rigid, 0)
    for name in PEAK_CHANNELS:
        # First-revolution maxima: the rigid body at h = 2e-6 s is within 6.4e-4 of the converged
        # ones (docs/performance.md), the tree at rtol 1e-8 within 4e-5; CompareTolerance says 1 %.
        assert pt[name]["max"] == pytest.approx(pr[name]["max"], rel=2e-3), name
    # Same rapier motion through the start-up impacts (0..36 deg): 1e-4 of the 1.05 m stroke.
    t = rigid.samples["time_s"]
    early = t < 0.1 * rigid.scene.drive.period
    s_tree = np.interp(t[early], tree.steps["time_s"], tree.steps["rapier_displacement_m"])
    assert np.abs(s_tree - rigid.samples["rapier_displacement_m"][early]).max() < 1e-4 * 1.05


def test_tree_model_matches_the_reference_engine_under_max_approach():
    """The default rule in both engines: the first revolution (start-up impact and the lasting contact
    after it, where the held value is raised ~50 times) with both integrated tightly."""
    pytest.importorskip("exudyn")
    from conftest import door
    exudyn_solve = door("exudyn")

    tree = exudyn_solve(_exudyn_scene(revolutions=1.0, rule="max_approach", relative_tolerance=1e-8,
                                      absolute_tolerance=1e-11))  # fmt: skip
    reference = solve(_scene(method="numba_DOP853", rtol=1e-11, atol=1e-14, revolutions=1.0))
    assert tree.ok and reference.ok, (tree.message, reference.message)
    assert reference.scene.joint.impact_velocity_rule == "max_approach"
    assert tree.first_contact_angle_deg == pytest.approx(reference.first_contact_angle_deg, abs=1e-5)
    pt, pr = peaks(tree, 0), peaks(reference, 0)
    for name in PEAK_CHANNELS:
        # Peaks read at the tree's step ends only (no dense output): measured 4.9e-6 (force),
        # 8.9e-7 (acceleration), 3.2e-6 (torque) at rtol 1e-8; the onset-rule test allows 3e-4.
        assert pt[name]["max"] == pytest.approx(pr[name]["max"], rel=3e-4), name


def test_tree_model_matches_the_reference_engine(start_up_exudyn):
    tree, ref = start_up_exudyn["tree"], start_up_exudyn["reference"]
    # The same equations in other coordinates, both integrated tightly: onset to 1e-6 deg.
    assert tree.first_contact_angle_deg == pytest.approx(ref.first_contact_angle_deg, abs=1e-5)
    pt, pr = peaks(tree, 0), peaks(ref, 0)
    for name in PEAK_CHANNELS:
        # Peaks read at the tree's step ends only (no dense output): measured 4e-5 at rtol 1e-8.
        assert pt[name]["max"] == pytest.approx(pr[name]["max"], rel=3e-4), name
    r = tree.steps
    residual = r["driving_work_J"] - (r["kinetic_energy_J"] - r["kinetic_energy_J"][0]) \
        - (r["potential_energy_J"] - r["potential_energy_J"][0]) - r["contact_energy_J"] - r["dissipated_energy_J"]
    # Trapezoid sums of the contact powers over the steps (O(h^2)): 5e-3 J of the ~5 J that the
    # start-up impacts dissipate; over the whole first revolution measured 9.6e-5 of the largest
    # kinetic energy (~500 J) at rtol 1e-8; a lost contact force would leave ~1e-2.
    assert np.abs(residual).max() < 3e-4 * r["kinetic_energy_J"].max()


def test_tree_callback_routes_agree():
    pytest.importorskip("exudyn")
    from conftest import door
    exudyn_solve = door("exudyn")

    # rtol 1e-10: under "max_approach" the held rate has a kink (max) that DOPRI5's step control
    # feels, so at the default rtol round-off shifts the step sequence and the peak sampled at step
    # ends moves by 2e-5 between routes; at 1e-10 (1.2 us steps at the peak) measured 1e-8.
    runs = {route: exudyn_solve(_exudyn_scene(revolutions=0.04, callback=route, relative_tolerance=1e-10))
            for route in ("python", "numba")}  # fmt: skip
    base = runs["python"]
    assert base.ok and base.solver_stats["callback_calls"] > 0
    for route, r in runs.items():
        assert r.ok, r.message
        assert r.solver_stats["callback"] == route
        # Same kernel, compiled or interpreted: the step sequence may differ by round-off, values by far less than 1e-6.
        assert r.steps["contact_force_N"].max() == pytest.approx(base.steps["contact_force_N"].max(), rel=1e-6)
        assert r.first_contact_angle_deg == pytest.approx(base.first_contact_angle_deg, abs=1e-9)


def test_tree_model_settings_and_guards():
    pytest.importorskip("exudyn")
    from conftest import door
    exudyn_solve = door("exudyn")

    ideal = dataclasses.replace(_exudyn_scene(), joint=dataclasses.replace(BASE.joint, clearance=0.0))
    r = exudyn_solve(ideal)
    assert r.status == "failed" and "clearance joint" in r.message
    r = exudyn_solve(_exudyn_scene(explicit_method="RK44"))
    assert r.status == "failed" and "explicit_method" in r.message
    r = exudyn_solve(_exudyn_scene(callback="symbolic"))  # the tree has no symbolic route (tree.py)
    assert r.status == "failed" and "'symbolic'" in r.message and "rigid_body" in r.message
    scene = _exudyn_scene()
    r = exudyn_solve(dataclasses.replace(scene, limits=dataclasses.replace(scene.limits, max_penetration=0.001)))
    assert r.status == "failed" and r.solver_stats["failure"] == "penetration", r.message
    # Stopped at the first step beyond 10 um, inside the start-up impact.
    assert 6.6 < r.steps["crank_angle_deg"][-1] < 10.0
    calls = []
    r = exudyn_solve(_exudyn_scene(revolutions=0.02), progress=calls.append)
    assert r.ok and calls[0] == 0.0 and calls[-1] == 1.0 and calls == sorted(calls)


# --- The benchmark's bookkeeping (no timing is asserted anywhere) ---


def test_bench_errors_are_relative_and_means_relative_to_the_rms():
    from weftsim.bench.measure import QUANTITY_CHANNELS, errors

    ref = {"revolutions": 10, "first_contact_deg": 6.6,
           "peak": {ch: 100.0 for ch in QUANTITY_CHANNELS},
           "rms": {ch: 50.0 for ch in QUANTITY_CHANNELS}, "mean": {ch: 0.0 for ch in QUANTITY_CHANNELS}}  # fmt: skip
    run = {"revolutions": 10, "first_contact_deg": 6.7,
           "peak": {ch: 101.0 for ch in QUANTITY_CHANNELS},
           "rms": {ch: 49.0 for ch in QUANTITY_CHANNELS}, "mean": {ch: 1.5 for ch in QUANTITY_CHANNELS}}  # fmt: skip
    e = errors(run, ref)
    assert e["peak_max"] == pytest.approx(0.01)
    # A mean of ~0 (rapier acceleration over whole revolutions) is compared against the RMS.
    assert e["stats_max"] == pytest.approx(0.03)
    assert e["first_contact_deg"] == pytest.approx(0.1)
    short = dict(run, revolutions=5)
    assert errors(short, ref)["stats_max"] is None  # fewer revolutions: no statistics to compare
    assert errors(None, ref) is None


def test_bench_measures_a_setting_and_reports_failures(tmp_path):
    from weftsim.bench import measure as bench
    from weftsim.bench.report import markdown

    ref = bench.converged_solution("c0.25mm-400rpm", "models", 1.0, log=lambda text: None)
    ok = bench.measure("c0.25mm-400rpm", bench._ref("numba_DOP853", 1e-6), ref, "models", 1.0, 2, 10.0, 0.5)
    assert ok["status"] == "success" and ok["timing"]["runs"] == 2 and len(ok["timing"]["wall_s"]) == 2
    assert ok["errors"]["peak_max"] < 1e-3  # rtol 1e-6 against 1e-12: the docs' 1e-4 spread
    assert ok["realtime_ratio"] > 0.0 and ok["steps"] > 0
    # A run that fails is kept with its reason; a too-long run is timed on the short scene.
    bad_setting = bench.Setting("reference", "reference numba_DOP853", "capped", {
        "solver.reference.method": "numba_DOP853", "limits.max_steps": 20})
    bad = bench.measure("c0.25mm-400rpm", bad_setting, ref, "models", 1.0, 2, 0.0, 0.5)
    assert bad["status"] == "failed" and bad["failure"] == "steps" and "limits.max_steps" in bad["message"]
    assert bad["timing"]["runs"] == 1  # a failed run is not repeated
    assert bad["errors"] is None  # no whole revolution before the failure: nothing to compare
    slow = bench.measure("c0.25mm-400rpm", bench._ref("numba_DOP853", 1e-6), ref, "models", 1.0, 2, 0.0, 0.5)
    assert slow["timing"]["revolutions"] == pytest.approx(0.5)  # over the repeat limit: timed on 0.5 rev
    report = {"mode": "test", "revolutions": 1.0, "repeats": 2, "repeat_limit_s": 10.0, "timing_revolutions": 0.5,
              "targets": bench.TARGETS, "total_time_s": 1.0, "machine_start": _machine(), "machine_end": _machine(),
              "startup": {}, "cases": {"c0.25mm-400rpm": {"converged": ref, "runs": [ok, bad]}}}  # fmt: skip
    text = markdown(report)
    assert "**failed** (steps)" in text and "limits.max_steps" in text and ok["setting"] in text


def _machine():
    from weftsim.bench.report import machine_info

    return machine_info()


def test_compiled_chunks_and_pauses_do_not_change_the_run(monkeypatch):
    from weftsim.reference import compiled_run

    scene = _scene(method="numba_DOP853", revolutions=0.05, rtol=1e-7, atol=1e-10)
    whole = compiled_run.integrate_compiled(scene)
    monkeypatch.setattr(compiled_run, "_STEP_BUFFER", 16)  # a chunk every few steps
    pieces = compiled_run.integrate_compiled(scene, progress=lambda fraction: None)  # and pauses every 0.1 %
    for a, b in zip(whole[0] + whole[1], pieces[0] + pieces[1]):
        np.testing.assert_array_equal(a, b)  # bit for bit: the state carries over exactly
    assert whole[2]["steps"] == pieces[2]["steps"] and whole[2]["function_evaluations"] == pieces[2]["function_evaluations"]


def test_the_copied_tableaux_are_scipys():
    """scripts/make_rk_tableaux.py copied scipy's DOP853 and RK45 coefficients (so a run needs no
    scipy.integrate): bitwise equal to the installed scipy's, or the copy must be regenerated."""
    from scipy.integrate import RK45
    from scipy.integrate._ivp import dop853_coefficients as dop853

    from weftsim.reference import rk_tableaux as copy

    assert copy.DOP853_N_STAGES == dop853.N_STAGES
    for name in ("A", "B", "C", "E3", "E5", "D"):
        assert np.array_equal(getattr(copy, f"DOP853_{name}"), getattr(dop853, name)), name
    for name in ("A", "B", "C", "E", "P"):
        assert np.array_equal(getattr(copy, f"RK45_{name}"), getattr(RK45, name)), name


def test_the_periodic_spline_is_scipys():
    """The crank-side table's spline (compiled_channels.periodic_spline, Fourier solve) is the periodic
    CubicSpline: coefficients agree to round-off (measured 1.3e-12 of values ~3 at 64 knots; the cubic
    terms scale as 1/h, hence the bound relative to the largest coefficient)."""
    from scipy.interpolate import CubicSpline

    from weftsim.reference.compiled_channels import periodic_spline

    n = 64
    h = 2.0 * math.pi / n
    x = np.arange(n) * h
    y = np.stack([np.sin(x) + 0.3 * np.cos(3.0 * x), np.exp(np.cos(x))], axis=1)
    spline = CubicSpline(np.append(x, 2.0 * math.pi), np.vstack([y, y[:1]]), bc_type="periodic")
    expected = np.transpose(spline.c, (2, 1, 0))
    assert np.abs(periodic_spline(y, h) - expected).max() < 1e-10 * np.abs(expected).max()
