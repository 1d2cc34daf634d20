"""Asperity contact of a lubricated journal bearing: Greenwood-Tripp (the one definition).

Two rough surfaces a nominal gap h apart (combined RMS roughness sigma) touch at their highest
asperities; the mean pressure the asperities carry is (Greenwood and Tripp, Proc. Instn Mech.
Engrs 185, 1970-71; the fit of F_5/2 from Hu, Cheng, Arai, Kobayashi and Aoyama, STLE Tribology
Trans. 37, 1994)::

    p_a(h) = K E* F_5/2(H),   H = h / sigma,
    K      = (16 sqrt(2) pi / 15) (eta_s beta sigma)^2 sqrt(sigma / beta),
    F_5/2(H) = 4.4086e-5 (4 - H)^6.804  for H < 4,  0 for H >= 4,

with the asperity density eta_s, summit radius beta and the Hertz modulus E* (1/E* = (1 - nu_j^2)/E_j
+ (1 - nu_b^2)/E_b, the joint's ``effective_modulus``).  Papers that write K with 8 sqrt(2) use the
composite modulus E' = 2 E*: the same pressure.

In the journal bearing the gap is h(theta) = c - |e| cos(theta) (theta from the direction of e, where
the film is thinnest, h_min = c - |e|).  The asperities push the journal back along -n with

    F_a(|e|) = R_j L_b integral p_a(h(theta)) cos(theta) dtheta,

over the arc where h < 4 sigma (nothing when h_min >= 4 sigma), continued linearly beyond |e| = c with its
slope there (:func:`asperity_load`).  The force depends on |e| only: it has
a potential U_a(|e|) = R_j L_b integral Pi(h(theta)) dtheta with Pi(h) = integral_h^(4 sigma) p_a,
in closed form K E* sigma 4.4086e-5 (4 - H)^7.804 / 7.804, so the energy balance books it as stored,
not dissipated.  The integrand is symmetric and vanishes at theta_max as (theta_max - theta)^6.8 (the
load's, the stiffness's as ^5.8): the integrals over [0, theta_max] are a Gauss-Jacobi rule of :data:`NODES`
points for the weight (theta_max - theta)^5.804, exact for that factor times a polynomial, so 8 points
reach the 1e-11 of 24 Gauss-Legendre points (which converge only algebraically at that endpoint zero) at a
third of the cost (the asperity load was ~80 % of a lubricated right-hand side's time).  Where the contact
arc is the whole circle (theta_max = pi, c + |e| < 4 sigma) nothing vanishes at the end, and the 24-point
Gauss-Legendre rule is used.

The functions take floats and return floats, never check their arguments, and are compiled by numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

F52_SCALE = 4.4086e-5
F52_EXPONENT = 6.804
H_CUTOFF = 4.0  # film ratio above which no asperity touches (the fit's end)
# Gauss-Legendre nodes on [0, 1]: 24 points integrate the (4 - H)^6.8 arc to ~1e-11 relative; used where the arc
# is the whole circle (module docstring).
LEGENDRE_NODES = 24
_X, _W = np.polynomial.legendre.leggauss(LEGENDRE_NODES)
GAUSS_X = 0.5 * (_X + 1.0)
GAUSS_W = 0.5 * _W


def gauss_jacobi(n: int, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights on [0, 1] of the n-point Gauss rule for the weight (1 - x)^alpha, folded into the weights.

    Golub-Welsch on the recurrence of the Jacobi polynomials (weight (1 - t)^alpha on [-1, 1]); the returned
    weights W_k = w_k 2^(-alpha-1) / (1 - x_k)^alpha apply to the whole integrand: sum W_k f(x_k) integrates
    f = (1 - x)^alpha p(x) exactly for polynomials p of degree < 2n.
    """
    k = np.arange(1, n, dtype=float)
    s = 2.0 * k + alpha
    diagonal = np.concatenate([[-alpha / (alpha + 2.0)], -alpha**2 / (s * (s + 2.0))])
    off = np.sqrt(4.0 * k * k * (k + alpha) ** 2 / (s**2 * (s + 1.0) * (s - 1.0)))
    t, vectors = np.linalg.eigh(np.diag(diagonal) + np.diag(off, 1) + np.diag(off, -1))
    mu0 = 2.0 ** (alpha + 1.0) / (alpha + 1.0)  # integral of (1 - t)^alpha over [-1, 1]
    x = 0.5 * (t + 1.0)
    return x, mu0 * vectors[0] ** 2 * 2.0 ** (-alpha - 1.0) / (1.0 - x) ** alpha


# Gauss-Jacobi on [0, 1] for the weight (1 - x)^5.804, the stiffness integrand's endpoint zero (the load's and the
# potential's are one and two powers higher): 8 points agree with 400-point Gauss-Legendre within 1e-11 over film
# ratios 0-4 at c = 2 um-0.25 mm (6 points: 1e-8; 24-point Gauss-Legendre: 1.4e-11); tests/test_lubrication.py.
NODES = 8
JACOBI_X, JACOBI_W = gauss_jacobi(NODES, F52_EXPONENT - 1.0)


def greenwood_tripp_coefficient(eta_beta_sigma: float, sigma_over_beta: float, effective_modulus: float) -> float:
    """K E*, Pa: (16 sqrt(2) pi / 15) (eta_s beta sigma)^2 sqrt(sigma / beta) E* (module docstring)."""
    return 16.0 * math.sqrt(2.0) * math.pi / 15.0 * eta_beta_sigma**2 * math.sqrt(sigma_over_beta) * effective_modulus


@njit(cache=True, error_model="numpy")
def f52(ratio: float) -> float:
    """F_5/2(H) of Greenwood-Tripp (Hu et al.'s fit), dimensionless; 0 for H >= 4."""
    if ratio >= H_CUTOFF:
        return 0.0
    return F52_SCALE * (H_CUTOFF - ratio) ** F52_EXPONENT


@njit(cache=True, error_model="numpy")
def asperity_pressure(coef: float, sigma: float, gap: float) -> float:
    """p_a(h) = K E* F_5/2(h / sigma), Pa (``coef`` = K E*)."""
    return coef * f52(gap / sigma)


@njit(cache=True, error_model="numpy")
def asperity_load(coef: float, sigma: float, clearance: float, ecc: float, radius: float,
                  length: float) -> tuple[float, float]:
    """(F_a, U_a): asperity load along -n on the journal (N) and its potential (J) at |e| = ``ecc``.

    ``coef`` = K E* (Pa), ``sigma`` the combined RMS roughness (m), ``clearance`` c (m), ``radius`` R_j
    and ``length`` L_b (m).  Beyond |e| = c (there the dry contact law takes over) continued with the
    asperities' stiffness at c, k_a = dF_a/d|e|: F_a(c) + k_a (|e| - c) and its potential, so that the
    force stays continuous with a continuous slope, and conservative.
    """
    if coef <= 0.0:
        return 0.0, 0.0
    e = ecc if ecc < clearance else clearance
    if clearance - e >= H_CUTOFF * sigma:
        return 0.0, 0.0
    cos_max = (clearance - H_CUTOFF * sigma) / e if e > 0.0 else -1.0
    nodes, weights = JACOBI_X, JACOBI_W  # the integrand vanishes at theta_max (module docstring)
    if cos_max <= -1.0:  # the whole circle: no zero at the end
        cos_max = -1.0
        nodes, weights = GAUSS_X, GAUSS_W
    theta_max = math.acos(cos_max)
    force = 0.0
    energy = 0.0
    slope = 0.0
    for k in range(nodes.size):
        theta = theta_max * nodes[k]
        c_t = math.cos(theta)
        ratio = (clearance - e * c_t) / sigma
        if ratio < H_CUTOFF:
            base = H_CUTOFF - ratio
            p = F52_SCALE * base**F52_EXPONENT
            force += weights[k] * p * c_t
            energy += weights[k] * p * base / (F52_EXPONENT + 1.0)
            slope += weights[k] * F52_EXPONENT * p / base * c_t * c_t
    scale = 2.0 * theta_max * radius * length * coef  # both halves of the arc
    force *= scale
    energy *= scale * sigma
    if ecc > clearance:
        # Beyond c the asperities keep their stiffness at h_min = 0 (a C1 continuation: the integrators see no
        # kink where the dry law starts): F_a(c) + k_a (|e| - c), k_a = dF_a/d|e| at c.
        stiffness = slope * scale / sigma
        d = ecc - clearance
        energy += force * d + 0.5 * stiffness * d * d
        force += stiffness * d
    return force, energy


@njit(cache=True, error_model="numpy")
def asperity_half_angle(sigma: float, clearance: float, ecc: float) -> float:
    """theta_max = acos((c - 4 sigma) / |e|): half the arc where the asperities touch (h < 4 sigma), rad;
    0 while h_min >= 4 sigma (|e| held at c beyond c, as the load)."""
    e = ecc if ecc < clearance else clearance
    if e <= 0.0 or clearance - e >= H_CUTOFF * sigma:
        return 0.0
    cos_max = (clearance - H_CUTOFF * sigma) / e
    return math.acos(cos_max if cos_max > -1.0 else -1.0)
