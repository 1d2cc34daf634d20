"""The reusable clearance connector on a worn joint: the local clearance from the two bodies' frames.

A joint between any two bodies (:func:`weftsim.exudyn_engine.add_clearance_joint`) carries its wear
profiles h_b(psi_b), h_j(psi_j) in the frame of each body: psi is the angle of the eccentricity
direction n from the body's own x axis, about the joint axis.  With the bodies turned by theta_b,
theta_j (rad, their rotation about the joint axis) and turning at omega_b, omega_j::

    psi_b = angle(e) - theta_b,   psi_j = angle(e) - theta_j
    c     = c0 + h_b(psi_b) + h_j(psi_j)                   (weftsim.physics.wear.clearance_along)
    dc/dt = h_b'(psi_b) (turn - omega_b) + h_j'(psi_j) (turn - omega_j),   turn = (e x e_dot) / |e|^2

and the force is the round connector's at that clearance (:func:`weftsim.physics.joint.connector_force_at`):
the same functions as the loom's reference chain and kinematic tree.  The parameters are the joint block
(:func:`weftsim.physics.joint.joint_parameters`) followed by the wear block
(:func:`weftsim.physics.wear.wear_block`) at :data:`WEAR_BLOCK`.
"""

from __future__ import annotations

from numba import njit

from weftsim.physics.joint import CLEARANCE, N_JOINT, connector_friction_force_at
from weftsim.physics.lubricated import connector_lubricated_force_at
from weftsim.physics.wear import clearance_along

WEAR_BLOCK = N_JOINT  # the wear block's start in the connector's parameters


@njit(cache=True, error_model="numpy", inline="always")
def body_frame_clearance(prm, ex: float, ey: float, vx: float, vy: float, omega_j: float, omega_b: float,
                         theta_j: float, theta_b: float) -> tuple[float, float]:
    """(c, dc/dt) along e of a worn connector (module docstring; :func:`weftsim.physics.wear.clearance_along`
    with the wear block at :data:`WEAR_BLOCK`); (c0, 0) without a wear block."""
    return clearance_along(prm, WEAR_BLOCK, prm[CLEARANCE], ex, ey, vx, vy, theta_b, omega_b, theta_j, omega_j)


@njit(cache=True, error_model="numpy")
def connector_worn_force(prm, ex: float, ey: float, vx: float, vy: float, held: float, delta0: float, rate0: float,
                         omega_j: float, omega_b: float, theta_j: float, theta_b: float) -> tuple[float, ...]:
    """:func:`weftsim.physics.joint.connector_friction_force` (the same nine values) of a worn connector whose
    bodies are turned by ``theta_j``, ``theta_b`` (rad)."""
    c, c_rate = body_frame_clearance(prm, ex, ey, vx, vy, omega_j, omega_b, theta_j, theta_b)
    return connector_friction_force_at(prm, c, c_rate, ex, ey, vx, vy, held, delta0, rate0, omega_j, omega_b)


@njit(cache=True, error_model="numpy")
def connector_worn_lubricated_force(prm, ex: float, ey: float, vx: float, vy: float, held: float, delta0: float,
                                    rate0: float, omega_j: float, omega_b: float, theta_j: float,
                                    theta_b: float) -> tuple[float, ...]:
    """:func:`weftsim.physics.lubricated.connector_lubricated_force` (the same fourteen values) of a worn
    lubricated connector (:func:`connector_worn_force`)."""
    c, c_rate = body_frame_clearance(prm, ex, ey, vx, vy, omega_j, omega_b, theta_j, theta_b)
    return connector_lubricated_force_at(prm, c, c_rate, ex, ey, vx, vy, held, delta0, rate0, omega_j, omega_b)
