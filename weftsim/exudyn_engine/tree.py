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
centre P_b(t) = E of the prescribed rocker is not a body.  The contact enters as the tree's
generalized force (``forceUserFunction``, :func:`make_python_force`): the callback computes the
journal centre and its velocity from the joint coordinates, subtracts P_b(t) and its velocity
(closed form),

    e = P_j - P_b(t),   e_dot = v_j - V_b(t),

applies the same law, onset interpolation and held impact velocity rule
(``joint.impact_velocity_rule``) as :mod:`.callbacks` / :mod:`.onset`, and returns the joint
torques of the contact force by virtual work.  No constraints remain, so an error-controlled
explicit solver (DOPRI5 with automatic step size) integrates it; there is no Jacobian and no
Newton iteration.

The driving torque comes from the contact force in closed form, with the crank-side
terms of :mod:`weftsim.reference.ideal` (SPEC.md 4, docs/reference-solver.md):

    T = 1/2 J13'(theta) omega^2 + U13'(theta) - Q3,   Q3 = F_b . dP_b/dtheta

(F_b = F_N n, the force on the bearing, recorded by the callback at every accepted state).  The full rigid-body
model (:mod:`.mechanism`) stays the general path; ``tests/test_fast_paths.py`` checks the
two against each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree

from weftsim.contact import make_law
from weftsim.exudyn_engine.onset import (
    RESTING_RATE_FRACTION,
    OnsetTracker,
    callback_impact_velocity,
    damping_rate,
)
from weftsim.params import Scene
from weftsim.reference.dynamics import initial_state
from weftsim.reference.ideal import sector_chain_inertia

UNSPECIFIED_MASS = 1.0  # sector mass (balanced, on its fixed axis: no effect), kg
# Callback routes of this model.  No symbolic route: Exudyn's symbolic user functions do not take the
# tree's forceUserFunction (its coordinate vectors have no size when the expression is recorded), and
# as an expression tree the bearing motion was repeated in every use of e (51 us per call in the
# connector form this model had before, against ~1.5 us for plain Python).
TREE_ROUTES = ("auto", "python", "numba")


def tree_route(callback: str) -> str:
    """The route a ``solver.exudyn.callback`` value runs on the tree: "auto" = numba when installed.

    The numba core costs ~1 us per call against ~2 us for the plain-Python body (the numba dispatch
    is most of it; docs/performance.md), and compiles once per machine (numba's cache).
    """
    if callback != "auto":
        return callback
    try:
        import numba  # noqa: F401 - a dependency of weftsim; "python" only where it is missing
    except ImportError:
        return "python"
    return "numba"


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


def make_python_force(law, clearance: float, min_impact_velocity: float, bearing: BearingMotion,
                      geometry, memory: list, stash: list, counter: list | None = None,
                      max_approach: bool = True):
    """Plain-Python generalized contact force of the tree, ``forceUserFunction(mbs, t, i, q, q_t)``.

    The journal centre and its velocity follow from the joint coordinates in closed form
    (``geometry``: :class:`weftsim.params.Geometry`, lengths L_OG, L_FG, L_EF; b = q0 + q1 = psi + pi
    is the absolute angle of the rod's x axis from F to the journal),

        P_j = G + L_FG u(a) + L_EF u(b),  v_j = L_FG a' u'(a) + L_EF b' u'(b),  b = q0 + q1,

    the eccentricity from e = P_j - P_b(t) (:class:`BearingMotion`), the normal force F_N from the
    law with the held impact velocity (:mod:`.onset`), and the joint torques from the force on the
    journal, F_j = -F_N n (n = e/|e|), by virtual work:

        Q1 = F_j . dP_j/dq1 = F_N L_EF (n_x sin b - n_y cos b),
        Q0 = F_j . dP_j/dq0 = F_N L_FG (n_x sin a - n_y cos a) + Q1.

    (An Exudyn connector between a ground marker and a kinematic-tree marker does the same
    projection in C++, but its marker kinematics cost about twice the whole tree per evaluation:
    docs/performance.md.)  ``memory`` = [v_held, delta0, rate0] of the last accepted step (written by
    the post-step bookkeeping); every call leaves [t, delta, delta_dot, F_b,x, F_b,y] in ``stash``
    (F_b = F_N n, the force on the bearing): the last call of an accepted step is at its end state
    (the last DOPRI5 / ODE23 stage), so the bookkeeping needs no extra evaluation.
    """
    normal_force = law.scalar()
    c, v_min, sqrt, cos, sin = clearance, min_impact_velocity, math.sqrt, math.cos, math.sin
    l_og, l_fg, l_ef = geometry.l_og, geometry.l_fg, geometry.l_ef
    counter = [0] if counter is None else counter
    impact_velocity, damped = callback_impact_velocity, damping_rate
    v_dead = RESTING_RATE_FRACTION * min_impact_velocity

    def tree_force(mbs, t, itemNumber, q, q_t):
        counter[0] += 1
        b_y, b_z, vb_y, vb_z = bearing(t)
        a = q[0]
        b = a + q[1]
        da = q_t[0]
        db = da + q_t[1]
        sa, ca, sb, cb = sin(a), cos(a), sin(b), cos(b)
        ex = l_og + l_fg * ca + l_ef * cb - b_y
        ey = l_fg * sa + l_ef * sb - b_z
        length = sqrt(ex * ex + ey * ey)
        delta = length - c
        if length <= 0.0:
            stash[0], stash[1], stash[2], stash[3], stash[4] = t, delta, 0.0, 0.0, 0.0
            return [0.0, 0.0]
        nx = ex / length
        ny = ey / length
        rate = (-l_fg * sa * da - l_ef * sb * db - vb_y) * nx + (l_fg * ca * da + l_ef * cb * db - vb_z) * ny
        if delta <= 0.0:
            stash[0], stash[1], stash[2], stash[3], stash[4] = t, delta, rate, 0.0, 0.0
            return [0.0, 0.0]
        v_imp = impact_velocity(memory[0], memory[1], memory[2], delta, rate, v_min, max_approach)
        f = normal_force(delta, damped(rate, v_dead), v_imp)
        stash[0], stash[1], stash[2], stash[3], stash[4] = t, delta, rate, f * nx, f * ny
        q1 = f * l_ef * (nx * sb - ny * cb)
        return [f * l_fg * (nx * sa - ny * ca) + q1, q1]

    return tree_force


def make_numba_force(scene: Scene, memory: list):
    """Compiled generalized force (as :func:`make_python_force`): (callback, memory, stash, call count).

    The callback only unpacks Exudyn's lists; the numba dispatch (~0.7 us) is most of its cost,
    against ~2 us for the plain-Python body.  The memory, stash and count returned are views of
    the core's state array (indexable as the python route's lists).
    """
    from weftsim.exudyn_engine.tree_kernel import CALLS, HELD, N_SLOTS, STASH, tree_force_core
    from weftsim.reference.compiled_kernel import N_PARAMETERS, pack_parameters

    state = np.concatenate([pack_parameters(scene), np.zeros(N_SLOTS)])
    slots = state[N_PARAMETERS:]
    slots[HELD:HELD + 3] = memory
    slots[STASH] = math.nan
    core = tree_force_core

    def tree_force(mbs, t, itemNumber, q, q_t):
        return core(state, t, q[0], q[1], q_t[0], q_t[1])

    return tree_force, slots[HELD:HELD + 3], slots[STASH:STASH + 5], slots[CALLS:CALLS + 1]


@dataclass
class TreeModel:
    """Items of the kinematic-tree model and the clearance bookkeeping."""

    scene: Scene
    node: object  # NodeGenericODE2 with q = [a, psi + pi - a]
    tree: object  # ObjectKinematicTree, contact through its forceUserFunction
    force: object  # the forceUserFunction (python or numba route)
    bearing: BearingMotion
    tracker: OnsetTracker
    route: str
    memory: list  # [v_held, delta0, rate0] read by the force callback (numba: a view of its state)
    stash: list  # [t, delta, delta_dot, F_b,x, F_b,y] of the last callback (numba: a view)
    callback_calls: list = field(default_factory=lambda: [0])  # [count] (numba: a view)
    bearing_force: list = field(default_factory=list)  # [t, F_b,x, F_b,y] per accepted state

    def accept(self, mbs, t: float) -> None:
        """Post-step bookkeeping: onset, held impact velocity, callback memory, force on the bearing."""
        read = self.stash.tolist if isinstance(self.stash, np.ndarray) else self.stash.copy
        t_call, delta, rate, fx, fy = read()
        if t_call != t:  # no evaluation at this state yet (the initial state)
            q = mbs.GetNodeOutput(self.node, exu.OutputVariableType.Coordinates)
            q_t = mbs.GetNodeOutput(self.node, exu.OutputVariableType.Coordinates_t)
            self.force(mbs, t, self.tree, q, q_t)
            t_call, delta, rate, fx, fy = read()
        tracker = self.tracker
        tracker.accept(t, delta, rate)
        self.memory[0], self.memory[1], self.memory[2] = tracker.held, delta, rate
        self.bearing_force.append((t, fx, fy))


def build_tree(mbs, scene: Scene, callback: str = "auto") -> TreeModel:
    """Add the kinematic tree of members 4-8, gravity and the clearance contact to ``mbs``.

    Initial state: the ideal mechanism at theta = 0, journal centred
    (:func:`weftsim.reference.dynamics.initial_state`).  ``callback``: "auto" (:func:`tree_route`),
    "python" or "numba".  Needs ``scene.joint.clearance > 0`` and no friction.
    """
    g, m, joint = scene.geometry, scene.inertia, scene.joint
    a0, psi0, da0, dpsi0 = initial_state(scene)[:4]
    law = make_law(joint)
    bearing = BearingMotion.from_scene(scene)
    route = tree_route(callback)
    calls = [0]
    c, v_min = joint.clearance, joint.min_impact_velocity
    max_approach = joint.impact_velocity_rule == "max_approach"
    tracker = OnsetTracker(c, v_min, rule=joint.impact_velocity_rule)
    memory = list(tracker.callback_state)
    stash = [math.nan, 0.0, 0.0, 0.0, 0.0]
    if route == "python":
        force = make_python_force(law, c, v_min, bearing, g, memory, stash, calls, max_approach)
    elif route == "numba":
        force, memory, stash, calls = make_numba_force(scene, memory)
    else:
        raise ValueError(f"`callback` of the kinematic tree must be one of {TREE_ROUTES}, got {callback!r}")
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
        forceUserFunction=force,
    ))  # fmt: skip
    return TreeModel(scene, node, tree, force, bearing, tracker, route, memory, stash, calls)
