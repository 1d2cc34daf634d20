"""Force of a lubricated clearance joint: oil film + asperity contact + the dry law (the one definition).

A lubricated joint (``joint.lubrication``, the block of :mod:`.joint` from ``LUBRICATED`` on) is loaded
at every eccentricity, in contact or not::

    f_journal = f_film(e*, e_dot*, omega_j, omega_b)        oil film, :func:`weftsim.physics.film.rough_film_force`
              - F_a(|e|) n + F_Ta t                         asperities (Greenwood-Tripp, :mod:`.asperity`)
                                                            and boundary friction on their load
              + f_dry                                       the dry law beyond |e| = c (:mod:`.joint`)

- **Film.** Evaluated at the journal's eccentricity while h_min = c - abs(e) >= h_floor = ``film_floor_ratio`` sigma.
  Below the floor it is continued, not held: evaluated at abs(e*) = c - h_floor (e* along e; e_dot* with the true
  radial rate d abs(e)/dt and whirl rate (e x e_dot) / abs(e)^2, the tangential part scaled by abs(e*) / abs(e)),
  its force grown by exp(x (n + k x / 2)), x = ln(h_floor / h_min), with n = -d ln abs(f) / d ln h_min and k = dn/dx
  its slope and curvature at the floor (from two steps FLOOR_SLOPE_STEP h_floor above it; n in [0,
  FLOOR_SLOPE_MAX], k in [0, FLOOR_CURVATURE_MAX]) and its direction turned by x times its turning rate at the
  floor (within FLOOR_TURN_MAX), the Couette torque at the true film and the pressure torque
  -(e x f)_x / 2 at the true e, down to the wall h = h_wall = FILM_WALL_RATIO sigma (sigma / 4, where the rough
  film's table ends: :mod:`weftsim.physics.film`); below the wall all of it is held at the wall's value.  So the
  floor is a numerical knob that does not decide the mixed regime (the film between the floor and the wall is the
  film continued with its own slope and curvature, not a frozen field), and the film force stays finite where the
  dry law starts (its squeeze term grows as (1 - eps^2)^-2.5 towards eps = 1).  A floor of sigma / 4 (the least)
  is the wall.  The
  film's shear torques act on journal and bearing; its power -(f.e_dot + T_j omega_j + T_b omega_b) is dissipated.
- **Asperities.** F_a(|e|) of :func:`weftsim.physics.asperity.asperity_load`, zero while h_min >= 4 sigma, up to
  |e| = c; beyond c the dry law takes it over (:func:`asperity_share`: the solids carry max(F_a(c), F_el)
  elastically).  That elastic share has a potential U_a (stored); on it the asperities' hysteresis loop
  (:func:`asperity_normal`: (1 +- kappa) on loading and unloading, kappa from the joint's restitution) dissipates
  what an impact of that restitution loses.  Boundary
  friction F_Ta = -mu_b c_d(v_T) F_a sign(v_T) acts at the contact point Q = P_b + R_b n with the moments
  of the dry friction, M_j = (R_b - |e|) F_Ta, M_b = -R_b F_Ta (:func:`weftsim.physics.joint.friction_force`
  with mu_b and the joint's friction ramp).
- **Dry law.** :func:`weftsim.physics.joint.clearance_force_at`, its friction coefficient the boundary mu_b (a
  lubricated joint's block carries mu_b as its mu, :func:`weftsim.physics.joint.joint_parameters`: the solids'
  contact in oil is boundary-lubricated, so the load the asperities hand over keeps its friction): zero at
  |e| = c and growing from there, so the total radial force is continuous in |e| (the film term is continuous and held
  constant in |e| beyond its wall, the asperity share is continuous and falls as the dry law rises).

Dissipated power of the film, the boundary friction and the asperities' hysteresis, the part of the power the
asperity potential does not store: D' = -(f_l.e_dot + M_lj omega_j + M_lb omega_b) - F_s d|e|/dt.
"""

from __future__ import annotations

import math

from numba import njit

from weftsim.physics.asperity import asperity_load
from weftsim.physics.film import RATIO_MIN, couette_torque, rough_film_force
from weftsim.physics.joint import (
    ASPERITY_COEF, ASPERITY_HYSTERESIS, BEARING_LENGTH, BEARING_RADIUS, BOUNDARY_MU, CLEARANCE, COEF, FILM_FLOOR,
    FILM_MODEL, JOURNAL_RADIUS, KIND, LUBRICATED, ROUGHNESS, V0, V1, V_MIN, VISCOSITY, connector_friction_force_at,
    tangential_velocity,
)  # fmt: skip
from weftsim.physics.laws import elastic_energy, elastic_force, friction_factor

# The film's wall h_wall = FILM_WALL_RATIO sigma: the rough film's table ends there (film.RATIO_MIN, the least floor).
FILM_WALL_RATIO = RATIO_MIN
# Below the floor ln abs(f) is continued in x = ln(h_floor / h_min) with its slope n and curvature k at the floor
# (film_at_floor), from steps of FLOOR_SLOPE_STEP h_floor above it; n in [0, FLOOR_SLOPE_MAX] (the table's squeeze
# film near the wall: n ~ 2.5), k in [0, FLOOR_CURVATURE_MAX] (the loom's pin at h_floor = sigma: n 1.2-1.7,
# k 0.26-0.36).
FLOOR_SLOPE_STEP, FLOOR_SLOPE_MAX, FLOOR_CURVATURE_MAX = 0.05, 3.0, 1.0
# Its direction turns by at most this rate in x, rad (the pin's attitude at sigma: -0.1 rad per unit x).
FLOOR_TURN_MAX = 0.5

# Outputs of lubricated_force, in order (the channels of weftsim.joint.lubrication read them by these indices).
(L_FX, L_FY, L_MJ, L_MB, L_FILM, L_ASPERITY, L_FILM_TORQUE, L_ASPERITY_ENERGY, L_DISSIPATED, L_FILM_POWER) = range(10)


@njit(cache=True, error_model="numpy", inline="always")
def is_lubricated(prm) -> bool:
    """True when the joint block ``prm`` has an oil film (``joint.lubrication`` given)."""
    return prm[LUBRICATED] != 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _film_along(prm, clearance: float, ex: float, ey: float, vx: float, vy: float, w_j: float, w_b: float,
                length: float, at: float) -> tuple[float, float, float, float]:
    """The film of the journal moved along e from abs(e) = ``length`` to ``at``, keeping its radial rate d abs(e)/dt
    and its whirl rate (e x e_dot) / abs(e)^2 (the tangential rate scaled by at / length)."""
    nx, ny = ex / length, ey / length
    radial = vx * nx + vy * ny
    scale = at / length
    tx, ty = vx - radial * nx, vy - radial * ny
    return rough_film_force(at * nx, at * ny, radial * nx + scale * tx, radial * ny + scale * ty, w_j, w_b, clearance,
                            prm[JOURNAL_RADIUS], prm[BEARING_LENGTH], prm[VISCOSITY], int(prm[FILM_MODEL]),
                            prm[ROUGHNESS])  # fmt: skip


@njit(cache=True, error_model="numpy")
def film_at_floor(prm, clearance: float, ex: float, ey: float, vx: float, vy: float, w_j: float,
                  w_b: float) -> tuple[float, float, float, float]:
    """Film force on the journal and shear torques (f_x, f_y, T_j, T_b), N and N m, continued below the film
    floor h_floor with its slope, curvature and turning rate in ln h_min down to the wall h_wall (module
    docstring); zeros at zero viscosity."""
    if prm[VISCOSITY] <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    sigma = prm[ROUGHNESS]
    length = math.sqrt(ex * ex + ey * ey)
    h_floor = prm[FILM_FLOOR] * sigma
    if clearance - length >= h_floor:
        return rough_film_force(ex, ey, vx, vy, w_j, w_b, clearance, prm[JOURNAL_RADIUS], prm[BEARING_LENGTH],
                                prm[VISCOSITY], int(prm[FILM_MODEL]), sigma)  # fmt: skip
    fx, fy, t_j, t_b = _film_along(prm, clearance, ex, ey, vx, vy, w_j, w_b, length, clearance - h_floor)
    h_wall = FILM_WALL_RATIO * sigma
    if h_floor <= h_wall:  # a floor at the wall: the film held there
        return fx, fy, t_j, t_b
    # ln abs(f) continued as a parabola in x = ln(h_floor / h): slope n and curvature k at the floor from two steps
    # of FLOOR_SLOPE_STEP h_floor above it (the secants' slopes at their midpoints), k in [0, FLOOR_CURVATURE_MAX],
    # n in [0, FLOOR_SLOPE_MAX].
    step = math.log1p(FLOOR_SLOPE_STEP)
    gx, gy, _, _ = _film_along(prm, clearance, ex, ey, vx, vy, w_j, w_b, length, clearance - h_floor * math.exp(step))
    kx, ky, _, _ = _film_along(prm, clearance, ex, ey, vx, vy, w_j, w_b, length,
                               clearance - h_floor * math.exp(2.0 * step))  # fmt: skip
    f0, f1, f2 = math.hypot(fx, fy), math.hypot(gx, gy), math.hypot(kx, ky)
    slope = curvature = turn = 0.0
    if f0 > 0.0 and f1 > 0.0 and f2 > 0.0:
        near, far = math.log(f0 / f1) / step, math.log(f1 / f2) / step
        curvature = min(max((near - far) / step, 0.0), FLOOR_CURVATURE_MAX)
        slope = min(max(near + 0.5 * curvature * step, 0.0), FLOOR_SLOPE_MAX)
        # The force's direction (its attitude to e) turns linearly in x at the floor's rate, within FLOOR_TURN_MAX.
        turn = math.atan2(gx * fy - gy * fx, gx * fx + gy * fy) / step
        turn = min(max(turn, -FLOOR_TURN_MAX), FLOOR_TURN_MAX)
    h = max(clearance - length, h_wall)
    x = math.log(h_floor / h)
    grow = math.exp(x * (slope + 0.5 * curvature * x))
    cos_t, sin_t = math.cos(turn * x), math.sin(turn * x)
    fx, fy = grow * (cos_t * fx - sin_t * fy), grow * (sin_t * fx + cos_t * fy)
    at = (clearance - h) / length
    couette = couette_torque((clearance - h) / clearance, w_j, w_b, clearance, prm[JOURNAL_RADIUS],
                             prm[BEARING_LENGTH], prm[VISCOSITY], int(prm[FILM_MODEL]), sigma)  # fmt: skip
    pressure = -0.5 * at * (ex * fy - ey * fx)
    return fx, fy, couette + pressure, -couette + pressure


HANDOVER_TOL = 1e-13  # relative: the penetration at which the dry law's elastic force reaches F_a(c)


@njit(cache=True, error_model="numpy")
def handover_depth(prm, clearance: float, load: float, delta: float) -> float:
    """delta* in (0, delta]: the penetration at which the dry law's elastic force F_el reaches ``load`` (N),
    given F_el(delta) >= load.  Secant steps on log F_el against log delta (every law is close to a power
    1.5-2 there), bracketed; exact for the constant-stiffness law in one step."""
    kind, coef = prm[KIND], prm[COEF]
    hi, f_hi = delta, elastic_force(kind, coef, clearance, delta)
    if f_hi <= load:
        return delta
    lo = hi * (load / f_hi) ** (2.0 / 3.0)  # a power 1.5 from hi
    f_lo = elastic_force(kind, coef, clearance, lo)
    if f_lo >= load:  # the law is steeper than 1.5 below hi: bracket from below
        while f_lo >= load:
            hi, f_hi = lo, f_lo
            lo *= 0.5
            f_lo = elastic_force(kind, coef, clearance, lo)
    target = math.log(load)
    for _ in range(60):
        x_lo, x_hi = math.log(lo), math.log(hi)
        g_lo, g_hi = math.log(f_lo) - target, math.log(f_hi) - target
        x = x_hi - g_hi * (x_hi - x_lo) / (g_hi - g_lo)
        mid = math.exp(x)
        f_mid = elastic_force(kind, coef, clearance, mid)
        if abs(f_mid - load) <= HANDOVER_TOL * load or hi - lo <= HANDOVER_TOL * hi:
            return mid
        if f_mid > load:
            hi, f_hi = mid, f_mid
        else:
            lo, f_lo = mid, f_mid
    return 0.5 * (lo + hi)


@njit(cache=True, error_model="numpy")
def asperity_share(prm, clearance: float, ecc: float) -> tuple[float, float]:
    """(F_s, U_s): the elastic load the asperities carry at |e| = ``ecc`` (N) and its potential (J).

    Up to |e| = c (the mean planes touch) Greenwood and Tripp's F_a (:func:`weftsim.physics.asperity.asperity_load`).
    Beyond c the asperities are pressed into the bulk and the dry law's contact (elastic force F_el(delta),
    delta = |e| - c) takes their load over: F_s = max(F_a(c) - F_el(delta), 0), so that the solids carry
    max(F_a(c), F_el(delta)) elastically, never more than the dry law once it carries F_a(c), and exactly the
    dry joint as the roughness vanishes (F_a(c) falls as sqrt(sigma)).  U_s = U_a(c) + F_a(c) d - W_el(d),
    d = min(delta, delta*) with F_el(delta*) = F_a(c) (:func:`handover_depth`).
    """
    f_a, u_a = asperity_load(prm[ASPERITY_COEF], prm[ROUGHNESS], clearance, ecc, prm[JOURNAL_RADIUS],
                             prm[BEARING_LENGTH])  # fmt: skip
    delta = ecc - clearance
    if delta <= 0.0 or f_a <= 0.0:
        return f_a, u_a
    kind, coef = prm[KIND], prm[COEF]
    f_el = elastic_force(kind, coef, clearance, delta)
    d = delta if f_el < f_a else handover_depth(prm, clearance, f_a, delta)
    energy = u_a + f_a * d - elastic_energy(kind, coef, clearance, d)
    return (f_a - f_el if f_el < f_a else 0.0), energy


@njit(cache=True, error_model="numpy")
def asperity_normal(prm, clearance: float, ex: float, ey: float, vx: float, vy: float) -> tuple[float, float, float]:
    """(F_an, U_s, D'_h): the asperities' normal load on their loading or unloading branch (N), the potential of
    their elastic share (J) and the power their hysteresis dissipates (W) at eccentricity e and its rate.

    F_an = F_s (1 + kappa s), s = r' / max(abs(r'), v_min) the sign of the approach rate r' = d|e|/dt (a ramp
    below the joint's v_min), kappa = ``prm[ASPERITY_HYSTERESIS]`` = (1 - e^2) / (1 + e^2): a rate-independent
    loop (loading (1 + kappa) F_s, unloading (1 - kappa) F_s) that returns e^2 of the work done on it, the
    energy ratio of an impact with the joint's restitution e at any depth (the partially latching
    spring of Walton and Braun, J. Rheol. 30, 1986, with its two branches in proportion).  D'_h = kappa s F_s r'
    >= 0.  Rows with |e| = 0 or no asperity contact: (0, 0, 0).
    """
    length = math.sqrt(ex * ex + ey * ey)
    f_s, u_s = asperity_share(prm, clearance, length)
    if f_s <= 0.0 or length <= 0.0:
        return 0.0, u_s, 0.0
    rate = (ex * vx + ey * vy) / length
    v_min = prm[V_MIN]
    side = rate / (abs(rate) if abs(rate) > v_min else v_min)
    hysteresis = prm[ASPERITY_HYSTERESIS] * side * f_s
    return f_s + hysteresis, u_s, hysteresis * rate


@njit(cache=True, error_model="numpy")
def lubricated_force(prm, clearance: float, ex: float, ey: float, vx: float, vy: float, w_j: float,
                     w_b: float) -> tuple[float, ...]:
    """Film and asperity force of a lubricated joint (block ``prm``) at eccentricity e and its rate.

    ``clearance``: the local clearance along e (m; the round joint's c); ``w_j``, ``w_b``: angular
    velocities of journal and bearing about the joint axis (rad/s).  The dry law is not included
    (:func:`weftsim.physics.joint.clearance_force_at` adds it in contact).

    Returns
    -------
    (f_x, f_y, M_j, M_b, |f_film|, F_a, T_j, U_a, D', P_film): force on the journal (N), moments on
    journal and bearing about their centres (N m; film shear torques + boundary friction), the film
    force's magnitude (N), the asperity load (N), the film's shear torque on the journal (N m), the
    asperity potential (J), the dissipated power (W, module docstring) and the film's part of it (W).
    Indices: ``L_FX`` ... ``L_FILM_POWER``.
    """
    ffx, ffy, t_j, t_b = film_at_floor(prm, clearance, ex, ey, vx, vy, w_j, w_b)
    film_power = -(ffx * vx + ffy * vy + t_j * w_j + t_b * w_b)
    length = math.sqrt(ex * ex + ey * ey)
    f_a, u_a, hysteresis_power = asperity_normal(prm, clearance, ex, ey, vx, vy)
    fx, fy, m_j, m_b = ffx, ffy, t_j, t_b
    dissipated = film_power + hysteresis_power
    if f_a > 0.0 and length > 0.0:
        nx, ny = ex / length, ey / length
        f_t = 0.0
        mu_b = prm[BOUNDARY_MU]
        r_b = prm[BEARING_RADIUS]
        if mu_b > 0.0:
            v_t = tangential_velocity(ex, ey, vx, vy, length, w_j, w_b, r_b)
            c_d = friction_factor(v_t, prm[V0], prm[V1])
            if c_d > 0.0:
                f_t = -mu_b * c_d * f_a if v_t > 0.0 else mu_b * c_d * f_a
            dissipated -= f_t * v_t  # -F_Ta v_T >= 0
        fx += -f_a * nx - f_t * ny
        fy += -f_a * ny + f_t * nx
        m_j += (r_b - length) * f_t
        m_b += -r_b * f_t
    return fx, fy, m_j, m_b, math.hypot(ffx, ffy), f_a, t_j, u_a, dissipated, film_power


@njit(cache=True, error_model="numpy")
def connector_lubricated_force(prm, ex: float, ey: float, vx: float, vy: float, held: float, delta0: float,
                               rate0: float, omega_j: float, omega_b: float) -> tuple[float, ...]:
    """:func:`weftsim.physics.joint.connector_friction_force` with the film and asperity terms (Exudyn).

    Returns the same nine values (the force on the bearing, now - f_journal of :func:`lubricated_force`
    added; M_j, M_b including the film's torques and the boundary friction), then the lubricated part's
    dissipated power D' (W), the asperity potential U_a (J), the film force's magnitude (N), the
    asperity load F_a (N) and the film's shear torque on the journal T_j (N m).  The round joint:
    :func:`connector_lubricated_force_at` with the clearance ``prm[CLEARANCE]``.
    """
    return connector_lubricated_force_at(prm, prm[CLEARANCE], 0.0, ex, ey, vx, vy, held, delta0, rate0, omega_j,
                                         omega_b)  # fmt: skip


@njit(cache=True, error_model="numpy")
def connector_lubricated_force_at(prm, clearance: float, clearance_rate: float, ex: float, ey: float, vx: float,
                                  vy: float, held: float, delta0: float, rate0: float, omega_j: float,
                                  omega_b: float) -> tuple[float, ...]:
    """:func:`connector_lubricated_force` with a local clearance and its rate (a worn joint,
    :func:`weftsim.physics.joint.connector_force_at`): the film and the asperities see the local clearance
    too, as on the reference engine's chain."""
    fx, fy, delta, rate, f_n, f_t, m_j, m_b, v_t = connector_friction_force_at(
        prm, clearance, clearance_rate, ex, ey, vx, vy, held, delta0, rate0, omega_j, omega_b)
    lub = lubricated_force(prm, clearance, ex, ey, vx, vy, omega_j, omega_b)
    return (fx - lub[L_FX], fy - lub[L_FY], delta, rate, f_n, f_t, m_j + lub[L_MJ], m_b + lub[L_MB], v_t,
            lub[L_DISSIPATED], lub[L_ASPERITY_ENERGY], lub[L_FILM], lub[L_ASPERITY], lub[L_FILM_TORQUE])  # fmt: skip
