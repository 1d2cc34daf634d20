"""The load a loose joint carries, film + asperities + dry law, from the states of a run (both engines).

``joint_force_N`` (``joint_force_f_N`` at F) is the magnitude of the whole force of the joint on the journal:
the dry law's normal force F_N (the engine's ``contact_force_N``, along -n) with its friction F_T t
(:func:`weftsim.physics.joint.friction_force` at the contact points' sliding velocity), plus, for a lubricated
joint, the film's and the asperities' force with their boundary friction
(:func:`weftsim.physics.lubricated.lubricated_force`).  For a dry frictionless joint it is ``contact_force_N``.
The design checks, ``compare``, the plots, the wear report and sweeps read it (:func:`joint_load`), so an
oiled joint is judged by the load its film carries as a dry one by its contact's.

Rows are reference-engine states (:func:`weftsim.model.dynamics.initial_state` layout), as in
:mod:`weftsim.joint.lubrication`; the Exudyn rigid-body model measures the connector's force directly
(:mod:`weftsim.exudyn_engine.sensors`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.input.params import Scene
from weftsim.physics import chain as kc
from weftsim.physics import chain_f as kf
from weftsim.physics.joint import BEARING_RADIUS, friction_force, tangential_velocity
from weftsim.joint.lubrication import joint_states
from weftsim.physics.lubricated import L_FX, L_FY, is_lubricated, lubricated_force
from weftsim.physics.python import specialize
from weftsim.model.channels import JOINT_FORCE_CHANNELS, JOINT_FORCE_CHANNELS_F, LOAD_FALLBACK

JOINT_FORCE, JOINT_FORCE_F = JOINT_FORCE_CHANNELS + JOINT_FORCE_CHANNELS_F


@njit(cache=True, error_model="numpy")
def _force(jp, clearance, e_y, e_z, v_y, v_z, w_j, w_b, f_n) -> float:
    """|f| of one joint on the journal: dry law F_N along -n with its friction, plus film and asperities."""
    fy = fz = f_t = 0.0
    length = math.sqrt(e_y * e_y + e_z * e_z)
    if f_n > 0.0 and length > 0.0:
        ny, nz = e_y / length, e_z / length
        f_t = friction_force(jp, f_n, tangential_velocity(e_y, e_z, v_y, v_z, length, w_j, w_b, jp[BEARING_RADIUS]))
        fy, fz = -f_n * ny - f_t * nz, -f_n * nz + f_t * ny
    if not is_lubricated(jp):
        return math.hypot(f_n, f_t)  # the dry joint: exactly its contact force without friction
    if is_lubricated(jp):
        lub = lubricated_force(jp, clearance, e_y, e_z, v_y, v_z, w_j, w_b)
        fy += lub[L_FX]
        fz += lub[L_FY]
    return math.hypot(fy, fz)


@njit(cache=True, error_model="numpy")
def joint_force_rows(prm: np.ndarray, time: np.ndarray, states: np.ndarray, f_n_e: np.ndarray, f_n_f: np.ndarray,
                     out_e: np.ndarray, out_f: np.ndarray) -> None:
    """|f| of joint E and F (where loose) at each row into out_e, out_f (n,), N; ``f_n_*`` the dry law's F_N."""
    jf = prm[kf.JOINT_F:kf.JOINT_F + kc.N_JOINT]
    has_e = prm[kf.TOPOLOGY] != kf.F_ONLY
    has_f = prm[kf.TOPOLOGY] != kf.E_ONLY
    for i in range(time.size):
        (c, e_y, e_z, v_y, v_z, w_j, w_b), joint_f = joint_states(prm, time[i], states[i])
        if has_e:
            out_e[i] = _force(prm, c, e_y, e_z, v_y, v_z, w_j, w_b, f_n_e[i])
        if has_f:
            c, e_y, e_z, v_y, v_z, w_j, w_b = joint_f
            out_f[i] = _force(jf, c, e_y, e_z, v_y, v_z, w_j, w_b, f_n_f[i])


# joint_force_rows for a plain scene (weftsim.physics.chain_f.PLAIN), compiled on first use.
_joint_force_rows_plain = specialize(joint_force_rows, "plain", lean=True, counted=(), **kf.PLAIN)


def joint_force_table(scene: Scene, prm: np.ndarray, time: np.ndarray, states: np.ndarray,
                      channels: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``joint_force_N`` / ``joint_force_f_N`` of the scene's loose joints at the rows, from the states and the
    engine's dry-law channels ``contact_force_N`` / ``contact_force_f_N`` in ``channels``."""
    n = time.size
    loose_e, loose_f = not scene.joint.is_ideal, not scene.joint_f.is_ideal
    out_e, out_f = np.zeros(n), np.zeros(n)
    if n and (loose_e or loose_f):
        zero = np.zeros(n)
        f_n_e = np.ascontiguousarray(channels.get("contact_force_N", zero), dtype=float)
        f_n_f = np.ascontiguousarray(channels.get("contact_force_f_N", zero), dtype=float)
        rows = _joint_force_rows_plain if kf.is_plain(prm) else joint_force_rows
        rows(prm, np.ascontiguousarray(time, dtype=float), np.ascontiguousarray(states, dtype=float),
             f_n_e, f_n_f, out_e, out_f)  # fmt: skip
    out = {}
    if loose_e:
        out[JOINT_FORCE] = out_e
    if loose_f:
        out[JOINT_FORCE_F] = out_f
    return out


def joint_load(table: dict[str, np.ndarray], name: str = JOINT_FORCE) -> np.ndarray:
    """The joint's load channel ``name`` of a result's table; a result saved before the channel existed
    (weftsim 0.2) gives its dry law's ``contact_force_N`` (the joint's whole load unless it was oiled)."""
    if name in table:
        return table[name]
    return table[LOAD_FALLBACK[name]]
