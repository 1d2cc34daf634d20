"""Archard wear of one run at joint E, from the run's accepted steps (docs/wear.md section 1).

At every step row the kernel gives the normal force F_N, the sliding velocity v_T of the contact
points (:func:`weftsim.kernel.joint.tangential_velocity`: the journal's rotation relative to the
bearing plus the tangential eccentricity rate), the contact direction in the bearing's and in the
journal's frame and the contact half-angle.  The sliding work integral W = int F_N |v_T| dt is
taken with the trapezoidal weights of the rows (:func:`weftsim.analysis.time_weights`), so each row
i carries dW_i = F_N,i |v_T,i| w_i; each surface of hardness H loses dV = (k / H) dW_i, spread over
the contact arc (:func:`weftsim.kernel.wear.deposit`).  The worn depth of a profile cell is its
volume over the cell's area L_b R dpsi (R = R_b for the bearing, R_j for the journal).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from weftsim.analysis import time_weights
from weftsim.kernel.chain import BEARING_RADIUS, OMEGA, chain, eccentricity, local_clearance, rocker_angle
from weftsim.kernel.asperity import asperity_half_angle, asperity_load
from weftsim.kernel.joint import ASPERITY_COEF, BEARING_LENGTH, JOURNAL_RADIUS, ROUGHNESS, tangential_velocity
from weftsim.kernel.lubricated import is_lubricated
from weftsim.kernel.wear import contact_half_angle, deposit

if TYPE_CHECKING:
    from weftsim.params import ClearanceJoint, Scene


@njit(cache=True, error_model="numpy")
def contact_rows(prm: np.ndarray, time: np.ndarray, states: np.ndarray, contact: np.ndarray, impact: np.ndarray,
                 out: np.ndarray) -> None:
    """Per step row into ``out`` (n, 5): F_N (N), v_T (m/s), psi_b, psi_j (rad), phi0 (rad).

    A lubricated joint: F_N is the load the solids carry, the asperity load F_a plus the dry law's beyond
    e = c, never the film's (no wear under a full film: F_a = 0 while h_min >= 4 sigma); phi0 then covers
    the asperity arc too (:func:`weftsim.kernel.asperity.asperity_half_angle`).

    ``psi_b``, ``psi_j``: the contact direction n in the bearing's (rocker) and the journal's (rod)
    frame; ``phi0``: half the contact arc (:func:`weftsim.kernel.wear.contact_half_angle`).  Rows
    out of contact have F_N = 0.  The dry law's F_N is the reference kernel's (:func:`weftsim.kernel.chain.chain`
    with the run's modes and held impact velocities); the rest is :func:`rows_from_contact`.
    """
    d = np.empty(6)
    f_dry = np.zeros(time.size)
    for i in range(time.size):
        f_dry[i] = chain(prm, time[i], states[i], contact[i], impact[i], d)[1]
    rows_from_contact(prm, time, states, f_dry, np.full(time.size, np.nan), out)


@njit(cache=True, error_model="numpy")
def rows_from_contact(prm: np.ndarray, time: np.ndarray, states: np.ndarray, f_dry: np.ndarray, v_t: np.ndarray,
                      out: np.ndarray) -> None:
    """:func:`contact_rows` from an engine's own contact channels: the dry law's normal force ``f_dry`` (n,) N
    and the sliding velocity ``v_t`` (n,) m/s at the states (n, >= 4: a, psi, a', psi') and times given.
    A NaN in ``v_t`` (a row where the engine applied no dry contact, e.g. the asperities of a lubricated joint
    alone): the contact points' sliding velocity at the state (:func:`weftsim.kernel.joint.tangential_velocity`).

    The contact angles, the arc and, for a lubricated joint, the asperity load come from the state at the
    local clearance (:func:`weftsim.kernel.chain.local_clearance`): every engine's run goes through the
    same Archard rows (the Exudyn engine's kinematic tree: :mod:`weftsim.wear.engines`).
    """
    for i in range(time.size):
        t = time[i]
        y = states[i]
        f_n = f_dry[i]
        ecc_y, ecc_z, v_y, v_z, _, _, dphi = eccentricity(prm, t, y)[:7]
        length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
        out[i, :] = 0.0
        c = local_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y)[0]
        half_angle = contact_half_angle(c, length - c)
        if is_lubricated(prm) and length > 0.0:
            # Mixed lubrication: the solids touch only through the asperities (and the dry law beyond e = c);
            # the film's load wears nothing.  The arc is where the asperities touch, h < 4 sigma.
            f_a = asperity_load(prm[ASPERITY_COEF], prm[ROUGHNESS], c, length, prm[JOURNAL_RADIUS],
                                prm[BEARING_LENGTH])[0]  # fmt: skip
            if f_a > 0.0:
                f_n += f_a
                half_angle = max(half_angle, asperity_half_angle(prm[ROUGHNESS], c, length))
        if f_n > 0.0 and length > 0.0:
            direction = math.atan2(ecc_z, ecc_y)
            out[i, 0] = f_n
            v = v_t[i]
            if v != v:  # NaN: from the state
                v = tangential_velocity(ecc_y, ecc_z, v_y, v_z, length, y[3], prm[OMEGA] * dphi, prm[BEARING_RADIUS])
            out[i, 1] = v
            out[i, 2] = direction - rocker_angle(prm, t)
            out[i, 3] = direction - y[1]
            out[i, 4] = half_angle


@njit(cache=True, error_model="numpy")
def deposit_rows(rows: np.ndarray, work: np.ndarray, depth_b: float, depth_j: float, bearing: np.ndarray,
                 journal: np.ndarray) -> None:
    """Add each row's worn depth (``work`` (n,) times ``depth_b`` or ``depth_j``, m/J) to the profiles."""
    for i in range(work.size):
        if work[i] > 0.0:
            deposit(bearing, rows[i, 2], rows[i, 4], work[i] * depth_b)
            deposit(journal, rows[i, 3], rows[i, 4], work[i] * depth_j)


@dataclass(frozen=True)
class RunWear:
    """Wear of one run's window: depth profiles (m) and volumes (m^3) of bearing and journal.

    ``sliding_work`` = int F_N |v_T| dt (J); ``bearing_volume`` = (k / H_b) sliding_work and
    ``journal_volume`` = (k / H_j) sliding_work exactly; the profiles hold the same volumes
    (sum(h) L_b R dpsi) to round-off.
    """

    bearing: np.ndarray
    journal: np.ndarray
    bearing_volume: float
    journal_volume: float
    sliding_work: float
    sliding_distance: float  # int |v_T| dt in contact, m


def wear_from_rows(joint: ClearanceJoint, time: np.ndarray, rows: np.ndarray) -> RunWear:
    """Archard wear of contact rows (``rows`` (n, 5) as :func:`contact_rows` fills them) at times ``time`` (s).

    ``joint``: the :class:`~weftsim.params.ClearanceJoint` (radii, length, ``wear``).
    """
    wear = joint.wear
    weights = time_weights(time) if time.size > 1 else np.zeros(time.size)
    work = rows[:, 0] * np.abs(rows[:, 1]) * weights
    n = wear.profile_points
    cell = 2.0 * math.pi / n
    k_b = wear.wear_coefficient / wear.bearing_hardness
    k_j = wear.wear_coefficient / wear.journal_hardness
    bearing, journal = np.zeros(n), np.zeros(n)
    deposit_rows(np.ascontiguousarray(rows, dtype=float), work,
                 k_b / (joint.bearing_length * joint.bearing_radius * cell),
                 k_j / (joint.bearing_length * joint.journal_radius * cell), bearing, journal)  # fmt: skip
    total = float(work.sum())
    sliding = float(np.sum(np.abs(rows[:, 1]) * weights * (rows[:, 0] > 0.0)))
    return RunWear(bearing, journal, k_b * total, k_j * total, total, sliding)


def run_wear(scene: Scene, prm: np.ndarray, time: np.ndarray, states: np.ndarray, contact: np.ndarray,
             impact: np.ndarray) -> RunWear:
    """Archard wear over the given step rows (times (n,) s, states (n, 6), modes, held impact velocities).

    ``prm``: the kernel parameter array of ``scene`` (:func:`weftsim.reference.dynamics.pack_parameters`).
    """
    time = np.ascontiguousarray(time, dtype=float)
    rows = np.zeros((time.size, 5))
    contact_rows(prm, time, np.ascontiguousarray(states, dtype=float).reshape(time.size, 6),
                 np.asarray(contact, dtype=np.bool_), np.asarray(impact, dtype=float), rows)
    return wear_from_rows(scene.joint, time, rows)
