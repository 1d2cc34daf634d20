"""Equations of motion of the clearance mode in closed form (SPEC.md sections 2 and 4).

Members 1-3 are prescribed by theta = omega t; the bearing centre P_b is E of the
rocker.  Members 4-8 form a 2-DOF chain with coordinates q = (a, psi):

    a   = theta_FG, angle of F - G (sector 5, gears 6/7 and rapier 8 follow it)
    psi = theta_EF, angle of the rod vector from the journal centre to F

in four-bar plane coordinates (Y, Z), angles from +Y towards +Z (about +x)::

        P_b (bearing, rocker 3)
         .  e = P_j - P_b          F = G + L_FG u(a)
        P_j (journal, rod 4) ----- F          P_j = F - L_EF u(psi)
                                    \\ L_FG   r4  = F - (L_EF/2) u(psi)
                                     G = (L_OG, 0)

with u(x) = (cos x, sin x), n(x) = (-sin x, cos x).  Lagrange's equations
M(q) q'' = Q(q, q', t) read, with k = m4 L_FG L_EF / 2 and s = sin(psi - a),

    M = [[m4 L_FG^2 + J_FG,  -k cos(psi - a)],
         [-k cos(psi - a),    m4 L_EF^2/4 + J4]]
    Q_a   = L_FG n(a).f  - m4 g L_FG cos a         - k psi'^2 s
    Q_psi = -L_EF n(psi).f + M_f + m4 g (L_EF/2) cos psi + k a'^2 s

where f is the contact force on the journal and M_j the contact moment about the
journal centre, J_FG = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2.

Contact (SPEC.md section 2, :mod:`weftsim.clearance`): e = P_j - P_b, n = e/|e|,
delta = |e| - c, delta_dot = e_dot.n, t = n turned +90 deg; f = -F_N n + F_T t acts on
the journal and -f on the bearing, both at Q = P_b + R_b n, so only friction has moments:
M_j = (R_b - |e|) F_T about P_j and M_b = -R_b F_T about P_b.  The generalized force of
the contact on the crank side (members 1-3, coordinate theta) is

    Q3 = -f . dP_b/dtheta + M_b dtheta_OE/dtheta

and the driving torque T = 1/2 J13' omega^2 + U13' - Q3 (module :mod:`.ideal`).  The
power -Q3 omega and the dissipated power (F_N - F_el) delta_dot - F_T v_T are integrated
with the state so the energy balance closes to the solver tolerance.

The kernel :func:`chain_dynamics` is written once for two numeric backends,
:func:`math_backend` (floats, inside the integrator) and :func:`numpy_backend` (arrays,
to evaluate channels after the run), so the channels are computed by exactly the equations that
were integrated.  See docs/reference-solver.md for the derivation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from weftsim import kinematics as kin
from weftsim.clearance import clearance_contact, make_clearance_kernel
from weftsim.params import ClearanceJoint, Scene
from weftsim.reference.ideal import sector_chain_inertia

MATH = SimpleNamespace(sin=math.sin, cos=math.cos, atan=math.atan, hypot=math.hypot)
NUMPY = SimpleNamespace(sin=np.sin, cos=np.cos, atan=np.arctan, hypot=np.hypot)


def math_backend(law, joint: ClearanceJoint) -> SimpleNamespace:
    """Float backend for :func:`chain_dynamics`: plain ``math`` and the scalar contact kernel."""
    elastic = law.scalar()
    return SimpleNamespace(
        **vars(MATH),
        contact=make_clearance_kernel(law, joint),
        elastic=lambda delta, v_imp: elastic(delta, 0.0, v_imp),
        zero=0.0,
    )


def numpy_backend(law, joint: ClearanceJoint) -> SimpleNamespace:
    """Array backend for :func:`chain_dynamics`: numpy and :func:`weftsim.clearance.clearance_contact`."""

    def contact(ecc_y, ecc_z, v_y, v_z, v_t, v_imp):
        r = clearance_contact(
            np.stack([ecc_y, ecc_z], axis=-1), np.stack([v_y, v_z], axis=-1), v_t, v_imp, law, joint
        )
        f = r.force_on_journal
        return (f[..., 0], f[..., 1], r.normal_force, r.penetration, r.penetration_rate,
                r.moment_on_journal, r.moment_on_bearing)  # fmt: skip

    return SimpleNamespace(
        **vars(NUMPY),
        contact=contact,
        elastic=lambda delta, v_imp: law.elastic_force(delta),
        zero=0.0,
    )


# Order of the values returned by chain_dynamics.
OUTPUTS = (
    "dd_a", "dd_psi", "crank_side_power", "dissipated_power",
    "normal_force", "elastic_force", "penetration", "penetration_rate",
    "ecc_y", "ecc_z", "force_y", "force_z", "bearing_moment", "q3",
)  # fmt: skip


@dataclass(frozen=True)
class ChainConstants:
    """Numbers the clearance-mode kernel needs, in SI units (built from a Scene)."""

    omega: float  # crank speed, rad/s
    tan_beta: float  # tan of the crank inclination
    rocker_arm_angle: float  # theta_OE0, rad
    l_oe: float
    l_ef: float
    l_fg: float
    l_og: float  # m
    rod_mass: float  # m4, kg
    gravity: float  # m/s^2
    m11: float  # m4 L_FG^2 + J_FG, kg m^2
    m22: float  # m4 L_EF^2 / 4 + J4, kg m^2
    coupling: float  # k = m4 L_FG L_EF / 2, kg m^2
    clearance: float  # c, m
    journal_radius: float
    bearing_radius: float  # m
    friction_coefficient: float  # mu
    friction_v0: float
    friction_v1: float  # m/s

    @classmethod
    def from_scene(cls, scene: Scene) -> "ChainConstants":
        geo, inert, joint = scene.geometry, scene.inertia, scene.joint
        m4 = inert.rod_mass
        return cls(
            omega=scene.drive.speed,
            tan_beta=math.tan(geo.crank_inclination),
            rocker_arm_angle=geo.rocker_arm_angle,
            l_oe=geo.l_oe, l_ef=geo.l_ef, l_fg=geo.l_fg, l_og=geo.l_og,
            rod_mass=m4,
            gravity=inert.gravity,
            m11=m4 * geo.l_fg**2 + sector_chain_inertia(scene),
            m22=m4 * geo.l_ef**2 / 4.0 + inert.rod_inertia,
            coupling=m4 * geo.l_fg * geo.l_ef / 2.0,
            clearance=joint.clearance,
            journal_radius=joint.journal_radius,
            bearing_radius=joint.bearing_radius,
            friction_coefficient=joint.friction_coefficient,
            friction_v0=joint.friction_velocities[0],
            friction_v1=joint.friction_velocities[1],
        )  # fmt: skip


def eccentricity(xp, p: ChainConstants, t, a, psi, da, dpsi):
    """Eccentricity e = P_j - P_b, its rate, and the bearing's motion (SPEC.md sections 1, 2).

    Crank side (prescribed): phi = -atan(tan(beta) cos theta), theta_OE = theta_OE0 + phi,
    P_b = E = L_OE u(theta_OE).  Chain: P_j = G + L_FG u(a) - L_EF u(psi).

    Returns
    -------
    e_Y, e_Z (m); e_dot_Y, e_dot_Z (m/s); phi' = dphi/dtheta; dP_b/dtheta (Y, Z) (m/rad).
    """
    theta = p.omega * t
    u = p.tan_beta * xp.cos(theta)
    dphi = p.tan_beta * xp.sin(theta) / (1.0 + u * u)
    q = p.rocker_arm_angle - xp.atan(u)
    sq, cq = xp.sin(q), xp.cos(q)
    db_y, db_z = -p.l_oe * sq * dphi, p.l_oe * cq * dphi
    sa, ca, sp, cp = xp.sin(a), xp.cos(a), xp.sin(psi), xp.cos(psi)
    ecc_y = p.l_og + p.l_fg * ca - p.l_ef * cp - p.l_oe * cq
    ecc_z = p.l_fg * sa - p.l_ef * sp - p.l_oe * sq
    v_y = -p.l_fg * sa * da + p.l_ef * sp * dpsi - p.omega * db_y
    v_z = p.l_fg * ca * da - p.l_ef * cp * dpsi - p.omega * db_z
    return ecc_y, ecc_z, v_y, v_z, dphi, db_y, db_z


def penetration(p: ChainConstants, t: float, y) -> tuple[float, float]:
    """delta = |e| - c (m) and delta_dot = e_dot . n (m/s) of a state y (floats)."""
    ecc_y, ecc_z, v_y, v_z, *_ = eccentricity(MATH, p, t, y[0], y[1], y[2], y[3])
    ecc = math.hypot(ecc_y, ecc_z)
    rate = (v_y * ecc_y + v_z * ecc_z) / ecc if ecc > 0.0 else 0.0
    return ecc - p.clearance, rate


def chain_dynamics(xp, p: ChainConstants, t, a, psi, da, dpsi, contact, impact_velocity):
    """Accelerations of the 2-DOF chain and the contact quantities at time t.

    Parameters
    ----------
    xp : namespace
        :func:`math_backend` (floats) or :func:`numpy_backend` (arrays broadcast together).
    p : ChainConstants
    t : float or ndarray
        Time, s (theta = omega t).
    a, psi, da, dpsi : float or ndarray
        theta_FG, theta_EF (rad) and their rates (rad/s).
    contact : bool
        False in free flight: the contact force is not evaluated (it is 0).
    impact_velocity : float or ndarray
        Held delta_dot at onset, floored, m/s (used only if ``contact``).

    Returns
    -------
    tuple
        Values named by :data:`OUTPUTS`: a'' and psi'' (rad/s^2); crank-side contact power
        -Q3 omega (W); dissipated power (W); F_N, F_el (N); delta (m); delta_dot (m/s);
        e_Y, e_Z (m); force on the journal f_Y, f_Z (N); friction moment on the bearing M_b (N m);
        Q3 (N m, contact generalized force on the crank side w.r.t. theta).
    """
    ecc_y, ecc_z, v_y, v_z, dphi, db_y, db_z = eccentricity(xp, p, t, a, psi, da, dpsi)
    if contact:
        v_t = xp.zero
        if p.friction_coefficient > 0.0:
            # v_T = e_dot.t + w_j (R_b - |e|) - w_b R_b (weftsim.clearance.tangential_velocity).
            ecc = xp.hypot(ecc_y, ecc_z)
            v_t = (ecc_y * v_z - ecc_z * v_y) / ecc + dpsi * (p.bearing_radius - ecc) \
                - p.omega * dphi * p.bearing_radius
        f_y, f_z, f_n, delta, delta_dot, m_j, m_b = xp.contact(
            ecc_y, ecc_z, v_y, v_z, v_t, impact_velocity
        )
        f_el = xp.elastic(delta, impact_velocity)
        # Power of the contact on both bodies, f.e_dot + M_j w_j + M_b w_b = -F_N delta_dot + F_T v_T;
        # what the elastic energy (rate F_el delta_dot) does not store is dissipated.
        dissipated = -(f_y * v_y + f_z * v_z + m_j * dpsi + m_b * p.omega * dphi) - f_el * delta_dot
    else:
        ecc = xp.hypot(ecc_y, ecc_z)
        delta = ecc - p.clearance
        delta_dot = f_n = f_el = dissipated = f_y = f_z = m_j = m_b = 0.0 * ecc  # +0.0 (ecc >= 0)
    # Generalized forces and the 2x2 solve.
    sa, ca, sp, cp = xp.sin(a), xp.cos(a), xp.sin(psi), xp.cos(psi)
    s, c = xp.sin(psi - a), xp.cos(psi - a)
    k = p.coupling
    q_a = p.l_fg * (ca * f_z - sa * f_y) - p.rod_mass * p.gravity * p.l_fg * ca - k * dpsi * dpsi * s
    q_psi = p.l_ef * (sp * f_y - cp * f_z) + m_j + 0.5 * p.rod_mass * p.gravity * p.l_ef * cp + k * da * da * s
    m12 = -k * c
    det = p.m11 * p.m22 - m12 * m12
    dd_a = (p.m22 * q_a - m12 * q_psi) / det
    dd_psi = (p.m11 * q_psi - m12 * q_a) / det
    # Crank side: Q3 = F_b.dP_b/dtheta + M_b dtheta_OE/dtheta with F_b = -f.
    q3 = -(f_y * db_y + f_z * db_z) + m_b * dphi
    return (dd_a, dd_psi, -q3 * p.omega, dissipated, f_n, f_el, delta, delta_dot,
            ecc_y, ecc_z, f_y, f_z, m_b, q3)  # fmt: skip


def chain_energy(p: ChainConstants, a, psi, da, dpsi):
    """Kinetic and potential energy of members 4-8 (J): 1/2 q'^T M q', m4 g z4."""
    m12 = -p.coupling * np.cos(np.asarray(psi) - a)
    kinetic = 0.5 * (p.m11 * da * da + 2.0 * m12 * da * dpsi + p.m22 * dpsi * dpsi)
    potential = p.rod_mass * p.gravity * (p.l_fg * np.sin(a) - 0.5 * p.l_ef * np.sin(psi))
    return kinetic, potential


def initial_state(scene: Scene) -> np.ndarray:
    """State at t = 0: journal centred (e = 0), ideal-mechanism velocities (SPEC.md section 2).

    Returns [a, psi, a', psi', W3, D] with a = theta_FG(0), psi = theta_EF(0) (angle of
    F - E, so P_j = F - L_EF u(psi) = E), rates omega * d/dtheta of the ideal kinematics,
    and the two integrated energy terms 0.
    """
    omega = scene.drive.speed
    st = kin.linkage_state(0.0, scene.geometry, scene.inertia.rocker_com)
    return np.array([
        float(st.theta_fg), float(st.theta_ef),
        omega * float(st.d_theta_fg), omega * float(st.d_theta_ef),
        0.0, 0.0,
    ])  # fmt: skip
