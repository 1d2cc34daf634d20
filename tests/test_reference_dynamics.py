"""Clearance-mode equations of the reference solver: the 2-DOF chain against a Lagrangian
built numerically from positions, the contact's generalized forces by virtual work, the
link with the ideal-joint torque (the one kernel, weftsim.physics.chain)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from weftsim.mechanism import kinematics as kin
from weftsim.physics.chain import chain
from weftsim.input.params import Scene
from weftsim.model.dynamics import ChainConstants, eccentricity, initial_state, pack_parameters, penetration
from weftsim.model.ideal import crank_side_inertia, crank_side_potential, ideal_torque

SCENE = Scene()
FRICTION = dataclasses.replace(SCENE, joint=dataclasses.replace(SCENE.joint, friction_coefficient=0.1))


def _chain(scene, t, q, q_dot, contact, impact_velocity):
    """Accelerations and contact terms of the kernel: (q'' (2,), dict of named outputs)."""
    out = np.empty(6)
    y = np.array([q[0], q[1], q_dot[0], q_dot[1], 0.0, 0.0])
    r = chain(pack_parameters(scene), float(t), y, contact, impact_velocity, out)
    names = ("q3", "normal_force", "penetration", "ecc_y", "ecc_z", "sa", "ca", "sp", "cp",
             "force_y", "force_z", "journal_moment", "bearing_moment")  # fmt: skip
    return out[2:4].copy(), dict(zip(names, r))


def _positions(scene, a, psi):
    """F, journal centre P_j and rod CoM from the chain coordinates (independent of the kernel)."""
    geo = scene.geometry
    f = np.array([geo.l_og + geo.l_fg * math.cos(a), geo.l_fg * math.sin(a)])
    p_j = f - geo.l_ef * np.array([math.cos(psi), math.sin(psi)])
    return f, p_j, 0.5 * (f + p_j)


def _lagrangian(scene, q, q_dot, h=1e-6):
    """L = KE - U of members 4-8 with the rod CoM velocity from a position difference along q_dot."""
    inert, geo = scene.inertia, scene.geometry
    r_plus = _positions(scene, *(q + h * q_dot))[2]
    r_minus = _positions(scene, *(q - h * q_dot))[2]
    v = (r_plus - r_minus) / (2 * h)
    j_fg = inert.sector_inertia + inert.pinion_gear_inertia * geo.pinion_ratio**2 + inert.rapier_mass * geo.rapier_ratio**2
    kinetic = 0.5 * inert.rod_mass * v @ v + 0.5 * inert.rod_inertia * q_dot[1] ** 2 + 0.5 * j_fg * q_dot[0] ** 2
    return kinetic - inert.rod_mass * inert.gravity * _positions(scene, *q)[2][1]


def _grad(fun, x, h):
    return np.array([(fun(x + h * e) - fun(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def _contact_state(scene, theta, offset):
    """Ideal configuration at theta with the sector angle moved by `offset` rad (journal off-centre)."""
    st = kin.linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    omega = scene.drive.speed
    q = np.array([float(st.theta_fg) + offset, float(st.theta_ef)])
    q_dot = omega * np.array([float(st.d_theta_fg), float(st.d_theta_ef)]) + np.array([0.3, -2.0])
    return q, q_dot


@pytest.mark.parametrize("scene", [SCENE, FRICTION], ids=["frictionless", "friction"])
@pytest.mark.parametrize("theta", [0.4, 2.1, 4.0])
def test_chain_equations_are_lagrange_equations_with_virtual_work_of_contact(scene, theta):
    """M q'' = d/dt dL/dq' - dL/dq residual is ~0 with Q = (dP_j/dq)^T f + (0, M_j) from positions."""
    q, q_dot = _contact_state(scene, theta, 0.0068)  # ~0.34 mm journal offset: in contact at c = 0.25 mm
    t = theta / scene.drive.speed
    q_ddot, out = _chain(scene, t, q, q_dot, True, 0.5)
    assert out["penetration"] > 0.0 and out["normal_force"] > 0.0
    # Numerical d/dt dL/dq' = (d2L/dq'2) q'' + (d2L/dq'dq) q' and dL/dq by nested central differences.
    # L is quadratic in q', so differences in q' are exact for any step: h_v = 1 rad/s keeps round-off
    # (eps L / h) negligible.  h_q = 1e-4 rad: truncation ~h^2 = 1e-8 relative, round-off ~1e-10.
    h_v, h_q = 1.0, 1e-4
    dl_dqdot = lambda qd, qq=q: _grad(lambda x: _lagrangian(scene, qq, x), qd, h_v)  # noqa: E731
    hess_vv = np.array([(dl_dqdot(q_dot + h_v * e) - dl_dqdot(q_dot - h_v * e)) / (2 * h_v) for e in np.eye(2)]).T
    hess_vq = np.array([(dl_dqdot(q_dot, q + h_q * e) - dl_dqdot(q_dot, q - h_q * e)) / (2 * h_q) for e in np.eye(2)]).T
    dl_dq = _grad(lambda x: _lagrangian(scene, x, q_dot), q, h_q)
    h = h_q
    # Contact generalized force by virtual work: dP_j/dq from positions, f and M_j from the kernel.
    jac = np.array([(_positions(scene, *(q + h * e))[1] - _positions(scene, *(q - h * e))[1]) / (2 * h) for e in np.eye(2)])
    force = np.array([out["force_y"], out["force_z"]])
    f_t = -out["bearing_moment"] / scene.joint.bearing_radius  # M_b = -R_b F_T
    ecc = math.hypot(out["ecc_y"], out["ecc_z"])
    moment_j = (scene.joint.bearing_radius - ecc) * f_t
    q_contact = jac @ force + np.array([0.0, moment_j])
    residual = hess_vv @ q_ddot + hess_vq @ q_dot - dl_dq - q_contact
    scale = np.abs(q_contact).max() + np.abs(hess_vv @ q_ddot).max()
    # FD error <= 1e-8 of the scale (see h_q; measured ~1e-9); a wrong or missing term is >= 1e-3 of it.
    assert np.abs(residual).max() < 1e-7 * scale


@pytest.mark.parametrize("theta", [0.0, 0.9, 2.5, 3.3, 5.6])
def test_ideal_reaction_through_the_contact_gives_the_ideal_torque(theta):
    """Links the two modes by virtual work: at the ideal state, the journal force f that makes the
    chain follow the ideal accelerations gives T = 1/2 J13' w^2 + U13' + f.dP_b/dtheta = ideal torque."""
    scene, omega = SCENE, SCENE.drive.speed
    p = ChainConstants.from_scene(scene)
    st = kin.linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    a, psi = float(st.theta_fg), float(st.theta_ef)
    q_dot = omega * np.array([float(st.d_theta_fg), float(st.d_theta_ef)])
    q_ddot_ideal = omega**2 * np.array([float(st.dd_theta_fg), float(st.dd_theta_ef)])
    free_q_ddot, free = _chain(scene, theta / omega, (a, psi), q_dot, False, 0.0)
    assert abs(free["ecc_y"]) < 1e-12 and abs(free["ecc_z"]) < 1e-12  # journal centred
    m12 = -p.coupling * math.cos(psi - a)
    mass = np.array([[p.m11, m12], [m12, p.m22]])
    geo = scene.geometry
    jac = np.array([[-geo.l_fg * math.sin(a), geo.l_ef * math.sin(psi)],
                    [geo.l_fg * math.cos(a), -geo.l_ef * math.cos(psi)]])  # columns dP_j/da, dP_j/dpsi
    force = np.linalg.solve(jac.T, mass @ (q_ddot_ideal - free_q_ddot))
    _, dj13 = crank_side_inertia(theta, scene)
    _, du13 = crank_side_potential(theta, scene)
    torque = 0.5 * float(dj13) * omega**2 + float(du13) + force @ (st.d_point_e)
    # Same closed forms by two routes: agreement to round-off of the ~5e2 N m torque (~1e-12 relative
    # through a 2x2 solve with condition number ~1e3).
    assert torque == pytest.approx(float(ideal_torque(theta, scene)), rel=1e-9, abs=1e-9)


def test_eccentricity_uses_the_kinematics_of_the_rocker():
    """The inlined rocker law (fast float path) equals weftsim.mechanism.kinematics: P_b = E, dP_b/dtheta = E'."""
    p = ChainConstants.from_scene(SCENE)
    theta = np.linspace(0.0, 2 * np.pi, 37)
    st = kin.linkage_state(theta, SCENE.geometry, SCENE.inertia.rocker_com)
    q = (st.theta_fg, st.theta_ef)
    from weftsim.model.dynamics import NUMPY

    ecc_y, ecc_z, v_y, v_z, dphi, db_y, db_z = eccentricity(
        NUMPY, p, theta / p.omega, q[0], q[1], p.omega * st.d_theta_fg, p.omega * st.d_theta_ef
    )
    # Ideal configuration and velocities: journal centred and moving with the bearing, to round-off
    # of lengths ~0.3 m (1e-15 m) and velocities ~10 m/s (1e-13 m/s).
    assert np.abs(ecc_y).max() < 1e-14 and np.abs(ecc_z).max() < 1e-14
    assert np.abs(v_y).max() < 1e-12 and np.abs(v_z).max() < 1e-12
    np.testing.assert_allclose(dphi, st.d_phi, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(np.stack([db_y, db_z], -1), st.d_point_e, rtol=0, atol=1e-15)


def test_initial_state_is_centred_with_ideal_velocities():
    y0 = initial_state(SCENE)
    delta, rate = penetration(ChainConstants.from_scene(SCENE), 0.0, y0)
    # e = 0 to round-off: delta = -c, and the journal moves with the bearing (e_dot = 0).
    assert delta == pytest.approx(-SCENE.joint.clearance, abs=1e-15)
    assert rate == 0.0 or abs(rate) < 1e-12
    assert np.all(y0[4:] == 0.0)
