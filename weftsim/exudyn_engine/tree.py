"""Kinematic-tree model of the loom: only the free members in minimal coordinates, explicit solver.

With members 1-3 ideal and rigid, their motion is known in closed form from the crank
angle theta = omega t (SPEC.md section 1); only the chain 4-8 behind the clearance joint
moves freely.  This model integrates that chain alone, as an ``ObjectKinematicTree`` with
two revolute joints about Exudyn Z (the four-bar plane is Exudyn's XY plane, as in
:mod:`.mechanism`)::

    base at G = (L_OG, 0)
    joint 0 (RevoluteZ)  q0 = a = theta_FG    link 0: sector 5 with gears 6/7 and rapier 8
                                              reflected (J_FG about G, balanced)
    joint 1 (RevoluteZ)  at F = G + L_FG u(q0)
                         q1 = psi + pi - a    link 1: rod 4, x axis from F to the journal,
                                              centre of mass at L_EF/2, journal at L_EF

(psi = theta_EF of :mod:`weftsim.reference.dynamics`: P_j = F - L_EF u(psi)).  The bearing
centre P_b(t) = E of the prescribed rocker is not a body: the clearance connector joins
the journal to a ground marker at O, and its force callback subtracts P_b(t) and its
velocity (closed form) from the connector's displacement and velocity,

    e = (P_j - O) - P_b(t),   e_dot = v_j - V_b(t),

then applies the same law, onset interpolation and held impact velocity rule
(``joint.impact_velocity_rule``) as :mod:`.callbacks` / :mod:`.onset`.  No constraints
remain, so an error-controlled explicit solver (DOPRI5 with automatic step size) integrates
it; there is no Jacobian and no Newton iteration.

The driving torque comes from the contact force in closed form, with the crank-side
terms of :mod:`weftsim.reference.ideal` (SPEC.md 4, docs/reference-solver.md):

    T = 1/2 J13'(theta) omega^2 + U13'(theta) - Q3,   Q3 = F_b . dP_b/dtheta

(F_b = F_N n, the force on the bearing, the connector's ``Force``).  The full rigid-body
model (:mod:`.mechanism`) stays the general path; ``tests/test_fast_paths.py`` checks the
two against each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    MarkerBodyPosition,
    MarkerKinematicTreeRigid,
    NodeGenericODE2,
    ObjectConnectorCartesianSpringDamper,
    ObjectGround,
    ObjectKinematicTree,
)

from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.onset import OnsetTracker, penetration_state
from weftsim.params import Scene
from weftsim.reference.dynamics import initial_state, pack_parameters
from weftsim.reference.ideal import sector_chain_inertia

UNSPECIFIED_MASS = 1.0  # sector mass (balanced, on its fixed axis: no effect), kg
# "auto" route of this model: the fastest measured (scripts/bench_callbacks.py).
AUTO_ROUTE = "numba"


@dataclass(frozen=True)
class BearingMotion:
    """Closed-form motion of the bearing centre P_b = E of the rocker (SPEC.md section 1).

    phi = -atan(u), u = tan(beta) cos(theta); theta_OE = theta_OE0 + phi;
    P_b = L_OE (cos theta_OE, sin theta_OE);  dP_b/dtheta = L_OE phi' (-sin, cos);
    phi' = tan(beta) sin(theta) / (1 + u^2).  Plane coordinates (Y, Z) = Exudyn (X, Y).
    """

    omega: float
    tan_beta: float
    cos_oe0: float
    sin_oe0: float
    l_oe: float

    @classmethod
    def from_scene(cls, scene: Scene) -> "BearingMotion":
        g = scene.geometry
        return cls(scene.drive.speed, math.tan(g.crank_inclination), math.cos(g.rocker_arm_angle),
                   math.sin(g.rocker_arm_angle), g.l_oe)  # fmt: skip

    def terms(self, t, xp=math):
        """(P_b, dP_b/dtheta) components (m, m/rad) at time t; ``xp`` = math, numpy or esym."""
        theta = self.omega * t
        u = self.tan_beta * xp.cos(theta)
        w = 1.0 + u * u
        r = 1.0 / xp.sqrt(w)
        sq = self.sin_oe0 * r - self.cos_oe0 * u * r  # sin(theta_OE0 - atan u)
        cq = self.cos_oe0 * r + self.sin_oe0 * u * r
        dphi = self.tan_beta * xp.sin(theta) / w
        return self.l_oe * cq, self.l_oe * sq, -self.l_oe * sq * dphi, self.l_oe * cq * dphi

    def __call__(self, t: float):
        """P_b (m) and its velocity (m/s) at time t, floats."""
        by, bz, dby, dbz = self.terms(t)
        return by, bz, self.omega * dby, self.omega * dbz


@dataclass
class TreeModel:
    """Items of the kinematic-tree model and the clearance bookkeeping."""

    scene: Scene
    node: object  # NodeGenericODE2 with q = [a, psi + pi - a]
    tree: object  # ObjectKinematicTree
    connector: object  # ObjectConnectorCartesianSpringDamper, Force = F_N n on the bearing side
    bearing: BearingMotion
    tracker: OnsetTracker
    route: str
    memory: list  # [v_held, delta0, rate0] read by the python and numba callbacks
    stash: list  # [t, delta, delta_dot] of the last callback (python, numba)
    callback_calls: list = field(default_factory=lambda: [0])
    keep_alive: object = field(default=None, repr=False)

    def accept(self, mbs, t: float) -> None:
        """Post-step bookkeeping: onset, held impact velocity, callback memory."""
        if self.stash[0] == t:  # the callback's last call was at this accepted state
            delta, rate = self.stash[1], self.stash[2]
        else:
            u = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Displacement)
            v = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Velocity)
            by, bz, vby, vbz = self.bearing(t)
            delta, rate = penetration_state(u[0] - by, u[1] - bz, v[0] - vby, v[1] - vbz,
                                            self.scene.joint.clearance)  # fmt: skip
        self.tracker.accept(t, delta, rate)
        self.memory[:] = self.tracker.callback_state


def build_tree(mbs, scene: Scene, callback: str = "auto") -> TreeModel:
    """Add the kinematic tree of members 4-8, gravity and the clearance connector to ``mbs``.

    Initial state: the ideal mechanism at theta = 0, journal centred
    (:func:`weftsim.reference.dynamics.initial_state`).  ``callback``: "auto" (= :data:`AUTO_ROUTE`),
    "python" or "numba".  Needs ``scene.joint.clearance > 0`` and no friction.
    """
    g, m, joint = scene.geometry, scene.inertia, scene.joint
    a0, psi0, da0, dpsi0 = initial_state(scene)[:4]
    node = mbs.AddNode(NodeGenericODE2(
        referenceCoordinates=[0.0, 0.0], initialCoordinates=[a0, psi0 + math.pi - a0],
        initialCoordinates_t=[da0, dpsi0 - da0], numberOfODE2Coordinates=2,
    ))  # fmt: skip
    tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * 2, linkParents=[-1, 0],
        jointTransformations=exu.Matrix3DList([np.eye(3)] * 2),
        jointOffsets=exu.Vector3DList([[0.0, 0.0, 0.0], [g.l_fg, 0.0, 0.0]]),
        linkInertiasCOM=exu.Matrix3DList([np.eye(3) * sector_chain_inertia(scene), np.eye(3) * m.rod_inertia]),
        linkCOMs=exu.Vector3DList([[0.0, 0.0, 0.0], [0.5 * g.l_ef, 0.0, 0.0]]),
        linkMasses=[UNSPECIFIED_MASS, m.rod_mass], baseOffset=[g.l_og, 0.0, 0.0], gravity=[0.0, -m.gravity, 0.0],
    ))  # fmt: skip
    ground = mbs.AddObject(ObjectGround())
    m_origin = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    m_journal = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=1, localPosition=[g.l_ef, 0, 0]))
    if callbacks.route_error(callback):
        raise ValueError(callbacks.route_error(callback))
    bearing = BearingMotion.from_scene(scene)
    route = AUTO_ROUTE if callback == "auto" else callback
    calls = [0]
    keep = None
    c, v_min = joint.clearance, joint.min_impact_velocity
    tracker = OnsetTracker(c, v_min, rule=joint.impact_velocity_rule)
    memory = list(tracker.callback_state)
    stash = [math.nan, 0.0, 0.0]
    force = callbacks.make_tree_force(pack_parameters(scene), memory, stash, route, calls)
    connector = mbs.AddObject(ObjectConnectorCartesianSpringDamper(
        markerNumbers=[m_origin, m_journal], stiffness=tracker.callback_state, damping=[0.0, 0.0, 0.0],
        offset=[0.0, 0.0, 0.0], springForceUserFunction=force,
    ))  # fmt: skip
    return TreeModel(scene, node, tree, connector, bearing, tracker, route, memory, stash, calls, keep)
