"""Output channels of a clearance-mode run, evaluated from the integrated states.

Everything is recomputed with the array backend of the same kernel that was integrated
(:func:`weftsim.reference.dynamics.chain_dynamics`), so the rapier acceleration is the
equation of motion's a'' (not a finite difference) and the contact force is the one the
solver saw.

Energy channels (SPEC.md section 4, COMMON interface)::

    kinetic   = 1/2 J13(theta) omega^2 + 1/2 q'^T M(q) q'
    potential = U13(theta) + m4 g z4
    contact   = integral_0^delta F_el  (0 when delta <= 0)
    driving work W = integral T omega dt = [1/2 J13 omega^2 + U13]_0^t + W3(t)
    dissipated = D(t)

with W3 = integral -Q3 omega dt and D = integral (F_N - F_el) delta_dot - F_T v_T dt the
two integrated states.  The closed form of the crank-side part is exact at constant omega
because T omega = d/dt(1/2 J13 omega^2 + U13) - Q3 omega.
"""

from __future__ import annotations

import numpy as np

from weftsim.contact import make_law
from weftsim.params import Scene
from weftsim.reference.dynamics import (
    ChainConstants,
    chain_dynamics,
    chain_energy,
    eccentricity,
    initial_state,
    numpy_backend,
)
from weftsim.reference.ideal import crank_side_inertia, crank_side_potential


def clearance_channels(scene: Scene, time, states, contact, impact) -> dict[str, np.ndarray]:
    """All :data:`weftsim.results.CHANNELS` at the given times.

    Parameters
    ----------
    scene : Scene
    time : (N,) s
    states : (N, 6) [a, psi, a', psi', W3, D]
    contact : (N,) bool, the segment's mode (contact force evaluated or not)
    impact : (N,) m/s, held, floored impact velocity of the segment (ignored in free flight)

    Returns
    -------
    dict of str to (N,) ndarray
        ``penetration_m`` is delta = |e| - c, negative in free flight (SPEC.md 4);
        ``in_contact`` is 1 where delta > 0 in a contact segment, else 0;
        ``impact_velocity_m_s`` is the held value in contact segments, 0 in free flight;
        ``penetration_rate_m_s`` is delta_dot = e_dot . n in both modes (the plausibility
        checks read the approach rate at each onset from it).
    """
    time = np.asarray(time, dtype=float)
    states = np.asarray(states, dtype=float).reshape(len(time), 6)
    contact = np.asarray(contact, dtype=bool)
    impact = np.asarray(impact, dtype=float)
    p = ChainConstants.from_scene(scene)
    law = make_law(scene.joint)
    backend = numpy_backend(law, scene.joint)
    omega = p.omega
    a, psi, da, dpsi, w3, dissipated = states.T

    n_out = 14
    out = [np.zeros_like(time) for _ in range(n_out)]
    for mode in (False, True):
        idx = np.flatnonzero(contact == mode)
        if idx.size == 0:
            continue
        values = chain_dynamics(backend, p, time[idx], a[idx], psi[idx], da[idx], dpsi[idx], mode, impact[idx])
        for k in range(n_out):
            out[k][idx] = values[k]
    dd_a, _, _, _, f_n, _, delta, _, ecc_y, ecc_z, _, _, _, q3 = out
    # chain_dynamics gives delta_dot only in contact: the geometric rate holds in both modes.
    _, _, v_y, v_z, *_ = eccentricity(backend, p, time, a, psi, da, dpsi)
    length = np.hypot(ecc_y, ecc_z)
    rate = np.where(length > 0.0, (ecc_y * v_y + ecc_z * v_z) / np.where(length > 0.0, length, 1.0), 0.0)

    theta = omega * time
    j13, dj13 = crank_side_inertia(theta, scene)
    u13, du13 = crank_side_potential(theta, scene)
    j13_0, _ = crank_side_inertia(0.0, scene)
    u13_0, _ = crank_side_potential(0.0, scene)
    kin48, pot48 = chain_energy(p, a, psi, da, dpsi)
    kin13 = 0.5 * j13 * omega**2
    ratio = scene.geometry.rapier_ratio
    a0 = initial_state(scene)[0]  # the rapier displacement's zero, theta_FG(0)
    in_contact = contact & (delta > 0.0)
    return {
        "time_s": time,
        "crank_angle_deg": np.degrees(theta),
        "rapier_displacement_m": ratio * (a - a0),
        "rapier_velocity_m_s": ratio * da,
        "rapier_acceleration_m_s2": ratio * dd_a,
        "driving_torque_Nm": 0.5 * dj13 * omega**2 + du13 - q3,
        "contact_force_N": f_n,
        "penetration_m": delta,
        "eccentricity_y_m": ecc_y,
        "eccentricity_z_m": ecc_z,
        "impact_velocity_m_s": np.where(contact, impact, 0.0),
        "in_contact": in_contact.astype(float),
        "kinetic_energy_J": kin13 + kin48,
        "potential_energy_J": u13 + pot48,
        "contact_energy_J": np.where(delta > 0.0, law.elastic_energy(delta), 0.0),
        "driving_work_J": kin13 + u13 - (0.5 * float(j13_0) * omega**2 + float(u13_0)) + w3,
        "dissipated_energy_J": dissipated,
        "penetration_rate_m_s": rate,
    }

