"""The linearly implicit path of the reference engine (RODAS4, weftsim/reference/compiled_ros.py): its order,
its Jacobian, its agreement with the explicit DOP853 path with and without friction, the energy balance with
friction, the first contact, and the automatic choice."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("numba")

from weftsim.post.analysis import energy_balance, peaks  # noqa: E402
from weftsim.physics.chain_f import rhs_any  # noqa: E402
from weftsim.reference import compiled_ros as ros  # noqa: E402
from weftsim.reference import select_path  # noqa: E402
from conftest import door
solve = door("reference")
from weftsim.model.dynamics import initial_state, pack_parameters  # noqa: E402
from weftsim.input.scene import load_scene  # noqa: E402

REFERENCE = Path(__file__).resolve().parents[1] / "models" / "reference.toml"
PEAK_CHANNELS = ("contact_force_N", "rapier_acceleration_m_s2", "driving_torque_Nm")


def _scene(mu=0.0, degrees=60.0, **solver):
    keys = {"joint_e.clearance_mm": 0.5, "joint_e.friction_coefficient": mu, "drive.revolutions": degrees / 360.0}
    keys.update({f"solver.reference.{k}": v for k, v in solver.items()})
    return load_scene(REFERENCE, keys)


def pack_penetration(scene, t, y):
    from weftsim.physics.chain_f import penetration_at

    return penetration_at(pack_parameters(scene), t, y, 0)[0]


def _first_peaks(result):
    return {name: peaks(result, 0)[name]["max"] for name in PEAK_CHANNELS}


class _Stepper:
    """Fixed-step RODAS4 on the kernel's right-hand side, for the order tests."""

    def __init__(self, scene, contact=0, impact=(0.0, 0.0)):
        self.prm = pack_parameters(scene)
        self.contact = contact
        self.impact = np.array(impact, dtype=float)
        self.n = initial_state(scene).size
        n = self.n
        self.ist = np.zeros(32, dtype=np.int64)
        self.J, self.E = np.zeros((n, n)), np.zeros((n, n))
        self.K, self.F = np.zeros((16, n)), np.zeros((7, n))
        self.piv = np.zeros(n, dtype=np.int64)

    def f(self, t, y):
        out = np.empty(self.n)
        rhs_any(self.prm, t, y, self.contact, self.impact, out)
        return out

    def step(self, t, y, h):
        n = self.n
        f_t, a, b, tmp, arg, y_new = (np.zeros(n) for _ in range(6))
        f0 = self.f(t, y)
        ros.jacobian(self.prm, t, y, f0, self.contact, self.impact, self.ist, self.J, f_t, a, b, tmp)
        ros.step(self.prm, t, y, h, f0, self.J, f_t, self.contact, self.impact, self.ist, self.K, self.E,
                 self.piv, y_new, self.F, tmp, arg, 1e-6, 1e-9)  # fmt: skip
        ros.finish_dense(self.F, h, self.f(t + h, y_new))
        return y_new

    def dense(self, t, h, y, t_out):
        out = np.zeros(self.n)
        ros.dense(self.F, t, h, y, t_out, out)
        return out


def _slope(hs, errors):
    return float(np.polyfit(np.log(hs), np.log(errors), 1)[0])


def test_rodas4_converges_with_order_4_and_its_dense_output_with_local_order_4():
    """Free flight of the chain over one revolution (smooth): global error ~ h^4, dense output's local error ~ h^4."""
    from scipy.integrate import solve_ivp

    scene = _scene(degrees=360.0)
    stepper = _Stepper(scene)
    y0 = initial_state(scene).astype(float)
    period = scene.drive.period
    exact = solve_ivp(stepper.f, (0.0, period), y0, method="DOP853", rtol=1e-13, atol=1e-15, dense_output=True)
    hs = [period / 6, period / 12, period / 24]
    global_errors, dense_errors = [], []
    for h in hs:
        t, y, worst = 0.0, y0.copy(), 0.0
        for _ in range(round(period / h)):
            y_new = stepper.step(t, y, h)
            local = solve_ivp(stepper.f, (t, t + 0.37 * h), y, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
            worst = max(worst, float(np.max(np.abs(stepper.dense(t, h, y, t + 0.37 * h) - local)[:4])))
            t, y = t + h, y_new
        global_errors.append(float(np.max(np.abs(y - exact.sol(t))[:4])))
        dense_errors.append(worst)
    # Measured slopes 4.2 (global; 4.33 and 4.02 between neighbours) and 3.99 (dense): order 4 within 0.4.
    assert 3.6 < _slope(hs, global_errors) < 4.6
    assert 3.6 < _slope(hs, dense_errors) < 4.4


def test_jacobian_of_the_kernel_matches_a_richardson_extrapolated_difference_in_sticking_contact():
    """The forward differences with the fixed steps of compiled_ros against an independent, extrapolated
    difference (steps 100x and 200x larger, which cancels the h^2 term), in contact with friction."""
    scene = _scene(mu=0.15, degrees=20.0)
    rows = {}
    solve(scene, observe=lambda t, y, contact, impact: rows.update(t=t, y=y, contact=contact, impact=impact))
    # The deepest contact row: near delta = 0 the law's delta^1.5 has no second derivative, and any
    # difference across it compares the kink, not the Jacobian (at the onset row: 40-100 % for h = 1e-7).
    k = int(np.argmax(np.where(rows["contact"], [pack_penetration(scene, t, y) for t, y in zip(rows["t"], rows["y"])],
                               -np.inf)))  # fmt: skip
    stepper = _Stepper(scene, contact=1, impact=(rows["impact"][k], 0.0))
    t, y = float(rows["t"][k]), rows["y"][k].astype(float)
    n = y.size
    f_t, a, b, tmp = (np.zeros(n) for _ in range(4))
    ros.jacobian(stepper.prm, t, y, stepper.f(t, y), 1, stepper.impact, stepper.ist, stepper.J, f_t, a, b, tmp)

    def central(j, step):
        plus, minus = y.copy(), y.copy()
        plus[j] += step
        minus[j] -= step
        return (stepper.f(t, plus) - stepper.f(t, minus)) / (2.0 * step)

    worst = 0.0
    for j in range(n - ros.N_QUADRATURES):
        h = 1e-8  # 10x the kernel's step: 1e-7 can cross a kink of the friction ramp (3e-3 measured there)
        extrapolated = (4.0 * central(j, h) - central(j, 2.0 * h)) / 3.0
        scale = np.max(np.abs(extrapolated))
        worst = max(worst, float(np.max(np.abs(stepper.J[:, j] - extrapolated)) / scale))
    # Measured 5e-8-7e-6 at rows inside the contact (truncation of the 1e-9 forward steps, largest where the
    # penetration is shallow); a Rosenbrock step needs far less than 1e-3.
    assert worst < 1e-5
    assert not stepper.J[:, -ros.N_QUADRATURES:].any()  # W3 and D are not read by the right-hand side


def test_without_friction_rodas4_agrees_with_the_explicit_path_and_finds_the_same_first_contact():
    explicit = solve(_scene(method="numba_DOP853", rtol=1e-8, atol=1e-11))
    for method in ("numba_RODAS4", "numba_DOP853_RODAS4"):
        implicit = solve(_scene(method=method, rtol=1e-6, atol=1e-9))
        assert implicit.status == "success", implicit.message
        got, want = _first_peaks(implicit), _first_peaks(explicit)
        for name in PEAK_CHANNELS:
            # Measured 3e-5 (acceleration) or less at rtol 1e-6; the [compare] tolerance is 1e-2.
            assert got[name] == pytest.approx(want[name], rel=3e-4), name
        # Free flight up to the first onset: DOP853 in both (bit-identical) or RODAS4 (9.389207399817153 deg
        # against ...792: 6e-13 deg, the event search's 1e-13 s).
        assert implicit.first_contact_angle_deg == pytest.approx(explicit.first_contact_angle_deg, abs=1e-9)


def test_with_friction_the_automatic_path_agrees_with_explicit_dop853_at_rtol_1e_8():
    """The first 12 deg of crank (the start-up impact at 9.4 deg and the sticking after it): the explicit
    reference takes ~2e5 steps of ~1e-9 s here, the automatic path ~100."""
    explicit = solve(_scene(mu=0.15, degrees=12.0, method="numba_DOP853", rtol=1e-8, atol=1e-11))
    automatic = solve(_scene(mu=0.15, degrees=12.0))
    assert automatic.solver_stats["method"] == "numba_DOP853_RODAS4"
    assert automatic.solver_stats["steps"] * 100 < explicit.solver_stats["steps"]
    got, want = _first_peaks(automatic), _first_peaks(explicit)
    for name in PEAK_CHANNELS:
        # Measured 3e-5 (acceleration), 2e-5 (torque), 3e-6 (force) over 15 deg.
        assert got[name] == pytest.approx(want[name], rel=3e-4), name
    assert automatic.first_contact_angle_deg == pytest.approx(explicit.first_contact_angle_deg, abs=1e-9)


def test_with_friction_the_energy_balance_closes_and_mu_0_5_runs_in_few_steps():
    for mu in (0.15, 0.5):
        result = solve(_scene(mu=mu, degrees=360.0))
        assert result.status == "success", result.message
        balance = energy_balance(result)
        assert balance["dissipated_energy_J"] > 0.0
        # Measured 5e-8-7e-8 of the largest kinetic energy at rtol 1e-6 (the guard's limit is 1e-2).
        assert abs(balance["relative_residual"]) < 1e-6
        # Measured ~3000 steps for one revolution (the explicit path: 2.5 M at mu = 0.15, 6 M at mu = 0.5).
        assert result.solver_stats["steps"] < 20_000


def test_automatic_choice_names_the_stiff_joint_and_keeps_explicit_paths_selectable():
    dry, rough = _scene(), _scene(mu=0.15)
    assert select_path(dry)["method"].startswith("numba_DOP853 rtol 1e-05")
    path = select_path(rough)
    # Dry friction at E alone: RODAS4 near the friction ramp only, at the tighter rtol of that path.
    assert path["method"].startswith("numba_DOP853_RODAS4 rtol 1e-07")
    assert "friction at E" in path["reason"] and "friction ramp" in path["reason"]
    assert select_path(_scene(mu=0.15, method="numba_DOP853"))["method"].startswith("numba_DOP853 rtol 1e-05")


def test_run_time_and_record_estimates_know_friction():
    from weftsim.engines import get
    from weftsim.reference.engine import EXPLICIT_STIFF_FACTOR

    def estimate_run_time(scene, engine):
        return get(engine).estimate(scene).run_time_s

    def estimate_step_bytes(scene, engine):
        return get(engine).estimate(scene).step_bytes

    dry, rough = _scene(degrees=360.0), _scene(mu=0.15, degrees=360.0)
    explicit = _scene(mu=0.15, degrees=360.0, method="numba_DOP853")
    # The implicit path with friction near its ramp only: measured 1.6-2.1x the dry default in one process.
    assert 1.3 <= estimate_run_time(rough, "reference") / estimate_run_time(dry, "reference") <= 3.0
    # numba_DOP853 on friction: measured 1661x the dry run (issue 23), and a record of millions of rows.
    assert estimate_run_time(explicit, "reference") == pytest.approx(EXPLICIT_STIFF_FACTOR
                                                                     * estimate_run_time(dry, "reference"))
    assert estimate_step_bytes(explicit, "reference") > 1e9 > 1e7 > estimate_step_bytes(rough, "reference")


def test_weftsim_run_announces_an_explicit_friction_run_before_it_starts(capsys):
    from weftsim.cli.commands import _announce_run_time

    _announce_run_time(_scene(mu=0.15, degrees=720.0, method="numba_DOP853"), ("reference",), "run")
    err = capsys.readouterr().err
    assert "warning: the per-step record will be ~" in err and "estimated run time" in err
    _announce_run_time(_scene(mu=0.15, degrees=720.0), ("reference",), "run")  # the default: seconds, small
    assert capsys.readouterr().err == ""


def test_friction_on_the_loom_takes_rodas4_near_its_ramp_only_at_the_converged_peaks():
    """Issue 36: the worn loom with friction (c = 0.1 mm, mu = 0.15) is in contact 99.9 % of the time, and RODAS4
    (order 4) in lasting contact needs many times the steps of DOP853 (order 8), friction or not.  The ramp's
    stiff eigenvalue (~-3e7 1/s) is there only while the rocker reverses; RODAS4 runs only within 10 v1 of it.

    Measured under the loom's cylindrical law (issue 37), one revolution at rtol 1e-7: the hybrid path 10 972
    steps (7 614 on RODAS4), RODAS4 alone 78 270, DOP853 alone 77 142, dry 1 296 (under the former variable_kd:
    3 664 (1 996), 34 489, 26 491, 938).  Against DOP853 at rtol 1e-10 (which agrees with RODAS4 at 1e-10 to
    6e-5): the start-up impact's maxima (3.2 deg) of rapier acceleration, contact force and joint load within
    3.2e-5.  The driving torque's first-revolution maximum is no longer reproducible: after about 119 deg every
    run leaves the rtol 1e-11 one (DOP853 at 1e-7 .. 1e-10, RODAS4 at 1e-7 .. 1e-10), and its later impacts are
    draws: the hybrid's maximum is 11 331 N m at 287 deg, the converged 7 669 N m at 98 deg, DOP853 alone gives
    10 213 .. 11 897 N m at 1e-7 .. 1e-9.  As ``weftsim compare`` does (weftsim.post.compare), a maximum reached
    at crank angles further apart than the first-contact tolerance is judged by the start-up impact's
    (518.12 against 518.13 N m)."""
    from weftsim.post.compare import _max_angle_deg, startup_impact_max

    overrides = {"joint_e.clearance_mm": 0.1, "drive.revolutions": 1.0}
    friction = {**overrides, "joint_e.friction_coefficient": 0.15}
    rough = solve(load_scene("loom", friction))
    rodas = solve(load_scene("loom", {**friction, "solver.reference.method": "numba_RODAS4",
                                      "solver.reference.rtol": 1e-7}))  # the hybrid's rtol (asserted below)
    converged = solve(load_scene("loom", {**friction, "solver.reference.method": "numba_DOP853",
                                          "solver.reference.rtol": 1e-10, "solver.reference.atol": 1e-13}))
    assert rough.ok and rodas.ok and converged.ok
    assert rough.path["method"].startswith("numba_DOP853_RODAS4 rtol 1e-07")
    tolerance = np.degrees(rough.scene.compare.first_contact_angle)
    for name in ("rapier_acceleration_m_s2", "driving_torque_Nm", "contact_force_N", "joint_force_N"):
        if abs(_max_angle_deg(rough, name) - _max_angle_deg(converged, name)) > tolerance:
            peak, want = (startup_impact_max(r, name) for r in (rough, converged))
        else:
            peak, want = (np.abs(r.steps[name]).max() for r in (rough, converged))
        # 1e-3: thirty times the measured 3.2e-5; a path that loses the impact's peak misses it by percents.
        assert peak == pytest.approx(want, rel=1e-3), name
    stats = rough.solver_stats
    # RODAS4 only near the ramp: the hybrid takes a seventh of the steps of RODAS4 alone at the same rtol
    # (measured 10 972 against 78 270; 1 / 9.4 under variable_kd), of which 69 % on RODAS4 (54 % then).
    assert stats["steps"] < 0.25 * rodas.solver_stats["steps"]
    assert 0 < stats["implicit_steps"] < 0.8 * stats["steps"]
