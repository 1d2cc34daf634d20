"""Tests of weftsim.mechanism.kinematics: docs/physics.md section 1 check values, closure identities,
analytic derivatives against finite differences, assembly failure detection."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from weftsim.mechanism import kinematics as kin
from weftsim.input.params import Drive, Geometry

GEOM = Geometry()
OMEGA_400 = Drive().speed  # 400 rpm
BETA = GEOM.crank_inclination
THETA = np.linspace(0.0, 2.0 * np.pi, 721)

# Finite-difference step, rad.  Central differences err by h^2/6 |f'''| (truncation,
# ~2e-10 for |f'''| <= 10 as in this mechanism) plus ~eps |f| / h (round-off, ~1e-10);
# the largest discrepancy measured over all fields is 6e-10.  FD_ATOL (times the
# field's scale, >= 1) sits > 100x above that and orders of magnitude below the O(1)
# relative error of a wrong or missing term.
FD_STEP = 1e-5
FD_ATOL = 1e-7


def half_unit(quoted: str) -> float:
    """Half a unit in the last quoted digit: the tolerance of "reproduce to N digits"."""
    decimals = len(quoted.split(".")[1]) if "." in quoted else 0
    return 0.5 * 10.0 ** (-decimals)


def central_difference(func, theta, h=FD_STEP, angle=False):
    """(f(x + h) - f(x - h)) / 2h; ``angle=True`` wraps the difference into (-pi, pi]
    so that a 2 pi jump of an atan2 result does not count."""
    diff = func(theta + h) - func(theta - h)
    if angle:
        diff = np.angle(np.exp(1j * diff))
    return diff / (2.0 * h)


def assert_derivative(func, d_func, theta, h=FD_STEP, angle=False):
    """Analytic derivative d_func against the central difference of func."""
    fd = central_difference(func, theta, h, angle)
    analytic = d_func(theta)
    scale = max(1.0, float(np.nanmax(np.abs(analytic))))
    np.testing.assert_allclose(analytic, fd, rtol=0.0, atol=FD_ATOL * scale)


def refined_extremum(func, sign, grid=np.linspace(0.0, 2.0 * np.pi, 3601)):
    """(angle, value) of the max (sign=+1) or min (sign=-1) of a periodic scalar func.

    Grid search, then a bounded scalar optimiser within one grid step either side.
    """
    values = sign * func(grid)
    i = int(np.argmax(values))
    step = grid[1] - grid[0]
    res = minimize_scalar(
        lambda t: -sign * float(func(t)),
        bounds=(grid[i] - step, grid[i] + step),
        method="bounded",
        options={"xatol": 1e-10},
    )
    assert res.success
    return res.x % (2.0 * np.pi), sign * -res.fun


# --- docs/physics.md section 1 check values --------------------------------------------------


def test_check_values_at_theta_zero():
    st = kin.linkage_state(0.0, GEOM)
    assert abs(math.degrees(st.phi) - (-20.0)) <= 1e-12  # closed form: phi(0) = -beta exactly
    assert abs(math.degrees(st.theta_oe) - 85.0) <= 1e-12  # 105 - 20 exactly
    assert abs(math.degrees(st.theta_fg) - 29.911439) <= half_unit("29.911439")
    assert abs(st.point_f[0] - 0.263340) <= half_unit("0.263340")
    assert abs(st.point_f[1] - 0.024933) <= half_unit("0.024933")


def test_stroke_at_half_revolution():
    angle, stroke = refined_extremum(lambda t: kin.linkage_state(t, GEOM).rapier_displacement, +1)
    assert abs(stroke - 1.052348) <= half_unit("1.052348")
    # phi(theta) is even about pi, so the deepest point is exactly at 180 deg; the
    # optimiser locates a smooth maximum to ~sqrt(eps) relative in the angle.
    assert abs(angle - np.pi) <= 1e-6
    s_pi = kin.linkage_state(np.pi, GEOM)
    assert abs(s_pi.rapier_displacement - 1.052348) <= half_unit("1.052348")
    assert abs(s_pi.d_rapier_displacement) <= 1e-12  # stationary: round-off only
    # s = 0 outermost at theta = 0
    assert kin.linkage_state(0.0, GEOM).rapier_displacement == 0.0
    assert np.all(kin.linkage_state(THETA, GEOM).rapier_displacement >= -1e-12)  # round-off


def test_transmission_angle_range():
    def mu_deg(t):
        return np.degrees(kin.linkage_state(t, GEOM).transmission_angle)

    _, lo = refined_extremum(mu_deg, -1)
    _, hi = refined_extremum(mu_deg, +1)
    assert abs(lo - 50.42) <= half_unit("50.42")
    assert abs(hi - 130.92) <= half_unit("130.92")


def test_transmission_angle_definition():
    """Interior angle at F between F->E and F->G."""
    st = kin.linkage_state(THETA, GEOM)
    fe = st.point_e - st.point_f
    fg = np.array([GEOM.l_og, 0.0]) - st.point_f
    cos_mu = np.sum(fe * fg, axis=-1) / (np.linalg.norm(fe, axis=-1) * np.linalg.norm(fg, axis=-1))
    np.testing.assert_allclose(st.transmission_angle, np.arccos(cos_mu), atol=1e-12)  # round-off


def test_rapier_velocity_and_acceleration_at_400_rpm():
    def v(t):
        return kin.rapier_motion(t, OMEGA_400, GEOM)[1]

    def a(t):
        return kin.rapier_motion(t, OMEGA_400, GEOM)[2]

    th_vmax, vmax = refined_extremum(v, +1)
    th_vmin, vmin = refined_extremum(v, -1)
    th_amax, amax = refined_extremum(a, +1)
    th_amin, amin = refined_extremum(a, -1)
    assert abs(vmax - 21.754) <= half_unit("21.754")
    assert abs(vmin + 21.754) <= half_unit("21.754")
    assert abs(amax - 1142.05) <= half_unit("1142.05")
    assert abs(amin + 829.42) <= half_unit("829.42")
    # phi is even about theta = pi, so v is odd and a even about pi: the velocity
    # peaks are mirror images and the acceleration extremes sit at 0 and 180 deg.
    # 1e-5 rad: the optimiser's location accuracy for a smooth extremum (~sqrt(eps)).
    assert abs((th_vmax + th_vmin) - 2.0 * np.pi) <= 1e-5
    assert min(th_amax, 2.0 * np.pi - th_amax) <= 1e-5
    assert abs(th_amin - np.pi) <= 1e-5


def test_rapier_motion_scales_with_speed():
    s, v, a = kin.rapier_motion(THETA, OMEGA_400, GEOM)
    s2, v2, a2 = kin.rapier_motion(THETA, 2.0 * OMEGA_400, GEOM)
    np.testing.assert_array_equal(s, s2)
    np.testing.assert_allclose(v2, 2.0 * v, rtol=1e-14)  # round-off
    np.testing.assert_allclose(a2, 4.0 * a, rtol=1e-14)  # round-off


# --- closure identities --------------------------------------------------------------


def test_loop_closure_residual():
    st = kin.linkage_state(THETA, GEOM)
    rod = GEOM.l_ef * np.stack([np.cos(st.theta_ef), np.sin(st.theta_ef)], axis=-1)
    residual = np.linalg.norm(st.point_e + rod - st.point_f, axis=-1)
    assert residual.max() <= 1e-14  # round-off of O(0.3 m) coordinates
    np.testing.assert_allclose(
        np.linalg.norm(st.point_f - [GEOM.l_og, 0.0], axis=-1), GEOM.l_fg, rtol=1e-14
    )  # round-off
    np.testing.assert_allclose(np.linalg.norm(st.point_e, axis=-1), GEOM.l_oe, rtol=1e-14)
    np.testing.assert_allclose(st.rod_com, 0.5 * (st.point_e + st.point_f), rtol=1e-14)


def test_other_fourbar_branch_also_closes():
    geom = dataclasses.replace(GEOM, fourbar_branch=-1)
    fb_minus = kin.fourbar(GEOM.rocker_arm_angle + np.linspace(-BETA, BETA, 51), geom)
    fb_plus = kin.fourbar(fb_minus.theta_oe, GEOM)
    e = GEOM.l_oe * np.stack([np.cos(fb_minus.theta_oe), np.sin(fb_minus.theta_oe)], -1)
    f = [GEOM.l_og, 0.0] + GEOM.l_fg * np.stack(
        [np.cos(fb_minus.theta_fg), np.sin(fb_minus.theta_fg)], -1
    )
    np.testing.assert_allclose(np.linalg.norm(f - e, axis=-1), GEOM.l_ef, rtol=1e-13)  # round-off
    assert np.all(np.cos(fb_minus.theta_fg - fb_plus.theta_fg) < 0.99)  # a distinct pose


def test_periodic_in_crank_angle():
    a = kin.linkage_state(THETA, GEOM)
    b = kin.linkage_state(THETA + 2.0 * np.pi, GEOM)
    for field in ("rapier_displacement", "d_rapier_displacement", "dd_rapier_displacement"):
        np.testing.assert_allclose(getattr(a, field), getattr(b, field), atol=1e-12)  # round-off


# --- analytic derivatives vs finite differences ---------------------------------------

STATE_FIELDS = (
    "phi",
    "theta_oe",
    "theta_fg",
    "theta_ef",
    "rapier_displacement",
    "gear67_angle",
    "point_e",
    "point_f",
    "rod_com",
    "rocker_com",
)


@pytest.mark.parametrize("field", STATE_FIELDS)
def test_linkage_state_derivatives(field):
    def value(order):
        prefix = ("", "d_", "dd_")[order]
        return lambda t: getattr(kin.linkage_state(t, GEOM), prefix + field)

    assert_derivative(value(0), value(1), THETA)
    assert_derivative(value(1), value(2), THETA)


def test_rocker_angle_derivatives_and_closure():
    phi, _, _ = kin.rocker_angle(THETA, BETA)
    closure = np.sum(kin.crank_axis(THETA, BETA) * kin.rocker_axis(phi), axis=-1)
    assert np.abs(closure).max() <= 1e-15  # b . c = 0 to round-off
    def rocker(order):
        return lambda t: kin.rocker_angle(t, BETA)[order]

    assert_derivative(rocker(0), rocker(1), THETA)
    assert_derivative(rocker(1), rocker(2), THETA)
    np.testing.assert_allclose([phi.min(), phi.max()], [-BETA, BETA], atol=1e-12)  # swing +-beta


def test_fourbar_derivatives_wrt_rocker_arm_angle():
    q = GEOM.rocker_arm_angle + np.linspace(-BETA, BETA, 101)
    for name in ("theta_fg", "theta_ef"):
        assert_derivative(lambda x: getattr(kin.fourbar(x, GEOM), name),
                          lambda x: getattr(kin.fourbar(x, GEOM), "d_" + name), q)
        assert_derivative(lambda x: getattr(kin.fourbar(x, GEOM), "d_" + name),
                          lambda x: getattr(kin.fourbar(x, GEOM), "dd_" + name), q)


# --- coupler frame and angular velocity -----------------------------------------------


def test_coupler_frame_orthonormal():
    r = kin.coupler_frame(THETA, BETA)
    assert r.shape == THETA.shape + (3, 3)
    eye = np.broadcast_to(np.eye(3), r.shape)
    np.testing.assert_allclose(np.swapaxes(r, -1, -2) @ r, eye, atol=1e-15)  # round-off
    np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-15)  # right-handed
    assert np.abs(np.sum(r[..., 0] * r[..., 1], axis=-1)).max() <= 1e-15  # b . c = 0


def test_coupler_angular_velocity_from_rotation_matrix():
    """skew(w) = R' R^T with R' by central differences."""
    w, _ = kin.coupler_angular_velocity(THETA, BETA)
    r = kin.coupler_frame(THETA, BETA)
    dr = central_difference(lambda t: kin.coupler_frame(t, BETA), THETA)
    skew = dr @ np.swapaxes(r, -1, -2)
    np.testing.assert_allclose(skew, -np.swapaxes(skew, -1, -2), atol=1e-9)  # FD truncation
    w_skew = np.stack([skew[..., 2, 1], skew[..., 0, 2], skew[..., 1, 0]], axis=-1)
    np.testing.assert_allclose(w, w_skew, atol=FD_ATOL)


def test_coupler_angular_velocity_both_chains_agree():
    """omega_2 / theta_dot = z + lambda b (via the crank) = phi' x + mu c (via the rocker)."""
    w, _ = kin.coupler_angular_velocity(THETA, BETA)
    _, dphi, _ = kin.rocker_angle(THETA, BETA)
    b = kin.crank_axis(THETA, BETA)
    lam = dphi * b[..., 0] - np.cos(BETA)
    via_crank = np.array([0.0, 0.0, 1.0]) + lam[..., None] * b
    np.testing.assert_allclose(w, via_crank, atol=1e-15)  # round-off
    assert_derivative(lambda t: kin.coupler_angular_velocity(t, BETA)[0],
                      lambda t: kin.coupler_angular_velocity(t, BETA)[1], THETA)


# --- general spherical 4R law --------------------------------------------------------


def closure_residual(theta_in, phi_out, a1, a2, a3, a4):
    """b . c - cos(alpha3) with the vectors of docs/physics.md section 1 in the law's own frame."""
    b = np.stack([np.sin(a2) * np.cos(theta_in), np.sin(a2) * np.sin(theta_in),
                  np.full_like(theta_in, np.cos(a2))], axis=-1)
    v = np.stack([np.sin(a4) * np.cos(phi_out), np.sin(a4) * np.sin(phi_out),
                  np.full_like(phi_out, np.cos(a4))], axis=-1)
    ry = np.array([[np.cos(a1), 0.0, np.sin(a1)], [0.0, 1.0, 0.0], [-np.sin(a1), 0.0, np.cos(a1)]])
    c = v @ ry.T
    return np.sum(b * c, axis=-1) - np.cos(a3)


def test_general_law_reproduces_loom_rocker_angle():
    """Loom arcs: A-D = 90 (alpha1), A-B = beta (alpha2), B-C = 90 (alpha3), C-D = 90 (alpha4)."""
    right = 0.5 * np.pi
    out, d_out, dd_out = kin.spherical_4r(THETA + right, right, BETA, right, right, branch=-1)
    phi, dphi, ddphi = kin.rocker_angle(THETA, BETA)
    wrapped = np.angle(np.exp(1j * (out - right)))
    np.testing.assert_allclose(wrapped, phi, atol=1e-14)  # round-off
    np.testing.assert_allclose(d_out, dphi, atol=1e-14)  # round-off
    np.testing.assert_allclose(dd_out, ddphi, atol=1e-13)  # round-off
    # and the "+" branch is the mirror pose phi + 180 deg, not the loom's
    plus, _, _ = kin.spherical_4r(THETA + right, right, BETA, right, right, branch=+1)
    np.testing.assert_allclose(np.cos(plus - right - phi), -1.0, atol=1e-14)  # round-off


ARCS = np.radians([75.0, 25.0, 80.0, 65.0])  # a crank-rocker that assembles all round


@pytest.mark.parametrize("branch", [1, -1])
def test_general_law_branches_satisfy_closure(branch):
    assert kin.spherical_4r_assembles(THETA, *ARCS).all()
    out, _, _ = kin.spherical_4r(THETA, *ARCS, branch=branch)
    assert np.abs(closure_residual(THETA, out, *ARCS)).max() <= 1e-14  # round-off
    assert_derivative(lambda t: kin.spherical_4r(t, *ARCS, branch)[0],
                      lambda t: kin.spherical_4r(t, *ARCS, branch)[1], THETA, angle=True)
    assert_derivative(lambda t: kin.spherical_4r(t, *ARCS, branch)[1],
                      lambda t: kin.spherical_4r(t, *ARCS, branch)[2], THETA)


def test_general_law_nan_where_it_cannot_assemble():
    arcs = np.radians([30.0, 60.0, 20.0, 20.0])  # coupler + output arcs too short for some inputs
    ok = kin.spherical_4r_assembles(THETA, *arcs)
    assert ok.any() and not ok.all()
    out, d_out, dd_out = kin.spherical_4r(THETA, *arcs, branch=1)
    for result in (out, d_out, dd_out):
        assert np.all(np.isnan(result[~ok]))
    assert np.all(np.isfinite(out[ok]))
    assert np.abs(closure_residual(THETA[ok], out[ok], *arcs)).max() <= 1e-14  # round-off


def test_general_law_rejects_bad_branch():
    with pytest.raises(ValueError, match="branch"):
        kin.spherical_4r(THETA, *ARCS, branch=0)


# --- assembly failure ------------------------------------------------------------------


def test_reference_mechanism_assembles():
    assert kin.assembly_failure_angle(GEOM) is None
    assert kin.assembly_problem(GEOM) is None


def frame_distance(theta, geom):
    """D = |G - E| as a function of the crank angle."""
    phi, _, _ = kin.rocker_angle(theta, geom.crank_inclination)
    q = geom.rocker_arm_angle + phi
    return math.hypot(geom.l_og - geom.l_oe * math.cos(q), geom.l_oe * math.sin(q))


def test_rod_too_short_fails_at_the_right_angle():
    """D grows from theta = 0 to 180 deg (theta_OE 85 -> 125 deg); with L_EF = D(60 deg) - L_FG
    the triangle E-F-G closes up to 60 deg and not beyond."""
    target = math.radians(60.0)
    geom = dataclasses.replace(GEOM, l_ef=frame_distance(target, GEOM) - GEOM.l_fg)
    angle = kin.assembly_failure_angle(geom)
    assert angle is not None
    # bisection brackets to ~1e-13 rad; round-off of the acos argument near 1 (~1e-16)
    # moves the crossing by ~1e-16 / |d arg/d theta| ~ 1e-15 rad: 1e-9 is generous.
    assert abs(angle - target) <= 1e-9
    st = kin.linkage_state(np.array([target - 1e-3, target + 1e-3]), geom)
    assert np.isfinite(st.theta_fg[0]) and np.isnan(st.theta_fg[1])
    assert "60.0000 deg" in kin.assembly_problem(geom)


def test_rod_far_too_short_fails_at_zero():
    geom = dataclasses.replace(GEOM, l_ef=0.05)
    assert kin.assembly_failure_angle(geom) == 0.0
    assert np.isnan(kin.linkage_state(THETA, geom).rapier_displacement).all()
    assert "cannot be assembled" in kin.assembly_problem(geom)


def test_bad_crank_inclination_reported():
    flat = dataclasses.replace(GEOM, crank_inclination=0.0)
    assert "crank_inclination" in kin.assembly_problem(flat)
