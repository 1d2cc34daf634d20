"""Friction of the reusable clearance joint on rigid bodies (docs/physics.md section 2).

The modified Coulomb friction (Ambrosio 2003) acts at the contact point Q = P_b + R_b n.  The joint's
``ObjectConnectorCartesianSpringDamper`` applies one force at the two centres, so Q's force is split
into that force and two pure moments, one per body::

    journal: f_j = -F_N n + F_T t at P_j,   M_j = (R_b - |e|) F_T     (Q - P_j = (R_b - |e|) n)
    bearing: -f_j at P_b,                   M_b = -R_b F_T            (Q - P_b = R_b n)

M_j + M_b = -|e| F_T balances the moment e x f_j of the force pair about the two centres, so the two
moments differ and cannot be one equal-and-opposite connector torque: each is a ``LoadTorqueVector``
with a user function on its own body.  The sliding speed needs the bodies' rotation rates,

    v_T = e_dot . t + omega_j (R_b - |e|) - omega_b R_b,

which the Cartesian connector's callback does not receive: it reads them from the system
(``GetObjectOutputBody``, the current trial state inside Newton).  Force, moments and v_T are
:func:`weftsim.physics.joint.connector_friction_force` (compiled or plain Python, the joint's route),
evaluated once per state and shared by the connector callback and the two loads.

Newton: the connector's numerical Jacobian contains the friction force's dependence on e and e_dot;
the loads' and the rates' dependence is in the Jacobian only with
``timeIntegration.computeLoadsJacobian = 2``, and a stale Jacobian (modified Newton) does not follow the
journal from sliding into sticking (ramp slope mu F_N / (v1 - v0) ~ 1e8 N s/m on the loom): the loom's
rigid-body model sets both (solver.py, with what failed without them); a user's own settings need them too.

A body without rotation (ground, mass point) turns at 0 and takes no moment.

A worn joint (``joint.bearing_wear``, ``joint.journal_wear``: the wear block after the joint block in
``prm``) also reads the bodies' angles about Z (``RotationMatrix``, reference rotation included): its
profiles are in each body's frame, and the force is :func:`weftsim.physics.worn_joint.connector_worn_force`
(or its lubricated form) at the local clearance.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import exudyn as exu
from exudyn.itemInterface import LoadTorqueVector, MarkerBodyRigid

from weftsim.exudyn_engine import callbacks
from weftsim.physics import joint as kernel_joint
from weftsim.physics.lubricated import connector_lubricated_force
from weftsim.physics.worn_joint import connector_worn_force, connector_worn_lubricated_force

if TYPE_CHECKING:
    from collections.abc import Sequence

    import exudyn.exudynCPP  # the index classes' module (exudyn's stub imports them from itself)
    from numba.core.dispatcher import Dispatcher

_ROTATING = ("RigidBody", "RigidBody2D")
_FIXED = ("Ground", "MassPoint", "MassPoint2D")
_OMEGA = exu.OutputVariableType.AngularVelocity
_ROTATION = exu.OutputVariableType.RotationMatrix


def _body_of(mbs, marker) -> tuple[int | None, list, bool]:
    """(body, local position, rotates) of a position marker; body None for a node marker (a point)."""
    item = mbs.GetMarker(marker)
    if "bodyNumber" not in item:
        node_type = str(mbs.GetNode(item["nodeNumber"])["nodeType"])
        if "Point" not in node_type or "Rigid" in node_type:
            raise ValueError(f"friction in the clearance joint needs MarkerBodyPosition markers on rigid bodies, "
                             f"ground or mass points, or node markers on point nodes; got a marker on a {node_type} node")
        return None, [0.0, 0.0, 0.0], False
    body = item["bodyNumber"]
    kind = str(mbs.GetObject(body)["objectType"])
    if kind not in _ROTATING + _FIXED:
        raise ValueError(f"friction in the clearance joint needs the markers on rigid bodies, ground or mass "
                         f"points; got a body of type {kind!r}")
    return body, list(item.get("localPosition", [0.0, 0.0, 0.0])), kind in _ROTATING


class JointFriction:
    """Friction force and moments of one clearance joint (module docstring).

    Parameters
    ----------
    mbs : exudyn.MainSystem
    marker_bearing, marker_journal : exudyn MarkerIndex
        The joint's position markers (bearing centre, journal centre).
    prm : numpy.ndarray
        The joint block of :func:`weftsim.physics.joint.joint_parameters` (friction included).
    route : {"numba", "python"}
    memory : callable
        Returns the connector's memory [v_held, delta0, rate0] (the tracker's ``callback_state``).

    Attributes
    ----------
    history : list of tuple
        (t, F_N, F_T v_T) at every accepted state (:meth:`accept`): normal force (N) and friction
        power on the pair (W, <= 0).
    """

    def __init__(self, mbs, marker_bearing, marker_journal, prm, route: str, memory):
        self.bearing, self.bearing_local, self.bearing_rotates = _body_of(mbs, marker_bearing)
        self.journal, self.journal_local, self.journal_rotates = _body_of(mbs, marker_journal)
        # A lubricated joint (the block's LUBRICATED flag): the same nine values with the film and the
        # asperities added, then their power, potential and channels (weftsim.physics.lubricated).
        self.lubricated = bool(prm[kernel_joint.LUBRICATED] != 0.0)
        self.worn = len(prm) > kernel_joint.N_JOINT  # a wear block follows the joint block
        function: Dispatcher  # the four kernels take different arguments (the worn ones the angles too)
        if self.worn:
            function = connector_worn_lubricated_force if self.lubricated else connector_worn_force
        else:
            function = connector_lubricated_force if self.lubricated else kernel_joint.connector_friction_force
        self.prm = callbacks.parameters_for_route(prm, route)
        self.kernel = callbacks.loaded_kernel(function, route, self.prm, 1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0,
                                              *((0.0, 0.0) if self.worn else ()))
        self.memory = memory
        self.connector = None
        self._key: tuple[float, ...] | None = None  # evaluate's memo: the state last evaluated, its kernel value
        self._value: tuple[float, ...] = ()
        self.history: list = []
        self.lubrication_history: list = []

    def rates(self, mbs: exu.MainSystem) -> tuple[float, float]:
        """(omega_j, omega_b), rad/s about Z, of the current (trial) state."""
        w_j = mbs.GetObjectOutputBody(self.journal, _OMEGA, [0.0, 0.0, 0.0])[2] if self.journal_rotates else 0.0
        w_b = mbs.GetObjectOutputBody(self.bearing, _OMEGA, [0.0, 0.0, 0.0])[2] if self.bearing_rotates else 0.0
        return w_j, w_b

    def angles(self, mbs: exu.MainSystem) -> tuple[float, float]:
        """(theta_j, theta_b), rad about Z, of the current (trial) state (0 for a body that does not rotate)."""
        out = []
        for rotates, body in ((self.journal_rotates, self.journal), (self.bearing_rotates, self.bearing)):
            r = mbs.GetObjectOutputBody(body, _ROTATION, [0.0, 0.0, 0.0]) if rotates else (1.0, 0.0, 0.0, 0.0)
            out.append(math.atan2(r[3], r[0]))
        return out[0], out[1]

    def evaluate(self, mbs: exu.MainSystem, ex: float, ey: float, vx: float, vy: float) -> tuple[float, ...]:
        """The kernel's (f_x, f_y, delta, delta_dot, F_N, F_T, M_j, M_b, v_T) at this state (memoized)."""
        w_j, w_b = self.rates(mbs)
        held, delta0, rate0 = self.memory()
        turned = self.angles(mbs) if self.worn else ()
        key = (ex, ey, vx, vy, w_j, w_b, held, delta0, rate0, *turned)
        if key != self._key:
            self._key = key
            self._value = self.kernel(self.prm, ex, ey, vx, vy, held, delta0, rate0, w_j, w_b, *turned)
        return self._value

    def penetration(self, mbs: exu.MainSystem) -> tuple[float, float]:
        """(delta, delta_dot) of the current state as the force saw them (a worn joint: at the local clearance)."""
        out = self._state(mbs)
        return out[2], out[3]

    def spring_force(self, mbs: exu.MainSystem, t: float, itemNumber: int, displacement: Sequence[float],
                     velocity: Sequence[float], stiffness: Sequence[float], damping: Sequence[float],
                     offset: Sequence[float]) -> list[float]:
        """``springForceUserFunction`` of the connector: F_N n - F_T t, the force on the bearing."""
        out = self.evaluate(mbs, displacement[0], displacement[1], velocity[0], velocity[1])
        return [out[0], out[1], 0.0]

    def _state(self, mbs):
        u = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Displacement)
        v = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Velocity)
        return self.evaluate(mbs, u[0], u[1], v[0], v[1])

    def install(self, mbs: exu.MainSystem, connector: exudyn.exudynCPP.ObjectIndex) -> None:
        """Add the torque loads M_j and M_b on the bodies that rotate (after the connector exists)."""
        self.connector = connector

        def journal_moment(mbs, t, load):
            return [0.0, 0.0, self._state(mbs)[6]]

        def bearing_moment(mbs, t, load):
            return [0.0, 0.0, self._state(mbs)[7]]

        # A worn joint without friction or film has no moments (M_j = M_b = 0): no loads (their user functions
        # at every Newton iteration took the worn loom's rigid-body model 13.5 s for 0.05 revolution, 2.4 s without).
        moments = self.lubricated or self.prm[kernel_joint.MU] > 0.0
        for rotates, body, local, moment in ((self.journal_rotates, self.journal, self.journal_local, journal_moment),
                                             (self.bearing_rotates, self.bearing, self.bearing_local, bearing_moment)):
            if rotates and moments:
                marker = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body, localPosition=local))
                mbs.AddLoad(LoadTorqueVector(markerNumber=marker, loadVector=[0.0, 0.0, 0.0],
                                             loadVectorUserFunction=moment))  # fmt: skip

    def accept(self, mbs: exu.MainSystem, t: float) -> None:
        """Record (t, F_N, F_T v_T) of an accepted state (post-step, before the tracker's update); a
        lubricated joint also (D'_lub, U_a, |f_film|, F_a, T_j) in :attr:`lubrication_history`."""
        out = self._state(mbs)
        self.history.append((t, out[4], out[5] * out[8]))
        if self.lubricated:
            self.lubrication_history.append((t,) + tuple(out[9:14]))
