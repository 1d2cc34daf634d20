"""Compiled (numba) right-hand side of the clearance-mode equations, with cacheable parameters.

The same equations as :func:`weftsim.reference.dynamics.chain_dynamics` and the contact
laws of :mod:`weftsim.contact`, written as module-level ``@njit(cache=True, error_model="numpy")`` functions
whose every scene-dependent number comes in one float array (:func:`pack_parameters`),
so numba compiles them once per machine and loads them from its cache afterwards (a law
built as a closure, ``law.numba()``, has to be compiled again in every process).
``tests/test_fast_paths.py`` checks these kernels against ``chain_dynamics`` and
``law.normal_force`` for every law, in free flight and in contact, with and without friction.

Contact laws (:mod:`weftsim.contact`), selected by :data:`LAW_IDS`::

    F_N = max(0, K(delta) delta^1.5 (1 + xi delta_dot / v_imp)),  delta > 0
    K = k                                          constant-stiffness laws (LN, flores, ...)
    K = a sqrt(2 delta (3c + 2 delta)^2 / (c + delta)^3)     variable_kd (a = pi/8 E*)
    K = b / sqrt(2 (c + delta))                    elastic_foundation (b = L_b pi/2 E*)

State y = [a, psi, a', psi', W3, D] as in :mod:`weftsim.reference.integrate`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.contact import ElasticFoundation, VariableKD, make_law
from weftsim.reference.dynamics import ChainConstants
from weftsim.params import Scene

LAW_CONSTANT, LAW_VARIABLE_KD, LAW_ELASTIC_FOUNDATION = 0, 1, 2

# Indices into the parameter array.
(OMEGA, TAN_BETA, COS_OE0, SIN_OE0, L_OE, L_EF, L_FG, L_OG, ROD_MASS, GRAVITY, M11, M22, COUPLING,
 CLEARANCE, BEARING_RADIUS, MU, V0, V1, LAW_ID, LAW_COEF, XI, V_MIN, TRACK_MAX) = range(23)  # fmt: skip
N_PARAMETERS = 23


def law_parameters(law) -> tuple[int, float]:
    """(law id, its coefficient k, a or b) of a contact law object of :mod:`weftsim.contact`."""
    if isinstance(law, VariableKD):
        return LAW_VARIABLE_KD, law.modulus_factor
    if isinstance(law, ElasticFoundation):
        return LAW_ELASTIC_FOUNDATION, law.length_modulus
    if hasattr(law, "stiffness_constant"):
        return LAW_CONSTANT, law.stiffness_constant
    raise NotImplementedError(f"no compiled form of contact law {law.name!r}")


def pack_parameters(scene: Scene) -> np.ndarray:
    """Every number the compiled kernels need, as one float64 array (indices above)."""
    p = ChainConstants.from_scene(scene)
    law = make_law(scene.joint)
    law_id, coef = law_parameters(law)
    out = np.zeros(N_PARAMETERS)
    out[OMEGA], out[TAN_BETA] = p.omega, p.tan_beta
    out[COS_OE0], out[SIN_OE0] = math.cos(p.rocker_arm_angle), math.sin(p.rocker_arm_angle)
    out[L_OE], out[L_EF], out[L_FG], out[L_OG] = p.l_oe, p.l_ef, p.l_fg, p.l_og
    out[ROD_MASS], out[GRAVITY] = p.rod_mass, p.gravity
    out[M11], out[M22], out[COUPLING] = p.m11, p.m22, p.coupling
    out[CLEARANCE], out[BEARING_RADIUS] = p.clearance, p.bearing_radius
    out[MU], out[V0], out[V1] = p.friction_coefficient, p.friction_v0, p.friction_v1
    out[LAW_ID], out[LAW_COEF], out[XI] = law_id, coef, law.hysteresis
    out[V_MIN] = scene.joint.min_impact_velocity
    out[TRACK_MAX] = 1.0 if scene.joint.impact_velocity_rule == "max_approach" else 0.0
    return out


@njit(cache=True, error_model="numpy")
def elastic_force(prm, delta):
    """F_el = K(delta) delta^1.5 for delta > 0, else 0, N."""
    if delta <= 0.0:
        return 0.0
    law, coef, c = prm[LAW_ID], prm[LAW_COEF], prm[CLEARANCE]
    if law == LAW_VARIABLE_KD:
        w = 3.0 * c + 2.0 * delta
        s = c + delta
        k = coef * math.sqrt(2.0 * delta * w * w / (s * s * s))
    elif law == LAW_ELASTIC_FOUNDATION:
        k = coef / math.sqrt(2.0 * (c + delta))
    else:
        k = coef
    return k * delta * math.sqrt(delta)


@njit(cache=True, error_model="numpy")
def normal_force(prm, delta, delta_dot, impact_velocity):
    """F_N = max(0, F_el(delta) (1 + xi delta_dot / v_imp)), 0 for delta <= 0, N."""
    if delta <= 0.0:
        return 0.0
    f = elastic_force(prm, delta) * (1.0 + prm[XI] * delta_dot / impact_velocity)
    return f if f > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def crank_side(prm, t):
    """Bearing centre P_b = E of the rocker: (P_b, dP_b/dtheta, phi') at time t.

    phi = -atan(u), u = tan(beta) cos(theta); theta_OE = theta_OE0 + phi; sin and cos of
    atan(u) from u directly (1/sqrt(1 + u^2), u/sqrt(1 + u^2)).
    """
    theta = prm[OMEGA] * t
    st, ct = math.sin(theta), math.cos(theta)
    u = prm[TAN_BETA] * ct
    w = 1.0 + u * u
    r = 1.0 / math.sqrt(w)
    sq = prm[SIN_OE0] * r - prm[COS_OE0] * u * r  # sin(theta_OE0 - atan u)
    cq = prm[COS_OE0] * r + prm[SIN_OE0] * u * r
    dphi = prm[TAN_BETA] * st / w
    l_oe = prm[L_OE]
    return l_oe * cq, l_oe * sq, -l_oe * sq * dphi, l_oe * cq * dphi, dphi


@njit(cache=True, error_model="numpy")
def eccentricity(prm, t, y):
    """e = P_j - P_b, its rate, and sin/cos of a, psi (m, m/s) of state y at time t."""
    b_y, b_z, db_y, db_z, dphi = crank_side(prm, t)
    sa, ca, sp, cp = math.sin(y[0]), math.cos(y[0]), math.sin(y[1]), math.cos(y[1])
    l_fg, l_ef, omega = prm[L_FG], prm[L_EF], prm[OMEGA]
    ecc_y = prm[L_OG] + l_fg * ca - l_ef * cp - b_y
    ecc_z = l_fg * sa - l_ef * sp - b_z
    v_y = -l_fg * sa * y[2] + l_ef * sp * y[3] - omega * db_y
    v_z = l_fg * ca * y[2] - l_ef * cp * y[3] - omega * db_z
    return ecc_y, ecc_z, v_y, v_z, db_y, db_z, dphi, sa, ca, sp, cp


@njit(cache=True, error_model="numpy")
def penetration(prm, t, y):
    """(delta, delta_dot) = (|e| - c, e_dot . n) of state y at time t (m, m/s)."""
    ecc_y, ecc_z, v_y, v_z = eccentricity(prm, t, y)[:4]
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    rate = (v_y * ecc_y + v_z * ecc_z) / length if length > 0.0 else 0.0
    return length - prm[CLEARANCE], rate


@njit(cache=True, error_model="numpy")
def chain(prm, t, y, contact, impact_velocity, out):
    """y' of the clearance mode into ``out`` (6,); same equations as ``chain_dynamics``.

    Free flight (``contact`` False): no contact force, W3' = D' = 0.

    Returns
    -------
    q3 (N m, contact generalized force on the crank side), F_N (N), delta (m), e_Y, e_Z (m),
    sin a, cos a, sin psi, cos psi.
    """
    ecc_y, ecc_z, v_y, v_z, db_y, db_z, dphi, sa, ca, sp, cp = eccentricity(prm, t, y)
    da, dpsi, omega = y[2], y[3], prm[OMEGA]
    f_y = f_z = m_j = m_b = dissipated = f_n = 0.0
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    delta = length - prm[CLEARANCE]
    if contact:
        if length > 0.0:
            nx, ny = ecc_y / length, ecc_z / length
            delta_dot = v_y * nx + v_z * ny
            v_imp = impact_velocity
            if prm[TRACK_MAX] != 0.0 and delta_dot > v_imp:  # weftsim.clearance.effective_impact_velocity
                v_imp = delta_dot
            f_n = normal_force(prm, delta, delta_dot, v_imp)
            f_t = 0.0
            mu = prm[MU]
            if mu > 0.0 and f_n > 0.0:
                r_b = prm[BEARING_RADIUS]
                v_t = (ecc_y * v_z - ecc_z * v_y) / length + dpsi * (r_b - length) - omega * dphi * r_b
                s = abs(v_t)
                v0, v1 = prm[V0], prm[V1]
                if s > v0:
                    c_d = 1.0 if s >= v1 else (s - v0) / (v1 - v0)
                    f_t = -mu * c_d * f_n if v_t > 0.0 else mu * c_d * f_n
                m_j = (r_b - length) * f_t
                m_b = -r_b * f_t
            f_y = -f_n * nx - f_t * ny
            f_z = -f_n * ny + f_t * nx
            f_el = elastic_force(prm, delta)
            dissipated = -(f_y * v_y + f_z * v_z + m_j * dpsi + m_b * omega * dphi) - f_el * delta_dot
    s = sp * ca - cp * sa  # sin(psi - a)
    c = cp * ca + sp * sa  # cos(psi - a)
    k = prm[COUPLING]
    weight = prm[ROD_MASS] * prm[GRAVITY]
    l_fg, l_ef = prm[L_FG], prm[L_EF]
    q_a = l_fg * (ca * f_z - sa * f_y) - weight * l_fg * ca - k * dpsi * dpsi * s
    q_psi = l_ef * (sp * f_y - cp * f_z) + m_j + 0.5 * weight * l_ef * cp + k * da * da * s
    m11, m22, m12 = prm[M11], prm[M22], -k * c
    det = m11 * m22 - m12 * m12
    q3 = -(f_y * db_y + f_z * db_z) + m_b * dphi
    out[0] = da
    out[1] = dpsi
    out[2] = (m22 * q_a - m12 * q_psi) / det
    out[3] = (m11 * q_psi - m12 * q_a) / det
    out[4] = -q3 * omega
    out[5] = dissipated
    return q3, f_n, delta, ecc_y, ecc_z, sa, ca, sp, cp


@njit(cache=True, error_model="numpy")
def rhs(prm, t, y, contact, impact_velocity, out):
    """y' into ``out`` (:func:`chain`); returns q3 (N m)."""
    return chain(prm, t, y, contact, impact_velocity, out)[0]
