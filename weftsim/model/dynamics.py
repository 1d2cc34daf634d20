"""Constants of the clearance-mode equations, their parameter array, and the initial state.

The equations themselves (members 1-3 prescribed by theta = omega t, members 4-8 a 2-DOF chain
q = (a, psi) forced through the contact at E) are written once, in :mod:`weftsim.physics.chain`;
both paths of the reference engine integrate that compiled right-hand side (the scipy path is
the independent integrator check over the same physics) and its output channels come from it.
This module turns a scene into the kernel's numbers (:class:`ChainConstants`,
:func:`pack_parameters`) and gives array forms of the chain's geometry and energy for the
post-processing of both engines.  Derivation: docs/reference-solver.md.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from types import SimpleNamespace
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from weftsim.mechanism import kinematics as kin
from weftsim.joint.contact import make_law
from weftsim.physics import chain as kc
from weftsim.physics import chain_f as kf
from weftsim.physics.joint import N_JOINT, joint_parameters
from weftsim.physics.wear import wear_block
from weftsim.input.params import Scene
from weftsim.model.ideal import sector_chain_inertia

if TYPE_CHECKING:
    from types import ModuleType

    from numpy.typing import ArrayLike

# Kept for callers that name the array backend of :func:`eccentricity` (it is always numpy now).
NUMPY = SimpleNamespace(sin=np.sin, cos=np.cos, atan=np.arctan, hypot=np.hypot)


@dataclass(frozen=True)
class ChainConstants:
    """Numbers the clearance-mode kernel needs, in SI units (built from a Scene)."""

    omega: float  # crank speed, rad/s
    tan_beta: float  # tan of the crank inclination
    rocker_arm_angle: float  # theta_OE0, rad
    l_oe: float
    l_ef: float
    l_fg: float
    l_og: float  # m
    rod_mass: float  # m4, kg
    gravity: float  # m/s^2
    m11: float  # m4 L_FG^2 + J_FG, kg m^2
    m22: float  # m4 L_EF^2 / 4 + J4, kg m^2
    coupling: float  # k = m4 L_FG L_EF / 2, kg m^2
    clearance: float  # c, m
    journal_radius: float
    bearing_radius: float  # m
    friction_coefficient: float  # mu
    friction_v0: float
    friction_v1: float  # m/s
    drive: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)  # the drive law's (law, t0, ramp, theta0)

    @classmethod
    def from_scene(cls, scene: Scene) -> "ChainConstants":
        geo, inert, joint = scene.geometry, scene.inertia, scene.joint
        m4 = inert.rod_mass
        return cls(
            omega=scene.drive.speed,
            tan_beta=math.tan(geo.crank_inclination),
            rocker_arm_angle=geo.rocker_arm_angle,
            l_oe=geo.l_oe, l_ef=geo.l_ef, l_fg=geo.l_fg, l_og=geo.l_og,
            rod_mass=m4,
            gravity=inert.gravity,
            m11=m4 * geo.l_fg**2 + sector_chain_inertia(scene),
            m22=m4 * geo.l_ef**2 / 4.0 + inert.rod_inertia,
            coupling=m4 * geo.l_fg * geo.l_ef / 2.0,
            clearance=joint.clearance,
            journal_radius=joint.journal_radius,
            bearing_radius=joint.bearing_radius,
            friction_coefficient=joint.friction_coefficient,
            friction_v0=joint.friction_velocities[0],
            friction_v1=joint.friction_velocities[1],
            drive=drive_entries(scene),
        )  # fmt: skip


def _chain_block(p: ChainConstants) -> np.ndarray:
    """The chain's constants of the kernel's parameter array (indices of :mod:`weftsim.physics.chain`)."""
    out = np.zeros(kc.N_PARAMETERS)
    out[kc.OMEGA], out[kc.TAN_BETA] = p.omega, p.tan_beta
    out[kc.COS_OE0], out[kc.SIN_OE0] = math.cos(p.rocker_arm_angle), math.sin(p.rocker_arm_angle)
    out[kc.L_OE], out[kc.L_EF], out[kc.L_FG], out[kc.L_OG] = p.l_oe, p.l_ef, p.l_fg, p.l_og
    out[kc.ROD_MASS], out[kc.GRAVITY] = p.rod_mass, p.gravity
    out[kc.M11], out[kc.M22], out[kc.COUPLING] = p.m11, p.m22, p.coupling
    out[kc.CLEARANCE] = p.clearance
    out[kc.DRIVE_LAW], out[kc.DRIVE_T0], out[kc.DRIVE_RAMP], out[kc.DRIVE_THETA0] = p.drive
    return out


DRIVE_LAWS = {"constant": kc.CONSTANT_SPEED, "run_down": kc.RUN_DOWN, "start_up": kc.START_UP}


def drive_entries(scene: Scene) -> tuple[float, float, float, float]:
    """The drive law's entries of the kernel's parameter array (law, t0, ramp, theta0;
    :func:`weftsim.physics.chain.crank_motion`): zeros at constant speed."""
    drive = scene.drive
    if drive.law == "constant":
        return 0.0, 0.0, 0.0, 0.0
    if drive.law not in DRIVE_LAWS or not drive.ramp > 0.0:
        raise ValueError(f"drive law {drive.law!r} with a ramp of {drive.ramp:g} s: the laws are "
                         f"{', '.join(DRIVE_LAWS)}, a transient's ramp > 0")
    if not scene.joint_f.is_ideal:
        raise ValueError("a stop-start transient (drive law run_down / start_up) covers the chain with joint E "
                         "alone; the scene gives a clearance at F")
    return DRIVE_LAWS[drive.law], drive.ramp_start, drive.ramp, drive.start_angle


def topology(scene: Scene) -> int:
    """The kernel's topology (:mod:`weftsim.physics.chain_f`): E_ONLY (also the ideal mechanism), F_ONLY, E_AND_F."""
    if scene.joint_f.is_ideal:
        return kf.E_ONLY
    return kf.F_ONLY if scene.joint.is_ideal else kf.E_AND_F


def pack_parameters(scene: Scene) -> np.ndarray:
    """Every number the kernel needs for this scene: the joint block at E, the chain's constants,
    the joint block at F (zeros while F is ideal), the topology, J_FG and J4; then the wear tables
    of the worn joints (:mod:`weftsim.physics.wear`): E's at ``kc.WEAR_E``, then F's (E's block is the
    empty ``[0, 0]`` when only F is worn; :func:`weftsim.physics.chain_f.wear_start_f`).

    A scene whose tape runs flexible (:func:`weftsim.model.tape_selection.tape_model`) gets topology E_TAPE and the
    tape block (:func:`weftsim.model.tape.flexible_parameters`); one whose tape runs rigid, its rigid equivalent's."""
    if scene.rapier_tape is not None:
        from weftsim.model import tape as tape_model_
        from weftsim.model.tape_selection import tape_model

        if tape_model(scene) == "rigid":
            return pack_parameters(tape_model_.rigid_equivalent(scene))
        return tape_model_.flexible_parameters(scene, pack_parameters(tape_model_.massless_rapier(scene)))
    out = np.zeros(kf.N_PARAMETERS)
    out[:kc.N_PARAMETERS] = _chain_block(ChainConstants.from_scene(scene))
    if not scene.joint.is_ideal or scene.joint_f.is_ideal:
        out[:N_JOINT] = joint_parameters(scene.joint, make_law(scene.joint))
    if not scene.joint_f.is_ideal:
        out[kf.JOINT_F:kf.JOINT_F + N_JOINT] = joint_parameters(scene.joint_f, make_law(scene.joint_f))
    out[kf.TOPOLOGY] = topology(scene)
    out[kf.SECTOR_CHAIN] = sector_chain_inertia(scene)
    out[kf.ROD_INERTIA] = scene.inertia.rod_inertia
    if scene.joint_f.is_worn and scene.joint_f.is_ideal:
        raise ValueError("a worn joint F (weftsim.wear) needs a clearance at F")
    if scene.joint.is_worn or scene.joint_f.is_worn:
        block_e = wear_block(scene.joint.bearing_wear, scene.joint.journal_wear)
        if scene.joint_f.is_worn:
            block_e = block_e if block_e.size else np.zeros(2)  # n_b = n_j = 0: E round, F's block follows
            block_e = np.concatenate([block_e, wear_block(scene.joint_f.bearing_wear, scene.joint_f.journal_wear)])
        out = np.concatenate([out, block_e])
    return out


@functools.lru_cache(maxsize=32)
def _geometry_parameters(p: ChainConstants) -> np.ndarray:
    return _chain_block(p)


@njit(cache=True, error_model="numpy")
def _eccentricity_rows(prm, t, a, psi, da, dpsi, out):
    y = np.zeros(4)
    for i in range(t.size):
        y[0], y[1], y[2], y[3] = a[i], psi[i], da[i], dpsi[i]
        ecc_y, ecc_z, v_y, v_z, db_y, db_z, dphi = kc.eccentricity(prm, t[i], y)[:7]
        out[0, i], out[1, i], out[2, i], out[3, i] = ecc_y, ecc_z, v_y, v_z
        out[4, i], out[5, i], out[6, i] = dphi, db_y, db_z


def eccentricity(xp: ModuleType | SimpleNamespace | None, p: ChainConstants, t: ArrayLike, a: ArrayLike,
                 psi: ArrayLike, da: ArrayLike, dpsi: ArrayLike) -> tuple[np.ndarray | float, ...]:
    """Eccentricity e = P_j - P_b, its rate and the bearing's motion, over arrays (broadcast).

    :func:`weftsim.physics.chain.eccentricity` at every element (``xp`` is ignored: kept for callers
    that passed the numpy namespace).

    Returns
    -------
    e_Y, e_Z (m); e_dot_Y, e_dot_Z (m/s); phi' = dphi/dtheta; dP_b/dtheta (Y, Z) (m/rad).
    """
    args = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (t, a, psi, da, dpsi)))
    shape = args[0].shape
    t_flat, a_flat, psi_flat, da_flat, dpsi_flat = (np.ascontiguousarray(v).ravel() for v in args)
    out = np.empty((7, t_flat.size))
    _eccentricity_rows(_geometry_parameters(p), t_flat, a_flat, psi_flat, da_flat, dpsi_flat, out)
    return tuple(row.reshape(shape)[()] for row in out)


def penetration(p: ChainConstants, t: float, y: np.ndarray) -> tuple[float, float]:
    """``delta = |e| - c`` (m) and delta_dot = e_dot . n (m/s) of a state y (:func:`weftsim.physics.chain.penetration`)."""
    return kc.penetration(_geometry_parameters(p), float(t), np.asarray(y[:4], dtype=float))


def chain_energy(p: ChainConstants, a: np.ndarray | float, psi: np.ndarray | float, da: np.ndarray | float,
                 dpsi: np.ndarray | float) -> tuple[np.ndarray | float, np.ndarray | float]:
    """Kinetic and potential energy of members 4-8 (J): 1/2 q'^T M q', m4 g z4."""
    m12 = -p.coupling * np.cos(np.asarray(psi) - a)
    kinetic = 0.5 * (p.m11 * da * da + 2.0 * m12 * da * dpsi + p.m22 * dpsi * dpsi)
    potential = p.rod_mass * p.gravity * (p.l_fg * np.sin(a) - 0.5 * p.l_ef * np.sin(psi))
    return kinetic, potential


def _transient_state(scene: Scene) -> np.ndarray:
    """The state at t = 0 of a stop-start transient (joint E alone): a run-down starts as a steady run (the
    journal centred at the crank angle ``start_angle``, the ideal velocities); a start-up starts at rest with the
    journal on the bearing's wall below its centre (e = 0.999 c (0, -1): the film squeezed out while the loom
    stood), every rate 0.

    The chain's coordinates (a, psi) of a journal centre P_j: F = G + L_FG u(a) lies on the circle of radius
    L_EF about P_j (P_j = F - L_EF u(psi)), the intersection on the ideal mechanism's branch (nearest a).
    """
    drive = scene.drive
    st = kin.linkage_state(drive.start_angle, scene.geometry, scene.inertia.rocker_com)
    a0, psi0 = float(st.theta_fg), float(st.theta_ef)
    if drive.law == "run_down":
        w = scene.drive.speed  # at full speed until the ramp
        return np.array([a0, psi0, w * float(st.d_theta_fg), w * float(st.d_theta_ef), 0.0, 0.0])
    prm = pack_parameters(scene)
    b_y, b_z = kc.crank_side(prm, 0.0)[:2]
    geo = scene.geometry
    # the journal centre on the wall below the bearing's, 1e-3 c off it (it settles onto the wall under its weight:
    # a contact that starts at t = 0 with no approach rate has no onset the contact history could check)
    p_y, p_z = b_y, b_z - (1.0 - 1e-3) * scene.joint.clearance
    # |G + L_FG u(a) - P_j| = L_EF: with d = G - P_j, 2 L_FG (d . u(a)) = L_EF^2 - |d|^2 - L_FG^2
    d_y, d_z = geo.l_og - p_y, -p_z
    rho = math.hypot(d_y, d_z)
    phase = math.atan2(d_z, d_y)
    arc = math.acos((geo.l_ef**2 - rho * rho - geo.l_fg**2) / (2.0 * geo.l_fg * rho))
    a = min((phase + arc, phase - arc), key=lambda x: abs(math.remainder(x - a0, 2.0 * math.pi)))
    a = a0 + math.remainder(a - a0, 2.0 * math.pi)
    f_y, f_z = geo.l_og + geo.l_fg * math.cos(a), geo.l_fg * math.sin(a)
    psi = math.atan2(f_z - p_z, f_y - p_y)
    psi = psi0 + math.remainder(psi - psi0, 2.0 * math.pi)
    return np.array([a, psi, 0.0, 0.0, 0.0, 0.0])


def initial_state(scene: Scene) -> np.ndarray:
    """State at t = 0: journal centred (e = 0), ideal-mechanism velocities (docs/physics.md section 2).

    Returns [a, psi, a', psi', W3, D] with a = theta_FG(0), psi = theta_EF(0) (angle of
    F - E, so P_j = F - L_EF u(psi) = E), rates omega * d/dtheta of the ideal kinematics,
    and the two integrated energy terms 0 (the same with clearance at F alone: psi is then the
    rod's angle about E of the rocker).
    With clearance at E and F (4 coordinates) the state is [a, Y, Z, psi, a', Y', Z', psi', W3, D],
    (Y, Z) the rod's centre of mass (:mod:`weftsim.physics.chain_f`).
    """
    if scene.rapier_tape is not None:  # [a, psi, q, a', psi', q', W3, D] (weftsim.physics.tape)
        from weftsim.model import tape as tape_model_
        from weftsim.model.tape_selection import tape_model

        if tape_model(scene) == "rigid":
            return initial_state(tape_model_.rigid_equivalent(scene))
        # The wheel's acceleration at t = 0 with the tape as the rigid rapier: the tape starts in equilibrium with it.
        rigid = tape_model_.rigid_equivalent(scene)
        y = initial_state(rigid)
        rate = np.empty(y.size)
        kc.chain(pack_parameters(rigid), 0.0, y, False, 0.0, rate)
        chain = initial_state(tape_model_.massless_rapier(scene))
        return tape_model_.flexible_initial_state(scene, chain, scene.geometry.rapier_ratio * rate[2])
    omega = scene.drive.speed
    if scene.drive.law != "constant":
        return _transient_state(scene)
    st = kin.linkage_state(0.0, scene.geometry, scene.inertia.rocker_com)
    if topology(scene) == kf.E_AND_F:
        com, d_com = np.asarray(st.rod_com, dtype=float), np.asarray(st.d_rod_com, dtype=float)
        return np.array([
            float(st.theta_fg), com[0], com[1], float(st.theta_ef),
            omega * float(st.d_theta_fg), omega * d_com[0], omega * d_com[1], omega * float(st.d_theta_ef),
            0.0, 0.0,
        ])  # fmt: skip
    return np.array([
        float(st.theta_fg), float(st.theta_ef),
        omega * float(st.d_theta_fg), omega * float(st.d_theta_ef),
        0.0, 0.0,
    ])  # fmt: skip
