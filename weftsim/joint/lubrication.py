"""Channels of the lubricated joints, from the states of a run (both engines; docs/lubricated-joint.md).

The film and the asperities are evaluated by the kernel the engines integrated
(:func:`weftsim.physics.lubricated.lubricated_force`) at each row's eccentricity, its rate and the
bodies' rotation rates, so the channels are the forces the solver saw.  Rows are reference-engine
states (:func:`weftsim.model.dynamics.initial_state` layout: [a, psi, a', psi', W3, D] with E alone,
the 4-DOF or F-only layouts of :mod:`weftsim.physics.chain_f` otherwise); the Exudyn kinematic tree
converts its joint coordinates to that layout first.

Channels (:data:`weftsim.model.channels.LUBRICATION_CHANNELS`, ``_F`` for joint F): minimum film thickness
h_min = max(c - |e|, 0) (m), film ratio h_min / sigma, film force |f_film| (N), asperity load F_a (N),
film shear torque on the journal T_j (N m).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.physics import chain as kc
from weftsim.physics import chain_f as kf
from weftsim.physics.joint import ROUGHNESS
from weftsim.physics.lubricated import L_ASPERITY, L_ASPERITY_ENERGY, L_FILM, L_FILM_TORQUE, lubricated_force
from weftsim.input.params import Scene
from weftsim.model.channels import LUBRICATION_CHANNELS, LUBRICATION_CHANNELS_F

# Rows of the compiled table: h_min, ratio, |f_film|, F_a, T_j, U_a.
N_ROWS = 6


@njit(cache=True, error_model="numpy")
def _row(jp, clearance, e_y, e_z, v_y, v_z, w_j, w_b, out, i):
    lub = lubricated_force(jp, clearance, e_y, e_z, v_y, v_z, w_j, w_b)
    h = clearance - math.sqrt(e_y * e_y + e_z * e_z)
    h = h if h > 0.0 else 0.0
    out[i, 0] = h
    out[i, 1] = h / jp[ROUGHNESS]
    out[i, 2] = lub[L_FILM]
    out[i, 3] = lub[L_ASPERITY]
    out[i, 4] = lub[L_FILM_TORQUE]
    out[i, 5] = lub[L_ASPERITY_ENERGY]


@njit(cache=True, error_model="numpy")
def joint_states(prm: np.ndarray, t: float, y: np.ndarray):
    """((c, e_y, e_z, v_y, v_z, w_j, w_b) of joint E, the same of joint F) at the state ``y`` (reference layout):
    the local clearance along e (a worn joint's; round: c0), eccentricity and its rate, the journal's and the
    bearing's rates about the joint axis.  A joint without clearance in the state's layout: zeros."""
    none = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    if prm[kf.TOPOLOGY] == kf.E_ONLY:
        e_y, e_z, v_y, v_z, _, _, dphi = kc.eccentricity(prm, t, y)[:7]
        c = kc.local_clearance(prm, t, e_y, e_z, v_y, v_z, y)[0]
        return (c, e_y, e_z, v_y, v_z, y[3], kc.crank_rate(prm, t) * dphi), none
    q = kf.eccentricities(prm, t, y)
    e_y, e_z, ve_y, ve_z, f_y, f_z, vf_y, vf_z, w_rocker, dpsi, da = q
    c_e, _, c_f, _ = kf.local_clearances(prm, t, y, q)
    joint_e = (c_e, e_y, e_z, ve_y, ve_z, dpsi, w_rocker) if prm[kf.TOPOLOGY] == kf.E_AND_F else none
    return joint_e, (c_f, f_y, f_z, vf_y, vf_z, dpsi, da)


@njit(cache=True, error_model="numpy")
def lubrication_rows(prm: np.ndarray, time: np.ndarray, states: np.ndarray, out_e: np.ndarray,
                     out_f: np.ndarray) -> None:
    """The lubricated joints' rows (h_min, h_min/sigma, |f_film|, F_a, T_j, U_a) into out_e, out_f (n, 6)."""
    jf = prm[kf.JOINT_F:kf.JOINT_F + kc.N_JOINT]
    has_e = prm[kf.TOPOLOGY] != kf.F_ONLY
    has_f = prm[kf.TOPOLOGY] != kf.E_ONLY
    for i in range(time.size):
        (c, e_y, e_z, v_y, v_z, w_j, w_b), joint_f = joint_states(prm, time[i], states[i])
        if has_e:
            _row(prm, c, e_y, e_z, v_y, v_z, w_j, w_b, out_e, i)
        if has_f:
            c, e_y, e_z, v_y, v_z, w_j, w_b = joint_f
            _row(jf, c, e_y, e_z, v_y, v_z, w_j, w_b, out_f, i)


def lubrication_table(scene: Scene, prm: np.ndarray, time: np.ndarray,
                      states: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """(channels, U_a): the lubrication channels of the scene's lubricated loose joints at the rows, and
    the asperity potential of all of them summed per row (J; zeros when none is lubricated)."""
    n = time.size
    out_e = np.zeros((n, N_ROWS))
    out_f = np.zeros((n, N_ROWS))
    lub_e = not scene.joint.is_ideal and scene.joint.is_lubricated
    lub_f = not scene.joint_f.is_ideal and scene.joint_f.is_lubricated
    channels: dict[str, np.ndarray] = {}
    if not (lub_e or lub_f) or n == 0:
        for names, on in ((LUBRICATION_CHANNELS, lub_e), (LUBRICATION_CHANNELS_F, lub_f)):
            if on:
                channels.update({name: np.zeros(0) for name in names})
        return channels, np.zeros(n)
    lubrication_rows(prm, np.ascontiguousarray(time, dtype=float), np.ascontiguousarray(states, dtype=float),
                     out_e, out_f)  # fmt: skip
    energy = np.zeros(n)
    for names, on, out in ((LUBRICATION_CHANNELS, lub_e, out_e), (LUBRICATION_CHANNELS_F, lub_f, out_f)):
        if on:
            channels.update({name: np.ascontiguousarray(out[:, k]) for k, name in enumerate(names)})
            energy += out[:, 5]
    return channels, energy
