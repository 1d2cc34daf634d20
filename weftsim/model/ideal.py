"""Ideal-joint dynamics in closed form: equivalent inertia, potential and driving torque.

With ideal joints the linkage has the single coordinate theta (crank angle).  Every
member's kinetic energy is (1/2) J_k(theta) theta_dot^2, so the Lagrangian is

    L = 1/2 J_eq(theta) theta_dot^2 - U(theta)

and the driving torque (paper Eq. 48, docs/physics.md section 4) at constant omega is

    T(theta) = d/dt dL/dtheta_dot - dL/dtheta = 1/2 J_eq'(theta) omega^2 + U'(theta).

Generalized inertias (primes are d/dtheta; docs/physics.md section 1 frames)::

    crank 1        J1
    coupler 2      w^T I_O w,  I_O = R diag(I_b, I_c, I_n) R^T,  R = [b, c, b x c],
                   omega_2 = theta_dot w(theta)
    rocker 3       J3 phi'^2
    rod 4          m4 |r4'|^2 + J4 theta_EF'^2           (r4 = mid EF)
    sector 5       J5 theta_FG'^2
    gears 6/7      J67 (d5/d6)^2 theta_FG'^2
    rapier 8       m8 (d5 d7/d6)^2 theta_FG'^2

and U = m3 g z3 + m4 g z4 (crank, coupler at O, sector and gears are balanced; the
rapier moves along y).  The derivative of the coupler term is 2 w^T I_O w' alone:
dR/dtheta = [w]x R makes dI_O/dtheta = [w]x I_O - I_O [w]x, whose quadratic form in w
vanishes.  See docs/reference-solver.md for the derivation.

Members 1-3 (the crank side, prescribed by theta in clearance mode too) are kept
separate: :func:`crank_side_inertia` and :func:`crank_side_potential`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING


import numpy as np


from weftsim.mechanism import kinematics as kin
from weftsim.input.params import Scene

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


def _coupler_terms(theta, scene: Scene):
    """w^T I_O w and its theta-derivative 2 w^T I_O w' (kg m^2, kg m^2/rad)."""
    beta = scene.geometry.crank_inclination
    frame = kin.coupler_frame(theta, beta)  # (..., 3, 3), columns b, c, b x c
    w, dw = kin.coupler_angular_velocity(theta, beta)
    body_w = np.einsum("...ji,...j->...i", frame, w)  # components of w along b, c, b x c
    body_dw = np.einsum("...ji,...j->...i", frame, dw)
    inertia = np.asarray(scene.inertia.coupler_inertia, dtype=float)
    return (
        np.sum(inertia * body_w * body_w, axis=-1),
        2.0 * np.sum(inertia * body_w * body_dw, axis=-1),
    )


def crank_side_inertia(theta: ArrayLike, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Generalized inertia of members 1-3 about the crank angle and its derivative.

    J13 = J1 + w^T I_O w + J3 phi'^2,  J13' = 2 w^T I_O w' + 2 J3 phi' phi''.

    Returns
    -------
    J13, dJ13 : ndarray
        kg m^2 and kg m^2/rad.
    """
    theta = np.asarray(theta, dtype=float)
    inert = scene.inertia
    _, dphi, ddphi = kin.rocker_angle(theta, scene.geometry.crank_inclination)
    coupler, d_coupler = _coupler_terms(theta, scene)
    j13 = inert.crank_inertia + coupler + inert.rocker_inertia * dphi * dphi
    dj13 = d_coupler + 2.0 * inert.rocker_inertia * dphi * ddphi
    return j13, dj13


def crank_side_potential(theta: ArrayLike, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Gravity potential of members 1-3: U13 = m3 g r3 sin(theta_OE), and dU13/dtheta.

    Only the rocker's centre of mass (on OE at r3 from O) moves in z; the crank is
    balanced and the coupler's centre of mass is at O.  J, J/rad.
    """
    theta = np.asarray(theta, dtype=float)
    geo, inert = scene.geometry, scene.inertia
    phi, dphi, _ = kin.rocker_angle(theta, geo.crank_inclination)
    q = geo.rocker_arm_angle + phi
    weight = inert.rocker_mass * inert.gravity * inert.rocker_com
    return weight * np.sin(q), weight * np.cos(q) * dphi


def sector_chain_inertia(scene: Scene) -> float:
    """J_FG = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2: inertia of members 5-8 about theta_FG, kg m^2."""
    geo, inert = scene.geometry, scene.inertia
    return (
        inert.sector_inertia
        + inert.pinion_gear_inertia * geo.pinion_ratio**2
        + inert.rapier_mass * geo.rapier_ratio**2
    )


def equivalent_inertia(theta: ArrayLike, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """J_eq(theta) of the whole ideal-joint linkage (members 1-8) and dJ_eq/dtheta.

    ::

        J_eq  = J13 + m4 |r4'|^2 + J4 theta_EF'^2 + J_FG theta_FG'^2
        J_eq' = J13' + 2 m4 r4'.r4'' + 2 J4 theta_EF' theta_EF'' + 2 J_FG theta_FG' theta_FG''
    """
    theta = np.asarray(theta, dtype=float)
    inert = scene.inertia
    st = kin.linkage_state(theta, scene.geometry, inert.rocker_com)
    j13, dj13 = crank_side_inertia(theta, scene)
    j_fg = sector_chain_inertia(scene)
    rod_v2 = np.sum(st.d_rod_com * st.d_rod_com, axis=-1)
    rod_va = np.sum(st.d_rod_com * st.dd_rod_com, axis=-1)
    j = (
        j13
        + inert.rod_mass * rod_v2
        + inert.rod_inertia * st.d_theta_ef**2
        + j_fg * st.d_theta_fg**2
    )
    dj = (
        dj13
        + 2.0 * inert.rod_mass * rod_va
        + 2.0 * inert.rod_inertia * st.d_theta_ef * st.dd_theta_ef
        + 2.0 * j_fg * st.d_theta_fg * st.dd_theta_fg
    )
    return j, dj


def potential_energy(theta: ArrayLike, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """U(theta) = m3 g z3 + m4 g z4 (J) and dU/dtheta (J/rad), ideal joints."""
    theta = np.asarray(theta, dtype=float)
    inert = scene.inertia
    st = kin.linkage_state(theta, scene.geometry, inert.rocker_com)
    u13, du13 = crank_side_potential(theta, scene)
    weight4 = inert.rod_mass * inert.gravity
    return u13 + weight4 * st.rod_com[..., 1], du13 + weight4 * st.d_rod_com[..., 1]


def ideal_torque(theta: ArrayLike, scene: Scene) -> np.ndarray:
    """Driving torque of the ideal-joint linkage at constant crank speed, N m.

    T = 1/2 J_eq'(theta) omega^2 + U'(theta), about +z, applied by the motor on the crank
    (positive when it drives the crank forward).
    """
    omega = scene.drive.speed
    _, dj = equivalent_inertia(theta, scene)
    _, du = potential_energy(theta, scene)
    return 0.5 * dj * omega**2 + du


def ideal_channels(time: np.ndarray, scene: Scene) -> dict[str, np.ndarray]:
    """All :data:`weftsim.post.results.CHANNELS` of the ideal-joint run at the given times.

    theta = omega t.  Kinetic energy 1/2 J_eq omega^2, potential U; driving work
    W(t) = integral_0^t T omega dt = [KE + U](t) - [KE + U](0) exactly (closed form,
    constant omega).  Contact channels are identically 0.
    """
    time = np.asarray(time, dtype=float)
    omega = scene.drive.speed
    theta = omega * time
    st = kin.linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    j, dj = equivalent_inertia(theta, scene)
    u, du = potential_energy(theta, scene)
    j0, _ = equivalent_inertia(0.0, scene)
    u0, _ = potential_energy(0.0, scene)
    kinetic = 0.5 * j * omega**2
    zeros = np.zeros_like(theta)
    return {
        "time_s": time,
        "crank_angle_deg": np.degrees(theta),
        "rapier_displacement_m": st.rapier_displacement,
        "rapier_velocity_m_s": omega * st.d_rapier_displacement,
        "rapier_acceleration_m_s2": omega**2 * st.dd_rapier_displacement,
        "driving_torque_Nm": 0.5 * dj * omega**2 + du,
        "contact_force_N": zeros,
        "penetration_m": zeros,
        "eccentricity_y_m": zeros,
        "eccentricity_z_m": zeros,
        "impact_velocity_m_s": zeros,
        "in_contact": zeros,
        "kinetic_energy_J": kinetic,
        "potential_energy_J": u,
        "contact_energy_J": zeros,
        "driving_work_J": kinetic + u - (0.5 * float(j0) * omega**2 + float(u0)),
        "dissipated_energy_J": zeros,
        "penetration_rate_m_s": zeros,
    }


