"""The 2-DOF chain of members 4-8 driven through the clearance joint (the one definition).

Members 1-3 are prescribed by theta = omega t; the bearing centre P_b is E of the rocker.
Members 4-8 form a 2-DOF chain with coordinates q = (a, psi) (a = theta_FG, psi = theta_EF), in
four-bar plane coordinates (Y, Z), u(x) = (cos x, sin x)::

        P_b (bearing, rocker 3)  e = P_j - P_b      F = G + L_FG u(a)
        P_j (journal, rod 4) ----- F               P_j = F - L_EF u(psi)
                                    \\ L_FG        G = (L_OG, 0)

Lagrange's equations M(q) q'' = Q(q, q', t), with k = m4 L_FG L_EF / 2 and s = sin(psi - a):

    M = [[m4 L_FG^2 + J_FG,  -k cos(psi - a)], [-k cos(psi - a),  m4 L_EF^2/4 + J4]]
    Q_a   = L_FG n(a).f  - m4 g L_FG cos a         - k psi'^2 s
    Q_psi = -L_EF n(psi).f + M_j + m4 g (L_EF/2) cos psi + k a'^2 s

with n(x) = (-sin x, cos x), f and M_j the contact force and moment on the journal
(:func:`weftsim.physics.joint.clearance_force`), J_FG = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2.
The contact's generalized force on the crank side is Q3 = -f . dP_b/dtheta + M_b dtheta_OE/dtheta;
its power -Q3 omega and the dissipated power (F_N - F_el) delta_dot - F_T v_T are integrated with
the state y = [a, psi, a', psi', W3, D] so the energy balance closes to the solver tolerance.
Derivation: docs/reference-solver.md.

Every number comes in one float array: the joint block of :mod:`weftsim.physics.joint` followed by
the chain's constants (indices below; :func:`weftsim.model.dynamics.pack_parameters` builds it
from a scene), so numba compiles these functions once per machine and loads them from its cache.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from numba import njit

from weftsim.physics.joint import connector_friction_force_at
from weftsim.physics.joint import (  # noqa: F401 - the joint block is part of this array
    BEARING_RADIUS, CLEARANCE, COEF, KIND, MU, N_JOINT, TRACK_MAX, V_MIN, clearance_force, clearance_force_at,
    tangential_velocity,
)  # fmt: skip
from weftsim.physics.laws import elastic_force
from weftsim.physics.lubricated import L_DISSIPATED, L_FX, L_FY, L_MB, L_MJ, is_lubricated, lubricated_force
from weftsim.physics.lubricated import connector_lubricated_force_at
from weftsim.physics.wear import clearance_along

if TYPE_CHECKING:
    import numpy as np

# Indices of the chain's constants, after the joint block; the drive law's four (:func:`crank_motion`) last.
(OMEGA, TAN_BETA, COS_OE0, SIN_OE0, L_OE, L_EF, L_FG, L_OG, ROD_MASS, GRAVITY, M11, M22,
 COUPLING, DRIVE_LAW, DRIVE_T0, DRIVE_RAMP, DRIVE_THETA0) = range(N_JOINT, N_JOINT + 17)  # fmt: skip
N_PARAMETERS = N_JOINT + 17
# Drive laws of the crank (prm[DRIVE_LAW]): constant speed theta = omega t; a run-down from omega to rest; a
# start-up from rest to omega (:func:`crank_motion`).
CONSTANT_SPEED, RUN_DOWN, START_UP = 0.0, 1.0, 2.0
# A worn joint E appends its wear block (weftsim.physics.wear.wear_block) here, after the blocks of
# weftsim.physics.chain_f (joint F's parameters, the topology, J_FG, J4); a round one appends nothing.
WEAR_E = N_PARAMETERS + N_JOINT + 3


@njit(cache=True, error_model="numpy", inline="always")
def _ramp(tau: float) -> tuple[float, float, float]:
    """(S, s, s') of the smooth step s(tau) = 3 tau^2 - 2 tau^3 on [0, 1]: S = integral of s = tau^3 - tau^4 / 2,
    s' = 6 tau (1 - tau) (zero at both ends: the crank's acceleration is continuous)."""
    t2 = tau * tau
    return t2 * tau - 0.5 * t2 * t2, t2 * (3.0 - 2.0 * tau), 6.0 * tau * (1.0 - tau)


@njit(cache=True, error_model="numpy")
def constant_speed(prm: np.ndarray, t: float) -> tuple[float, float, float]:
    """:func:`crank_motion` at constant speed: (omega t, omega, 0) (rad, rad/s, rad/s^2)."""
    omega = prm[OMEGA]
    return omega * t, omega, 0.0


@njit(cache=True, error_model="numpy")
def constant_rate(prm: np.ndarray, t: float) -> float:
    """:func:`crank_rate` at constant speed: omega (rad/s)."""
    return prm[OMEGA]


@njit(cache=True, error_model="numpy")
def crank_motion(prm: np.ndarray, t: float) -> tuple[float, float, float]:
    """The crank's prescribed motion: (theta, theta_dot, theta_ddot) at time t (rad, rad/s, rad/s^2).

    - ``CONSTANT_SPEED`` (every run but a stop-start's): theta = omega t, exactly as before the drive laws.
    - ``RUN_DOWN``: omega until t0, then theta_dot = omega (1 - s(tau)) over the ramp T (tau = (t - t0) / T,
      :func:`_ramp`), at rest after it: the crank turns omega T / 2 while it stops.
    - ``START_UP``: at rest until t0, then theta_dot = omega s(tau) over T, omega after it (the drive's start-up
      ramp; the crank turns omega T / 2 on the ramp).
    Both from theta0 = prm[DRIVE_THETA0] (the crank angle at t = 0).  A loom drive reaches full speed within
    the first pick or two (docs/wear.md section 12).
    """
    law = prm[DRIVE_LAW]
    if law == CONSTANT_SPEED:
        return constant_speed(prm, t)
    omega = prm[OMEGA]
    t0, ramp, theta0 = prm[DRIVE_T0], prm[DRIVE_RAMP], prm[DRIVE_THETA0]
    if law == RUN_DOWN:
        if t <= t0:
            return theta0 + omega * t, omega, 0.0
        tau = (t - t0) / ramp
        if tau >= 1.0:
            return theta0 + omega * (t0 + 0.5 * ramp), 0.0, 0.0
        big, small, slope = _ramp(tau)
        return theta0 + omega * (t0 + ramp * (tau - big)), omega * (1.0 - small), -omega * slope / ramp
    if t <= t0:
        return theta0, 0.0, 0.0
    tau = (t - t0) / ramp
    if tau >= 1.0:
        return theta0 + omega * (0.5 * ramp + (t - t0 - ramp)), omega, 0.0
    big, small, slope = _ramp(tau)
    return theta0 + omega * ramp * big, omega * small, omega * slope / ramp


@njit(cache=True, error_model="numpy", inline="always")
def crank_rate(prm: np.ndarray, t: float) -> float:
    """theta_dot at time t (rad/s): prm[OMEGA] itself at constant speed (:func:`crank_motion`)."""
    if prm[DRIVE_LAW] == CONSTANT_SPEED:
        return constant_rate(prm, t)
    return crank_motion(prm, t)[1]


@njit(cache=True, error_model="numpy")
def crank_side(prm: np.ndarray, t: float) -> tuple[float, ...]:
    """Bearing centre P_b = E of the rocker: (P_b, dP_b/dtheta, phi') at time t.

    phi = -atan(u), u = tan(beta) cos(theta); theta_OE = theta_OE0 + phi; sin and cos of
    atan(u) from u directly (1/sqrt(1 + u^2), u/sqrt(1 + u^2)); theta of :func:`crank_motion`.
    """
    theta = crank_motion(prm, t)[0]
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
def eccentricity(prm: np.ndarray, t: float, y: np.ndarray) -> tuple[float, ...]:
    """e = P_j - P_b, its rate, and sin/cos of a, psi (m, m/s) of state y at time t."""
    b_y, b_z, db_y, db_z, dphi = crank_side(prm, t)
    sa, ca, sp, cp = math.sin(y[0]), math.cos(y[0]), math.sin(y[1]), math.cos(y[1])
    l_fg, l_ef, omega = prm[L_FG], prm[L_EF], crank_rate(prm, t)
    ecc_y = prm[L_OG] + l_fg * ca - l_ef * cp - b_y
    ecc_z = l_fg * sa - l_ef * sp - b_z
    v_y = -l_fg * sa * y[2] + l_ef * sp * y[3] - omega * db_y
    v_z = l_fg * ca * y[2] - l_ef * cp * y[3] - omega * db_z
    return ecc_y, ecc_z, v_y, v_z, db_y, db_z, dphi, sa, ca, sp, cp


@njit(cache=True, error_model="numpy", inline="always")
def local_clearance(prm: np.ndarray, t: float, ecc_y: float, ecc_z: float, v_y: float, v_z: float,
                    y: np.ndarray) -> tuple[float, float]:
    """(c, dc/dt) along the eccentricity e of state y at time t: (c0, 0) when round, else (:mod:`.wear`)
    c0 + h_b + h_j with the rate of c as the contact direction turns in each body's frame, m, m/s.

    The bearing turns with the rocker (theta_OE = theta_OE0 + phi, :func:`rocker_angle`), the journal
    with the rod (its axis E -> F along u(psi)); the direction of e turns at (e x e_dot) / |e|^2.
    """
    return rod_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y[1], y[3])


@njit(cache=True, error_model="numpy")
def round_clearance(prm: np.ndarray, t: float, ecc_y: float, ecc_z: float, v_y: float, v_z: float,
                    y: np.ndarray) -> tuple[float, float]:
    """:func:`local_clearance` of a round joint (no wear tables): (c0, 0), m, m/s."""
    return prm[CLEARANCE], 0.0


@njit(cache=True, error_model="numpy", inline="always")
def rod_clearance(prm: np.ndarray, t: float, ecc_y: float, ecc_z: float, v_y: float, v_z: float, psi: float,
                  dpsi: float) -> tuple[float, float]:
    """:func:`local_clearance` with the rod's angle psi (rad) and rate (rad/s) given (every engine's state
    has them: the reference's y[1], y[3]; the kinematic tree's q0 + q1 - pi and its rate).  ``prm``: an array,
    or a list on the Exudyn engine's plain-Python callback route (hence ``len``)."""
    if len(prm) <= WEAR_E:
        return prm[CLEARANCE], 0.0
    theta, omega, _ = crank_motion(prm, t)
    w_b = omega * prm[TAN_BETA] * math.sin(theta) / (1.0 + (prm[TAN_BETA] * math.cos(theta)) ** 2)
    return clearance_along(prm, WEAR_E, prm[CLEARANCE], ecc_y, ecc_z, v_y, v_z, rocker_angle(prm, t), w_b, psi, dpsi)


@njit(cache=True, error_model="numpy")
def rocker_angle(prm: np.ndarray, t: float) -> float:
    """theta_OE = theta_OE0 + phi, phi = -atan(tan(beta) cos(theta)): the bearing's frame angle, rad (theta of
    :func:`crank_motion`)."""
    return math.atan2(prm[SIN_OE0], prm[COS_OE0]) - math.atan(prm[TAN_BETA] * math.cos(crank_motion(prm, t)[0]))


@njit(cache=True, error_model="numpy")
def penetration(prm: np.ndarray, t: float, y: np.ndarray) -> tuple[float, float]:
    """(delta, delta_dot) = (|e| - c, e_dot . n - dc/dt) of state y at time t (m, m/s), c and dc/dt of
    :func:`local_clearance` (round: c0 and 0)."""
    ecc_y, ecc_z, v_y, v_z = eccentricity(prm, t, y)[:4]
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    c, c_rate = local_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y)
    rate = (v_y * ecc_y + v_z * ecc_z) / length - c_rate if length > 0.0 else 0.0
    return length - c, rate


@njit(cache=True, error_model="numpy")
def chain(prm: np.ndarray, t: float, y: np.ndarray, contact: bool, impact_velocity: float,
          out: np.ndarray) -> tuple[float, ...]:
    """y' of the clearance mode into ``out`` (6,) (module docstring).

    Free flight (``contact`` False): no contact force, W3' = D' = 0.

    Returns
    -------
    q3 (N m, contact generalized force on the crank side), F_N (N), delta (m), e_Y, e_Z (m),
    sin a, cos a, sin psi, cos psi, force on the journal f_Y, f_Z (N), friction moments M_j, M_b (N m).
    """
    ecc_y, ecc_z, v_y, v_z, db_y, db_z, dphi, sa, ca, sp, cp = eccentricity(prm, t, y)
    da, dpsi, omega = y[2], y[3], crank_rate(prm, t)
    f_y = f_z = m_j = m_b = dissipated = f_n = 0.0
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    c, c_rate = local_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y)
    delta = length - c
    if contact and length > 0.0:
        v_t = 0.0
        if prm[MU] > 0.0:
            v_t = tangential_velocity(ecc_y, ecc_z, v_y, v_z, length, dpsi, omega * dphi, prm[BEARING_RADIUS])
        f_y, f_z, f_n, _, delta, delta_dot, m_j, m_b = clearance_force_at(
            prm, c, c_rate, ecc_y, ecc_z, v_y, v_z, v_t, impact_velocity)
        f_el = elastic_force(prm[KIND], prm[COEF], c, delta)
        # Power of the contact on both bodies, f.e_dot + M_j w_j + M_b w_b = -F_N e_dot.n + F_T v_T;
        # what the elastic energy (rate F_el delta_dot) does not store is dissipated.  On a worn wall
        # delta_dot also holds -dc/dt, so this term also books the work of the radial force as the
        # wall's profile passes under it (the small-wear normal, docs/wear.md section 2).
        dissipated = -(f_y * v_y + f_z * v_z + m_j * dpsi + m_b * omega * dphi) - f_el * delta_dot
    if is_lubricated(prm):  # the film loads the joint in free flight too (weftsim.physics.lubricated)
        lub = lubricated_force(prm, c, ecc_y, ecc_z, v_y, v_z, dpsi, omega * dphi)
        f_y += lub[L_FX]
        f_z += lub[L_FY]
        m_j += lub[L_MJ]
        m_b += lub[L_MB]
        dissipated += lub[L_DISSIPATED]
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
    return q3, f_n, delta, ecc_y, ecc_z, sa, ca, sp, cp, f_y, f_z, m_j, m_b


@njit(cache=True, error_model="numpy")
def rhs(prm: np.ndarray, t: float, y: np.ndarray, contact: bool, impact_velocity: float, out: np.ndarray) -> float:
    """y' into ``out`` (:func:`chain`); returns q3 (N m)."""
    return chain(prm, t, y, contact, impact_velocity, out)[0]


@njit(cache=True, error_model="numpy")
def tree_joint_force(prm: np.ndarray, t: float, a: float, q1: float, da: float, dq1: float, held: float, delta0: float,
                     rate0: float) -> tuple[float, ...]:
    """Generalized contact force on the two joints of the kinematic tree (Exudyn's tree model).

    Joint coordinates q0 = a, q1 = psi + pi - a (b = q0 + q1 = psi + pi is the absolute angle of
    the rod's axis from F to the journal).  The journal centre and its velocity,

        P_j = G + L_FG u(a) + L_EF u(b),  v_j = L_FG a' u'(a) + L_EF b' u'(b),

    less the bearing centre P_b(t) of :func:`crank_side` and its velocity, go through
    :func:`weftsim.physics.joint.connector_friction_force_at`: the normal force F_N n on the bearing and,
    with friction (``prm[MU]`` > 0, in contact), F_T t on the journal (rod turning at b', rocker at
    omega phi') with the moments M_j = (R_b - |e|) F_T about P_j and M_b = -R_b F_T about P_b.  The force on the bearing is F_b = F_N n - F_T t; the journal's, -F_b,
    and M_j enter the joints by virtual work (db/dq0 = db/dq1 = 1):

        Q1 = -F_b . dP_j/dq1 + M_j = L_EF (F_bx sin b - F_by cos b) + M_j,
        Q0 = L_FG (F_bx sin a - F_by cos a) + Q1.

    A lubricated joint adds its film and asperity force at every state
    (:func:`weftsim.physics.lubricated.connector_lubricated_force`; F_b, M_j and M_b include them).  A worn
    joint (the wear block at :data:`WEAR_E`) takes the local clearance c0 + h_b + h_j along e and its rate
    (:func:`rod_clearance`, the rod's angle psi = b - pi), as :func:`chain` does: delta and delta_dot are then
    |e| - c and e_dot . n - dc/dt.

    The two powers of the energy balance, at this state (the explicit tree integrates them with the motion,
    as the reference engine integrates W3 and D in :func:`chain`):

        W3' = -Q3 omega,  Q3 = F_b . dP_b/dtheta + M_b phi'       (drawn through the rocker)
        D'  = F_N (delta_dot + dc/dt) - F_el(delta) delta_dot - F_T v_T + D'_lub  (damping, friction, film,
              and on a worn wall the radial force's work as the profile passes under it, as in :func:`chain`)

    Returns (Q0, Q1, delta, delta_dot, F_bx, F_by, F_N, M_b, F_T v_T, v_T, D'_lub, U_a, W3', D'): N m, N m, m,
    m/s, N, N, N, N m, W (the dry friction power on the pair, <= 0; 0 without friction), m/s (the sliding speed
    of the contact points, 0 out of contact; the implicit tree's friction segments read it), the
    lubricated part's dissipated power (W) and the asperity potential (J) (both 0 for a dry joint), W, W.
    """
    l_fg, l_ef = prm[L_FG], prm[L_EF]
    b = a + q1
    db = da + dq1
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    px = prm[L_OG] + l_fg * ca + l_ef * cb
    py = l_fg * sa + l_ef * sb
    vx = -l_fg * sa * da - l_ef * sb * db
    vy = l_fg * ca * da + l_ef * cb * db
    b_y, b_z, db_y, db_z, dphi = crank_side(prm, t)
    omega = crank_rate(prm, t)
    # F_N = hypot of the normal force, as the channels computed it before friction: bit-identical at mu = 0.
    lub_power = asperity_energy = 0.0
    ex, ey, evx, evy = px - b_y, py - b_z, vx - omega * db_y, vy - omega * db_z
    # A worn joint E: the local clearance along e and its rate, the journal's frame turning with the rod
    # (psi = b - pi); a round one: (c0, 0), the unchanged call below.
    c, c_rate = rod_clearance(prm, t, ex, ey, evx, evy, b - math.pi, db)
    if is_lubricated(prm):
        fx, fy, delta, rate, f_n, f_t, m_j, m_b, v_t, lub_power, asperity_energy = connector_lubricated_force_at(
            prm, c, c_rate, ex, ey, evx, evy, held, delta0, rate0, db, omega * dphi)[:11]
    else:
        fx, fy, delta, rate, f_n, f_t, m_j, m_b, v_t = connector_friction_force_at(
            prm, c, c_rate, ex, ey, evx, evy, held, delta0, rate0, db, omega * dphi)
    g1 = l_ef * (fx * sb - fy * cb) + m_j
    drawn = -(fx * db_y + fy * db_z + m_b * dphi) * omega
    # F_N e_dot.n = F_N (delta_dot + dc/dt): on a worn wall the radial force also works as the profile passes
    # under it, which :func:`chain` books as dissipated (its D' from the forces' work on both bodies).
    dissipated = (f_n - elastic_force(prm[KIND], prm[COEF], c, delta)) * rate + f_n * c_rate - f_t * v_t + lub_power
    return (l_fg * (fx * sa - fy * ca) + g1, g1, delta, rate, fx, fy, f_n, m_b, f_t * v_t, v_t, lub_power,
            asperity_energy, drawn, dissipated)  # fmt: skip
