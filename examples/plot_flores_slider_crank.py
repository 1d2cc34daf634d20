"""
Flores slider-crank: a revolute clearance joint between rod and slider
======================================================================

The classic benchmark of the clearance-joint literature (Flores and Ambrosio, Comput. Struct. 82,
2004): a slider-crank whose piston pin B, between the connecting rod and the slider, has a radial
clearance of 0.5 mm, the crank driven at 5000 rpm.  The pin is modelled with weftsim's reusable
Exudyn joint, :func:`weftsim.exudyn_engine.add_clearance_joint`, and the Lankarani-Nikravesh law.

The example

- builds the mechanism in an Exudyn system (crank and rod rigid bodies, slider a mass point),
- runs its own step-size study of the peak contact force and of the slider acceleration over the
  steady crank revolutions, with the energy balance (the ideal joint is checked against the
  slider-crank's closed form, the start-up impact against a one-degree-of-freedom model),
- draws the journal centre's orbit inside the clearance circle, impacts marked.

Run it as a script: ``python examples/plot_flores_slider_crank.py`` (coarse steps, seconds) or
``python examples/plot_flores_slider_crank.py --fine`` (the full study, minutes).  docs/clearance-joint.md
discusses the results against the paper.
"""

# %%
# The mechanism
# -------------
# Crank OA (length r, turning about O at constant speed omega) - rod AB (length l) - slider B on
# the X axis, all in Exudyn's XY plane, gravity along -Y.  At B the slider carries the bearing
# (radius R_b = R_j + c) and the rod the journal (radius R_j); the
# :class:`~weftsim.params.ClearanceJoint` is given every value explicitly.  Parameters of Flores
# and Ambrosio (2004); assumed here: the crank and rod centres of mass at their midpoints.  The
# crank angle theta starts at 0 (B at its outer dead centre), the journal centred,
# every velocity that of the ideal mechanism.

from __future__ import annotations

import argparse
import math
import sys
from typing import NamedTuple

import exudyn as exu
import matplotlib.pyplot as plt
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
from weftsim.params import ClearanceJoint, Material

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

    With friction the joint's torque loads depend on the velocities and the friction ramp is a
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
    friction = joint is not None and joint.friction_coefficient > 0.0
    exu.MainSolverImplicitSecondOrder().SolveSystem(mbs, settings(step, revolutions * REVOLUTION, friction))
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


def _cumulative(rate, time):
    """Trapezoid integral of ``rate`` over ``time`` from the first sample."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(time))])


def energy_balance(run: dict) -> dict:
    """Energy terms since t = 0, J: driving work = kinetic + potential + contact + dissipated + rest.

    The drive's work is the trapezoid sum of T omega (T the velocity constraint's force on the crank
    coordinate); kinetic and potential energy of the three bodies; the contact's elastic energy
    ``law.elastic_energy(delta)`` and the work of its damping term, the trapezoid sum of
    (F_N - F_el(delta)) delta_dot.  ``residual`` = work - the others: the integrator's own
    dissipation (generalized-alpha, spectral radius 0.8) and the quadrature error of the sums;
    with friction it also holds the friction work, which this balance does not separate.
    """
    t, theta = run["time"], run["theta"]
    r, omega = CRANK_LENGTH, CRANK_SPEED
    crank_inertia = CRANK_INERTIA + CRANK_MASS * (r / 2.0) ** 2  # about O
    rod = 0.5 * ROD_MASS * np.sum(run["rod_velocity"] ** 2, axis=1) + 0.5 * ROD_INERTIA * run["rod_rate"] ** 2
    kinetic = 0.5 * crank_inertia * omega**2 + rod + 0.5 * SLIDER_MASS * run["slider_velocity"] ** 2
    potential = GRAVITY * (CRANK_MASS * 0.5 * r * np.sin(theta) + ROD_MASS * run["rod_height"])
    terms = {"work": _cumulative(-run["drive_force"] * omega, t), "kinetic": kinetic - kinetic[0],
             "potential": potential - potential[0]}  # fmt: skip
    if "model" in run:
        law = run["model"].law
        delta = np.linalg.norm(run["eccentricity"], axis=1) - run["model"].joint.clearance
        elastic = law.elastic_force(delta)
        terms["contact"] = law.elastic_energy(delta)
        terms["dissipated"] = _cumulative((run["normal_force"] - elastic) * run["penetration_rate"], t)
    terms["residual"] = terms["work"] - sum(v for k, v in terms.items() if k != "work")
    return terms


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


def start_up_impact(joint: ClearanceJoint) -> dict:
    """The first impact from a one-degree-of-freedom model, integrated with scipy (rtol 1e-11).

    The journal starts centred and the slider at rest at the dead centre, so the slider does not
    move until the journal, pulled inwards by the rod at r omega^2 (1 + r / l), has crossed the
    clearance: it hits the slider almost along the rod (theta ~ 7 deg).  Along the rod the journal
    is driven by the crank (prescribed speed), so this impact is, to first order, the slider mass
    m_s hitting a wall that moves as the ideal pin B, x_B(t) (:func:`ideal_slider_acceleration`):

        delta = x_s - x_B(t) - c,   m_s x_s'' = -F_N(delta, delta_dot, v_imp),   delta_dot = x_s' - x_B'

    What it leaves out: the rod's angle (cos 7 deg = 0.993 of the push along X) and its rotation.

    Returns
    -------
    dict
        ``onset_time`` (s), ``impact_velocity`` (m/s), ``peak_force`` (N), ``max_penetration`` (m),
        ``duration`` (s, onset to separation).
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    from weftsim.contact import make_law

    r, l, omega, c = CRANK_LENGTH, ROD_LENGTH, CRANK_SPEED, joint.clearance
    force = make_law(joint).scalar()

    def pin(t):
        s, co = math.sin(omega * t), math.cos(omega * t)
        big_s = math.sqrt(l * l - (r * s) ** 2)
        return r * co + big_s, -omega * (r * s + r * r * s * co / big_s)

    x0 = r + l
    onset = brentq(lambda t: x0 - pin(t)[0] - c, 0.0, 0.25 * REVOLUTION, xtol=1e-16, rtol=1e-15)
    v_imp = -pin(onset)[1]

    def rhs(t, y):
        x_b, v_b = pin(t)
        return [y[1], -force(y[0] - x_b - c, y[1] - v_b, v_imp) / SLIDER_MASS]

    def separated(t, y):
        return y[0] - pin(t)[0] - c

    separated.terminal, separated.direction = True, -1.0
    sol = solve_ivp(rhs, (onset, onset + 0.05 * REVOLUTION), [x0, 0.0], method="DOP853", rtol=1e-11,
                    atol=1e-15, events=separated, dense_output=True, first_step=1e-9)  # fmt: skip
    t = np.linspace(sol.t[0], sol.t[-1], 20001)
    x_b, v_b = np.array([pin(ti) for ti in t]).T
    y = sol.sol(t)
    f = np.array([force(d, v, v_imp) for d, v in zip(y[0] - x_b - c, y[1] - v_b)])
    return {"onset_time": onset, "impact_velocity": v_imp, "peak_force": float(f.max()),
            "max_penetration": float((y[0] - x_b - c).max()), "duration": float(sol.t[-1] - onset)}  # fmt: skip


def first_contact(run: dict) -> slice:
    """Indices of the first contact (start-up impact): from its onset to the first separation."""
    inside = run["in_contact"] > 0.0
    start = int(np.argmax(inside))
    stop = start + int(np.argmax(~inside[start:]))
    return slice(start, stop)


def revolution_statistics(run: dict, skip: int = 1) -> dict:
    """Per crank revolution after the first ``skip``: peak F_N, peak |a_slider| and RMS a_slider."""
    n = int(round(run["time"][-1] / REVOLUTION))
    peaks, acc_peaks, acc_rms = [], [], []
    for k in range(skip, n):
        sel = (run["time"] >= k * REVOLUTION) & (run["time"] < (k + 1) * REVOLUTION)
        a = run["slider_acceleration"][sel]
        peaks.append(run["normal_force"][sel].max())
        acc_peaks.append(np.abs(a).max())
        acc_rms.append(math.sqrt(np.mean(a * a)))
    return {"peak_force": np.array(peaks), "peak_acceleration": np.array(acc_peaks),
            "rms_acceleration": np.array(acc_rms)}  # fmt: skip


STUDY_COLUMNS = {  # label: (row key, unit scale, format)
    "start-up F_N (kN)": ("startup_peak", 1e-3, "{:.4f}"),
    "steady peak F_N (kN)": ("peak_force", 1e-3, "{:.2f}"),
    "steady peak |a| (km/s2)": ("peak_acceleration", 1e-3, "{:.1f}"),
    "steady RMS a (km/s2)": ("rms_acceleration", 1e-3, "{:.2f}"),
}


def convergence_study(steps, revolutions: int, friction_coefficient: float = 0.0) -> list[dict]:
    """Run the clearance model at every step; one row per step (steady values: mean over revolutions 2..).

    The peak of the start-up impact is a converged quantity (an isolated impact from a defined
    state); the steady values are means over revolutions of a motion whose impact sequence is
    sensitive to any perturbation, so each carries its standard error (``*_sem``) and the
    change on halving is only meaningful against it.  If the installed weftsim refuses friction,
    the study returns one row with the ``error`` it raised.
    """
    rows = []
    for step in steps:
        try:
            run = simulate(step, revolutions, flores_joint(friction_coefficient))
        except NotImplementedError as err:
            return [{"step": step, "error": str(err)}]
        stats = revolution_statistics(run)
        energy = energy_balance(run)
        row = {"step": step, "startup_peak": float(run["normal_force"][first_contact(run)].max()),
               "contacts_per_revolution": run["model"].tracker.contact_events / revolutions,
               "dissipated": float(energy["dissipated"][-1]),
               "energy_residual": float(np.abs(energy["residual"]).max()),
               "run": run}  # fmt: skip
        for key, values in stats.items():
            row[key + "_range"] = (float(values.min()), float(values.max()))
            row[key] = float(values.mean())
            row[key + "_sem"] = float(values.std(ddof=1) / math.sqrt(len(values))) if len(values) > 1 else math.nan
        rows.append(row)
    return rows


def format_study(rows: list[dict]) -> str:
    """Markdown table: step, the values of :data:`STUDY_COLUMNS` and their relative change on halving."""
    if "error" in rows[0]:
        return f"not run: {rows[0]['error']}"
    head = ["step (s)"] + [f"{label} (change)" for label in STUDY_COLUMNS]
    head += ["contacts/rev", "dissipated (J)", "max energy residual (J)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for i, row in enumerate(rows):
        cells = [f"{row['step']:.3g}"]
        for key, scale, fmt in STUDY_COLUMNS.values():
            value = fmt.format(row[key] * scale)
            if key + "_sem" in row:
                value += " +- " + fmt.format(row[key + "_sem"] * scale)
            change = f" ({row[key] / rows[i - 1][key] - 1.0:+.1e})" if i else ""
            cells.append(value + change)
        cells += [f"{row['contacts_per_revolution']:.1f}", f"{row['dissipated']:.3f}", f"{row['energy_residual']:.1e}"]
        lines.append("| " + " | ".join(cells) + " |")
    spans = []
    for label, (key, scale, _) in list(STUDY_COLUMNS.items())[1:]:
        low = min(row[key + "_range"][0] for row in rows) * scale
        high = max(row[key + "_range"][1] for row in rows) * scale
        spans.append(f"{label.replace('steady ', '')} {low:.3g} .. {high:.3g}")
    lines.append("\nsingle steady revolutions, all steps: " + "; ".join(spans))
    return "\n".join(lines)


def impacts(run: dict) -> np.ndarray:
    """Indices of the first accepted state of every contact (onsets)."""
    inside = run["in_contact"] > 0.0
    return np.flatnonzero(inside[1:] & ~inside[:-1]) + 1


def plot_orbit(run: dict, revolution: int = 1, ax=None):
    """Journal centre relative to the bearing centre (mm) over one crank revolution, impacts marked."""
    if ax is None:
        ax = plt.figure(figsize=(5.2, 5.6)).add_subplot()
    c = run["model"].joint.clearance * 1e3
    keep = (run["time"] >= revolution * REVOLUTION) & (run["time"] <= (revolution + 1) * REVOLUTION)
    e = run["eccentricity"] * 1e3
    hits = impacts(run)
    hits = hits[keep[hits]]
    angle = np.linspace(0.0, 2.0 * math.pi, 361)
    ax.plot(c * np.cos(angle), c * np.sin(angle), "k--", lw=0.8, label=f"clearance circle, c = {c:g} mm")
    ax.plot(e[keep, 0], e[keep, 1], lw=0.8, label="journal centre")
    ax.plot(e[hits, 0], e[hits, 1], "rx", ms=6, label=f"impacts ({len(hits)})")
    ax.set(xlabel="e_x (mm), along the slider's rail", ylabel="e_y (mm)", aspect="equal",
           xlim=(-1.2 * c, 1.2 * c), ylim=(-1.2 * c, 1.2 * c),
           title=f"Journal orbit, revolution {revolution + 1}")  # fmt: skip
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=7)
    return ax.figure


def plot_acceleration(run: dict, ideal: dict, revolution: int = 1, ax=None):
    """Slider acceleration over one crank revolution against the ideal joint's closed form."""
    if ax is None:
        ax = plt.figure(figsize=(7.0, 3.6)).add_subplot()
    sel = (run["time"] >= revolution * REVOLUTION) & (run["time"] < (revolution + 1) * REVOLUTION)
    deg = np.degrees(run["theta"][sel]) - 360.0 * revolution
    ax.plot(deg, run["slider_acceleration"][sel] * 1e-3, lw=0.6, label="clearance c = 0.5 mm")
    ax.plot(deg, ideal_slider_acceleration(run["theta"][sel]) * 1e-3, "k", lw=1.2, label="ideal joint (closed form)")
    ax.set(xlabel="crank angle (deg)", ylabel="slider acceleration (km/s$^2$)", xlim=(0, 360),
           title=f"Slider acceleration, revolution {revolution + 1}")  # fmt: skip
    ax.legend(fontsize=7)
    return ax.figure


def options() -> argparse.Namespace:
    """Command-line options; sphinx-gallery (and an import) get the defaults: the coarse study."""
    parser = argparse.ArgumentParser(description="Flores slider-crank with a clearance joint")
    parser.add_argument("--fine", action="store_true", help="full step-size study (minutes)")
    parser.add_argument("--save", metavar="DIR", help="write the figures as DIR/flores_*.png")
    return parser.parse_known_args(sys.argv[1:] if __name__ == "__main__" else [])[0]


# %%
# Ideal joint against the closed form
# -----------------------------------
# With an ideal revolute joint at B the slider's acceleration is that of the slider-crank at
# constant crank speed, peak r omega^2 (1 + r / l) = 19.42 km/s^2 at theta = 0.

OPTIONS = options()
FINE = OPTIONS.fine
COARSE_STEPS, FINE_STEPS = (2e-6, 1e-6, 5e-7), (2e-6, 1e-6, 5e-7, 2.5e-7, 1.25e-7)
STEPS = FINE_STEPS if FINE else COARSE_STEPS
REVOLUTIONS = 21 if FINE else 3  # the first revolution holds the start-up impacts

ideal = simulate(STEPS[-1], 1.0)
ideal_error = np.abs(ideal["slider_acceleration"] - ideal_slider_acceleration(ideal["theta"])).max()
ideal_rms = math.sqrt(np.mean(ideal["slider_acceleration"] ** 2))
print(f"ideal joint, h = {STEPS[-1]:.3g} s: peak |a| {np.abs(ideal['slider_acceleration']).max():.1f} m/s^2, "
      f"RMS {ideal_rms:.1f} m/s^2, largest deviation from the closed form {ideal_error:.2e} m/s^2")  # fmt: skip

# %%
# The start-up impact
# -------------------
# Started centred, the journal crosses the clearance in 0.23 ms and hits the resting slider at
# about 4.4 m/s: the hardest impact of the run.  A one-degree-of-freedom model of it
# (:func:`start_up_impact`) gives its peak force and penetration independently of Exudyn.

impact = start_up_impact(flores_joint())
print(f"1-DOF start-up impact: onset {impact['onset_time'] * 1e3:.5f} ms, v_imp {impact['impact_velocity']:.4f} m/s, "
      f"peak F_N {impact['peak_force']:.1f} N, max penetration {impact['max_penetration'] * 1e6:.3f} um, "
      f"duration {impact['duration'] * 1e6:.1f} us")  # fmt: skip

# %%
# Step-size study, without friction
# ---------------------------------
# Peak contact force of the start-up impact and, over the steady revolutions (2 onwards), the mean
# per revolution of the peak contact force, of the peak slider acceleration and of its RMS value,
# each +- its standard error over the revolutions; in brackets the relative change on halving
# the step.

study = convergence_study(STEPS, REVOLUTIONS)
print(format_study(study))

# %%
# Step-size study, with friction
# ------------------------------
# The same with the modified Coulomb friction of the joint, mu = FLORES_FRICTION.  A weftsim whose
# Exudyn joint does not carry friction yet says so here instead of running.  The energy residual
# then includes the friction work.

# Friction makes every step several times dearer (full Newton, loads Jacobian): the coarse run
# keeps two steps and two revolutions.
friction_study = convergence_study(STEPS if FINE else STEPS[:2], REVOLUTIONS if FINE else 2, FLORES_FRICTION)
print(f"mu = {FLORES_FRICTION}:")
print(format_study(friction_study))

# %%
# Orbit of the journal centre
# ---------------------------
# Finest step, the second crank revolution: the journal runs along the bearing wall (continuous
# contact, with small rebounds) over much of the revolution and crosses the clearance (free
# flight, then an impact) where the load on the pin reverses.

orbit = plot_orbit(study[-1]["run"])

# %%
# Slider acceleration
# -------------------

acceleration = plot_acceleration(study[-1]["run"], ideal)

if OPTIONS.save:
    orbit.savefig(f"{OPTIONS.save}/flores_orbit.png", dpi=120, bbox_inches="tight")
    acceleration.savefig(f"{OPTIONS.save}/flores_acceleration.png", dpi=120, bbox_inches="tight")
if __name__ == "__main__" and not OPTIONS.save:
    plt.show()
