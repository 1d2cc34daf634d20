"""The flexible rapier tape on the kinematic tree: the tape's variable-length Ritz bar as an Exudyn object.

The tree (:mod:`.tree`) of the scene's linkage with a rapier of mass 0 (:func:`weftsim.model.tape.massless_rapier`)
carries the wheel; the tape and head are an ``ObjectGenericODE2`` over two nodes, the tree's node (its first
coordinate is the wheel's angle a = theta_FG, its fourth the dissipated energy D of the power joints) and a
``NodeGenericODE2`` of the n Ritz coordinates q.  The object adds the tape's mass matrix and forces of
:func:`weftsim.physics.tape.tape_terms` (the one definition the reference engine integrates, docs/rapier-tape.md
section 1) in the coordinates (a, q), s = R (a - a0):

    M_aa = R^2 M_ss,  M_aq = R M_sq,  M_qq;    f_a = R F_s,  f_q,  f_D = the tape's dissipated power

so Exudyn assembles the same coupled system (a'', psi'', q'') as the kernel's
:func:`weftsim.physics.tape.chain_tape`, and the tape's force on the wheel enters the tree's equation for a:
the clearance joint feels the tape and the tape the joint's impacts.  The free length lambda = L0 + s changes
with the stroke inside these terms (the Ritz functions stretch with it); the head is the mass at eta = 0.

Why this formulation and not Exudyn's cable elements: the ALE cable (``ObjectALEANCFCable2D``) moves material
through a mesh fixed in space, while the head travels 1.24 m with its end; a fixed mesh of the whole tape would
need its clamp at a moving material point, which Exudyn's sliding joints leave free under the axial force
instead of imposing it (docs/rapier-tape.md section 6).  The ANCF cable checks the same bar at a fixed free
length (:mod:`.tape`).
"""

from __future__ import annotations

from dataclasses import dataclass

import exudyn as exu
import numpy as np
from exudyn.itemInterface import NodeGenericODE2, ObjectGenericODE2

from weftsim.input.params import Scene
from weftsim.model.dynamics import initial_state, pack_parameters
from weftsim.physics import tape as kt

# The tree node's coordinates with the power joints: a, psi + pi - a, W3, D.
_A, _D = 0, 3
TREE_COORDINATES = 4


@dataclass
class TapeObject:
    """Items of the tape on the tree: its node (the Ritz coordinates), its object and the kernel's parameters."""

    node: object
    item: object
    prm: np.ndarray
    modes: int
    a0: float  # theta_FG at s = 0, rad
    ratio: float  # R = ds/da, m/rad


def add_tape(mbs: exu.MainSystem, scene: Scene, tree_node) -> TapeObject:
    """Add the scene's tape and head to ``mbs`` on the tree node ``tree_node`` (built with ``powers=True``).

    The Ritz coordinates start as the reference engine's (:func:`weftsim.model.tape.flexible_initial_state`): the
    tape at rest on the wheel in equilibrium with its acceleration at t = 0.
    """
    prm = pack_parameters(scene)
    n = kt.modes(prm)
    y0 = initial_state(scene)  # [a, psi, q, a', psi', q', W3, D]
    ratio = float(prm[kt.TAPE + kt.RATIO])
    a0 = float(prm[kt.TAPE + kt.A0])
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=list(y0[2:2 + n]),
                                       initialCoordinates_t=list(y0[n + 4:2 * n + 4]), numberOfODE2Coordinates=n))
    size = TREE_COORDINATES + n
    m_sq, m_qq, f_q = np.empty(n), np.empty((n, n)), np.empty(n)
    mass = np.zeros((size, size))
    force = np.zeros(size)

    def terms(q, q_t):
        qq = np.asarray(q[TREE_COORDINATES:], dtype=float)
        qd = np.asarray(q_t[TREE_COORDINATES:], dtype=float)
        lam = prm[kt.TAPE + kt.FREE0] + ratio * (q[_A] - a0)
        return kt.tape_terms(prm, lam, ratio * q_t[_A], qq, qd, m_sq, m_qq, f_q)

    def mass_matrix(mbs_, t, item, q, q_t):
        m_ss = terms(q, q_t)[0]
        mass[_A, _A] = ratio * ratio * m_ss
        mass[_A, TREE_COORDINATES:] = mass[TREE_COORDINATES:, _A] = ratio * m_sq
        mass[TREE_COORDINATES:, TREE_COORDINATES:] = m_qq
        return mass

    def forces(mbs_, t, item, q, q_t):
        r = terms(q, q_t)
        force[_A] = ratio * r[1]
        force[_D] = r[2]
        force[TREE_COORDINATES:] = f_q
        return force

    item = mbs.AddObject(ObjectGenericODE2(nodeNumbers=[tree_node, node], massMatrixUserFunction=mass_matrix,
                                           forceUserFunction=forces))
    return TapeObject(node, item, prm, n, a0, ratio)


def tape_sensors(mbs: exu.MainSystem, tape: TapeObject, store: dict) -> dict:
    """Sensors of the Ritz coordinates, their rates and accelerations (keys ``tape_q``, ``tape_q_t``, ``tape_q_tt``)."""
    from exudyn.itemInterface import SensorNode

    ovt = exu.OutputVariableType
    return {f"tape_{name}": mbs.AddSensor(SensorNode(nodeNumber=tape.node, outputVariableType=kind, **store))
            for name, kind in (("q", ovt.Coordinates), ("q_t", ovt.Coordinates_t), ("q_tt", ovt.Coordinates_tt))}


def with_tape(steps: dict[str, np.ndarray], tape: TapeObject, scene: Scene, data: dict) -> dict[str, np.ndarray]:
    """The tree's channels ``steps`` (of the linkage with a massless rapier) with the tape's: its kinetic energy in
    ``kinetic_energy_J``, its strain energy in ``potential_energy_J`` (its damping is in the power joint's D
    already), and :data:`weftsim.post.results.TAPE_CHANNELS` from Exudyn's coordinates, rates and accelerations
    at the stored steps (the head's acceleration R a'' + h.q'', as the reference engine's channels
    :mod:`weftsim.reference.tape_channels` give it from its own state)."""
    from weftsim.model.tape import first_frequency, tape_of

    rows = len(steps["time_s"])
    q, q_t, q_tt = (np.asarray(data[k])[:rows, 1:] for k in ("tape_q", "tape_q_t", "tape_q_tt"))
    a_t, a_tt = np.asarray(data["q_t"])[:rows, 1 + _A], np.asarray(data["q_tt"])[:rows, 1 + _A]
    prm, n, ratio = tape.prm, tape.modes, tape.ratio
    h = prm[kt.TAPE + kt.N_SCALARS + n:kt.TAPE + kt.N_SCALARS + 2 * n]
    head = prm[kt.TAPE + kt.HEAD]
    guide = prm[kt.TAPE + kt.GUIDE_MU] * prm[kt.TAPE + kt.GUIDE_G] * head
    lam = prm[kt.TAPE + kt.FREE0] + steps["rapier_displacement_m"]
    m_sq, m_qq, f_q = np.empty(n), np.empty((n, n)), np.empty(n)
    kinetic, strain, root = np.empty(rows), np.empty(rows), np.empty(rows)
    for i in range(rows):
        r = kt.tape_terms(prm, float(lam[i]), ratio * float(a_t[i]), np.ascontiguousarray(q[i]),
                          np.ascontiguousarray(q_t[i]), m_sq, m_qq, f_q)
        kinetic[i], strain[i], root[i] = r[3], r[4], r[6]
    head_v = ratio * a_t + q_t @ h
    head_a = ratio * a_tt + q_tt @ h
    return steps | {
        "kinetic_energy_J": steps["kinetic_energy_J"] + kinetic,
        "potential_energy_J": steps["potential_energy_J"] + strain,
        "head_displacement_m": steps["rapier_displacement_m"] + q @ h,
        "head_velocity_m_s": head_v,
        "head_acceleration_m_s2": head_a,
        "tape_force_wheel_N": root,
        # Newton on the head: m a_head = (compression at the head) + guide friction.
        "tape_force_head_N": -head * head_a - guide * np.tanh(head_v / kt.V_GUIDE),
        "tape_free_length_m": lam,
        "tape_frequency_hz": first_frequency(tape_of(scene), lam),
        "tape_strain_energy_J": strain,
    }
