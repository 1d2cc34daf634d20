"""Ideal-joint mode of the reference solver: the closed-form driving torque against a
Lagrangian built independently from positions by finite differences."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from weftsim.mechanism import kinematics as kin
from weftsim.input.params import Scene
from conftest import door
solve = door("reference")
from weftsim.model.ideal import equivalent_inertia, ideal_torque, potential_energy
from weftsim.post.results import CHANNELS, CONTACT_CHANNELS

SCENE = dataclasses.replace(Scene(), joint=dataclasses.replace(Scene().joint, clearance=0.0))
THETA = np.linspace(0.0, 2.0 * np.pi, 73)[:-1] + 0.013  # off the symmetric points 0, 90, 180 deg

# Position finite differences (central, h = 1e-5 rad): truncation h^2/6 |x'''| ~ 1e-10,
# round-off eps |x| / h ~ 1e-11, so velocities are good to ~1e-10 relative.
H_POS = 1e-5
# Outer difference of the Lagrangian terms (h = 1e-3 rad): truncation h^2/6 |J'''| ~ 2e-7 J-scale,
# round-off 1e-10 / 1e-3 = 1e-7 relative.
H_LAG = 1e-3


def _d(func, theta, h=H_POS):
    return (func(theta + h) - func(theta - h)) / (2.0 * h)


def _lagrangian_terms(theta, scene):
    """J_eq(theta) = 2 KE / theta_dot^2 and U(theta), from positions only (no analytic derivative)."""
    geo, inert = scene.geometry, scene.inertia
    beta = geo.crank_inclination

    def state(x):
        return kin.linkage_state(x, geo, inert.rocker_com)

    # Coupler: omega_2 / theta_dot from the central difference of the rotation matrix, skew(w) = R' R^T.
    r_dot = _d(lambda x: kin.coupler_frame(x, beta), theta)
    skew = np.einsum("...ij,...kj->...ik", r_dot, kin.coupler_frame(theta, beta))
    w = np.stack([skew[..., 2, 1], skew[..., 0, 2], skew[..., 1, 0]], axis=-1)
    frame = kin.coupler_frame(theta, beta)
    w_body = np.einsum("...ji,...j->...i", frame, w)
    coupler = np.sum(np.asarray(inert.coupler_inertia) * w_body**2, axis=-1)
    phi_rate = _d(lambda x: kin.rocker_angle(x, beta)[0], theta)
    rod_com_rate = _d(lambda x: 0.5 * (state(x).point_e + state(x).point_f), theta)
    rod = state(theta).point_f - state(theta).point_e
    rod_rate = _d(lambda x: state(x).point_f - state(x).point_e, theta)
    rod_angle_rate = (rod[..., 0] * rod_rate[..., 1] - rod[..., 1] * rod_rate[..., 0]) / np.sum(rod**2, axis=-1)
    fg_rate = _d(lambda x: state(x).theta_fg, theta)
    rapier_rate = _d(lambda x: state(x).rapier_displacement, theta)
    j_eq = (
        inert.crank_inertia
        + coupler
        + inert.rocker_inertia * phi_rate**2
        + inert.rod_mass * np.sum(rod_com_rate**2, axis=-1)
        + inert.rod_inertia * rod_angle_rate**2
        + inert.sector_inertia * fg_rate**2
        + inert.pinion_gear_inertia * (geo.pinion_ratio * fg_rate) ** 2
        + inert.rapier_mass * rapier_rate**2
    )
    st = state(theta)
    u = inert.gravity * (inert.rocker_mass * st.rocker_com[..., 1] + inert.rod_mass * 0.5 * (st.point_e + st.point_f)[..., 1])
    return j_eq, u


def test_ideal_torque_equals_numerical_lagrange_equation():
    """T = d/dt dL/dtheta_dot - dL/dtheta with L = 1/2 J theta_dot^2 - U built from positions."""
    omega = SCENE.drive.speed
    j_plus, u_plus = _lagrangian_terms(THETA + H_LAG, SCENE)
    j_minus, u_minus = _lagrangian_terms(THETA - H_LAG, SCENE)
    # At constant omega: d/dt (J omega) - 1/2 J' omega^2 + U' = 1/2 J' omega^2 + U'.
    torque_fd = 0.5 * omega**2 * (j_plus - j_minus) / (2 * H_LAG) + (u_plus - u_minus) / (2 * H_LAG)
    torque = ideal_torque(THETA, SCENE)
    scale = np.abs(torque).max()
    # Relative to the peak torque: outer FD error ~3e-7 (see H_LAG) times J_eq omega^2 / T_max ~ 2,
    # so 1e-5 leaves a 10x margin and is far below any missing or wrong term (>= 1e-3).
    np.testing.assert_allclose(torque, torque_fd, rtol=0, atol=1e-5 * scale)


def test_equivalent_inertia_matches_position_differences_and_its_derivative():
    j, dj = equivalent_inertia(THETA, SCENE)
    j_fd, _ = _lagrangian_terms(THETA, SCENE)
    # Position FD velocities err ~1e-10 relative; squared terms double it.
    np.testing.assert_allclose(j, j_fd, rtol=1e-8)
    j_p, _ = equivalent_inertia(THETA + H_LAG, SCENE)
    j_m, _ = equivalent_inertia(THETA - H_LAG, SCENE)
    # Central difference of the analytic J_eq: truncation h^2/6 |J'''| ~ 1e-6 * max|J'| at h = 1e-3.
    np.testing.assert_allclose(dj, (j_p - j_m) / (2 * H_LAG), rtol=0, atol=1e-5 * np.abs(dj).max())
    u, du = potential_energy(THETA, SCENE)
    u_p, _ = potential_energy(THETA + H_LAG, SCENE)
    u_m, _ = potential_energy(THETA - H_LAG, SCENE)
    np.testing.assert_allclose(du, (u_p - u_m) / (2 * H_LAG), rtol=0, atol=1e-5 * np.abs(du).max())


def test_ideal_solve_channels_and_energy():
    result = solve(SCENE)
    assert result.ok and result.engine == "reference"
    assert set(result.samples) == set(CHANNELS)
    for name in CONTACT_CHANNELS:
        assert not np.any(result.steps[name]), name
    s = result.samples
    # Output grid: sample_angle apart from t = 0 to the end (2 revolutions).
    np.testing.assert_allclose(np.diff(s["crank_angle_deg"]), math.degrees(SCENE.output.sample_angle))
    assert math.isclose(s["time_s"][-1], SCENE.drive.end_time, rel_tol=1e-12)
    # Closed form: work of T = change of KE + PE to round-off (energies ~500 J, eps ~1e-16).
    balance = s["driving_work_J"] - (s["kinetic_energy_J"] - s["kinetic_energy_J"][0]) - (
        s["potential_energy_J"] - s["potential_energy_J"][0]
    )
    assert np.abs(balance).max() < 1e-9
    # The ideal acceleration is the kinematic one (the check values of docs/physics.md section 1, 6 digits).
    a = result.steps["rapier_acceleration_m_s2"]
    assert math.isclose(a.max(), 1142.05, abs_tol=0.005) and math.isclose(a.min(), -829.42, abs_tol=0.005)
    # The work of T over a whole revolution is 0: KE and PE are periodic (round-off of ~500 J).
    period_end = np.searchsorted(result.samples["time_s"], SCENE.drive.period - 1e-12)
    assert abs(s["driving_work_J"][period_end]) < 1e-9
