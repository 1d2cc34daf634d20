"""The film-borne loom on the reference engine's default path (RODAS4): converged peaks at few steps.

With an oil film the clearance rate is a stiff, quasi-static variable whose error estimate grows about as h;
under atol = 1e-8 rad/s it held the step at ~1e-7 s (61 416 steps a revolution).  RODAS4 now weighs the rates
with atol times the drive speed when a joint has a film (``compiled_ros.rate_tolerance_factor``;
docs/performance.md, "Where the time goes in a lubricated run").  These tests check that the default path's
first-half-revolution peaks stay converged and that dry and friction runs keep their norm.  In the mixed
regime (asperities carrying, film ratio down to 0.37) the Jacobian is a central difference
(``compiled_ros.central_differences``): its accuracy and the run's convergence are checked at the end.
"""

from __future__ import annotations

import numpy as np
import pytest

import weftsim
from weftsim.post.analysis import peaks
from weftsim.reference.compiled_ros import rate_tolerance_factor
from weftsim.model.dynamics import pack_parameters
from conftest import door

FILM = {"joint_e.lubrication.viscosity_mpa_s": 80.0}  # the loom at c = 0.02 mm, 600 rpm: no contact
TIGHT = {"solver.reference.rtol": 1e-8, "solver.reference.atol": 1e-11}
HALF = 0.5  # revolutions: the rapier's acceleration and film force peaks of the first stroke
# Issue 23's accuracy target for first-revolution peaks; measured over the full revolution: 0.055-0.13 %.
PEAK_TOLERANCE = 0.005


def _run(overrides: dict):
    scene = weftsim.load_scene("loom", overrides, revolutions=HALF)
    result = weftsim.simulate(scene, "reference")
    assert result.ok, result.message
    return result


@pytest.fixture(scope="module")
def runs():
    return _run(FILM), _run({**FILM, **TIGHT})


@pytest.mark.parametrize("channel", ["film_force_N", "rapier_acceleration_m_s2", "driving_torque_Nm"])
def test_default_peaks_match_the_tight_run(runs, channel):
    fast, tight = (peaks(r, 0)[channel] for r in runs)
    for end in ("min", "max"):
        if abs(tight[end]) > 1e-6:
            assert fast[end] == pytest.approx(tight[end], rel=PEAK_TOLERANCE), (channel, end)


def test_min_film_ratio_matches_the_tight_run(runs):
    fast, tight = (peaks(r, 0)["film_ratio"]["min"] for r in runs)
    assert fast == pytest.approx(tight, rel=PEAK_TOLERANCE)


def test_film_does_not_hold_the_step_at_its_stiff_rate(runs):
    fast = runs[0]
    assert fast.solver_stats["method"] == "numba_RODAS4"
    assert fast.solver_stats["contact_events"] == 0  # the film holds the journal off the wall
    # Before the rate weighting: 61 416 steps a revolution (~30 700 in this half); now ~1 500.
    assert fast.solver_stats["steps"] < 5_000


@pytest.mark.parametrize("overrides, lubricated", [
    ({}, False),
    ({"joint_e.friction_coefficient": 0.15}, False),
    ({"joint_e.lubrication.viscosity_mpa_s": 0.0}, False),  # asperities only: no film, the norm unchanged
    (FILM, True),
])  # fmt: skip
def test_rate_weight_only_with_a_film(overrides, lubricated):
    scene = weftsim.load_scene("loom", overrides, revolutions=HALF)
    factor = rate_tolerance_factor(pack_parameters(scene))
    assert factor == (scene.drive.speed if lubricated else 1.0)
    assert np.isfinite(factor)


# The mixed regime (issue 26): the loom at 10 mPa s runs with film ratios 0.37-23, the asperities carrying part
# of the load over 2/3 of the cycle and the film held at its floor (film ratio 1) near 260 deg of crank.
MIXED = {"joint_e.lubrication.viscosity_mpa_s": 10.0}


@pytest.fixture(scope="module")
def mixed_runs():
    """One revolution of the mixed loom at the default tolerance, the worn-update tolerance and tight."""
    def run(extra):
        scene = weftsim.load_scene("loom", {**MIXED, **extra}, revolutions=1.0)
        result = weftsim.simulate(scene, "reference")
        assert result.ok, result.message
        return result
    return (run({}), run({"solver.reference.rtol": 1e-6, "solver.reference.atol": 1e-9}), run(TIGHT))


def test_jacobian_of_the_mixed_film_is_accurate():
    """With a lubricated joint RODAS4's Jacobian is a central difference: against a Richardson-extrapolated
    difference (steps m and 2m times larger), at the thinnest film of the first quarter revolution (on the
    asperities).

    The thinnest film is where the radial rate d abs(e)/dt changes sign, and there the film's force bends: a
    zero rate is the squeeze angle xi = pi/2, a node of the film table (weftsim.physics.film.finite_force,
    Catmull-Rom in xi: C1 only), so a difference whose steps carry the rate across zero has a truncation error of order h, not h^2, and
    Richardson's extrapolation is then no reference.  The reference takes the largest m of 10, 5, 2 whose
    perturbations keep the rate's sign (the Jacobian's own steps, m = 1, are 10x below m = 10).
    """
    from weftsim.physics.chain import penetration
    from weftsim.physics.chain_f import rhs_any
    from weftsim.reference import compiled_ros as ros
    from conftest import door
    solve = door("reference")

    scene = weftsim.load_scene("loom", MIXED, revolutions=0.25)
    rows = {}
    solve(scene, observe=lambda t, y, contact, impact: rows.update(t=t, y=y))
    prm = pack_parameters(scene)
    gaps = [penetration(prm, t, y)[0] for t, y in zip(rows["t"], rows["y"])]
    k = int(np.argmax(gaps))
    assert -gaps[k] < 4.0 * scene.joint.lubrication.roughness  # the asperities carry load here
    t, y = float(rows["t"][k]), rows["y"][k].astype(float)
    n, impact = y.size, np.zeros(2)
    n_mech = n - ros.N_QUADRATURES
    steps = np.array([ros.JAC_CENTRAL_Q if j < n_mech // 2 else ros.JAC_CENTRAL_V for j in range(n_mech)])

    def f(time, state):
        out = np.empty(n)
        rhs_any(prm, time, state, 0, impact, out)
        return out

    def shifted(j, step):
        plus, minus = y.copy(), y.copy()
        plus[j] += step
        minus[j] -= step
        return plus, minus

    def keeps_rate_sign(m):
        rate = penetration(prm, t, y)[1]
        return all(penetration(prm, t, state)[1] * rate > 0.0
                   for j in range(n_mech) for state in shifted(j, 2.0 * m * steps[j]))

    m = next((m for m in (10.0, 5.0, 2.0) if keeps_rate_sign(m)), None)
    assert m is not None, "the radial rate changes sign within 4x the Jacobian's steps: no smooth reference"
    J, f_t, a, b, tmp = np.zeros((n, n)), *(np.zeros(n) for _ in range(4))
    ros.jacobian(prm, t, y, f(t, y), 0, impact, np.zeros(32, dtype=np.int64), J, f_t, a, b, tmp)

    def central(j, step):
        plus, minus = shifted(j, step)
        return (f(t, plus) - f(t, minus)) / (2.0 * step)

    worst = 0.0
    for j in range(n_mech):
        extrapolated = (4.0 * central(j, m * steps[j]) - central(j, 2.0 * m * steps[j])) / 3.0
        worst = max(worst, float(np.max(np.abs(J[:, j] - extrapolated)) / np.max(np.abs(extrapolated))))
    # Measured 1.4e-6 when written (m = 10).  On the state of today's run (rate 1.8e-8 m/s, carried across zero
    # by m = 10's psi steps 3e-9 and 6e-9 rad) m = 10 read 1.009e-5 and m = 5 1.8e-6; the friction coefficient of
    # the dry law (0.1 or 0) changes none of it (|e| < c here).  m = 2 keeps the sign: 1.44e-6; m = 3 2.1e-6;
    # m = 1 (the Jacobian's own steps) 4.8e-7: the Jacobian is within ~1e-6 of the smooth derivative.  The forward
    # differences of the dry path (JAC_STEP_*) give 8.6e-4, which left RODAS4's error estimate of psi' at order
    # 1 whatever the step (docs/performance.md, "The mixed regime"): 1e-5 lies between the two.
    assert worst < 1e-5, (worst, m)


def test_mixed_regime_converges_at_few_steps(mixed_runs):
    default, worn, tight = mixed_runs
    assert default.solver_stats["steps"] < 3_000  # measured 1 977 (13 548 with forward differences)
    for channel, end in (("film_ratio", "min"), ("asperity_force_N", "max"), ("film_force_N", "max")):
        ref = peaks(tight, 0)[channel][end]
        # Measured against rtol 1e-8: at the default rtol 1e-5 0.79 % (film ratio), 0.59 % (asperity load), 0.002 %
        # (film force); at the wear updates' rtol 1e-6 0.021 %, 0.016 %, 3e-4 %.  The asperity load goes as
        # (4 - h/sigma)^6.8, so it magnifies an error of the film thickness.  Bounds about twice those.
        assert peaks(default, 0)[channel][end] == pytest.approx(ref, rel=0.015), (channel, "default")
        assert peaks(worn, 0)[channel][end] == pytest.approx(ref, rel=5e-4), (channel, "worn")


def _rodas_step(prm, t, y, h):
    """One RODAS4 step of the kernel from (t, y): (y_new, dense rows F) with F complete for both dense outputs."""
    from weftsim.physics.chain_f import rhs_any
    from weftsim.reference import compiled_ros as ros

    n, impact, ist = y.size, np.zeros(2), np.zeros(32, dtype=np.int64)
    f0 = np.empty(n)
    rhs_any(prm, t, y, 0, impact, f0)
    J, E, K, F = np.zeros((n, n)), np.zeros((n, n)), np.zeros((16, n)), np.zeros((7, n))
    f_t, a, b, tmp, arg, y_new, f_new = (np.zeros(n) for _ in range(7))
    ros.jacobian(prm, t, y, f0, 0, impact, ist, J, f_t, a, b, tmp)
    ros.step(prm, t, y, h, f0, J, f_t, 0, impact, ist, K, E, np.zeros(n, dtype=np.int64), y_new, F, tmp, arg,
             1e-5, 1e-8)  # fmt: skip
    rhs_any(prm, t + h, y_new, 0, impact, f_new)
    ros.finish_dense(F, h, f_new)
    return y_new, F


def test_stiff_dense_output_is_order_3_and_follows_the_clearance_rate():
    """RODAS's continuous extension (compiled_ros.dense_stiff, the dense output with a lubricated joint): local
    error ~ h^4 in smooth free flight, and in the mixed regime it follows the stiff rate psi' where the cubic
    Hermite interpolant does not."""
    from scipy.integrate import solve_ivp

    from weftsim.physics.chain_f import rhs_any
    from weftsim.reference import compiled_ros as ros
    from weftsim.model.dynamics import initial_state

    def interpolants(prm, t, y, h, s):
        y_new, F = _rodas_step(prm, t, y, h)
        stiff, hermite = np.zeros(y.size), np.zeros(y.size)
        ros.dense_stiff(F, t, h, y, t + s * h, stiff)
        ros.dense(F, t, h, y, t + s * h, hermite)
        impact = np.zeros(2)

        def f(time, state):
            out = np.empty(y.size)
            rhs_any(prm, time, state, 0, impact, out)
            return out
        exact = solve_ivp(f, (t, t + s * h), y, method="Radau", rtol=1e-12, atol=1e-16).y[:, -1]
        return stiff - exact, hermite - exact

    dry = weftsim.load_scene("loom", {}, revolutions=1.0)
    prm, y0 = pack_parameters(dry), initial_state(dry).astype(float)
    hs = [8e-3, 4e-3, 2e-3]  # below 1e-3 s the errors (< 1e-13) meet the reference's round-off
    errors = [float(np.max(np.abs(interpolants(prm, 0.01, y0, h, 0.37)[0][:4]))) for h in hs]
    slope = float(np.polyfit(np.log(hs), np.log(errors), 1)[0])
    # Measured 5.0 (3.6e-9, 1.1e-10, 3.5e-12 rad; the Hermite interpolant's the same): at least the local
    # order 4 of a third-order continuous extension, which wrong coefficients would not reach.
    assert slope > 3.6

    mixed = weftsim.load_scene("loom", MIXED, revolutions=0.3)
    rows = {}
    door("reference")(mixed, observe=lambda t, y, contact, impact: rows.update(t=t, y=y))
    prm = pack_parameters(mixed)
    for degrees in (60.0, 80.0):  # film ratio ~2.1 and ~1.6: on the asperities
        k = int(np.searchsorted(rows["t"], degrees / 360.0 * mixed.drive.period))
        start = rows["y"][k].astype(float)
        # A step that starts off the slow manifold, as one from an event's state (read from the previous step's
        # interpolant) does: psi' off by 1e-5 rad/s, 1 % of it.  The Hermite interpolant carries h f/8 of the
        # start's large psi'' (the squeeze film relaxing it at ~1e7 1/s) to mid-step.
        start[3] += 1e-5
        stiff, hermite = interpolants(prm, float(rows["t"][k]), start, 2e-5, 0.5)
        # Measured at mid-step: 2.4e-6 and 1.9e-6 rad/s against the Hermite interpolant's 2.6e-4 and 3.8e-4 (a
        # quarter of psi', which sets the squeeze film's force).
        assert abs(stiff[3]) < 0.05 * abs(hermite[3]), degrees


def test_no_spurious_film_force_after_touching_the_wall():
    """c = 0.1 mm, 80 mPa s: the journal on its asperities touches the wall once a revolution.  The contact
    step's mid-step row read the Hermite interpolant, whose clearance rate overshot: a film force of 9 834 N
    between 7 040 and 7 024 N and a driving torque of 1 261 N m in revolution 2 against 1 027 N m (tight).
    (At 80 mPa s the rough film, stiffer near the wall than the smooth one, keeps the journal off it, and at 40 mPa s
    too since the film is continued below its floor instead of held there: 10 mPa s touches it 3 times in two
    revolutions.  20 mPa s touches it 3 times too, but its revolution-2 torque peak reads 1 034.3 N m against the
    tight run's 1 026.7 (0.74 %): not yet explained.)"""
    oil = {"joint_e.clearance_mm": 0.1, "joint_e.lubrication.viscosity_mpa_s": 10.0}
    runs = [weftsim.simulate(weftsim.load_scene("loom", {**oil, **extra}, revolutions=2.0), "reference")
            for extra in ({}, TIGHT)]  # fmt: skip
    assert all(r.ok for r in runs)
    assert runs[0].solver_stats["impacts"] > 0
    for channel in ("driving_torque_Nm", "film_force_N"):
        # Measured now: 0.008 % (torque), 0.01 % (film force) in revolution 2; the first revolution's peaks
        # (the start-up) within 0.1 %.
        assert peaks(runs[0], 1)[channel]["max"] == pytest.approx(peaks(runs[1], 1)[channel]["max"],
                                                                  rel=PEAK_TOLERANCE)  # fmt: skip
