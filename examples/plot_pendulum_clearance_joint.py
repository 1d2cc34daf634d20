"""
The reusable clearance joint on a pendulum
==========================================

:func:`weftsim.exudyn_engine.add_clearance_joint` puts a planar revolute clearance joint between any
two bodies of an Exudyn model, with any contact law of :mod:`weftsim.joint.contact`. Here it replaces the
pin of a pendulum: a 1 kg bar, 0.2 m long, hangs by a journal of radius 10 mm in a bearing with a
radial clearance c = 0.1 mm. The bar is released at 60 degrees with the journal centred; the journal
falls onto the bearing wall, bounces, and then slides along the wall as the bar swings, pressed by
gravity and the centripetal force.

The bar swings like a rigid pendulum pinned at the bearing centre, and the contact force follows the
pin force of that rigid pendulum (weight plus centripetal and tangential inertia loads), with an
oscillation on top: after the bounces the bar keeps vibrating on the contact's stiffness, which the
law's damping barely touches in a lasting contact. While the journal rides on the wall its
penetration is where the law's elastic force carries the contact force, ``F_el(delta) = F_N``.
"""

# %%
# Build the model
# ---------------
# The bearing is a marker on the ground at the origin, the journal a marker at the top end of the
# bar; both move in Exudyn's XY plane. The joint takes the place of ``ObjectJointRevolute2D``.
import math

import exudyn as exu
import numpy as np
from exudyn.itemInterface import MarkerBodyPosition, SensorBody, SensorObject
from exudyn.rigidBodyUtilities import RigidBodyInertia

from weftsim.exudyn_engine import add_clearance_joint
from weftsim.input.params import ClearanceJoint

MASS, LENGTH, GRAVITY = 1.0, 0.2, 9.81  # kg, m, m/s^2: a uniform bar hanging from one end
RELEASE = math.radians(60.0)  # initial angle of the bar from the downward vertical
joint = ClearanceJoint(clearance=0.1e-3, journal_radius=10e-3, law="lankarani_nikravesh")

sc = exu.SystemContainer()
mbs = sc.AddSystem()
ground = mbs.CreateGround()
half = 0.5 * LENGTH
centre = [half * math.sin(RELEASE), -half * math.cos(RELEASE), 0.0]  # centre of mass, journal at the origin
bar = mbs.CreateRigidBody(
    inertia=RigidBodyInertia(MASS, np.diag([1.0, 1.0, 1.0]) * MASS * LENGTH**2 / 12.0, inertiaTensorAtCOM=True),
    referencePosition=centre, referenceRotationMatrix=exu.rigidBodyUtilities.RotationMatrixZ(RELEASE),
    create2D=True, gravity=[0.0, -GRAVITY, 0.0],
)
bearing = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
journal = mbs.AddMarker(MarkerBodyPosition(bodyNumber=bar, localPosition=[0.0, half, 0.0]))
model = add_clearance_joint(mbs, bearing, journal, joint)

store = {"storeInternal": True, "writeToFile": False}
ovt = exu.OutputVariableType
eccentricity = mbs.AddSensor(SensorObject(objectNumber=model.connector, outputVariableType=ovt.Displacement, **store))
force = mbs.AddSensor(SensorObject(objectNumber=model.connector, outputVariableType=ovt.Force, **store))
angle = mbs.AddSensor(SensorBody(bodyNumber=bar, outputVariableType=ovt.Rotation, **store))
rate = mbs.AddSensor(SensorBody(bodyNumber=bar, outputVariableType=ovt.AngularVelocity, **store))
mbs.Assemble()
model.reset(mbs)

# %%
# Simulate half a second
# ----------------------
# Generalized-alpha with a fixed step of 5 us: the contact lasts ~0.1 ms per impact, so the step
# resolves each impact with about 20 steps (the Exudyn engine's loom model uses 2 us for 0.5 %).
settings = exu.SimulationSettings()
settings.timeIntegration.endTime = 0.5
settings.timeIntegration.numberOfSteps = 100_000
settings.timeIntegration.generalizedAlpha.spectralRadius = 0.8
settings.timeIntegration.newton.useModifiedNewton = True
settings.timeIntegration.verboseMode = 0
settings.solution.file.write = False
settings.solution.sensors.writePeriod = 0.0
settings.solution.solverInformationFileName = ""
assert exu.SolveDynamic(mbs, settings)

e = mbs.GetSensorStoredData(eccentricity)
t, ey, ez = e[:, 0], e[:, 1], e[:, 2]
f = mbs.GetSensorStoredData(force)
f_n = np.hypot(f[:, 1], f[:, 2])
psi = RELEASE + mbs.GetSensorStoredData(angle)[:, 1]  # bar angle from the downward vertical, rad (the sensor
# gives the rotation about Z from the reference orientation)
omega = mbs.GetSensorStoredData(rate)[:, -1]
print(f"{len(t)} steps, {model.tracker.contact_events} contact onsets, "
      f"first contact at {1e3 * model.tracker.first_contact_time:.2f} ms")

# %%
# Comparison with closed forms
# ----------------------------
# A rigid bar pinned at one end, swinging through psi with angular velocity omega, loads its pin with
# m (g cos psi + (L/2) omega^2) along the bar (weight and centripetal force) and m (g sin psi + (L/2)
# alpha) across it. Averaged over 20 ms (a few periods of the contact vibration) the contact force
# follows that pin force. The penetration is where the law's elastic force equals the contact force
# (the damping term is small in a slow, lasting contact).
from scipy.optimize import brentq

from weftsim.joint.contact import make_law

law = make_law(joint)
alpha = -(GRAVITY / half) * (3.0 / 4.0) * np.sin(psi)  # angular acceleration of the bar: I_pin = m L^2 / 3
radial = MASS * (GRAVITY * np.cos(psi) + half * omega**2)
tangential = MASS * (GRAVITY * np.sin(psi) + half * alpha)
pin_force = np.hypot(radial, tangential)
late = t > 0.2  # after the bounces
penetration = np.hypot(ey, ez) - joint.clearance
static = np.array([brentq(lambda d, F=F: float(law.elastic_force(d)) - F, 1e-15, joint.clearance)
                   for F in f_n[late][::500]])
window = np.ones(4000) / 4000  # 20 ms of 5 us steps
mean_force, mean_pin, mean_t = (np.convolve(x, window, "valid") for x in (f_n, pin_force, t))
settled = mean_t > 0.12
print(f"contact force / rigid-pendulum pin force, 20 ms means after the bounces: "
      f"{np.min(mean_force[settled] / mean_pin[settled]):.3f} .. {np.max(mean_force[settled] / mean_pin[settled]):.3f}")
print(f"penetration / static penetration F_el(delta) = F_N: "
      f"{np.min(penetration[late][::500] / static):.4f} .. {np.max(penetration[late][::500] / static):.4f}")

# %%
# The swing and the contact force
# -------------------------------
from matplotlib.figure import Figure

swing = Figure(figsize=(7, 5))
ax1, ax2 = swing.subplots(2, 1, sharex=True)
ax1.plot(t * 1e3, np.degrees(psi))
ax1.set_ylabel("bar angle [deg]")
ax2.plot(t * 1e3, f_n, lw=0.8, label="contact force $F_N$ (simulated)")
ax2.plot(t * 1e3, pin_force, lw=0.8, ls="--", label="pin force of a rigid pendulum")
ax2.set_ylabel("force [N]")
ax2.set_xlabel("time [ms]")
ax2.plot(mean_t * 1e3, mean_force, lw=1.5, label="contact force, 20 ms mean")
ax2.set_ylim(0.0, 3.0 * pin_force.max())
ax2.legend(fontsize=8)
for ax in (ax1, ax2):
    ax.grid(alpha=0.3)
swing.tight_layout()

# %%
# The journal in its clearance
# ----------------------------
# The journal centre relative to the bearing centre: it falls from the centre, bounces on the wall
# and then rides on the wall, following the direction of the bar.
orbit = Figure(figsize=(5.5, 5.5))
ax = orbit.subplots()
circle = np.linspace(0.0, 2.0 * np.pi, 361)
c_mm = joint.clearance * 1e3
ax.plot(c_mm * np.cos(circle), c_mm * np.sin(circle), color="0.3", label=f"clearance circle, c = {c_mm:g} mm")
ax.plot(ey * 1e3, ez * 1e3, lw=0.6, label="journal centre")
ax.set_aspect("equal")
ax.set_xlabel("eccentricity x [mm]")
ax.set_ylabel("eccentricity y [mm]")
ax.legend(fontsize=8, loc="upper right")
ax.grid(alpha=0.3)
orbit.tight_layout()
