"""The lubricated joint as a steadily loaded plain bearing: the kernel's forces at one eccentricity.

A journal spinning at omega_j in a still bearing, its centre held at e = (abs(e), 0) (along +y of the joint's
plane), e_dot = 0.  The force of the joint on the journal is the sum the transient engines integrate
(:func:`weftsim.physics.lubricated.lubricated_force`: the film with its floor, the asperities and their
boundary friction) and, beyond abs(e) = c, the dry law with its friction
(:func:`weftsim.physics.joint.clearance_force_at`, at zero penetration rate: its elastic part).  A steady load W
on the journal is carried where that force balances it, abs(f) = W (:mod:`weftsim.joint.steady`).

In steady motion the power the drive puts into the journal, -M_j omega_j, is what the joint dissipates
(film shear and the boundary and dry friction; the asperities' and the dry law's normal forces do no work at
e_dot = 0): the friction torque on the journal is -M_j, its friction coefficient -M_j / (W R_j).
"""

from __future__ import annotations

from numba import njit

from weftsim.physics.joint import BEARING_RADIUS, V_MIN, clearance_force_at, tangential_velocity
from weftsim.physics.lubricated import L_ASPERITY, L_FILM, L_FX, L_FY, L_MJ, lubricated_force


@njit(cache=True, error_model="numpy")
def steady_force(prm, clearance: float, ecc: float, omega_j: float) -> tuple[float, float, float, float, float,
                                                                              float]:
    """(f_y, f_z, M_j, abs(f_film), F_a, F_N): the joint's force on the journal (N) and its moment about the journal
    centre (N m) at eccentricity (``ecc``, 0), journal spin ``omega_j`` (rad/s), still bearing; the film force's
    magnitude, the asperity load and the dry law's normal force (N).  ``prm``: the joint block
    (:func:`weftsim.physics.joint.joint_parameters`), ``clearance`` the radial clearance (m)."""
    lub = lubricated_force(prm, clearance, ecc, 0.0, 0.0, 0.0, omega_j, 0.0)
    fy, fz, m_j = lub[L_FX], lub[L_FY], lub[L_MJ]
    f_n = 0.0
    if ecc > clearance:
        v_t = tangential_velocity(ecc, 0.0, 0.0, 0.0, ecc, omega_j, 0.0, prm[BEARING_RADIUS])
        dry = clearance_force_at(prm, clearance, 0.0, ecc, 0.0, 0.0, 0.0, v_t, prm[V_MIN])
        fy += dry[0]
        fz += dry[1]
        m_j += dry[6]
        f_n = dry[2]
    return fy, fz, m_j, lub[L_FILM], lub[L_ASPERITY], f_n
