"""Force of the planar revolute clearance joint from its eccentricity (the one definition).

Flores-Ambrosio formulation (Flores & Ambrosio, Comput. Struct. 82, 2004)::

             bearing (R_b), centre P_b
          .-----------.
        /     journal   \\            e = P_j - P_b        eccentricity vector, m
       |   P_b --e--> P_j|Q          n = e / |e|          contact normal (bearing -> journal)
        \\               /            t = (-n_y, n_x)     n turned +90 deg
          '-----------'              delta = |e| - c      penetration, m (< 0: free flight)

F_N = law(delta, delta_dot, v_imp) with delta_dot = e_dot . n (:mod:`.laws`, :mod:`.hold`);
modified Coulomb friction on the journal F_T = -mu c_d(|v_T|) F_N sign(v_T) (Ambrosio 2003);
force on the journal f = -F_N n + F_T t at Q = P_b + R_b n, so only friction has moments:
M_j = (R_b - |e|) F_T about P_j and M_b = -R_b F_T about P_b.  e = 0 is free flight.

The joint's numbers come in one float array (:func:`joint_parameters`, indices below); the
chain's parameter array (:mod:`.chain`) starts with the same block, so these functions take either.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from weftsim.physics.hold import RESTING_RATE_FRACTION, callback_impact_velocity, damping_rate
from weftsim.physics.hold import effective_impact_velocity
from weftsim.physics.laws import friction_factor, normal_force

if TYPE_CHECKING:
    from weftsim.joint.contact import _Law
    from weftsim.input.params import ClearanceJoint

# Indices into the joint parameter block: the dry joint's, then the lubrication's (zeros when dry;
# weftsim.physics.lubricated reads them).
(KIND, COEF, CLEARANCE, XI, BEARING_RADIUS, MU, V0, V1, V_MIN, TRACK_MAX, DEAD_RATE) = range(11)  # fmt: skip
(LUBRICATED, VISCOSITY, FILM_MODEL, ROUGHNESS, ASPERITY_COEF, BOUNDARY_MU, FILM_FLOOR, JOURNAL_RADIUS,
 BEARING_LENGTH, ASPERITY_HYSTERESIS) = range(11, 21)  # fmt: skip
N_JOINT = 21


def joint_parameters(joint: ClearanceJoint, law: _Law) -> np.ndarray:
    """The joint block: the law's (kind, coef, c, xi), R_b, mu, friction ramp, v_min, rule flag, dead zone,
    then the lubrication (flag, viscosity, film model, roughness, Greenwood-Tripp K E*, boundary mu, film
    floor, R_j, L_b, the asperities' hysteresis kappa = (1 - e^2) / (1 + e^2) from the joint's restitution e;
    zeros for a dry joint).  A lubricated joint's mu is its boundary mu: the dry law's contact is the solids'
    boundary-lubricated contact.

    ``joint``: a :class:`weftsim.input.params.ClearanceJoint`; ``law``: a law of :mod:`weftsim.joint.contact`
    (its ``parameters``).  ``TRACK_MAX`` is 1.0 under the "max_approach" rule, 0.0 under "onset";
    ``DEAD_RATE`` = RESTING_RATE_FRACTION v_min, the damping dead zone of :func:`connector_force`.
    """
    out = np.zeros(N_JOINT)
    out[KIND], out[COEF], out[CLEARANCE], out[XI] = law.parameters
    out[CLEARANCE] = joint.clearance
    out[BEARING_RADIUS] = joint.bearing_radius
    out[MU] = joint.friction_coefficient
    out[V0], out[V1] = joint.friction_velocities
    out[V_MIN] = joint.min_impact_velocity
    out[TRACK_MAX] = 1.0 if joint.impact_velocity_rule == "max_approach" else 0.0
    out[DEAD_RATE] = RESTING_RATE_FRACTION * joint.min_impact_velocity
    if joint.lubrication is not None:
        from weftsim.physics.asperity import greenwood_tripp_coefficient

        lub = joint.lubrication
        out[LUBRICATED] = 1.0
        out[VISCOSITY] = lub.viscosity
        out[FILM_MODEL] = lub.model_code
        out[ROUGHNESS] = lub.roughness
        modulus = lub.asperity_modulus if lub.asperity_modulus > 0.0 else joint.effective_modulus
        out[ASPERITY_COEF] = greenwood_tripp_coefficient(lub.asperity_density_radius_roughness,
                                                         lub.roughness_radius_ratio, modulus)
        out[BOUNDARY_MU] = lub.boundary_friction_coefficient
        # The solids' contact in oil is boundary-lubricated: beyond abs(e) = c, where the dry law takes the
        # asperities' load over (weftsim.physics.lubricated.asperity_share), its friction is mu_b too, so the
        # solids carry mu_b on their whole load in every engine (the dry joint's `friction_coefficient` is the
        # unlubricated contact's; a lubricated joint refuses one > 0, weftsim.input.params).
        out[MU] = lub.boundary_friction_coefficient
        out[FILM_FLOOR] = lub.film_floor_ratio
        out[JOURNAL_RADIUS] = joint.journal_radius
        out[BEARING_LENGTH] = joint.bearing_length
        out[ASPERITY_HYSTERESIS] = asperity_hysteresis(joint.restitution)
    return out


def asperity_hysteresis(restitution: float) -> float:
    """kappa of the asperities' loading and unloading branches (1 +- kappa) F_a: their loop returns the share
    (1 - kappa) / (1 + kappa) = e^2 of the work done on it (:mod:`weftsim.physics.lubricated`)."""
    return (1.0 - restitution**2) / (1.0 + restitution**2)


@njit(cache=True, error_model="numpy", inline="always")
def friction_force(prm: np.ndarray, f_n: float, v_t: float) -> float:
    """F_T, N: the modified Coulomb friction on the journal along t (Ambrosio 2003).

    F_T = -mu c_d(|v_T|) F_N sign(v_T), with c_d the ramp of :func:`~weftsim.physics.laws.friction_factor`
    between ``prm[V0]`` and ``prm[V1]``; 0 when mu = 0 or F_N = 0.  ``v_t``: relative tangential velocity
    of the contact points (journal relative to bearing, :func:`tangential_velocity`), m/s.
    """
    mu, v0, v1 = prm[MU], prm[V0], prm[V1]  # read first: see clearance_force_at
    if mu > 0.0 and f_n > 0.0:
        c_d = friction_factor(v_t, v0, v1)
        if c_d > 0.0:
            return -mu * c_d * f_n if v_t > 0.0 else mu * c_d * f_n
    return 0.0


@njit(cache=True, error_model="numpy", inline="always")
def tangential_velocity(ex: float, ey: float, ex_dot: float, ey_dot: float, length: float, omega_j: float,
                        omega_b: float, r_b: float) -> float:
    """v_T = e_dot . t + omega_j (R_b - |e|) - omega_b R_b, m/s (``length`` = |e| > 0).

    The velocity of the journal's material point at the contact point Q = P_b + R_b n relative to
    the bearing's, along t = (-n_y, n_x): Q - P_j = (R_b - |e|) n and Q - P_b = R_b n, so the two
    bodies' rotations (omega_j, omega_b about +z, rad/s) add omega (Q - P) x z-turned terms along t.
    """
    return (ex * ey_dot - ey * ex_dot) / length + omega_j * (r_b - length) - omega_b * r_b


@njit(cache=True, error_model="numpy", inline="always")
def contact_geometry(ex: float, ey: float, ex_dot: float, ey_dot: float, clearance: float) -> tuple[float, ...]:
    """Penetration delta = |e| - c (m), its rate delta_dot = e_dot . n (m/s) and the normal n = e / |e| of an
    eccentricity e = P_j - P_b and its rate (docs/physics.md section 2); at e = 0 (centred: no normal)
    delta = -c, delta_dot = 0, n = 0.  Returns (delta, delta_dot, n_x, n_y).

    The clearance geometry, written once: :func:`clearance_force_at` evaluates it, and the array forms of
    :mod:`weftsim.joint.clearance` are generated from it (:func:`weftsim.physics.python.python_form`).
    """
    length = math.sqrt(ex * ex + ey * ey)
    if length <= 0.0:
        return length - clearance, 0.0, 0.0, 0.0
    nx = ex / length
    ny = ey / length
    return length - clearance, ex_dot * nx + ey_dot * ny, nx, ny


@njit(cache=True, error_model="numpy", inline="always")
def contact_tangential_velocity(ex: float, ey: float, ex_dot: float, ey_dot: float, omega_j: float, omega_b: float,
                                r_b: float) -> float:
    """:func:`tangential_velocity` of an eccentricity e, its rate and the rotations, 0 at e = 0 (no normal)."""
    length = math.sqrt(ex * ex + ey * ey)
    if length <= 0.0:
        return 0.0
    return tangential_velocity(ex, ey, ex_dot, ey_dot, length, omega_j, omega_b, r_b)


@njit(cache=True, error_model="numpy", inline="always")
def clearance_force(prm: np.ndarray, ex: float, ey: float, ex_dot: float, ey_dot: float, v_t: float,
                    v_imp: float) -> tuple[float, ...]:
    """Force of the joint at eccentricity e and its rate, with held impact velocity v_imp.

    The round joint: :func:`clearance_force_at` with the clearance ``prm[CLEARANCE]``.
    """
    return clearance_force_at(prm, prm[CLEARANCE], 0.0, ex, ey, ex_dot, ey_dot, v_t, v_imp)


@njit(cache=True, error_model="numpy", inline="always")
def clearance_force_at(prm: np.ndarray, clearance: float, clearance_rate: float, ex: float, ey: float, ex_dot: float,
                       ey_dot: float, v_t: float, v_imp: float) -> tuple[float, ...]:
    """Force of the joint with the clearance ``clearance`` along e (m) changing at ``clearance_rate``
    (m/s; a worn joint's local values, :func:`weftsim.physics.wear.worn_clearance`; the round joint
    passes (c, 0)), at eccentricity e and its rate, held impact velocity v_imp.

    ``v_t``: relative tangential velocity of the contact points (journal relative to bearing), m/s,
    read only with friction; ``v_imp`` > 0 in contact, raised by the joint's rule
    (:func:`~weftsim.physics.hold.effective_impact_velocity`).

    Returns
    -------
    (f_x, f_y, F_N, F_T, delta, delta_dot, M_j, M_b): force on the journal (N), normal and
    friction force (N, F_T along t), penetration (m) and its rate (m/s), friction moments about
    P_j and P_b (N m).
    """
    length = math.sqrt(ex * ex + ey * ey)
    delta, rate, nx, ny = contact_geometry(ex, ey, ex_dot, ey_dot, clearance)
    if length <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, delta, 0.0, 0.0, 0.0
    delta_dot = rate - clearance_rate
    v = effective_impact_velocity(v_imp, delta_dot, prm[TRACK_MAX] != 0.0)
    f_n = normal_force(prm[KIND], prm[COEF], clearance, prm[XI], delta, delta_dot, v)
    f_t = friction_force(prm, f_n, v_t)
    r_b = prm[BEARING_RADIUS]
    fx = -f_n * nx - f_t * ny
    fy = -f_n * ny + f_t * nx
    return fx, fy, f_n, f_t, delta, delta_dot, (r_b - length) * f_t, -r_b * f_t


@njit(cache=True, error_model="numpy")
def connector_force(prm: np.ndarray, ex: float, ey: float, vx: float, vy: float, held: float, delta0: float,
                    rate0: float) -> tuple[float, ...]:
    """Force F_N n of the Exudyn clearance connector (on the bearing side; -F_N n on the journal).

    ``(ex, ey)``, ``(vx, vy)``: eccentricity P_j - P_b (m) and its rate (m/s) at a trial state;
    ``held``, ``delta0``, ``rate0``: the held impact velocity and the penetration and rate of the
    last accepted state (the connector's memory).  The impact velocity is
    :func:`~weftsim.physics.hold.callback_impact_velocity`, the damping rate has the resting-contact
    dead zone of :func:`~weftsim.physics.hold.damping_rate` (+-``prm[DEAD_RATE]``).

    The round joint: :func:`connector_force_at` with the clearance ``prm[CLEARANCE]``.

    Returns
    -------
    (f_x, f_y, delta, delta_dot): force (N), penetration (m) and its rate (m/s, 0 at e = 0).
    """
    return connector_force_at(prm, prm[CLEARANCE], 0.0, ex, ey, vx, vy, held, delta0, rate0)


@njit(cache=True, error_model="numpy")
def connector_force_at(prm: np.ndarray, clearance: float, clearance_rate: float, ex: float, ey: float, vx: float,
                       vy: float, held: float, delta0: float, rate0: float) -> tuple[float, ...]:
    """:func:`connector_force` with the clearance ``clearance`` along e (m) changing at ``clearance_rate``
    (m/s): a worn joint's local values (:func:`weftsim.physics.wear.worn_clearance`), as
    :func:`clearance_force_at` takes them; delta = |e| - c, delta_dot = e_dot . n - dc/dt."""
    length = math.sqrt(ex * ex + ey * ey)
    delta = length - clearance
    if length <= 0.0:
        return 0.0, 0.0, delta, 0.0
    nx = ex / length
    ny = ey / length
    rate = vx * nx + vy * ny - clearance_rate
    if delta <= 0.0:
        return 0.0, 0.0, delta, rate
    v_imp = callback_impact_velocity(held, delta0, rate0, delta, rate, prm[V_MIN], prm[TRACK_MAX] != 0.0)
    f = normal_force(prm[KIND], prm[COEF], clearance, prm[XI], delta, damping_rate(rate, prm[DEAD_RATE]),
                     v_imp)  # fmt: skip
    return f * nx, f * ny, delta, rate


@njit(cache=True, error_model="numpy")
def connector_friction_force(prm: np.ndarray, ex: float, ey: float, vx: float, vy: float, held: float, delta0: float,
                             rate0: float, omega_j: float, omega_b: float) -> tuple[float, ...]:
    """:func:`connector_force` with the modified Coulomb friction (the rigid-body Exudyn joint).

    ``omega_j``, ``omega_b``: angular velocities (rad/s, about +z) of the journal's and the bearing's
    body.  The normal force is :func:`connector_force`'s; in contact the journal also gets F_T t
    (:func:`friction_force` at :func:`tangential_velocity`) and the moment M_j = (R_b - |e|) F_T about
    P_j, the bearing -F_T t and M_b = -R_b F_T about P_b.  The round joint:
    :func:`connector_friction_force_at` with the clearance ``prm[CLEARANCE]``.

    Returns
    -------
    (f_x, f_y, delta, delta_dot, F_N, F_T, M_j, M_b, v_T): the force on the bearing F_N n - F_T t (N),
    penetration (m) and rate (m/s), normal and friction force (N), moments (N m), sliding speed (m/s).
    """
    return connector_friction_force_at(prm, prm[CLEARANCE], 0.0, ex, ey, vx, vy, held, delta0, rate0, omega_j,
                                       omega_b)  # fmt: skip


@njit(cache=True, error_model="numpy")
def connector_friction_force_at(prm: np.ndarray, clearance: float, clearance_rate: float, ex: float, ey: float,
                                vx: float, vy: float, held: float, delta0: float, rate0: float, omega_j: float,
                                omega_b: float) -> tuple[float, ...]:
    """:func:`connector_friction_force` with a local clearance and its rate (:func:`connector_force_at`)."""
    fx, fy, delta, rate = connector_force_at(prm, clearance, clearance_rate, ex, ey, vx, vy, held, delta0, rate0)
    if delta <= 0.0:
        return fx, fy, delta, rate, 0.0, 0.0, 0.0, 0.0, 0.0
    length = math.sqrt(ex * ex + ey * ey)
    f_n = math.hypot(fx, fy)
    r_b = prm[BEARING_RADIUS]
    v_t = tangential_velocity(ex, ey, vx, vy, length, omega_j, omega_b, r_b)
    f_t = friction_force(prm, f_n, v_t)
    nx, ny = ex / length, ey / length
    return fx + f_t * ny, fy - f_t * nx, delta, rate, f_n, f_t, (r_b - length) * f_t, -r_b * f_t, v_t
