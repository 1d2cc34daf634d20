"""The weft insertion mechanism (members 1-8, docs/physics.md section 1) as an Exudyn model.

Exudyn's global frame is rotated so that the four-bar plane is its XY plane (2-D bodies
live there and are 4-5x cheaper than 3-D ones)::

    Exudyn X = model y (along OG)      model (Y, Z) four-bar coordinates = Exudyn (X, Y)
    Exudyn Y = model z (crank axis A, up; gravity along -Y)
    Exudyn Z = model x (rocker axis D, normal of the four-bar plane)

Members and joints (all joints ideal except E and F when the scene gives them a clearance)::

    1 crank    3-D  revolute A (ground, axis Y through O); driven: d(rz)/dt = omega
    2 coupler  3-D  revolute B (crank, axis b(0) through O)
    3 rocker   3-D  revolute C (coupler, axis c(phi0) through O)
                    + generic joint D (ground) constraining only the rotations about X, Y:
                    the fourth revolute of the spherical 4R without redundant constraints
    4 rod      2-D  E: ideal revolute or clearance joint (bearing on 3, journal on 4)
    5 sector   2-D  F: ideal revolute or clearance joint (bearing on 5, journal on 4); revolute G (ground)
    6/7, 8          reflected onto the sector: J5_eff = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2
                    (ideal gear meshes; ``reflect_gears=False`` builds them as bodies with
                    coordinate constraints instead, for checking)

3-D nodes use Tait-Bryan Rxyz parameters with reference rotations chosen so the
middle angle stays far from its +-90 deg singularity: the crank's rotation is its node's
``rz`` (coordinate 5), which the drive constrains.  The driving torque is minus the
drive's Lagrange multiplier (checked against the energy rate in the tests).  Bodies with
unspecified mass (crank, sector: balanced, centre of mass on their fixed axis) get
:data:`UNSPECIFIED_MASS`; inertia about axes that cannot rotate only loads the bearings.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    MarkerBodyPosition,
    MarkerNodeCoordinate,
    NodePoint2D,
    NodePointGround,
    ObjectConnectorCoordinate,
    ObjectJointRevolute2D,
    ObjectMassPoint2D,
)
from exudyn.rigidBodyUtilities import RigidBodyInertia

from weftsim.exudyn_engine.clearance_joint import ClearanceJointModel, add_clearance_joint
from weftsim.mechanism.kinematics import coupler_angular_velocity, coupler_frame, crank_axis, linkage_state, rocker_axis
from weftsim.input.params import Scene

if TYPE_CHECKING:
    from collections.abc import Sequence

    from numpy.typing import ArrayLike

# Model-frame vector (x, y, z) (docs/physics.md section 1) -> Exudyn (X, Y, Z) = (y, z, x).
SPEC_TO_EXUDYN = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
# Mass given to balanced members whose mass the scene does not specify (no effect on results), kg.
UNSPECIFIED_MASS = 1.0
CRANK_COORDINATE = 5  # rz of the crank's Rxyz node = crank angle theta
ROTATION_2D = 2  # coordinate index of the angle of a 2-D rigid body node


def to_exudyn(vector: ArrayLike) -> np.ndarray:
    """Model-frame vector(s) (docs/physics.md section 1) (..., 3) to Exudyn's frame."""
    return np.asarray(vector, dtype=float) @ SPEC_TO_EXUDYN.T


def plane_point(yz: Sequence[float] | np.ndarray) -> list[float]:
    """Four-bar plane point (Y, Z) to an Exudyn position (X, Y, 0)."""
    return [float(yz[0]), float(yz[1]), 0.0]


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


@dataclass
class MechanismModel:
    """Indices of the items of a built mechanism (Exudyn ``NodeIndex`` / ``ObjectIndex`` ...)."""

    scene: Scene
    bodies: dict  # name -> ObjectIndex: crank, coupler, rocker, rod, sector (+ pinion, rapier)
    nodes: dict  # name -> NodeIndex, same names
    drive: object  # ObjectConnectorCoordinate; driving torque = -its Force output
    marker_bearing: object  # on the rocker at E
    marker_journal: object  # on the rod at E
    clearance: ClearanceJointModel | None
    sector_reference_angle: float  # theta_FG(0), rad
    reflect_gears: bool
    clearance_f: ClearanceJointModel | None = None  # the clearance joint at F (bearing on 5, journal on 4)

    @property
    def clearances(self) -> dict:
        """The clearance joints of the model by name ("e", "f"): those the scene gives a clearance."""
        return {name: c for name, c in (("e", self.clearance), ("f", self.clearance_f)) if c is not None}


def _rigid_3d(mbs, inertia, rotation, angular_velocity, gravity):
    return mbs.CreateRigidBody(
        inertia=inertia, referencePosition=[0.0, 0.0, 0.0], referenceRotationMatrix=rotation,
        initialAngularVelocity=list(angular_velocity), nodeType=exu.NodeType.RotationRxyz,
        gravity=gravity, returnDict=True,
    )  # fmt: skip


def _rigid_2d(mbs, mass, inertia_com, position, angle, velocity, angular_velocity, gravity):
    return mbs.CreateRigidBody(
        inertia=RigidBodyInertia(mass, np.diag([inertia_com] * 3), inertiaTensorAtCOM=True),
        referencePosition=position, referenceRotationMatrix=rot_z(angle),
        initialVelocity=[velocity[0], velocity[1], 0.0], initialAngularVelocity=[0.0, 0.0, angular_velocity],
        create2D=True, gravity=gravity, returnDict=True,
    )  # fmt: skip


def _pin(mbs, body0, local0, body1, local1):
    m0 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=body0, localPosition=local0))
    m1 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=body1, localPosition=local1))
    return mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[m0, m1]))


def build_mechanism(mbs: exu.MainSystem, scene: Scene, callback: str | None = None, reflect_gears: bool = True,
                    call_counter: list | None = None) -> MechanismModel:
    """Add members 1-8, their joints, gravity and the crank drive to ``mbs`` (not assembled).

    Initial state: the ideal mechanism at theta = 0 (positions and velocities from
    :func:`weftsim.mechanism.kinematics.linkage_state`), journal centred.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    scene : Scene
    callback : str, optional
        Clearance force route; default ``scene.exudyn_solver.callback``.
    reflect_gears : bool
        True: gears 6/7 and rapier 8 reflected onto the sector (default, cheaper);
        False: separate bodies with ideal gear constraints.
    call_counter : list, optional
        Passed to :func:`add_clearance_joint` (python route; benchmarks).
    """
    g, m = scene.geometry, scene.inertia
    omega = scene.drive.speed
    gravity = [0.0, -m.gravity, 0.0]
    st = linkage_state(0.0, g, rocker_com_distance=m.rocker_com)
    ground = mbs.CreateGround()

    # Spherical 4R: members 1-3, all revolute axes through O.
    crank = _rigid_3d(mbs, RigidBodyInertia(UNSPECIFIED_MASS, np.eye(3) * m.crank_inertia),
                      rot_x(-0.5 * math.pi), [0.0, omega, 0.0], gravity)  # body z = axis A  # fmt: skip
    mbs.CreateRevoluteJoint(itemNumbers=[ground, crank["bodyNumber"]], position=[0.0, 0.0, 0.0],
                            axis=[0.0, 1.0, 0.0])  # fmt: skip
    w, _ = coupler_angular_velocity(0.0, g.crank_inclination)
    coupler = _rigid_3d(mbs, RigidBodyInertia(m.coupler_mass, np.diag(m.coupler_inertia)),
                        SPEC_TO_EXUDYN @ coupler_frame(0.0, g.crank_inclination), to_exudyn(omega * w),
                        gravity)  # fmt: skip
    mbs.CreateRevoluteJoint(itemNumbers=[crank["bodyNumber"], coupler["bodyNumber"]], position=[0.0, 0.0, 0.0],
                            axis=to_exudyn(crank_axis(0.0, g.crank_inclination)))  # fmt: skip
    # Rocker: body x along OE, z = axis D; inertia about O, centre of mass on OE.
    rocker_inertia = RigidBodyInertia(m.rocker_mass, np.eye(3) * m.rocker_inertia, com=[m.rocker_com, 0.0, 0.0])
    rocker = _rigid_3d(mbs, rocker_inertia, rot_z(float(st.theta_oe)),
                       [0.0, 0.0, omega * float(st.d_phi)], gravity)  # fmt: skip
    mbs.CreateRevoluteJoint(itemNumbers=[coupler["bodyNumber"], rocker["bodyNumber"]], position=[0.0, 0.0, 0.0],
                            axis=to_exudyn(rocker_axis(float(st.phi))))  # fmt: skip
    mbs.CreateGenericJoint(itemNumbers=[ground, rocker["bodyNumber"]], position=[0.0, 0.0, 0.0],
                           rotationMatrixAxes=np.eye(3), constrainedAxes=[0, 0, 0, 1, 1, 0])  # fmt: skip

    # Planar four-bar O-E-F-G: members 4 and 5.
    e, f = st.point_e, st.point_f
    rod = _rigid_2d(mbs, m.rod_mass, m.rod_inertia, plane_point(st.rod_com), float(st.theta_ef),
                    omega * st.d_rod_com, omega * float(st.d_theta_ef), gravity)  # fmt: skip
    sector_inertia = m.sector_inertia
    if reflect_gears:
        sector_inertia += m.pinion_gear_inertia * g.pinion_ratio**2 + m.rapier_mass * g.rapier_ratio**2
    sector = _rigid_2d(mbs, UNSPECIFIED_MASS, sector_inertia, [g.l_og, 0.0, 0.0], float(st.theta_fg),
                       (0.0, 0.0), omega * float(st.d_theta_fg), gravity)  # fmt: skip
    half = 0.5 * math.hypot(f[0] - e[0], f[1] - e[1])
    route = scene.exudyn_solver.callback if callback is None else callback
    clearance_f = None
    if scene.joint_f.is_ideal:
        _pin(mbs, rod["bodyNumber"], [half, 0.0, 0.0], sector["bodyNumber"], [g.l_fg, 0.0, 0.0])  # F
    else:  # F with a clearance: the sector's eye is the bearing, the rod's pin the journal
        bearing_f = mbs.AddMarker(MarkerBodyPosition(bodyNumber=sector["bodyNumber"], localPosition=[g.l_fg, 0.0, 0.0]))
        journal_f = mbs.AddMarker(MarkerBodyPosition(bodyNumber=rod["bodyNumber"], localPosition=[half, 0.0, 0.0]))
        with warnings.catch_warnings():  # the scene's own check names joint_f.restitution (weftsim.checks.plausibility);
            warnings.simplefilter("ignore", UserWarning)  # the joint's warning names the Python field
            clearance_f = add_clearance_joint(mbs, bearing_f, journal_f, scene.joint_f, callback=route)
    _pin(mbs, ground, [g.l_og, 0.0, 0.0], sector["bodyNumber"], [0.0, 0.0, 0.0])  # G
    bodies = {"crank": crank, "coupler": coupler, "rocker": rocker, "rod": rod, "sector": sector}
    if not reflect_gears:
        bodies.update(_gear_train(mbs, scene, ground, sector, gravity))

    # Joint E: bearing on the rocker, journal on the rod.
    marker_bearing = mbs.AddMarker(MarkerBodyPosition(bodyNumber=rocker["bodyNumber"],
                                                      localPosition=[g.l_oe, 0.0, 0.0]))  # fmt: skip
    marker_journal = mbs.AddMarker(MarkerBodyPosition(bodyNumber=rod["bodyNumber"], localPosition=[-half, 0.0, 0.0]))
    clearance = None
    if scene.joint.is_ideal:
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[marker_bearing, marker_journal]))
    else:
        with warnings.catch_warnings():  # as at F: the scene's check names joint_e.restitution
            warnings.simplefilter("ignore", UserWarning)
            clearance = add_clearance_joint(mbs, marker_bearing, marker_journal, scene.joint,
                                            callback=route, call_counter=call_counter)  # fmt: skip

    drive = mbs.CreateCoordinateConstraint(itemNumbers=[None, crank["nodeNumber"]],
                                           coordinates=[None, CRANK_COORDINATE],
                                           offset=omega, velocityLevel=True)  # fmt: skip
    return MechanismModel(
        scene=scene,
        bodies={k: v["bodyNumber"] for k, v in bodies.items()},
        nodes={k: v["nodeNumber"] for k, v in bodies.items()},
        drive=drive, marker_bearing=marker_bearing, marker_journal=marker_journal,
        clearance=clearance, sector_reference_angle=float(st.theta_fg), reflect_gears=reflect_gears,
        clearance_f=clearance_f,
    )  # fmt: skip


def _gear_train(mbs, scene: Scene, ground, sector, gravity) -> dict:
    """Pinion/rapier gear 6/7 and rapier 8 as bodies with ideal gear constraints.

    Gear 6/7 angle q67 = -(d5/d6) q5 and rapier s = -d7 q67 (docs/physics.md section 1), written as
    Exudyn coordinate constraints factor1 q(m1) - q(m0) = 0.  Gear 6/7 sits at the mesh
    distance d5 + d6 beyond G (its position has no effect: balanced, pinned).
    """
    g, m = scene.geometry, scene.inertia
    omega = scene.drive.speed
    st = linkage_state(0.0, g, rocker_com_distance=m.rocker_com)
    pinion = _rigid_2d(mbs, UNSPECIFIED_MASS, m.pinion_gear_inertia,
                       [g.l_og + g.sector_pitch_radius + g.pinion_pitch_radius, 0.0, 0.0], 0.0,
                       (0.0, 0.0), omega * float(st.d_gear67_angle), gravity)  # fmt: skip
    _pin(mbs, ground, [g.l_og + g.sector_pitch_radius + g.pinion_pitch_radius, 0.0, 0.0],
         pinion["bodyNumber"], [0.0, 0.0, 0.0])  # fmt: skip
    rack_node = mbs.AddNode(NodePoint2D(referenceCoordinates=[0.0, 0.0],
                                        initialVelocities=[omega * float(st.d_rapier_displacement), 0.0]))  # fmt: skip
    rack = mbs.AddObject(ObjectMassPoint2D(nodeNumber=rack_node, mass=m.rapier_mass))
    ground_node = mbs.AddNode(NodePointGround())
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    m_rack_x = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=rack_node, coordinate=0))
    m_rack_y = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=rack_node, coordinate=1))
    m_sector = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=sector["nodeNumber"], coordinate=ROTATION_2D))
    m_pinion = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=pinion["nodeNumber"], coordinate=ROTATION_2D))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[m_ground, m_rack_y]))  # rack along X only
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[m_pinion, m_sector], factor1=-g.pinion_ratio))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[m_rack_x, m_pinion], factor1=-g.rapier_gear_pitch_radius))
    return {"pinion": pinion, "rapier": {"bodyNumber": rack, "nodeNumber": rack_node}}
