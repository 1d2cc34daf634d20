"""The chains with clearance at F (rod 4 - sector 5), alone or with clearance at E (the one definition).

Members 1-3 are prescribed by theta = omega t as in :mod:`.chain`; the bearing of E is the point E
of the rocker, P_E(t) (:func:`weftsim.physics.chain.crank_side`).  At F the **journal is the rod's
pin** (centre P_jF on member 4) and the **bearing the sector's eye** (centre P_bF = F of the sector,
G + L_FG u(a)), so that member 4 carries the journal at both joints.  Four-bar plane coordinates
(Y, Z), u(x) = (cos x, sin x), n(x) = (-sin x, cos x), g = (0, -g)::

    topology F_ONLY (E ideal, F loose): 2 DOF, y = [a, psi, a', psi', W3, D]
        rod pinned at E:  P_jF = P_E(t) + L_EF u(psi),  centre of mass P_E + (L_EF/2) u(psi)
        J_FG a''   = -L_FG n(a).f_F + M_bF
        M22 psi''  = L_EF n(psi).f_F + M_jF - m4 (L_EF/2) (n(psi).(a_E - g))
        force on the rocker at E: -(m4 a_c - f_F - m4 g)                 (Newton on the rod)

    topology E_AND_F (both loose): 4 DOF, y = [a, Y, Z, psi, a', Y', Z', psi', W3, D]
        rod free, centre of mass C = (Y, Z):  P_jE = C - (L_EF/2) u(psi),  P_jF = C + (L_EF/2) u(psi)
        J_FG a''   = -L_FG n(a).f_F + M_bF
        m4 C''     = f_E + f_F + m4 g
        J4 psi''   = -(L_EF/2) n(psi).f_E + (L_EF/2) n(psi).f_F + M_jE + M_jF

with J_FG = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2 (sector, gears and rapier reflected onto theta_FG;
the sector and gears are balanced, so gravity acts on the rod alone), M22 = m4 L_EF^2/4 + J4, a_E
= omega^2 d^2P_E/dtheta^2, f_k and M_jk, M_bk the force on the journal and the friction moments of
joint k (:func:`weftsim.physics.joint.clearance_force`).  The generalized force of the rod on the
crank side is Q3 = (force on the rocker at E) . dP_E/dtheta (+ the friction moment at E); W3' =
-Q3 omega and D' = the power both contacts dissipate, so the energy balance closes as with E alone
(docs/reference-solver.md, "Clearance at F").

The parameter array is that of :mod:`.chain` followed by joint F's block (same layout as joint E's,
:func:`weftsim.physics.joint.joint_parameters`) and the constants below.  Topology E_ONLY is the chain
of :mod:`.chain` itself: :func:`rhs_any` and :func:`penetration_at` call it unchanged there, so a
scene with clearance at E alone integrates bit for bit as before.

Worn joints (``weftsim wear``; docs/wear.md) append their wear tables after :data:`N_PARAMETERS`
(= :data:`weftsim.physics.chain.WEAR_E`): joint E's block (:func:`weftsim.physics.wear.wear_block`; the
empty ``[0, 0]`` when only F wears), then joint F's (:func:`wear_start_f`).  Each joint's contact then
sees its own worn clearance c(n) (:func:`local_clearances`), in the forces, the penetration the event
search follows and the energy balance, as the chain with E alone does.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from numba import njit

from weftsim.physics import chain as kc
from weftsim.physics.joint import BEARING_RADIUS, CLEARANCE, KIND, COEF, MU, N_JOINT, clearance_force_at, tangential_velocity
from weftsim.physics.laws import elastic_force
from weftsim.physics.lubricated import L_DISSIPATED, L_FX, L_FY, L_MB, L_MJ, is_lubricated, lubricated_force
from weftsim.physics.tape import chain_state, chain_tape
from weftsim.physics.wear import block_end, clearance_along

if TYPE_CHECKING:
    from collections.abc import Callable

    import numpy as np

# Indices after the chain's constants: joint F's block, the topology, J_FG and J4.
JOINT_F = kc.N_PARAMETERS
TOPOLOGY, SECTOR_CHAIN, ROD_INERTIA = range(JOINT_F + N_JOINT, JOINT_F + N_JOINT + 3)
N_PARAMETERS = JOINT_F + N_JOINT + 3
assert N_PARAMETERS == kc.WEAR_E, "the wear tables of a worn E follow this layout (weftsim.physics.chain.WEAR_E)"
# Topologies: which joints have a clearance; E_TAPE: clearance at E with the flexible rapier tape
# (weftsim.physics.tape; its state appends the tape's coordinates to E_ONLY's).
E_ONLY, F_ONLY, E_AND_F, E_TAPE = 0, 1, 2, 3
# Joint numbers (bits of the contact mask, rows of the held impact velocities).
JOINT_E_INDEX, JOINT_F_INDEX = 0, 1
N_JOINTS = 2
# Offsets of each joint's block in the parameter array.
BLOCKS = (0, JOINT_F)


@njit(cache=True, error_model="numpy")
def degrees_of_freedom(prm: np.ndarray) -> int:
    """Coordinates of the chain: 2 (E only, F only) or 4 (E and F)."""
    return 4 if prm[TOPOLOGY] == E_AND_F else 2


@njit(cache=True, error_model="numpy")
def joint_is_loose(prm: np.ndarray, joint: int) -> bool:
    """True when ``joint`` (:data:`JOINT_E_INDEX` or :data:`JOINT_F_INDEX`) has a clearance."""
    topology = prm[TOPOLOGY]
    if joint == JOINT_E_INDEX:
        return topology != F_ONLY and prm[CLEARANCE] > 0.0
    return topology != E_ONLY and topology != E_TAPE


@njit(cache=True, error_model="numpy")
def crank_side_acceleration(prm: np.ndarray, t: float) -> tuple[float, ...]:
    """P_E, dP_E/dtheta and d^2P_E/dtheta^2 (m, m/rad, m/rad^2) and phi' at time t.

    phi' = tan(beta) sin(theta) / w and phi'' = tan(beta) cos(theta) / w + 2 tan^3(beta) cos(theta)
    sin^2(theta) / w^2 with w = 1 + tan^2(beta) cos^2(theta) (docs/physics.md section 1);
    d^2P_E/dtheta^2 = L_OE (n phi'' - u phi'^2) = n(P_E) phi'' - P_E phi'^2 with n(P) = (-P_Z, P_Y).
    """
    b_y, b_z, db_y, db_z, dphi = kc.crank_side(prm, t)
    theta = prm[kc.OMEGA] * t
    st, ct = math.sin(theta), math.cos(theta)
    tb = prm[kc.TAN_BETA]
    w = 1.0 + tb * tb * ct * ct
    ddphi = tb * ct / w + 2.0 * tb * tb * tb * ct * st * st / (w * w)
    dd_y = -b_z * ddphi - b_y * dphi * dphi
    dd_z = b_y * ddphi - b_z * dphi * dphi
    return b_y, b_z, db_y, db_z, dd_y, dd_z, dphi


@njit(cache=True, error_model="numpy")
def contact_terms(jp: np.ndarray, c: float, c_rate: float, ecc_y: float, ecc_z: float, v_y: float, v_z: float,
                  w_j: float, w_b: float, impact_velocity: float) -> tuple[float, ...]:
    """Force of one joint in contact (block ``jp``) on its journal, and the power it dissipates.

    ``c``, ``c_rate``: the clearance along e and its rate (m, m/s; a round joint's (c0, 0), a worn
    one's :func:`local_clearances`); as in :func:`weftsim.physics.chain.chain`, delta_dot holds -dc/dt.

    ``w_j``, ``w_b``: angular velocities of the journal's and the bearing's bodies (rad/s).
    v_T = e_dot.t + w_j (R_b - |e|) - w_b R_b (:func:`weftsim.physics.joint.tangential_velocity`);
    dissipated power = -(f.e_dot + M_j w_j + M_b w_b) - F_el delta_dot (the contact's power less
    the rate of its elastic energy).

    Returns (f_Y, f_Z, F_N, delta, M_j, M_b, dissipated): N, N, N, m, N m, N m, W.
    """
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    delta = length - c
    if length <= 0.0:
        return 0.0, 0.0, 0.0, delta, 0.0, 0.0, 0.0
    v_t = 0.0
    if jp[MU] > 0.0:
        v_t = tangential_velocity(ecc_y, ecc_z, v_y, v_z, length, w_j, w_b, jp[BEARING_RADIUS])
    f_y, f_z, f_n, _, delta, delta_dot, m_j, m_b = clearance_force_at(jp, c, c_rate, ecc_y, ecc_z, v_y, v_z, v_t,
                                                                      impact_velocity)  # fmt: skip
    f_el = elastic_force(jp[KIND], jp[COEF], c, delta)
    dissipated = -(f_y * v_y + f_z * v_z + m_j * w_j + m_b * w_b) - f_el * delta_dot
    return f_y, f_z, f_n, delta, m_j, m_b, dissipated


@njit(cache=True, error_model="numpy")
def eccentricities(prm: np.ndarray, t: float, y: np.ndarray) -> tuple[float, ...]:
    """Eccentricity and its rate at E and at F of state y (topologies F_ONLY, E_AND_F).

    Returns (e_E, e_dot_E, e_F, e_dot_F) as eight floats (m, m/s; zeros at an ideal E), then the
    angular velocities of the rocker, the rod and the sector (rad/s).
    """
    omega, l_fg, l_ef = prm[kc.OMEGA], prm[kc.L_FG], prm[kc.L_EF]
    b_y, b_z, db_y, db_z, dphi = kc.crank_side(prm, t)
    a = y[0]
    if prm[TOPOLOGY] == E_AND_F:
        c_y, c_z, psi = y[1], y[2], y[3]
        da, dc_y, dc_z, dpsi = y[4], y[5], y[6], y[7]
        half = 0.5 * l_ef
        sp, cp = math.sin(psi), math.cos(psi)
        e_y = c_y - half * cp - b_y
        e_z = c_z - half * sp - b_z
        ve_y = dc_y + half * sp * dpsi - omega * db_y
        ve_z = dc_z - half * cp * dpsi - omega * db_z
        j_y, j_z = c_y + half * cp, c_z + half * sp
        vj_y, vj_z = dc_y - half * sp * dpsi, dc_z + half * cp * dpsi
    else:
        psi, da, dpsi = y[1], y[2], y[3]
        sp, cp = math.sin(psi), math.cos(psi)
        e_y = e_z = ve_y = ve_z = 0.0
        j_y, j_z = b_y + l_ef * cp, b_z + l_ef * sp
        vj_y, vj_z = omega * db_y - l_ef * sp * dpsi, omega * db_z + l_ef * cp * dpsi
    sa, ca = math.sin(a), math.cos(a)
    f_y = j_y - (prm[kc.L_OG] + l_fg * ca)
    f_z = j_z - l_fg * sa
    vf_y = vj_y + l_fg * sa * da
    vf_z = vj_z - l_fg * ca * da
    return e_y, e_z, ve_y, ve_z, f_y, f_z, vf_y, vf_z, omega * dphi, dpsi, da


@njit(cache=True, error_model="numpy")
def _rate(e_y, e_z, v_y, v_z):
    length = math.sqrt(e_y * e_y + e_z * e_z)
    return length, ((v_y * e_y + v_z * e_z) / length if length > 0.0 else 0.0)


@njit(cache=True, error_model="numpy")
def wear_start_f(prm: np.ndarray) -> int:
    """Index of joint F's wear block: after joint E's (``[0, 0]`` when E does not wear) at
    :data:`weftsim.physics.chain.WEAR_E`; ``prm.size`` or beyond when F has none (a round F)."""
    return block_end(prm, kc.WEAR_E)


@njit(cache=True, error_model="numpy")
def local_clearances(prm: np.ndarray, t: float, y: np.ndarray, q: tuple) -> tuple[float, float, float, float]:
    """(c_E, dc_E/dt, c_F, dc_F/dt) along each joint's eccentricity (topologies F_ONLY, E_AND_F), m and m/s.

    ``q``: :func:`eccentricities` of (t, y).  A round joint gives (c0, 0); a worn one c0 + h_b + h_j
    (:func:`weftsim.physics.wear.clearance_along`) with its bodies' frames: at E the bearing is the
    rocker (theta_OE, :func:`weftsim.physics.chain.rocker_angle`) and the journal the rod (psi); at F the
    bearing is the sector's eye (a = theta_FG) and the journal the rod's pin (psi).  Profiles are tables
    over each body's own frame, so the same wear tables serve E in either chain.
    """
    if prm.size <= kc.WEAR_E:  # no wear tables (every run but a wear update's): the round clearances
        return prm[CLEARANCE], 0.0, prm[JOINT_F + CLEARANCE], 0.0
    psi = y[3] if prm[TOPOLOGY] == E_AND_F else y[1]
    w_rocker, dpsi, da = q[8], q[9], q[10]
    c_e, rate_e = prm[CLEARANCE], 0.0
    if prm[TOPOLOGY] == E_AND_F:
        c_e, rate_e = clearance_along(prm, kc.WEAR_E, prm[CLEARANCE], q[0], q[1], q[2], q[3], kc.rocker_angle(prm, t),
                                      w_rocker, psi, dpsi)  # fmt: skip
    c_f, rate_f = clearance_along(prm, wear_start_f(prm), prm[JOINT_F + CLEARANCE], q[4], q[5], q[6], q[7], y[0], da,
                                  psi, dpsi)  # fmt: skip
    return c_e, rate_e, c_f, rate_f


@njit(cache=True, error_model="numpy", inline="always")  # no extra call in rhs_any / penetration_at
def penetration_e(prm: np.ndarray, t: float, y: np.ndarray, joint: int) -> tuple[float, float]:
    """:func:`penetration_at` of topology E_ONLY: :func:`weftsim.physics.chain.penetration` (``joint`` is E)."""
    return kc.penetration(prm, t, y)


@njit(cache=True, error_model="numpy", inline="always")  # no extra call in rhs_any / penetration_at
def rhs_e(prm: np.ndarray, t: float, y: np.ndarray, contact: int, impact: np.ndarray, out: np.ndarray) -> float:
    """:func:`rhs_any` of topology E_ONLY: :func:`weftsim.physics.chain.chain` with contact bit 0 and
    impact[0]; returns delta (m)."""
    return kc.chain(prm, t, y, (contact & 1) != 0, impact[0], out)[2]


@njit(cache=True, error_model="numpy")
def _no_film(prm: np.ndarray) -> bool:
    """:func:`weftsim.physics.lubricated.is_lubricated` of a dry joint: False."""
    return False


# The plain scene: clearance at E alone (no tape), dry (no film), round (no wear tables), at constant speed:
# the bindings that give the compiled paths its kernel (weftsim.physics.python.specialize; a tag "plain").
# Bound, the drive law, the film, the wear and the topology dispatch leave the compiled code, and numba's
# calls through them with it (each call that is not inlined increments and decrements the reference
# counts of its array arguments: docs/performance.md, "The plain kernel").  Same arithmetic, same results.
PLAIN: dict[str, Callable[..., Any]] = {"crank_motion": kc.constant_speed, "crank_rate": kc.constant_rate, "is_lubricated": _no_film,
         "local_clearance": kc.round_clearance, "rhs_any": rhs_e, "penetration_at": penetration_e}  # fmt: skip


def is_plain(prm: np.ndarray) -> bool:
    """True when the kernel's parameter array ``prm`` is a plain scene's (:data:`PLAIN`)."""
    return (prm[TOPOLOGY] == E_ONLY and not is_lubricated(prm) and prm.size <= kc.WEAR_E
            and prm[kc.DRIVE_LAW] == kc.CONSTANT_SPEED)  # fmt: skip


@njit(cache=True, error_model="numpy")
def penetration_at(prm: np.ndarray, t: float, y: np.ndarray, joint: int) -> tuple[float, float]:
    """(delta, delta_dot) of ``joint`` (0 = E, 1 = F) of state y at time t (m, m/s)."""
    if prm[TOPOLOGY] == E_ONLY:
        return penetration_e(prm, t, y, joint)
    if prm[TOPOLOGY] == E_TAPE:  # E's chain with the tape: the same first four coordinates, a round joint
        return kc.penetration(prm[:kc.WEAR_E], t, chain_state(prm, y))
    q = eccentricities(prm, t, y)
    c_e, rate_e, c_f, rate_f = local_clearances(prm, t, y, q)
    if joint == JOINT_E_INDEX:
        length, rate = _rate(q[0], q[1], q[2], q[3])
        return length - c_e, rate - rate_e
    length, rate = _rate(q[4], q[5], q[6], q[7])
    return length - c_f, rate - rate_f


@njit(cache=True, error_model="numpy")
def chain_f(prm: np.ndarray, t: float, y: np.ndarray, contact: int, impact: np.ndarray,
            out: np.ndarray) -> tuple[float, ...]:
    """y' of topologies F_ONLY and E_AND_F into ``out`` (module docstring).

    ``contact``: bit 0 (E) and bit 1 (F) set for the joints in a contact segment; ``impact`` (2,):
    their held impact velocities (m/s).

    Returns
    -------
    q3 (N m), then for E and for F: F_N (N), delta (m), e_Y, e_Z (m); the rapier side's a'' (rad/s^2).
    """
    q = eccentricities(prm, t, y)
    e_y, e_z, ve_y, ve_z, ef_y, ef_z, vf_y, vf_z, w_rocker, dpsi, da = q
    c_e, rate_e, c_f, rate_f = local_clearances(prm, t, y, q)
    b_y, b_z, db_y, db_z, dd_y, dd_z, dphi = crank_side_acceleration(prm, t)
    fe_y = fe_z = fe_n = m_je = m_be = diss_e = 0.0
    ff_y = ff_z = ff_n = m_jf = m_bf = diss_f = 0.0
    both = prm[TOPOLOGY] == E_AND_F
    delta_e = -prm[CLEARANCE]
    if both:
        delta_e = math.sqrt(e_y * e_y + e_z * e_z) - c_e
        if contact & 1:
            fe_y, fe_z, fe_n, delta_e, m_je, m_be, diss_e = contact_terms(prm, c_e, rate_e, e_y, e_z, ve_y, ve_z, dpsi,
                                                                          w_rocker, impact[0])  # fmt: skip
    jf = prm[JOINT_F:JOINT_F + N_JOINT]
    delta_f = math.sqrt(ef_y * ef_y + ef_z * ef_z) - c_f
    if contact & 2:
        ff_y, ff_z, ff_n, delta_f, m_jf, m_bf, diss_f = contact_terms(jf, c_f, rate_f, ef_y, ef_z, vf_y, vf_z, dpsi, da,
                                                                      impact[1])  # fmt: skip
    # Lubricated joints carry their film at every state (weftsim.physics.lubricated).
    if both and is_lubricated(prm):
        lub = lubricated_force(prm, c_e, e_y, e_z, ve_y, ve_z, dpsi, w_rocker)
        fe_y, fe_z, m_je, m_be = fe_y + lub[L_FX], fe_z + lub[L_FY], m_je + lub[L_MJ], m_be + lub[L_MB]
        diss_e += lub[L_DISSIPATED]
    if is_lubricated(jf):
        lub = lubricated_force(jf, c_f, ef_y, ef_z, vf_y, vf_z, dpsi, da)
        ff_y, ff_z, m_jf, m_bf = ff_y + lub[L_FX], ff_z + lub[L_FY], m_jf + lub[L_MJ], m_bf + lub[L_MB]
        diss_f += lub[L_DISSIPATED]
    a = y[0]
    sa, ca = math.sin(a), math.cos(a)
    l_fg, l_ef, omega = prm[kc.L_FG], prm[kc.L_EF], prm[kc.OMEGA]
    m4, g = prm[kc.ROD_MASS], prm[kc.GRAVITY]
    dda = (-l_fg * (ca * ff_z - sa * ff_y) + m_bf) / prm[SECTOR_CHAIN]
    if both:
        psi = y[3]
        sp, cp = math.sin(psi), math.cos(psi)
        half = 0.5 * l_ef
        out[0], out[1], out[2], out[3] = y[4], y[5], y[6], y[7]
        out[4] = dda
        out[5] = (fe_y + ff_y) / m4
        out[6] = (fe_z + ff_z) / m4 - g
        out[7] = (half * (cp * ff_z - sp * ff_y) - half * (cp * fe_z - sp * fe_y) + m_je + m_jf) / prm[ROD_INERTIA]
        q3 = -(fe_y * db_y + fe_z * db_z) + m_be * dphi
        n = 8
    else:
        psi = y[1]
        sp, cp = math.sin(psi), math.cos(psi)
        half = 0.5 * l_ef
        w2 = omega * omega
        ae_y, ae_z = w2 * dd_y, w2 * dd_z
        ddpsi = (l_ef * (cp * ff_z - sp * ff_y) + m_jf - m4 * half * (cp * (ae_z + g) - sp * ae_y)) / prm[kc.M22]
        out[0], out[1] = da, dpsi
        out[2], out[3] = dda, ddpsi
        # Newton on the rod: the force it takes at E, and the opposite on the rocker.
        ac_y = ae_y + half * (-sp * ddpsi - cp * dpsi * dpsi)
        ac_z = ae_z + half * (cp * ddpsi - sp * dpsi * dpsi)
        pin_y = m4 * ac_y - ff_y
        pin_z = m4 * (ac_z + g) - ff_z
        q3 = -(pin_y * db_y + pin_z * db_z)
        n = 4
    out[n] = -q3 * omega
    out[n + 1] = diss_e + diss_f
    return q3, fe_n, delta_e, e_y, e_z, ff_n, delta_f, ef_y, ef_z, dda


@njit(cache=True, error_model="numpy")
def rhs_any(prm: np.ndarray, t: float, y: np.ndarray, contact: int, impact: np.ndarray, out: np.ndarray) -> float:
    """y' of any topology into ``out``; returns delta of the first loose joint (the E-only chain's value).

    E_ONLY: :func:`weftsim.physics.chain.chain` with contact bit 0 and impact[0], unchanged; E_TAPE:
    :func:`weftsim.physics.tape.chain_tape` likewise.
    """
    if prm[TOPOLOGY] == E_ONLY:
        return rhs_e(prm, t, y, contact, impact, out)
    if prm[TOPOLOGY] == E_TAPE:
        return chain_tape(prm, t, y, (contact & 1) != 0, impact[0], out)[2]
    r = chain_f(prm, t, y, contact, impact, out)
    return r[2] if prm[TOPOLOGY] == E_AND_F else r[6]


@njit(cache=True, error_model="numpy")
def rod_energy(prm: np.ndarray, t: float, y: np.ndarray) -> tuple[float, float]:
    """Kinetic and potential energy (J) of members 4-8 in topologies F_ONLY and E_AND_F."""
    l_ef, m4, g = prm[kc.L_EF], prm[kc.ROD_MASS], prm[kc.GRAVITY]
    if prm[TOPOLOGY] == E_AND_F:
        da, dc_y, dc_z, dpsi = y[4], y[5], y[6], y[7]
        kinetic = 0.5 * (prm[SECTOR_CHAIN] * da * da + m4 * (dc_y * dc_y + dc_z * dc_z) + prm[ROD_INERTIA] * dpsi * dpsi)
        return kinetic, m4 * g * y[2]
    b_y, b_z, db_y, db_z, _ = kc.crank_side(prm, t)
    omega, psi, da, dpsi = prm[kc.OMEGA], y[1], y[2], y[3]
    half = 0.5 * l_ef
    sp, cp = math.sin(psi), math.cos(psi)
    vc_y = omega * db_y - half * sp * dpsi
    vc_z = omega * db_z + half * cp * dpsi
    kinetic = 0.5 * (prm[SECTOR_CHAIN] * da * da + m4 * (vc_y * vc_y + vc_z * vc_z) + prm[ROD_INERTIA] * dpsi * dpsi)
    return kinetic, m4 * g * (b_z + half * sp)
