"""The slider-crank of Flores and Ambrosio (2004) in Exudyn, shared by the gallery examples.

Not a gallery page itself (``docs/conf.py`` ignores it): ``plot_flores_slider_crank.py`` (dry pin) and
``plot_lubricated_slider_crank.py`` (oil film in the pin) build the same mechanism from here.

Crank OA (length r, turning about O at constant speed omega) - rod AB (length l) - slider B on the X
axis, all in Exudyn's XY plane, gravity along -Y.  At B the slider carries the bearing (radius
R_b = R_j + c) and the rod the journal (radius R_j) of a :class:`~weftsim.input.params.ClearanceJoint`
(:func:`weftsim.exudyn_engine.add_clearance_joint`).  The crank and rod centres of mass are assumed
at their midpoints.  The crank angle theta starts at 0 (B at its outer dead centre), the journal
centred, every velocity that of the ideal mechanism.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    MarkerBodyPosition,
    NodePoint2D,
    ObjectJointRevolute2D,
    ObjectMassPoint2D,
    SensorBody,
    SensorNode,
    SensorObject,
)
from exudyn.rigidBodyUtilities import RigidBodyInertia

from weftsim.exudyn_engine import add_clearance_joint
from weftsim.input.params import ClearanceJoint, Material

CRANK_LENGTH, ROD_LENGTH = 0.05, 0.12  # r, l, m
CRANK_MASS, ROD_MASS, SLIDER_MASS = 0.30, 0.21, 0.14  # kg
CRANK_INERTIA, ROD_INERTIA = 1.0e-4, 2.5e-4  # about the centres of mass, kg m^2
CRANK_SPEED = 5000.0 * 2.0 * math.pi / 60.0  # omega, rad/s
GRAVITY = 9.81  # m/s^2, along -Y
STEEL = Material(youngs_modulus=207e9, poisson_ratio=0.3)
FLORES_FRICTION = 0.01  # mu of the friction variant: a lubricated steel pin (not checked against the paper)
REVOLUTION = 2.0 * math.pi / CRANK_SPEED  # s, 0.012 s


def flores_joint(friction_coefficient: float = 0.0) -> ClearanceJoint:
    """The pin B of Flores and Ambrosio (2004): c = 0.5 mm, R_j = 10 mm, steel, ce = 0.9, LN law.

    Every field is explicit (the defaults of :class:`ClearanceJoint` are those of the loom).  The
    bearing length does not enter the Lankarani-Nikravesh law (a Hertz line contact reduced to a
    point law); the value only matters for ``law="elastic_foundation"``.
    """
    return ClearanceJoint(
        clearance=0.5e-3,
        journal_radius=10e-3,
        bearing_length=20e-3,
        journal_material=STEEL,
        bearing_material=STEEL,
        law="lankarani_nikravesh",
        restitution=0.9,
        friction_coefficient=friction_coefficient,
        friction_velocities=(1e-4, 2e-4),
        min_impact_velocity=1e-4,
        impact_velocity_rule="onset",  # the literature's rule, for comparison with the paper
    )


class SliderCrank(NamedTuple):
    """Handles of one built slider-crank: the clearance model (None if ideal) and the sensors."""

    clearance: object
    sensors: dict


def _rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def build(mbs, joint: ClearanceJoint | None) -> SliderCrank:
    """Crank, rod, slider and the pin B (clearance joint, or ideal revolute if ``joint`` is None).

    At theta = 0 the crank pin A is at (r, 0) and moves with (0, r omega); B is at (r + l, 0) at
    rest (dead centre), so the rod turns at -r omega / l and its centre moves with (0, r omega / 2).
    """
    r, l, omega = CRANK_LENGTH, ROD_LENGTH, CRANK_SPEED
    gravity = [0.0, -GRAVITY, 0.0]
    ground = mbs.CreateGround()
    crank = mbs.CreateRigidBody(
        inertia=RigidBodyInertia(CRANK_MASS, np.diag([CRANK_INERTIA] * 3), inertiaTensorAtCOM=True),
        referencePosition=[r / 2.0, 0.0, 0.0], referenceRotationMatrix=_rotation(0.0),
        initialVelocity=[0.0, r * omega / 2.0, 0.0], initialAngularVelocity=[0.0, 0.0, omega],
        gravity=gravity, create2D=True, returnDict=True,
    )  # fmt: skip
    rod = mbs.CreateRigidBody(
        inertia=RigidBodyInertia(ROD_MASS, np.diag([ROD_INERTIA] * 3), inertiaTensorAtCOM=True),
        referencePosition=[r + l / 2.0, 0.0, 0.0], referenceRotationMatrix=_rotation(0.0),
        initialVelocity=[0.0, r * omega / 2.0, 0.0], initialAngularVelocity=[0.0, 0.0, -r * omega / l],
        gravity=gravity, create2D=True, returnDict=True,
    )  # fmt: skip
    slider_node = mbs.AddNode(NodePoint2D(referenceCoordinates=[r + l, 0.0]))
    slider = mbs.AddObject(ObjectMassPoint2D(nodeNumber=slider_node, mass=SLIDER_MASS))
    mbs.CreateForce(itemNumber=slider, loadVector=[0.0, -GRAVITY * SLIDER_MASS, 0.0])

    def marker(body, local):
        return mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=local))

    crank_body, rod_body = crank["bodyNumber"], rod["bodyNumber"]
    o = [marker(ground, [0.0] * 3), marker(crank_body, [-r / 2.0, 0.0, 0.0])]
    a = [marker(crank_body, [r / 2.0, 0.0, 0.0]), marker(rod_body, [-l / 2.0, 0.0, 0.0])]
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=o))
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=a))
    mbs.CreateCoordinateConstraint(itemNumbers=[None, slider_node], coordinates=[None, 1])  # slider on X
    drive = mbs.CreateCoordinateConstraint(itemNumbers=[None, crank["nodeNumber"]], coordinates=[None, 2],
                                   offset=omega, velocityLevel=True)  # fmt: skip
    bearing, journal = marker(slider, [0.0] * 3), marker(rod_body, [l / 2.0, 0.0, 0.0])

    store = {"storeInternal": True, "writeToFile": False}
    ovt = exu.OutputVariableType
    sensors = {
        "crank": SensorNode(nodeNumber=crank["nodeNumber"], outputVariableType=ovt.Coordinates, **store),
        "slider_v": SensorNode(nodeNumber=slider_node, outputVariableType=ovt.Coordinates_t, **store),
        "slider": SensorNode(nodeNumber=slider_node, outputVariableType=ovt.Coordinates_tt, **store),
        "drive": SensorObject(objectNumber=drive, outputVariableType=ovt.Force, **store),
        "rod_position": SensorBody(bodyNumber=rod_body, outputVariableType=ovt.Position, **store),
        "rod_velocity": SensorBody(bodyNumber=rod_body, outputVariableType=ovt.Velocity, **store),
        "rod_rate": SensorBody(bodyNumber=rod_body, outputVariableType=ovt.AngularVelocity, **store),
    }
    clearance = None
    if joint is None:
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[bearing, journal]))
    else:
        clearance = add_clearance_joint(mbs, bearing, journal, joint)
        sensors["eccentricity"] = SensorObject(objectNumber=clearance.connector,
                                               outputVariableType=ovt.Displacement, **store)  # fmt: skip
        sensors["force"] = SensorObject(objectNumber=clearance.connector, outputVariableType=ovt.Force, **store)
        sensors["eccentricity_rate"] = SensorObject(objectNumber=clearance.connector,
                                                    outputVariableType=ovt.Velocity, **store)  # fmt: skip
    return SliderCrank(clearance, {name: mbs.AddSensor(s) for name, s in sensors.items()})


def settings(step: float, end_time: float, friction: bool = False) -> exu.SimulationSettings:
    """Generalized-alpha at a fixed step, Newton failures not ignored, no files, no console output.

    With friction (or an oil film, whose torques are loads of the same kind) the joint's torque loads depend on the velocities and the friction ramp is a
    stiff damper while the journal sticks: Newton then needs the loads' Jacobian with respect to
    q and q_t and a fresh Jacobian in every iteration (docs/clearance-joint.md, friction).
    """
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = end_time
    ti.numberOfSteps = round(end_time / step)
    ti.generalizedAlpha.spectralRadius = 0.8
    ti.newton.useModifiedNewton = not friction
    if friction:
        ti.computeLoadsJacobian = 2
    ti.discontinuous.ignoreMaxIterations = False
    ti.verboseMode = 0
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.0
    ss.solution.solverInformationFileName = ""
    return ss


def simulate(step: float, revolutions: float = 2.0, joint: ClearanceJoint | None = None) -> dict:
    """Run the slider-crank; arrays at every accepted step (SI units).

    Returns a dict with ``time``, ``theta`` (crank angle, rad), ``slider_velocity``,
    ``slider_acceleration`` (along X); with a
    clearance joint also ``eccentricity`` (n x 2, journal centre minus bearing centre),
    ``normal_force`` (the connector force projected on n = e / |e|: F_N, with or without
    friction), ``force`` (n x 2, the connector force: on the bearing, i.e. the slider), ``in_contact``
    (1.0 / 0.0), ``impact_velocity`` (held v_imp, m/s, 0 out of contact) and ``model`` (the
    :class:`ClearanceJointModel`).
    """
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    crank = build(mbs, joint)
    mbs.Assemble()
    # The film's torques and the boundary friction are torque loads reading the state, like friction.
    friction = joint is not None and (joint.friction_coefficient > 0.0 or joint.is_lubricated)
    solver = exu.MainSolverImplicitSecondOrder()
    if not solver.SolveSystem(mbs, settings(step, revolutions * REVOLUTION, friction)):
        # Exudyn returns False (no exception) when Newton fails down to its smallest step.
        raise RuntimeError(f"Exudyn stopped at t = {solver.it.currentTime:.6g} s of {revolutions * REVOLUTION:.6g} s "
                           f"(Newton failed down to the smallest step, h = {step:g} s)")
    data = {name: mbs.GetSensorStoredData(s) for name, s in crank.sensors.items()}
    out = {
        "time": data["crank"][:, 0],
        "theta": data["crank"][:, 3],
        "slider_velocity": data["slider_v"][:, 1],
        "slider_acceleration": data["slider"][:, 1],
        "drive_force": data["drive"][:, 1],
        "rod_height": data["rod_position"][:, 2],
        "rod_velocity": data["rod_velocity"][:, 1:3],
        "rod_rate": data["rod_rate"][:, 3],
    }
    if crank.clearance is not None:
        e = data["eccentricity"][:, 1:3]
        n = e / np.maximum(np.linalg.norm(e, axis=1), 1e-300)[:, None]
        out["eccentricity"] = e
        out["force"] = data["force"][:, 1:3]
        out["normal_force"] = np.sum(out["force"] * n, axis=1)
        out["penetration_rate"] = np.sum(data["eccentricity_rate"][:, 1:3] * n, axis=1)
        # The tracker records the initial state and every accepted step (t = 0 twice: Exudyn also
        # calls the post-step function after its initial state): take its last entry at each sample.
        history = crank.clearance.tracker.history()
        last = np.searchsorted(history["time"], out["time"], side="right") - 1
        out["in_contact"] = history["in_contact"][last]
        out["impact_velocity"] = history["impact_velocity"][last]
        out["model"] = crank.clearance
    return out



def ideal_slider_acceleration(theta, omega: float = CRANK_SPEED):
    """Slider acceleration of the ideal slider-crank at constant crank speed, m/s^2.

    x = r cos(theta) + S with S = sqrt(l^2 - r^2 sin^2 theta), theta_dot = omega:

        a = omega^2 (-r cos(theta) - r^2 cos(2 theta) / S - r^4 sin^2(theta) cos^2(theta) / S^3)

    (e.g. Norton, Design of Machinery, section 13.3; the exact form, not the two-term series).
    """
    r, l = CRANK_LENGTH, ROD_LENGTH
    s, c = np.sin(theta), np.cos(theta)
    big_s = np.sqrt(l * l - (r * s) ** 2)
    return omega**2 * (-r * c - r * r * np.cos(2.0 * theta) / big_s - r**4 * s * s * c * c / big_s**3)


# The lubricated pin of Flores, Ambrosio, Claro and Lankarani (Mech. Mach. Theory 41, 2006): journal and
# bearing radii 9.5 and 10 mm (c = 0.5 mm as in the dry pin), bearing length 40 mm, oil of 400 cP.
LUBRICATED_JOURNAL_RADIUS, LUBRICATED_BEARING_LENGTH, OIL_VISCOSITY = 9.5e-3, 40e-3, 0.4  # m, m, Pa s


def lubricated_joint(model: str | None = "short_half") -> ClearanceJoint:
    """The pin B of the lubricated slider-crank (Flores et al. 2006); ``model=None``: the same pin dry.

    ``model`` is the film model of :class:`~weftsim.input.params.Lubrication` (``"short_half"``: the short
    bearing as the paper writes it; ``"finite"``: weftsim's finite-length film).  Roughness and asperity
    parameters are weftsim's defaults (the paper has no asperity contact); the dry contact law beyond
    e = c is the dry example's.
    """
    from dataclasses import replace

    from weftsim.input.params import Lubrication

    lubrication = None if model is None else Lubrication(viscosity=OIL_VISCOSITY, model=model)
    return replace(flores_joint(), journal_radius=LUBRICATED_JOURNAL_RADIUS,
                   bearing_length=LUBRICATED_BEARING_LENGTH, lubrication=lubrication)  # fmt: skip
