"""The flexible rapier tape: an axially moving bar of variable free length driven by the rapier wheel
(the one definition; docs/rapier-tape.md).

The wheel's teeth hold the tape where it leaves the wheel (the root); the free length between the root and
the head grows with the stroke, lambda(s) = L0 + s, s = R (a - a0) the wheel's pitch travel (R = d5 d7 / d6,
a = theta_FG).  Material coordinate xi from the head (xi = 0) towards the wheel, eta = xi / lambda in [0, 1].
The material point xi sits at X = X0 + s - xi + w(xi, t); the part behind the root (xi > lambda) moves
rigidly with the wheel (w = 0).  Ritz approximation w = sum_i q_i phi_i(eta), phi_i(1) = 0 (clamped at
the root), phi_i(eta) = (1 - eta) P_i(2 eta - 1) (shifted Legendre polynomials: the exact mode shapes
sin(beta lambda (1 - eta)) are entire, so the first frequency converges spectrally with the number of
functions n; 4 meet the closed form to 1e-8).  The velocity of a material point is
s' + w_t, w_t = sum q_i' phi_i - (s' / lambda) eta sum q_i phi_i'.

Kinetic energy of tape (mass per length mu = rho A, length L_t) and head (mass m), z = (s, q):

    T = 1/2 z'^T M(s, q) z',  M_ss = m + mu L_t + 2 mu p.q + mu q^T C q / lambda,
                              M_sq = mu lambda p + m h - mu B q,   M_qq = mu lambda P + m h h^T,

with P_ij = int phi_i phi_j, p_i = int phi_i, h_i = phi_i(0), B_ij = int eta phi_i phi_j',
C_ij = int eta^2 phi_i' phi_j' (B + B^T = -P: phi(1) = 0).  Strain energy V = EA / (2 lambda) q^T S q,
S_ij = int phi_i' phi_j'.  Lagrange's equations M z'' + g = -dV/dz - dR/dz' + Q_guide with the
velocity terms (Ml' z' - dT/dz, worked out in docs/rapier-tape.md)

    g_s = -1/2 mu q^T C q s'^2 / lambda^2 + 2 mu s' p.q' + 2 mu s' (C q).q' / lambda,
    g_q = -mu s' (2 B q' + s' C q / lambda),

dV/ds = -EA q^T S q / (2 lambda^2), dV/dq = EA S q / lambda.  Structural damping is Kelvin-Voigt,
sigma = E (eps + tau eps_t) with the material strain rate eps_t = d/dxi (w_t) = (1 / lambda) r(eta),
r = sum q_i' phi_i' - (s' / lambda) sum q_i D_i, D_i = (eta phi_i')': Rayleigh's function
R = EA tau / (2 lambda) int r^2, its power 2 R is dissipated.  The guide rail carries the head's and the
free tape's weight with Coulomb friction mu_g (smoothed: tanh(v / V_GUIDE)); the free tape's force per
length takes its direction from the wheel's speed s'.

The tape's force on the wheel along s, F_s = -(M_ss s'' + M_sq.q'' + g_s + dV/ds + dR/ds') + Q_guide,s,
enters the chain's equation of a through R (the rigid rapier's -m8 s''); the axial force at the root is
N_root = (EA / lambda) (sum q_i phi_i'(1) + tau r(1)) (tension positive).

Every number sits in the tape block of the kernel's parameter array, at :data:`TAPE` (where a worn joint's
tables would go: a tape scene has none), laid out by :func:`block_size` (weftsim.model.tape packs it).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from weftsim.physics import chain as kc

if TYPE_CHECKING:
    pass

# The tape block starts where a worn joint's tables would (a tape scene wears nothing).
TAPE = kc.WEAR_E
# Scalars of the block (offsets from TAPE), then the vectors p, h, d1 = phi'(1), D(1) = phi'(1) + phi''(1)
# (n each) and the n x n matrices P, S, B, C, G, H (row-major).  G_ij = int phi_i' D_j, H_ij = int D_i D_j.
(MODES, MU, EA, TAU, HEAD, LENGTH, FREE0, RATIO, A0, GUIDE_MU, GUIDE_G, MASS) = range(12)
N_SCALARS = 12
V_GUIDE = 1e-2  # m/s: the guide friction's smoothing speed (tanh(v / V_GUIDE))
# The state of the chain with the tape: coordinates, rates, then the two quadratures (as every chain's, so the
# integrators' Jacobian and error norm treat them alike): [a, psi, q (n), a', psi', q' (n), W3, D].  D holds
# the contact's and the tape's dissipated energy.

def block_size(n: int) -> int:
    """Length of the tape block of ``n`` Ritz functions."""
    return N_SCALARS + 4 * n + 6 * n * n


@njit(cache=True, error_model="numpy", inline="always")
def _vec(prm, k, n):
    start = TAPE + N_SCALARS + k * n
    return prm[start:start + n]


@njit(cache=True, error_model="numpy", inline="always")
def _mat(prm, k, n):
    start = TAPE + N_SCALARS + 4 * n + k * n * n
    return prm[start:start + n * n].reshape((n, n))


@njit(cache=True, error_model="numpy")
def modes(prm: np.ndarray) -> int:
    """Number n of Ritz functions of the tape."""
    return int(prm[TAPE + MODES])


@njit(cache=True, error_model="numpy")
def free_length(prm: np.ndarray, a: float) -> float:
    """lambda = L0 + R (a - a0): the free length between the root and the head, m."""
    return prm[TAPE + FREE0] + prm[TAPE + RATIO] * (a - prm[TAPE + A0])


@njit(cache=True, error_model="numpy")
def tape_terms(prm: np.ndarray, lam: float, sd: float, q: np.ndarray, qd: np.ndarray, m_sq: np.ndarray,
               m_qq: np.ndarray, f_q: np.ndarray) -> tuple[float, ...]:
    """The tape's mass terms and forces at free length ``lam`` (m), wheel speed ``sd`` (m/s), q, q'.

    Fills ``m_sq`` (n,), ``m_qq`` (n, n) and ``f_q`` (n,) (the generalized force on q: minus the velocity,
    elastic and damping terms, plus the guide's).

    Returns
    -------
    M_ss (kg), F_s (N: the same on s, without the inertia M z''), dissipated power (W, >= 0 but for the
    guide's round-off), kinetic energy (J), strain energy (J), head velocity (m/s) and the axial force at the
    root, N_root = -(EA / lambda) (q.phi'(1) + tau r(1)) (N, tension positive: the physical strain is
    -dw/dxi, xi running from the head towards the wheel).
    """
    b = TAPE
    n = int(prm[b + MODES])
    mu, ea, tau, m = prm[b + MU], prm[b + EA], prm[b + TAU], prm[b + HEAD]
    p, h, d1, dd1 = _vec(prm, 0, n), _vec(prm, 1, n), _vec(prm, 2, n), _vec(prm, 3, n)
    mp, ms, mb, mc, mg, mh = _mat(prm, 0, n), _mat(prm, 1, n), _mat(prm, 2, n), _mat(prm, 3, n), _mat(prm, 4, n), \
        _mat(prm, 5, n)  # fmt: skip
    pq = pqd = hqd = d1q = d1qd = dd1q = 0.0
    for i in range(n):
        pq += p[i] * q[i]
        pqd += p[i] * qd[i]
        hqd += h[i] * qd[i]
        d1q += d1[i] * q[i]
        d1qd += d1[i] * qd[i]
        dd1q += dd1[i] * q[i]
    qcq = qsq = qhq = qdgq = qdsqd = cq_qd = 0.0
    for i in range(n):
        cq = sq = bq = bqd = gq = 0.0
        for j in range(n):
            cq += mc[i, j] * q[j]
            sq += ms[i, j] * q[j]
            bq += mb[i, j] * q[j]
            bqd += mb[i, j] * qd[j]
            gq += mg[i, j] * q[j]
            qhq += q[i] * mh[i, j] * q[j]
            qdsqd += qd[i] * ms[i, j] * qd[j]
            m_qq[i, j] = mu * lam * mp[i, j] + m * h[i] * h[j]
        qcq += q[i] * cq
        qsq += q[i] * sq
        qdgq += qd[i] * gq
        cq_qd += cq * qd[i]
        m_sq[i] = mu * lam * p[i] + m * h[i] - mu * bq
        # -(g_q + dV/dq + dR/dq'): dR/dq' = EA tau / lam (S q' - (s'/lam) G q); S q' is formed below.
        f_q[i] = mu * sd * (2.0 * bqd + sd * cq / lam) - ea / lam * sq + ea * tau * sd / (lam * lam) * gq
    for i in range(n):
        sqd = 0.0
        for j in range(n):
            sqd += ms[i, j] * qd[j]
        f_q[i] -= ea * tau / lam * sqd
    m_ss = m + mu * prm[b + LENGTH] + 2.0 * mu * pq + mu * qcq / lam
    g_s = -0.5 * mu * qcq * sd * sd / (lam * lam) + 2.0 * mu * sd * pqd + 2.0 * mu * sd * cq_qd / lam
    dv_s = -0.5 * ea * qsq / (lam * lam)
    dr_s = -ea * tau / (lam * lam) * (qdgq - sd / lam * qhq)
    f_s = -(g_s + dv_s + dr_s)
    # Rayleigh: 2 R = EA tau / lam int r^2, r = q'.phi' - (s'/lam) q.D.
    dissipated = ea * tau / lam * (qdsqd - 2.0 * sd / lam * qdgq + (sd / lam) ** 2 * qhq)
    head_v = sd + hqd
    mu_g = prm[b + GUIDE_MU]
    if mu_g > 0.0:
        weight = mu_g * prm[b + GUIDE_G]
        f_head = -weight * m * math.tanh(head_v / V_GUIDE)
        f_tape = -weight * mu * math.tanh(sd / V_GUIDE)  # per length, along the free length
        # Virtual work: head at s + h.q; a free material point moves by ds (1 - eta w'/lam) + phi.dq, and
        # int (1 - eta w'/lam) d xi = lam + p.q (int eta phi' = -p).
        f_s += f_head + f_tape * (lam + pq)
        for i in range(n):
            f_q[i] += f_head * h[i] + f_tape * lam * p[i]
        dissipated -= f_head * head_v + f_tape * ((lam + pq) * sd + lam * pqd)
    kinetic = 0.0
    for i in range(n):
        for j in range(n):
            kinetic += qd[i] * m_qq[i, j] * qd[j]
        kinetic += 2.0 * sd * m_sq[i] * qd[i]
    kinetic = 0.5 * (kinetic + m_ss * sd * sd)
    strain = 0.5 * ea / lam * qsq
    root = -ea / lam * (d1q + tau * (d1qd - sd / lam * dd1q))
    return m_ss, f_s, dissipated, kinetic, strain, head_v, root


@njit(cache=True, error_model="numpy")
def chain_state(prm: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The clearance chain's state [a, psi, a', psi', W3, D] inside the tape's state (module docstring)."""
    n = int(prm[TAPE + MODES])
    out = np.empty(6)
    out[0], out[1], out[2], out[3] = y[0], y[1], y[n + 2], y[n + 3]
    out[4], out[5] = y[2 * n + 4], y[2 * n + 5]
    return out


@njit(cache=True, error_model="numpy")
def chain_tape(prm: np.ndarray, t: float, y: np.ndarray, contact: bool, impact_velocity: float,
               out: np.ndarray) -> tuple[float, ...]:
    """y' of the clearance chain with the flexible tape into ``out`` (2 n + 6,; state in the module docstring).

    The chain of :func:`weftsim.physics.chain.chain` (its M11 holds no rapier mass: the tape and head are
    here) gives its generalized forces Q = M2 a_2 (M2 its 2 x 2 mass matrix, a_2 its accelerations without
    the tape); the coupled accelerations solve

        [[M11 + R^2 M_ss, M12, R M_sq^T], [M12, M22, 0], [R M_sq, 0, M_qq]] (a'', psi'', q'')
            = (Q_a + R F_s, Q_psi, F_q).

    Returns
    -------
    q3 (N m), F_N (N), delta (m), then sin a, cos a, sin psi, cos psi (of the chain), the axial force at the
    root (N, tension positive), the head's velocity (m/s) and acceleration (m/s^2), the free length (m), the
    tape's kinetic and strain energy (J), the wheel's s'' (m/s^2) and the tape's dissipated power (W).
    """
    n = int(prm[TAPE + MODES])
    ratio = prm[TAPE + RATIO]
    y6 = chain_state(prm, y)
    d6 = np.empty(6)
    res = kc.chain(prm[:kc.WEAR_E], t, y6, contact, impact_velocity, d6)  # the chain's blocks: a round E
    q3, f_n, delta = res[0], res[1], res[2]
    sa, ca, sp, cp = res[5], res[6], res[7], res[8]
    m11, m22 = prm[kc.M11], prm[kc.M22]
    m12 = -prm[kc.COUPLING] * (cp * ca + sp * sa)
    q_a = m11 * d6[2] + m12 * d6[3]
    q_psi = m12 * d6[2] + m22 * d6[3]
    q = y[2:2 + n]
    qd = y[n + 4:2 * n + 4]
    lam = free_length(prm, y[0])
    sd = ratio * y6[2]
    m_sq = np.empty(n)
    m_qq = np.empty((n, n))
    f_q = np.empty(n)
    m_ss, f_s, dissipated, kinetic, strain, head_v, root = tape_terms(prm, lam, sd, q, qd, m_sq, m_qq, f_q)
    size = n + 2
    a = np.zeros((size, size))
    acc = np.empty(size)
    a[0, 0] = m11 + ratio * ratio * m_ss
    a[0, 1] = a[1, 0] = m12
    a[1, 1] = m22
    acc[0] = q_a + ratio * f_s
    acc[1] = q_psi
    for i in range(n):
        a[0, 2 + i] = a[2 + i, 0] = ratio * m_sq[i]
        for j in range(n):
            a[2 + i, 2 + j] = m_qq[i, j]
        acc[2 + i] = f_q[i]
    acc[:] = np.linalg.solve(a, acc)
    h = _vec(prm, 1, n)
    hqdd = 0.0
    out[0], out[1] = y6[2], y6[3]
    out[n + 2], out[n + 3] = acc[0], acc[1]
    for i in range(n):
        out[2 + i] = qd[i]
        out[n + 4 + i] = acc[2 + i]
        hqdd += h[i] * acc[2 + i]
    out[2 * n + 4] = d6[4]
    out[2 * n + 5] = d6[5] + dissipated
    sdd = ratio * acc[0]
    return q3, f_n, delta, sa, ca, sp, cp, root, head_v, sdd + hqdd, lam, kinetic, strain, sdd, dissipated


@njit(cache=True, error_model="numpy")
def driven_tape(prm: np.ndarray, s: float, sd: float, sdd: float, q: np.ndarray, qd: np.ndarray,
                qdd: np.ndarray) -> tuple[float, ...]:
    """q'' of the tape with the wheel's motion prescribed (s, s', s'' in m, m/s, m/s^2) into ``qdd``.

    M_qq q'' = F_q - M_sq s'' (the q rows of :func:`chain_tape` with s'' given).  Returns the force the tape
    and head put on the wheel along s (N; the rigid rapier's -m8 s''), the root's axial force (N, tension
    positive), the head's velocity (m/s) and acceleration (m/s^2), the tape's kinetic and strain energy (J)
    and its dissipated power (W).  The wheel's power on the tape is -(force on the wheel) s'.
    """
    n = int(prm[TAPE + MODES])
    lam = prm[TAPE + FREE0] + s
    m_sq = np.empty(n)
    m_qq = np.empty((n, n))
    f_q = np.empty(n)
    m_ss, f_s, dissipated, kinetic, strain, head_v, root = tape_terms(prm, lam, sd, q, qd, m_sq, m_qq, f_q)
    rhs = np.empty(n)
    for i in range(n):
        rhs[i] = f_q[i] - m_sq[i] * sdd
    qdd[:] = np.linalg.solve(m_qq, rhs)
    h = _vec(prm, 1, n)
    wheel = f_s - m_ss * sdd
    head_a = sdd
    for i in range(n):
        wheel -= m_sq[i] * qdd[i]
        head_a += h[i] * qdd[i]
    return wheel, root, head_v, head_a, kinetic, strain, dissipated
