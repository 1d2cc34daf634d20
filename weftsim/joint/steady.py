"""A steadily loaded journal bearing on the lubricated joint's kernel: where the film and the asperities carry a
load, and the friction there (docs/lubricated-joint.md, "Mixed lubrication").

The journal spins at omega in a still bearing under a constant load W (along -z).  At rest in the clearance
(e_dot = 0) the joint's whole force, film + asperities + their boundary friction
(:func:`weftsim.kernel.lubricated.lubricated_force`, the one the transient engines integrate) and, beyond
|e| = c, the dry law's (:func:`weftsim.kernel.joint.clearance_force_at`), balances W:

    f(e) + (0, -W) = 0,    e = c eps (sin phi, -cos phi)   (phi the attitude angle, from the load line),

solved for (eps, phi) by Newton's method on the kernel's force (:func:`steady_point`).  The friction torque on
the journal is the film's shear torque and the boundary friction's moment, T = -M_j; the friction coefficient
mu = T / (W R).  ``weftsim bearing`` (the steady plain-bearing calculation) and the tests of the mixed regime
call it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from weftsim.input.params import ClearanceJoint
from weftsim.joint.contact import make_law
from weftsim.kernel.joint import BEARING_RADIUS, clearance_force_at, joint_parameters, tangential_velocity
from weftsim.kernel.lubricated import L_ASPERITY, L_FILM, L_FILM_TORQUE, L_FX, L_FY, L_MJ, lubricated_force

# The load balance is solved to this fraction of W (the kernel's force is smooth but for the film's cavitation
# boundary, the table's interpolation and the floor: a tighter tolerance buys nothing).
BALANCE_TOL = 1e-10


@dataclass(frozen=True)
class SteadyPoint:
    """The journal's resting point and its friction (SI units).

    Attributes
    ----------
    eccentricity_ratio, attitude_deg : float
        |e| / c and the angle between the load line and the line of centres, deg.
    film_thickness_m, film_ratio : float
        h_min = c - |e| (m, >= 0) and h_min / sigma.
    film_force_n, asperity_force_n, contact_force_n : float
        The film's force magnitude, the asperities' load and the dry law's normal force, N.
    friction_torque_nm : float
        Friction torque on the journal, opposing its rotation, N m (film shear + boundary friction).
    film_torque_nm : float
        The film's part of it, N m.
    friction_coefficient : float
        friction_torque / (W R_j).
    residual : float
        |f + W| / W at the point found.
    """

    eccentricity_ratio: float
    attitude_deg: float
    film_thickness_m: float
    film_ratio: float
    film_force_n: float
    asperity_force_n: float
    contact_force_n: float
    friction_torque_nm: float
    film_torque_nm: float
    friction_coefficient: float
    residual: float


def _forces(prm: np.ndarray, joint: ClearanceJoint, eps: float, phi: float, omega: float):
    """(the lubricated kernel's outputs, the dry law's force (f_y, f_z, F_N, M_j)) of the journal at rest."""
    c = joint.clearance
    e_y, e_z = c * eps * math.sin(phi), -c * eps * math.cos(phi)
    lub = lubricated_force(prm, c, e_y, e_z, 0.0, 0.0, omega, 0.0)
    dry = (0.0, 0.0, 0.0, 0.0)
    if eps > 1.0:  # at rest: the law's elastic force (no penetration rate, so no damping) and its friction
        v_t = tangential_velocity(e_y, e_z, 0.0, 0.0, c * eps, omega, 0.0, prm[BEARING_RADIUS])
        out = clearance_force_at(prm, c, 0.0, e_y, e_z, 0.0, 0.0, v_t, 1.0)
        dry = (out[0], out[1], out[2], out[6])
    return lub, dry


def _eps(x: float) -> float:
    """eps = 2 / (1 + exp(-x)) in (0, 2): fine near 1 (1 - eps ~ x / 2), where the mixed regime lies."""
    return 2.0 / (1.0 + math.exp(-x))


def steady_point(joint: ClearanceJoint, load: float, journal_speed: float) -> SteadyPoint:
    """The resting point of a journal turning at ``journal_speed`` (rad/s, > 0) under ``load`` (N, > 0) in
    ``joint`` (a lubricated :class:`~weftsim.input.params.ClearanceJoint`; the bearing stands still).

    The unknowns are x with eps = 2 / (1 + exp(-x)) and the attitude phi.  Beyond |e| = c the dry law's elastic
    force (and its Coulomb friction) carries what the film and the asperities cannot.
    """
    if joint.lubrication is None:
        raise ValueError("steady_point needs a lubricated joint (ClearanceJoint.lubrication)")
    prm = joint_parameters(joint, make_law(joint))

    def residual(x):
        lub, dry = _forces(prm, joint, _eps(x[0]), x[1], journal_speed)
        return [(lub[L_FX] + dry[0]) / load, (lub[L_FY] + dry[1] - load) / load]

    best = None
    for eps0, phi0 in ((0.5, 1.0), (0.9, 0.5), (0.99, 0.2), (0.999, 0.05), (1.001, 0.05)):
        sol = least_squares(residual, [-math.log(2.0 / eps0 - 1.0), phi0], xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=400)  # fmt: skip
        if best is None or sol.cost < best.cost:
            best = sol
        if math.sqrt(2.0 * sol.cost) < BALANCE_TOL:
            break
    eps = _eps(float(best.x[0]))
    phi = float(best.x[1])
    out, dry = _forces(prm, joint, eps, phi, journal_speed)
    h_min = max(joint.clearance * (1.0 - eps), 0.0)
    torque = -(out[L_MJ] + dry[3])
    return SteadyPoint(eccentricity_ratio=eps, attitude_deg=math.degrees(phi), film_thickness_m=h_min,
                       film_ratio=h_min / joint.lubrication.roughness, film_force_n=out[L_FILM],
                       asperity_force_n=out[L_ASPERITY], contact_force_n=dry[2], friction_torque_nm=torque, film_torque_nm=-out[L_FILM_TORQUE],
                       friction_coefficient=torque / (load * joint.journal_radius),
                       residual=float(math.sqrt(2.0 * best.cost)))  # fmt: skip
