"""Archard wear of one run at a clearance joint (E or F), from the run's accepted steps (docs/wear.md section 1).

At every step row the kernel gives the normal force F_N, the sliding velocity v_T of the contact
points (:func:`weftsim.physics.joint.tangential_velocity`: the journal's rotation relative to the
bearing plus the tangential eccentricity rate), the contact direction in the bearing's and in the
journal's frame and the contact half-angle.  The sliding work integral W = int F_N |v_T| dt is
taken with the trapezoidal weights of the rows (:func:`weftsim.post.analysis.time_weights`), so each row
i carries dW_i = F_N,i |v_T,i| w_i; each surface of hardness H loses dV = (k / H) dW_i, spread over
the contact arc (:func:`weftsim.physics.wear.deposit`).  The worn depth of a profile cell is its
volume over the cell's area L_b R dpsi (R = R_b for the bearing, R_j for the journal).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from weftsim.post.analysis import time_weights
from weftsim.physics import chain_f as kf
from weftsim.physics.chain import BEARING_RADIUS, OMEGA, chain, eccentricity, local_clearance, rocker_angle
from weftsim.physics.asperity import asperity_half_angle, asperity_load
from weftsim.physics.joint import (
    ASPERITY_COEF, BEARING_LENGTH, JOURNAL_RADIUS, N_JOINT, ROUGHNESS, tangential_velocity,
)  # fmt: skip
from weftsim.physics.lubricated import is_lubricated
from weftsim.physics.wear import contact_half_angle, deposit

if TYPE_CHECKING:
    from weftsim.input.params import ClearanceJoint, Scene


@njit(cache=True, error_model="numpy")
def contact_rows(prm: np.ndarray, time: np.ndarray, states: np.ndarray, contact: np.ndarray, impact: np.ndarray,
                 out: np.ndarray) -> None:
    """Per step row into ``out`` (n, 5): F_N (N), v_T (m/s), psi_b, psi_j (rad), phi0 (rad).

    A lubricated joint: F_N is the load the solids carry, the asperity load F_a plus the dry law's beyond
    e = c, never the film's (no wear under a full film: F_a = 0 while h_min >= 4 sigma); phi0 then covers
    the asperity arc too (:func:`weftsim.physics.asperity.asperity_half_angle`).

    ``psi_b``, ``psi_j``: the contact direction n in the bearing's (rocker) and the journal's (rod)
    frame; ``phi0``: half the contact arc (:func:`weftsim.physics.wear.contact_half_angle`).  Rows
    out of contact have F_N = 0.
    """
    d = np.empty(6)
    for i in range(time.size):
        t = time[i]
        y = states[i]
        f_n = chain(prm, t, y, contact[i], impact[i], d)[1]
        ecc_y, ecc_z, v_y, v_z, _, _, dphi = eccentricity(prm, t, y)[:7]
        c = local_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y)[0]
        _row(prm, f_n, c, ecc_y, ecc_z, v_y, v_z, rocker_angle(prm, t), prm[OMEGA] * dphi, y[1], y[3], out[i])


@njit(cache=True, error_model="numpy")
def rows_from_contact(prm: np.ndarray, time: np.ndarray, states: np.ndarray, f_dry: np.ndarray, v_t: np.ndarray,
                      out: np.ndarray) -> None:
    """:func:`contact_rows` from an engine's own contact channels: the dry law's normal force ``f_dry`` (n,) N
    and the sliding velocity ``v_t`` (n,) m/s at the states (n, >= 4: a, psi, a', psi') and times given.

    The contact angles, the arc and, for a lubricated joint, the asperity load come from the state at the
    local clearance (:func:`_row`, as for the reference engine's rows), so every engine's run goes through
    the same Archard rows (the Exudyn engine's kinematic tree: :mod:`weftsim.wear.engines`).  A NaN in
    ``v_t`` (a row where the engine applied no dry contact, e.g. the asperities of a lubricated joint
    alone): the contact points' sliding velocity at the state, as :func:`_row` computes it.
    """
    for i in range(time.size):
        t = time[i]
        y = states[i]
        ecc_y, ecc_z, v_y, v_z, _, _, dphi = eccentricity(prm, t, y)[:7]
        c = local_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y)[0]
        _row(prm, f_dry[i], c, ecc_y, ecc_z, v_y, v_z, rocker_angle(prm, t), prm[OMEGA] * dphi, y[1], y[3], out[i])
        if out[i, 0] > 0.0 and v_t[i] == v_t[i]:
            out[i, 1] = v_t[i]


@njit(cache=True, error_model="numpy")
def _row(jp: np.ndarray, f_n: float, c: float, ecc_y: float, ecc_z: float, v_y: float, v_z: float, frame_b: float,
         w_b: float, frame_j: float, w_j: float, out: np.ndarray) -> None:
    """One row of :func:`contact_rows` into ``out`` (5,) for a joint (block ``jp``) with the contact force F_N
    of its law, the clearance c along e, and its bearing's and journal's frame angles and rates."""
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    out[:] = 0.0
    half_angle = contact_half_angle(c, length - c)
    if is_lubricated(jp) and length > 0.0:
        # Mixed lubrication: the solids touch only through the asperities (and the dry law beyond e = c);
        # the film's load wears nothing.  The arc is where the asperities touch, h < 4 sigma.
        f_a = asperity_load(jp[ASPERITY_COEF], jp[ROUGHNESS], c, length, jp[JOURNAL_RADIUS],
                            jp[BEARING_LENGTH])[0]  # fmt: skip
        if f_a > 0.0:
            f_n += f_a
            half_angle = max(half_angle, asperity_half_angle(jp[ROUGHNESS], c, length))
    if f_n > 0.0 and length > 0.0:
        direction = math.atan2(ecc_z, ecc_y)
        out[0] = f_n
        out[1] = tangential_velocity(ecc_y, ecc_z, v_y, v_z, length, w_j, w_b, jp[BEARING_RADIUS])
        out[2] = direction - frame_b
        out[3] = direction - frame_j
        out[4] = half_angle


@njit(cache=True, error_model="numpy")
def contact_rows_f(prm: np.ndarray, time: np.ndarray, states: np.ndarray, contact: np.ndarray, impact: np.ndarray,
                   joint: int, out: np.ndarray) -> None:
    """:func:`contact_rows` of ``joint`` (0 = E, 1 = F) in the chains with clearance at F
    (:mod:`weftsim.physics.chain_f`: ``states`` (n, 6) or (n, 10), ``contact`` the joints' mask,
    ``impact`` (n, 2)).

    Frames as the kernel reads the worn tables (:func:`weftsim.physics.chain_f.local_clearances`): at E
    the rocker (bearing) and the rod (journal); at F the sector's eye (bearing, angle a = theta_FG) and
    the rod's pin (journal, psi).
    """
    d = np.empty(states.shape[1])
    both = prm[kf.TOPOLOGY] == kf.E_AND_F
    for i in range(time.size):
        t = time[i]
        y = states[i]
        r = kf.chain_f(prm, t, y, contact[i], impact[i], d)
        q = kf.eccentricities(prm, t, y)
        c_e, _, c_f, _ = kf.local_clearances(prm, t, y, q)
        psi = y[3] if both else y[1]
        if joint == kf.JOINT_E_INDEX:
            _row(prm[:N_JOINT], r[1], c_e, q[0], q[1], q[2], q[3], rocker_angle(prm, t), q[8], psi, q[9], out[i])
        else:
            _row(prm[kf.JOINT_F:kf.JOINT_F + N_JOINT], r[5], c_f, q[4], q[5], q[6], q[7], y[0], q[10], psi, q[9],
                 out[i])  # fmt: skip


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
    joint: str = "e"  # the joint worn ("e" or "f")
    second: RunWear | None = None  # joint F's wear when E and F wear in the same run


def wear_from_rows(joint: ClearanceJoint, time: np.ndarray, rows: np.ndarray) -> RunWear:
    """Archard wear of contact rows (``rows`` (n, 5) as :func:`contact_rows` fills them) at times ``time`` (s).

    ``joint``: the :class:`~weftsim.input.params.ClearanceJoint` (radii, length, ``wear``).
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
             impact: np.ndarray, joint: str = "e") -> RunWear:
    """Archard wear of ``joint`` ("e" or "f") over the given step rows (times (n,) s, states, contact
    modes, held impact velocities: as :func:`weftsim.reference.solve` gives them to ``observe``).

    ``prm``: the kernel parameter array of ``scene`` (:func:`weftsim.model.dynamics.pack_parameters`).
    With E alone loose, the rows of :func:`contact_rows` (states (n, 6)); with a clearance at F, those of
    :func:`contact_rows_f` for the joint asked for.
    """
    time = np.ascontiguousarray(time, dtype=float)
    rows = np.zeros((time.size, 5))
    if scene.joint_f.is_ideal:
        if joint != "e":
            raise ValueError(f"joint {joint!r} has no clearance in this scene")
        contact_rows(prm, time, np.ascontiguousarray(states, dtype=float).reshape(time.size, 6),
                     np.asarray(contact, dtype=np.bool_), np.asarray(impact, dtype=float), rows)
        return wear_from_rows(scene.joint, time, rows)
    states = np.ascontiguousarray(states, dtype=float).reshape(time.size, -1)
    contact_rows_f(prm, time, states, np.asarray(contact, dtype=np.int64),
                   np.ascontiguousarray(impact, dtype=float).reshape(time.size, 2),
                   kf.JOINT_E_INDEX if joint == "e" else kf.JOINT_F_INDEX, rows)
    return wear_from_rows(scene.joint if joint == "e" else scene.joint_f, time, rows)
