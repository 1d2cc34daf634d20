"""Contact force laws of the clearance joint as scalar functions (the one definition).

Every law of :mod:`weftsim.joint.contact` gives the normal force of a journal pressed into its bearing,

    F_N = max(0, K(delta) delta^1.5 (1 + xi delta_dot / v_imp))   for delta > 0, else 0,

with penetration delta (m), penetration rate delta_dot (m/s, positive while approaching), held
impact velocity v_imp (m/s, > 0) and hysteresis factor xi.  A law is four numbers:

=====================  =========================  =========================================
``kind``               ``coef``                   stiffness K(delta), delta >= 0
=====================  =========================  =========================================
``LAW_CONSTANT``       k = K_LN, N/m^1.5          k
``LAW_VARIABLE_KD``    a = (pi/8) E*, Pa          a sqrt(2 delta (3c + 2 delta)^2 / (c + delta)^3)
``LAW_ELASTIC_FOUND.`` b = L_b (pi/2) E*, N/m     b / sqrt(2 (c + delta))
=====================  =========================  =========================================

plus the clearance c (m, used by the delta-dependent laws) and xi.  :mod:`weftsim.joint.contact` builds
them from a joint (``law.parameters``) and documents each law and its sources (Lankarani &
Nikravesh 1990, Bai & Zhao 2013, Liu, Zhang & Yang 2007, ...).  The functions take floats and
return floats, never check their arguments (speed), and are compiled with numba; ``fn.py_func``
is the same source in plain Python.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

LAW_CONSTANT, LAW_VARIABLE_KD, LAW_ELASTIC_FOUNDATION = 0, 1, 2

# Below x = delta / c = 1/4 the energy integrals of the delta-dependent laws are summed as binomial
# series (their closed forms cancel catastrophically as x -> 0); 32 terms: 0.25^32 ~ 5e-20, far below
# double round-off.
SERIES_LIMIT = 0.25
SERIES_TERMS = 32


def _moment_coefficients(m: float, p: float) -> np.ndarray:
    """c_k = C(p, k) / (m + k + 1): integral_0^y x^m (1 + x)^p dx = y^(m+1) sum_k c_k y^k (|y| < 1)."""
    out = np.empty(SERIES_TERMS)
    coeff = 1.0
    for k in range(SERIES_TERMS):
        out[k] = coeff / (m + k + 1.0)
        coeff *= (p - k) / (k + 1.0)
    return out


# variable_kd: g(x) = 3 M(2, -1.5) + 2 M(3, -1.5); elastic_foundation: h(x) = M(1.5, -0.5), with
# M(m, p) = integral_0^x t^m (1 + t)^p dt.  Horner polynomials in x (constants of the compiled code).
_VKD_SQUARE = _moment_coefficients(2.0, -1.5) * 3.0
_VKD_CUBE = _moment_coefficients(3.0, -1.5) * 2.0
_EF_SERIES = _moment_coefficients(1.5, -0.5)


@njit(cache=True, error_model="numpy", inline="always")
def stiffness(kind: float, coef: float, clearance: float, delta: float) -> float:
    """K(delta) of the law, N/m^1.5 (delta <= 0 gives the value at 0)."""
    d = delta if delta > 0.0 else 0.0
    if kind == LAW_VARIABLE_KD:
        w = 3.0 * clearance + 2.0 * d
        s = clearance + d
        return coef * math.sqrt(2.0 * d * w * w / (s * s * s))
    if kind == LAW_ELASTIC_FOUNDATION:
        return coef / math.sqrt(2.0 * (clearance + d))
    return coef


@njit(cache=True, error_model="numpy", inline="always")
def elastic_force(kind: float, coef: float, clearance: float, delta: float) -> float:
    """F_el = K(delta) delta^1.5 for delta > 0, else 0, N."""
    if delta <= 0.0:
        return 0.0
    return stiffness(kind, coef, clearance, delta) * delta * math.sqrt(delta)


@njit(cache=True, error_model="numpy", inline="always")
def normal_force(kind: float, coef: float, clearance: float, xi: float, delta: float, delta_dot: float,
                 impact_velocity: float) -> float:
    """F_N = max(0, F_el(delta) (1 + xi delta_dot / v_imp)) for delta > 0, else 0, N (v_imp > 0)."""
    if delta <= 0.0:
        return 0.0
    f = elastic_force(kind, coef, clearance, delta) * (1.0 + xi * delta_dot / impact_velocity)
    return f if f > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def damping_coefficient(kind: float, coef: float, clearance: float, xi: float, delta: float,
                        impact_velocity: float) -> float:
    """D = xi F_el(delta) / v_imp, N s/m (Lankarani & Nikravesh 1990), so F_N = F_el + D delta_dot."""
    return xi * elastic_force(kind, coef, clearance, delta) / impact_velocity


@njit(cache=True, error_model="numpy")
def elastic_energy(kind: float, coef: float, clearance: float, delta: float) -> float:
    """W = integral_0^delta F_el(s) ds, J (0 for delta <= 0).

    Constant K: W = k delta^2.5 / 2.5.  variable_kd: W = a sqrt(2) c^2.5 g(x), x = delta / c,
    g(x) = 4/5 u^2.5 - 2 u^1.5 - 2 u^-0.5 + 16/5 with u = 1 + x.  elastic_foundation:
    W = (b / sqrt(2)) c^2 h(x), h(x) = sqrt(x (1 + x)) (2x - 3) / 4 + 3/4 asinh(sqrt(x)).
    Below x = :data:`SERIES_LIMIT` g and h are summed as binomial series (relative error ~1e-14).
    """
    if delta <= 0.0:
        return 0.0
    if kind == LAW_CONSTANT:
        return coef * delta**2.5 / 2.5
    c = clearance
    x = delta / c
    if kind == LAW_VARIABLE_KD:
        if x <= SERIES_LIMIT:
            square = 0.0
            cube = 0.0
            for k in range(SERIES_TERMS - 1, -1, -1):
                square = square * x + _VKD_SQUARE[k]
                cube = cube * x + _VKD_CUBE[k]
            g = x * x * x * (square + x * cube)
        else:
            u = 1.0 + x
            g = 0.8 * u**2.5 - 2.0 * u**1.5 - 2.0 / math.sqrt(u) + 3.2
        return coef * math.sqrt(2.0) * c**2.5 * g
    if x <= SERIES_LIMIT:
        series = 0.0
        for k in range(SERIES_TERMS - 1, -1, -1):
            series = series * x + _EF_SERIES[k]
        h = x * x * math.sqrt(x) * series
    else:
        h = 0.25 * math.sqrt(x * (1.0 + x)) * (2.0 * x - 3.0) + 0.75 * math.asinh(math.sqrt(x))
    return coef / math.sqrt(2.0) * c * c * h


@njit(cache=True, error_model="numpy")
def friction_factor(tangential_speed: float, v0: float, v1: float) -> float:
    """Dynamic correction factor c_d in [0, 1] of the modified Coulomb law (Ambrosio 2003).

    c_d = 0 for |v_T| <= v0, (|v_T| - v0) / (v1 - v0) for v0 < |v_T| < v1, 1 for |v_T| >= v1.
    """
    s = abs(tangential_speed)
    if s <= v0:
        return 0.0
    if s >= v1:
        return 1.0
    return (s - v0) / (v1 - v0)
