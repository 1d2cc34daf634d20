"""A slider-crank with a clearance joint at the piston pin: the reusable Exudyn clearance joint.

Usage::

    python scripts/example_slider_crank.py

Crank OA (driven at constant speed) - rod AB - slider B on the X axis, all 2-D bodies in
Exudyn's XY plane.  The pin B has a radial clearance: bearing on the slider, journal on the
rod, joined by :func:`weftsim.exudyn_engine.add_clearance_joint` instead of a revolute joint.
A constant force P pushes the slider towards the crank, so after the first impacts the
journal rests on the bearing (|e| = c + delta, delta ~ 2 um << c = 0.1 mm) and the slider's
equilibrium gives the joint force in closed form::

    n = e / |e|,   slider along X:  F_N n_x = P + m_slider a_slider
    quasi-static penetration:       F_el(delta) = F_N   (damping term xi delta_dot / v_imp small)

The script prints those against the simulation over the second half of the run, and the
angle between e and the rod: without friction the journal swings slowly around the
bearing (a tangential mode that only the numerical damping touches), so e leans a few
degrees off the rod axis that a massless two-force rod would give.
"""

from __future__ import annotations

import math

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    LoadForceVector,
    MarkerBodyPosition,
    NodePoint2D,
    ObjectJointRevolute2D,
    ObjectMassPoint2D,
    SensorBody,
    SensorNode,
    SensorObject,
)
from exudyn.rigidBodyUtilities import RigidBodyInertia
from scipy.optimize import brentq

from weftsim.exudyn_engine import add_clearance_joint
from weftsim.input.params import ClearanceJoint

CRANK, ROD = 0.05, 0.20  # lengths, m
ROD_MASS, SLIDER_MASS = 0.3, 0.5  # kg
LOAD = 500.0  # P, N, on the slider along -X
SPEED = 2.0 * math.pi  # crank speed, rad/s (60 rpm: inertia forces ~1 % of P)


def _rot(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def build(mbs, joint: ClearanceJoint, callback: str = "auto"):
    """Slider-crank at crank angle 0 (pin A at (r, 0)), ideal velocities, journal centred."""
    ground = mbs.CreateGround()
    store = {"storeInternal": True, "writeToFile": False}
    crank = mbs.CreateRigidBody(inertia=RigidBodyInertia(1.0, np.eye(3) * 1e-3), create2D=True,
                                initialAngularVelocity=[0.0, 0.0, SPEED], returnDict=True)  # fmt: skip
    # Rod from A = (r, 0) to B = (r + l, 0): angular velocity -r omega / l, centre velocity (0, r omega / 2).
    rod = mbs.CreateRigidBody(
        inertia=RigidBodyInertia(ROD_MASS, np.eye(3) * ROD_MASS * ROD**2 / 12.0, inertiaTensorAtCOM=True),
        referencePosition=[CRANK + ROD / 2.0, 0.0, 0.0], referenceRotationMatrix=_rot(0.0),
        initialVelocity=[0.0, CRANK * SPEED / 2.0, 0.0], initialAngularVelocity=[0.0, 0.0, -CRANK * SPEED / ROD],
        create2D=True, returnDict=True,
    )  # fmt: skip
    slider_node = mbs.AddNode(NodePoint2D(referenceCoordinates=[CRANK + ROD, 0.0]))
    slider = mbs.AddObject(ObjectMassPoint2D(nodeNumber=slider_node, mass=SLIDER_MASS))

    def pin(body0, local0, body1, local1):
        m0 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=body0, localPosition=local0))
        m1 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=body1, localPosition=local1))
        return [m0, m1]

    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=pin(ground, [0.0] * 3, crank["bodyNumber"], [0.0] * 3)))
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=pin(crank["bodyNumber"], [CRANK, 0.0, 0.0],
                                                          rod["bodyNumber"], [-ROD / 2.0, 0.0, 0.0])))  # fmt: skip
    mbs.CreateCoordinateConstraint(itemNumbers=[None, slider_node], coordinates=[None, 1])  # slider on the X axis
    mbs.CreateCoordinateConstraint(itemNumbers=[None, crank["nodeNumber"]], coordinates=[None, 2],
                                   offset=SPEED, velocityLevel=True)  # fmt: skip
    bearing, journal = pin(slider, [0.0] * 3, rod["bodyNumber"], [ROD / 2.0, 0.0, 0.0])
    mbs.AddLoad(LoadForceVector(markerNumber=bearing, loadVector=[-LOAD, 0.0, 0.0]))
    clearance = add_clearance_joint(mbs, bearing, journal, joint, callback=callback)

    ovt = exu.OutputVariableType
    rod_body, conn = rod["bodyNumber"], clearance.connector
    sensors = {
        "crank": SensorNode(nodeNumber=crank["nodeNumber"], outputVariableType=ovt.Coordinates, **store),
        "slider_a": SensorNode(nodeNumber=slider_node, outputVariableType=ovt.Coordinates_tt, **store),
        "pin_a": SensorBody(bodyNumber=rod_body, localPosition=[-ROD / 2.0, 0.0, 0.0],
                            outputVariableType=ovt.Position, **store),
        "pin_b": SensorBody(bodyNumber=rod_body, localPosition=[ROD / 2.0, 0.0, 0.0],
                            outputVariableType=ovt.Position, **store),
        "ecc": SensorObject(objectNumber=conn, outputVariableType=ovt.Displacement, **store),
        "force": SensorObject(objectNumber=conn, outputVariableType=ovt.Force, **store),
    }  # fmt: skip
    sensors = {name: mbs.AddSensor(sensor) for name, sensor in sensors.items()}
    return clearance, sensors


def run(joint: ClearanceJoint | None = None, end_time: float = 0.25, step: float = 5e-6, callback: str = "auto"):
    """Simulate; returns a dict of arrays over the second half of the run and the clearance model."""
    joint = joint or ClearanceJoint(clearance=0.1e-3, law="lankarani_nikravesh")
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    clearance, sensors = build(mbs, joint, callback)
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.endTime = end_time
    settings.timeIntegration.numberOfSteps = round(end_time / step)
    settings.timeIntegration.generalizedAlpha.spectralRadius = 0.8
    settings.timeIntegration.discontinuous.ignoreMaxIterations = False
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = 0.0
    settings.solution.solverInformationFileName = ""
    exu.MainSolverImplicitSecondOrder().SolveSystem(mbs, settings)
    data = {k: mbs.GetSensorStoredData(v) for k, v in sensors.items()}
    keep = data["crank"][:, 0] >= 0.5 * end_time
    rod = data["pin_b"][keep, 1:3] - data["pin_a"][keep, 1:3]
    u = rod / np.linalg.norm(rod, axis=1)[:, None]
    return {
        "time": data["crank"][keep, 0],
        "rod_direction": u,
        "slider_acceleration": data["slider_a"][keep, 1],
        "eccentricity": data["ecc"][keep, 1:3],
        "normal_force": np.linalg.norm(data["force"][keep, 1:3], axis=1),
    }, clearance


def statics(result: dict, law) -> dict:
    """Joint force from the slider's equilibrium along X and the quasi-static penetration."""
    e = result["eccentricity"]
    n_x = e[:, 0] / np.linalg.norm(e, axis=1)
    force = (LOAD + SLIDER_MASS * result["slider_acceleration"]) / n_x
    hi = 1e-3
    delta = np.array([brentq(lambda d, f=f: float(law.elastic_force(d)) - f, 0.0, hi, xtol=1e-15) for f in force])
    return {"normal_force": force, "penetration": delta}


def main(end_time: float = 0.25, step: float = 5e-6) -> None:
    result, clearance = run(end_time=end_time, step=step)
    closed = statics(result, clearance.law)
    c = clearance.joint.clearance
    ecc = result["eccentricity"]
    length = np.linalg.norm(ecc, axis=1)
    angle = np.degrees(np.arccos(np.clip(np.sum(ecc * result["rod_direction"], axis=1) / length, -1.0, 1.0)))
    print(f"clearance {c * 1e3} mm, law {clearance.law.name}, callback route {clearance.route}, "
          f"contact events {clearance.tracker.contact_events}")  # fmt: skip
    print(f"second half of the run ({len(length)} steps):")
    pen, stat = 1e6 * (length - c), 1e6 * closed["penetration"]
    print(f"  |e| - c            {pen.min():7.3f} .. {pen.max():7.3f} um   "
          f"statics {stat.min():7.3f} .. {stat.max():7.3f} um")  # fmt: skip
    rel = np.abs(result["normal_force"] / closed["normal_force"] - 1.0)
    print(f"  F_N / statics - 1  max {rel.max():.2e}")
    print(f"  angle(e, rod)      max {angle.max():.3f} deg")


if __name__ == "__main__":
    main()
