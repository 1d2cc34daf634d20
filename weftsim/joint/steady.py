"""The steadily loaded plain bearing: where the joint's kernel carries a load, and what that costs.

A journal of radius R spinning at omega (N = omega / 2 pi rev/s) in a still bearing of length L and radial
clearance c carries a steady load W where the force of the joint's kernel balances it
(:func:`weftsim.physics.steady.steady_force`: oil film, asperities and their boundary friction, the dry law
beyond e = c; the same functions the transient engines integrate).  By symmetry that force depends on abs(e)
alone (its direction turns with e), so abs(e) is the root of abs(f(abs(e))) = W (Brent's method; abs(f) grows
with abs(e)), and the attitude angle is the angle between the load and the line of centres.  Then (Raimondi and
Boyd, ASLE Trans. 1, 1958; Shigley's Mechanical Engineering Design, ch. 12):

- Sommerfeld number S = (R/c)^2 eta N / P, P = W / (2 R L) the projected pressure;
- eccentricity ratio eps = abs(e) / c, minimum film h_min = c - abs(e) (0 once the dry law carries), film ratio
  h_min / sigma;
- friction torque T = -M_j on the journal, friction coefficient f = T / (W R), power loss P_f = T omega;
- the regime by the film ratio, as the regime map (docs/lubricated-joint.md): hydrodynamic above 3, mixed
  from 1 to 3, boundary below 1;
- the film's inlet and side flow Q, Qs (:mod:`weftsim.joint.film_flow`) at the eccentricity the film is
  evaluated at (held below c - h_wall, :mod:`weftsim.physics.lubricated`).

With ``lubrication.elastic_film`` the point is the elastic film's (:mod:`weftsim.joint.ehl`, started from the rigid
point): eccentricity, attitude, minimum film (of the deformed gap), friction torque, film force and asperity load
are its, the Sommerfeld number and the flows stay the rigid film's, and ``elastic`` holds its own numbers.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

# Film ratios that bound the regimes (the regime map's, weftsim.studies.regime).
HYDRODYNAMIC_RATIO, MIXED_RATIO = 3.0, 1.0
# Relative tolerance of the eccentricity root (brentq xtol = this x c): the load balances to ~1e-12 relative.
ECCENTRICITY_TOL = 1e-13


@dataclass(frozen=True)
class SteadyPoint:
    """One steady operating point of a plain bearing (SI units; module docstring)."""

    load_n: float
    journal_speed_rad_s: float
    viscosity_pa_s: float
    sommerfeld: float
    eccentricity_ratio: float
    attitude_angle_deg: float
    min_film_m: float
    film_ratio: float
    friction_torque_nm: float
    friction_coefficient: float
    power_loss_w: float
    film_force_n: float
    asperity_load_n: float
    dry_force_n: float
    inlet_flow_m3_s: float
    side_flow_m3_s: float
    regime: str
    elastic: dict | None = None  # the elastic film's own numbers (weftsim.joint.ehl.ElasticPoint), when it is on

    def as_dict(self) -> dict:
        """JSON-ready (plain floats and the regime's name)."""
        return asdict(self)


def regime_of(ratio: float) -> str:
    """``"hydrodynamic"`` (film ratio > 3), ``"mixed"`` (1-3) or ``"boundary"`` (< 1)."""
    return "hydrodynamic" if ratio > HYDRODYNAMIC_RATIO else "mixed" if ratio >= MIXED_RATIO else "boundary"


def joint_block(joint) -> np.ndarray:
    """The kernel's parameter block of a lubricated :class:`weftsim.input.params.ClearanceJoint`."""
    from weftsim.joint.contact import make_law
    from weftsim.physics.joint import joint_parameters

    return joint_parameters(joint, make_law(joint))


def steady_point(joint, load: float, omega: float, viscosity: float, prm: np.ndarray | None = None,
                 warm: dict | None = None) -> SteadyPoint:
    """The :class:`SteadyPoint` of ``joint`` (lubricated) under ``load`` (N) at journal speed ``omega`` (rad/s)
    with the film at ``viscosity`` (Pa s).  ``prm``: the joint's block, if already built (:func:`joint_block`);
    ``warm``: the elastic film's start kept between neighbouring points (:func:`weftsim.joint.ehl.elastic_point`)."""
    from scipy.optimize import brentq

    from weftsim.joint.film_flow import flow_variables
    from weftsim.physics.joint import VISCOSITY
    from weftsim.physics.lubricated import FILM_WALL_RATIO
    from weftsim.physics.steady import steady_force

    prm = (joint_block(joint) if prm is None else prm).copy()
    prm[VISCOSITY] = viscosity
    c, radius, length = joint.clearance, joint.journal_radius, joint.bearing_length
    lub = joint.lubrication

    def force(ecc: float) -> float:
        fy, fz = steady_force(prm, c, ecc, omega)[:2]
        return math.hypot(fy, fz) - load

    lo, hi = 1e-9 * c, c
    if force(lo) >= 0.0:  # a load the centred journal carries already (only W = 0)
        ecc = lo
    else:
        while force(hi) < 0.0:  # beyond c: the dry law carries the rest
            hi = c + 2.0 * (hi - c + 1e-9 * c)
            if hi - c > radius:
                raise ValueError(f"the joint carries no load of {load:g} N within a penetration of R_j")
        ecc = brentq(force, lo, hi, xtol=ECCENTRICITY_TOL * c, rtol=1e-15)
    fy, fz, m_j, film, asperity, dry = steady_force(prm, c, ecc, omega)
    attitude = math.degrees(math.atan2(abs(fz), -fy)) if load > 0.0 else 90.0
    torque = -m_j
    pressure = load / (2.0 * radius * length)
    n = omega / (2.0 * math.pi)
    sommerfeld = (radius / c) ** 2 * viscosity * n / pressure if pressure > 0.0 else math.inf
    h_min = max(c - ecc, 0.0)
    eps_film = min(ecc, c - FILM_WALL_RATIO * lub.roughness) / c
    elastic = None
    if lub.elastic_film and load > 0.0:  # the elastic film from the rigid one's eccentricity (weftsim.joint.ehl)
        from weftsim.joint.ehl import Pair, elastic_point

        point = elastic_point(Pair.of(joint), load, omega, viscosity, min(ecc / c, 0.99), warm=warm)
        elastic = point.as_dict()
        ecc, attitude, h_min = point.eccentricity_ratio * c, point.attitude_angle_deg, point.min_film_m
        torque, film, asperity, dry = point.friction_torque_nm, point.film_force_n, point.asperity_load_n, 0.0
    ratio = h_min / lub.roughness
    q_in, q_side = flow_variables(eps_film, length / (2.0 * radius))
    scale = radius * c * n * length
    f = float  # plain floats for JSON
    return SteadyPoint(f(load), f(omega), f(viscosity), f(sommerfeld), f(ecc / c), f(attitude), f(h_min), f(ratio),
                       f(torque), f(torque / (load * radius)) if load > 0.0 else math.inf, f(torque * omega),
                       f(film), f(asperity), f(dry), f(q_in * scale), f(q_side * scale), regime_of(ratio), elastic)
