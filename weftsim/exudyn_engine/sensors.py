"""Sensors of the mechanism and their conversion to the result channels.

Every sensor stores internally at every accepted step (``storeInternal=True``,
``writePeriod = 0``, no files).  Channels (docs/physics.md section 4 signs; Exudyn frame in mechanism.py)::

    crank angle       theta = rz of the crank node
    rapier s, v, a    (d5 d7/d6) x (angle, rate, acceleration of the sector node)
    driving torque    T = -lambda_drive (the motor's torque on the crank about +z)
    contact           per clearance joint (E: the unsuffixed channels, F: the ``_f`` channels)
                      e = connector Displacement (X, Y) = model (y, z); F_N = |connector Force|;
                      delta = |e| - c, delta_dot = e_dot . e/|e|; held impact velocity and
                      contact flag from the tracker
    kinetic energy    sum of the bodies' KineticEnergy outputs
    potential energy  sum of m g Y_com (gravity along -Y)
    contact energy    law.elastic_energy(delta), summed over the clearance joints
    driving work      integral T dtheta (trapezoid over accepted steps; theta_dot = omega)
    dissipated        integral (F_N - F_el(delta)) delta_dot - F_T v_T dt (trapezoid over accepted
                      steps), the energy the contact damping and friction take out (all clearance
                      joints; with friction, F_N and F_T v_T come from the joint's record of every
                      accepted state, joint_friction.py, since the connector's force then also holds F_T t)

The trapezoid rules have errors O(h^2) per step; the integrator's own numerical
dissipation (generalized-alpha, spectral radius < 1) is not in any channel, so the
balance W = dKE + dPE + contact + dissipated closes only up to it (tests bound it).
"""

from __future__ import annotations

import exudyn as exu
import numpy as np
from exudyn.itemInterface import SensorBody, SensorNode, SensorObject

from weftsim.exudyn_engine.mechanism import CRANK_COORDINATE, ROTATION_2D, MechanismModel
from weftsim.post.results import (
    CHANNELS, CONTACT_CHANNELS, JOINT_E_NAME, JOINT_F_CHANNELS, LUBRICATION_CHANNELS, LUBRICATION_CHANNELS_F,
    optional_channels,
)  # fmt: skip

OVT = exu.OutputVariableType


def _sensor(mbs, item):
    return mbs.AddSensor(item)


def add_sensors(mbs: exu.MainSystem, model: MechanismModel) -> dict:
    """Add every sensor the channels need; returns name -> SensorIndex (or list of them)."""
    store = {"storeInternal": True, "writeToFile": False}
    sector = model.nodes["sector"]
    s = {
        "crank": _sensor(mbs, SensorNode(nodeNumber=model.nodes["crank"], outputVariableType=OVT.Coordinates, **store)),
        "drive": _sensor(mbs, SensorObject(objectNumber=model.drive, outputVariableType=OVT.Force, **store)),
        "sector_q": _sensor(mbs, SensorNode(nodeNumber=sector, outputVariableType=OVT.Coordinates, **store)),
        "sector_v": _sensor(mbs, SensorNode(nodeNumber=sector, outputVariableType=OVT.Coordinates_t, **store)),
        "sector_a": _sensor(mbs, SensorNode(nodeNumber=sector, outputVariableType=OVT.Coordinates_tt, **store)),
    }
    kinetic, heights = [], []
    for name, body in model.bodies.items():
        kinetic.append(_sensor(mbs, SensorBody(bodyNumber=body, outputVariableType=OVT.KineticEnergy, **store)))
        obj = mbs.GetObject(body)
        mass = obj["mass"]
        com = (list(obj.get("centerOfMass", [])) + [0.0, 0.0, 0.0])[:3]
        sensor = SensorBody(bodyNumber=body, outputVariableType=OVT.Position, localPosition=com, **store)
        heights.append((float(mass), _sensor(mbs, sensor)))
    s["kinetic"] = kinetic
    s["heights"] = heights
    for name, joint in model.clearances.items():
        conn = joint.connector
        for key, output in (("ecc", OVT.Displacement), ("ecc_rate", OVT.Velocity), ("force", OVT.Force)):
            s[f"{key}_{name}"] = _sensor(mbs, SensorObject(objectNumber=conn, outputVariableType=output, **store))
    return s


def _cumtrapz(y, x):
    out = np.zeros_like(y)
    if len(y) > 1:
        out[1:] = np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))
    return out


def step_channels(mbs: exu.MainSystem, model: MechanismModel, sensors: dict) -> dict[str, np.ndarray]:
    """All :data:`~weftsim.post.results.CHANNELS` at every stored step (rows cut to a common length)."""
    scene = model.scene

    def get(sensor) -> np.ndarray:  # a SensorIndex; exudyn's stub says ArrayLike, it is the (steps, 1 + k) array
        return np.asarray(mbs.GetSensorStoredData(sensor))

    crank = get(sensors["crank"])
    n = len(crank)
    data = {k: get(v)[:n] for k, v in sensors.items() if k not in ("kinetic", "heights")}
    kinetic = [get(k)[:n] for k in sensors["kinetic"]]
    heights = [(m, get(k)[:n]) for m, k in sensors["heights"]]
    n = min([len(crank)] + [len(v) for v in data.values()] + [len(k) for k in kinetic] + [len(h) for _, h in heights])
    t = crank[:n, 0]
    theta = crank[:n, 1 + CRANK_COORDINATE]
    ratio = scene.geometry.rapier_ratio
    torque = -data["drive"][:n, 1]
    ch = {
        "time_s": t,
        "crank_angle_deg": np.degrees(theta),
        "rapier_displacement_m": ratio * data["sector_q"][:n, 1 + ROTATION_2D],
        "rapier_velocity_m_s": ratio * data["sector_v"][:n, 1 + ROTATION_2D],
        "rapier_acceleration_m_s2": ratio * data["sector_a"][:n, 1 + ROTATION_2D],
        "driving_torque_Nm": torque,
        "kinetic_energy_J": np.sum([k[:n, 1] for k in kinetic], axis=0),
        "potential_energy_J": np.sum([m * scene.inertia.gravity * h[:n, 2] for m, h in heights], axis=0),
        "driving_work_J": _cumtrapz(torque, theta),
    }
    zeros = np.zeros(n)
    for name in CONTACT_CHANNELS:
        ch[name] = zeros
    if model.clearance_f is not None:
        for name in JOINT_F_CHANNELS:
            ch[name] = zeros
    for joint, cl in model.clearances.items():
        contact = _joint_channels(cl, data, joint, t, n)
        ch["contact_energy_J"] = ch["contact_energy_J"] + contact.pop("contact_energy_J")
        ch["dissipated_energy_J"] = ch["dissipated_energy_J"] + contact.pop("dissipated_energy_J")
        if joint == "f":  # joint F's channels carry its suffix; E's keep their names
            pairs = zip(LUBRICATION_CHANNELS_F, LUBRICATION_CHANNELS)
            lubricated = {f_name: contact[e_name] for f_name, e_name in pairs if e_name in contact}
            lubricated["joint_force_f_N"] = contact["joint_force_N"]
            contact = {f_name: contact[e_name] for f_name, e_name in JOINT_E_NAME.items()} | lubricated
        ch.update(contact)
    return ch


def _joint_channels(cl, data: dict, joint: str, t: np.ndarray, n: int) -> dict[str, np.ndarray]:
    """Contact channels of one clearance joint (E's names) from its sensors ``*_<joint>`` and tracker."""
    ecc = data[f"ecc_{joint}"][:n, 1:3]
    rate_vec = data[f"ecc_rate_{joint}"][:n, 1:3]
    length = np.hypot(ecc[:, 0], ecc[:, 1])
    delta = length - cl.joint.clearance
    safe = np.where(length > 0.0, length, 1.0)
    rate = np.where(length > 0.0, np.sum(ecc * rate_vec, axis=1) / safe, 0.0)
    force = data[f"force_{joint}"]
    f_n = np.hypot(force[:n, 1], force[:n, 2])
    load = f_n  # the connector's whole force: dry law, its friction, film and asperities (weftsim.joint.load)
    friction_power = np.zeros(n)
    f_el = np.where(delta > 0.0, cl.law.elastic_force(np.maximum(delta, 0.0)), 0.0)
    hist = cl.tracker.history()
    # The tracker records every post-step call (Exudyn also calls it once at t = 0): take,
    # for each stored step, the tracker's last record at that time.
    row = np.clip(np.searchsorted(hist["time"], t * (1.0 + 1e-12), side="right") - 1, 0, len(hist["time"]) - 1)
    lubricated: dict[str, np.ndarray] = {}
    energy = np.where(delta > 0.0, cl.law.elastic_energy(np.maximum(delta, 0.0)), 0.0)
    lub_power = np.zeros(n)
    if cl.friction is not None:
        record = np.array(cl.friction.history).reshape(-1, 3)  # t, F_N, F_T v_T: one row per tracker record after t = 0
        at = np.clip(np.searchsorted(record[:, 0], t * (1.0 + 1e-12), side="right") - 1, 0, len(record) - 1)
        f_n, friction_power = record[at, 1], record[at, 2]
        if cl.friction.lubricated:  # film and asperities (weftsim.physics.lubricated), one row per record too
            lub = np.array(cl.friction.lubrication_history).reshape(-1, 6)  # t, D', U_a, |f_film|, F_a, T_j
            lub = lub[at] if len(lub) else np.zeros((n, 6))
            lub_power = lub[:, 1]
            energy = energy + lub[:, 2]
            sigma = cl.joint.lubrication.roughness
            h_min = np.maximum(cl.joint.clearance - length, 0.0)
            lubricated = dict(zip(LUBRICATION_CHANNELS, (h_min, h_min / sigma, lub[:, 3], lub[:, 4], lub[:, 5])))
    return lubricated | {
        "joint_force_N": load,
        "contact_force_N": f_n,
        "penetration_m": delta,
        "eccentricity_y_m": ecc[:, 0],
        "eccentricity_z_m": ecc[:, 1],
        "impact_velocity_m_s": hist["impact_velocity"][row],
        "in_contact": hist["in_contact"][row],
        "contact_energy_J": energy,
        "dissipated_energy_J": _cumtrapz((f_n - f_el) * rate - friction_power + lub_power, t),
        "penetration_rate_m_s": rate,
    }


def sample_channels(steps: dict[str, np.ndarray], times: np.ndarray) -> dict[str, np.ndarray]:
    """Channels at the output times: linear interpolation between accepted steps.

    The step is chosen so output times fall on steps (solver.py), so this mostly picks
    stored values; ``in_contact`` takes the nearest step.  Times beyond the last step
    (a failed run) are dropped.
    """
    t = steps["time_s"]
    names = [k for k in CHANNELS + optional_channels(steps) if k in steps]
    if len(t) == 0:
        return {k: np.zeros(0) for k in names}
    # Exudyn accumulates t += h: the last step may fall short of the end time by round-off.
    last_step = t[-1] - t[-2] if len(t) > 1 else 0.0
    times = times[times <= t[-1] + 0.5 * last_step]
    out = {k: np.interp(times, t, steps[k]) for k in names}
    nearest = np.clip(np.searchsorted(t, times), 0, len(t) - 1)
    prev = np.clip(nearest - 1, 0, len(t) - 1)
    nearest = np.where(np.abs(t[prev] - times) < np.abs(t[nearest] - times), prev, nearest)
    for flag in ("in_contact", "in_contact_f"):
        if flag in steps:
            out[flag] = steps[flag][nearest]
    out["time_s"] = times
    return out


def first_nonfinite_row(steps: dict[str, np.ndarray]) -> int | None:
    """Index of the first step with a NaN or inf in any channel, or None."""
    bad = np.zeros(len(steps["time_s"]), dtype=bool)
    for v in steps.values():
        bad |= ~np.isfinite(v)
    idx = np.flatnonzero(bad)
    return int(idx[0]) if idx.size else None


def silence(settings: exu.SimulationSettings) -> None:
    """No console output and no files: results come from sensors stored in memory (by default Exudyn
    writes a solution folder and prints banners)."""
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = 0.0
    settings.solution.solverInformationFileName = ""
    settings.show.statistics = False
    settings.show.computationTime = False
