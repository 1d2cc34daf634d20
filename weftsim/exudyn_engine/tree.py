"""Kinematic-tree model of the loom: only the free members in minimal coordinates, explicit solver.

With members 1-3 ideal and rigid, their motion is known in closed form from the crank
angle theta = omega t (docs/physics.md section 1); only the chain 4-8 behind the clearance joint
moves freely.  This model integrates that chain alone, as an ``ObjectKinematicTree`` with
two revolute joints about Exudyn Z (the four-bar plane is Exudyn's XY plane, as in
:mod:`.mechanism`)::

    base at G = (L_OG, 0)
    joint 0 (RevoluteZ)  q0 = a = theta_FG    link 0: sector 5 with gears 6/7 and rapier 8
                                              reflected (J_FG about G, balanced)
    joint 1 (RevoluteZ)  at F = G + L_FG u(q0)
                         q1 = psi + pi - a    link 1: rod 4, x axis from F to the journal,
                                              centre of mass at L_EF/2, journal at L_EF

(psi = theta_EF of :mod:`weftsim.model.dynamics`: P_j = F - L_EF u(psi)).  The bearing
centre P_b(t) = E of the prescribed rocker is not a body.  The contact enters as the tree's
generalized force (``forceUserFunction``, :func:`weftsim.exudyn_engine.callbacks.make_tree_force`
over the kernel's :func:`weftsim.physics.chain.tree_joint_force`): the callback computes the
journal centre and its velocity from the joint coordinates, subtracts P_b(t) and its velocity
(closed form),

    e = P_j - P_b(t),   e_dot = v_j - V_b(t),

applies the same law, onset interpolation and held impact velocity rule
(``joint.impact_velocity_rule``) as every other route, adds the modified Coulomb friction at the
contact point when ``joint.friction_coefficient`` > 0 (its tangential velocity from the rod's and the
rocker's rotation rates, its moments about both centres), and returns the joint torques of the
contact force and moment by virtual work.  No constraints remain, so an error-controlled
explicit solver (DOPRI5 with automatic step size) integrates it; there is no Jacobian and no
Newton iteration.  With friction the friction ramp makes it stiff, and generalized-alpha with an
error-controlled step integrates it instead (:mod:`.tree_implicit`).

The driving torque comes from the contact force in closed form, with the crank-side
terms of :mod:`weftsim.model.ideal` (docs/physics.md section 4, docs/reference-solver.md):

    T = 1/2 J13'(theta) omega^2 + U13'(theta) - Q3,   Q3 = F_b . dP_b/dtheta + M_b phi'(theta)

(F_b = F_N n - F_T t, the force on the bearing, and M_b = -R_b F_T, its friction moment, recorded by
the callback at every accepted state).  The full rigid-body
model (:mod:`.mechanism`) stays the general path; ``tests/test_fast_paths.py`` checks the
two against each other.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree

from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.onset import OnsetTracker
from weftsim.input.params import Scene
from weftsim.model.dynamics import initial_state, pack_parameters
from weftsim.model.ideal import sector_chain_inertia

UNSPECIFIED_MASS = 1.0  # sector mass (balanced, on its fixed axis: no effect), kg
POWER_JOINTS = 2  # build_tree(powers=True): the integrators of W3 and D


def _matrices(items: list[np.ndarray]) -> exu.Matrix3DList:
    """``exu.Matrix3DList(items)``: 3x3 matrices for the kinematic tree."""
    return exu.Matrix3DList(items)  # type: ignore[call-arg]  # exudyn stub: no __init__ taking the list


def _vectors(items: list[list[float]]) -> exu.Vector3DList:
    """``exu.Vector3DList(items)``: 3-vectors for the kinematic tree."""
    return exu.Vector3DList(items)  # type: ignore[call-arg]  # exudyn stub: no __init__ taking the list


@dataclass
class TreeModel:
    """Items of the kinematic-tree model and the clearance bookkeeping."""

    scene: Scene
    node: object  # NodeGenericODE2 with q = [a, psi + pi - a]
    tree: object  # ObjectKinematicTree, contact through its forceUserFunction
    force: Callable[..., list[float]]  # the forceUserFunction (python or numba route)
    tracker: OnsetTracker
    route: str
    memory: list  # [v_held, delta0, rate0] read by the force callback
    # [t, (Q0, Q1, delta, delta_dot, F_b,x, F_b,y, F_N, M_b, F_T v_T, v_T, D'_lub, U_a, W3', D')] of the last callback
    stash: list
    callback_calls: list = field(default_factory=lambda: [0])  # [count]
    # [t, F_b,x, F_b,y, F_N, M_b, F_T v_T, D'_lub, U_a, v_T, W3', D'] per accepted state (tree_joint_force's joint
    # force on the bearing, the lubricated part's dissipated power, the asperity potential, the sliding velocity, the
    # drawn and the dissipated power)
    bearing_force: list = field(default_factory=list)

    def accept(self, mbs: exu.MainSystem, t: float) -> None:
        """Post-step bookkeeping: onset, held impact velocity, callback memory, force on the bearing."""
        if self.stash[0] != t:  # no evaluation at this state yet (the initial state)
            q = mbs.GetNodeOutput(self.node, exu.OutputVariableType.Coordinates)
            q_t = mbs.GetNodeOutput(self.node, exu.OutputVariableType.Coordinates_t)
            self.force(mbs, t, self.tree, q, q_t)
        state = self.stash[1][callbacks.STASH_DELTA:]  # what the kernel returned after the two joint forces
        delta, rate, fx, fy, f_n, m_b, power, v_t, lub_power, asperity_energy, drawn, dissipated = state
        tracker = self.tracker
        tracker.accept(t, delta, rate)
        self.memory[0], self.memory[1], self.memory[2] = tracker.held, delta, rate
        self.bearing_force.append((t, fx, fy, f_n, m_b, power, lub_power, asperity_energy, v_t, drawn, dissipated))


def build_tree(mbs: exu.MainSystem, scene: Scene, callback: str = "auto", powers: bool = False) -> TreeModel:
    """Add the kinematic tree of members 4-8, gravity and the clearance contact to ``mbs``.

    Initial state: the ideal mechanism at theta = 0, journal centred
    (:func:`weftsim.model.dynamics.initial_state`).  ``callback``: "auto" (:func:`weftsim.exudyn_engine.callbacks.resolve_route`),
    "python" or "numba"; both evaluate :func:`weftsim.physics.chain.tree_joint_force`.  Needs ``scene.joint.clearance > 0``;
    friction (``joint.friction_coefficient`` > 0) acts at the contact point with its moments on rod and rocker.

    ``powers``: two more joints (:data:`POWER_JOINTS`), prismatic along Exudyn Z on the base with a unit mass,
    so gravity (along -Y) and the rotating links do not couple to them and their accelerations are the
    callback's forces: the drawn power W3' = -Q3 omega and the dissipated power D'.  Their rates, q_t[2] = W3
    and q_t[3] = D, are then integrated by the solver with the motion, at its order and under its error control,
    as the reference engine integrates them (a quadrature over the steps afterwards left 1 J a revolution of the
    ~1000 J the contact moves in and out of the chain on the worn loom, c = 0.1 mm, 600 rpm).
    """
    g, m, joint = scene.geometry, scene.inertia, scene.joint
    a0, psi0, da0, dpsi0 = initial_state(scene)[:4]
    problem = callbacks.route_error(callback)
    if problem is not None:
        raise ValueError(problem)
    route = callbacks.resolve_route(callback)
    calls = [0]
    tracker = OnsetTracker(joint.clearance, joint.min_impact_velocity, rule=joint.impact_velocity_rule)
    memory = list(tracker.callback_state)
    stash = [math.nan, (0.0,) * 14]
    force = callbacks.make_tree_force(pack_parameters(scene), memory, stash, route, calls, powers)
    extra = POWER_JOINTS if powers else 0
    node = mbs.AddNode(NodeGenericODE2(
        referenceCoordinates=[0.0] * (2 + extra), initialCoordinates=[a0, psi0 + math.pi - a0] + [0.0] * extra,
        initialCoordinates_t=[da0, dpsi0 - da0] + [0.0] * extra, numberOfODE2Coordinates=2 + extra,
    ))  # fmt: skip
    tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * 2 + [exu.JointType.PrismaticZ] * extra,
        linkParents=[-1, 0] + [-1] * extra,
        jointTransformations=_matrices([np.eye(3)] * (2 + extra)),
        jointOffsets=_vectors([[0.0, 0.0, 0.0], [g.l_fg, 0.0, 0.0]] + [[0.0, 0.0, 0.0]] * extra),
        linkInertiasCOM=_matrices([np.eye(3) * sector_chain_inertia(scene), np.eye(3) * m.rod_inertia]
                                  + [np.eye(3)] * extra),
        linkCOMs=_vectors([[0.0, 0.0, 0.0], [0.5 * g.l_ef, 0.0, 0.0]] + [[0.0, 0.0, 0.0]] * extra),
        linkMasses=[UNSPECIFIED_MASS, m.rod_mass] + [1.0] * extra, baseOffset=[g.l_og, 0.0, 0.0],
        gravity=[0.0, -m.gravity, 0.0],
        forceUserFunction=force,  # type: ignore[arg-type]  # exudyn stub: wants an ndarray back (takes a list)
    ))  # fmt: skip
    return TreeModel(scene, node, tree, force, tracker, route, memory, stash, calls)
