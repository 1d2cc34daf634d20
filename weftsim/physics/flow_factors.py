"""Flow and shear-stress factors of the average-flow Reynolds equation (Patir and Cheng; the one definition).

Between rough surfaces the film's flow and shear are averaged over the roughness.  Patir and Cheng
(ASME J. Lubr. Technol. 100, 1978, 12-17; 101, 1979, 220-229) write the averaged Reynolds equation as

    d/dx (phi_x h^3 dp/dx) + d/dz (phi_z h^3 dp/dz) = 12 eta (U_m dh_T/dx + dh_T/dt) + 6 eta (U_1 - U_2) sigma dphi_s/dx

with the nominal gap h (between the mean planes), the combined RMS roughness sigma, the mean gap
h_T = E[max(h + delta, 0)] (delta the combined surface height, Gaussian), and the factors fitted to
their flow simulations.  For isotropic roughness (Peklenik number gamma = 1), H = h / sigma:

    phi_x = phi_z = 1 - 0.90 exp(-0.56 H)                     pressure flow factor (1978, Table 1)
    dh_T/dh = Phi(H) = (1 + erf(H / sqrt 2)) / 2                the mean gap's slope (the "contact factor"
                                                               of Wu and Zheng, J. Tribol. 111, 1989)

so that dh_T/dx = Phi(H) dh/dx and dh_T/dt = Phi(H) dh/dt: the right-hand side keeps Booker's form
(the squeeze velocity V alone, :mod:`weftsim.physics.film`), scaled by Phi(H) at each point.
weftsim knows one combined roughness of the joint and takes the two surfaces as alike (equal RMS and
structure): then the shear-flow factor phi_s = (sigma_1/sigma)^2 Phi_s - (sigma_2/sigma)^2 Phi_s cancels, and so does
the shear-stress factor phi_fs of the friction (Patir and Cheng 1979, eq. 16 and 30).

The film's Couette shear on a surface is then eta (U_1 - U_2) phi_f(H) / h with (1979, eqs. 38-39, for
their polynomial height distribution with 3 sigma = the largest height, eps* = 1/300)

    phi_f = 35/32 z [(1 - z^2)^3 ln((z + 1) / eps*) + (-55 + z (132 + z (345 + z (-160 + z (-405 + z (60
            + 147 z)))))) / 60]                                                     H <= 3, z = H / 3,
    phi_f = 35/32 z [(1 - z^2)^3 ln((z + 1) / (z - 1)) + z (66 + z^2 (30 z^2 - 80)) / 15]   H > 3,

which tends to 1 for thick films (as 1 + (3 sigma / h)^2 / 9, summed as that series above H = 6).  The shear of the pressure gradient keeps its smooth-surface form
(Patir and Cheng's phi_fp, within 1 - 1.40 exp(-0.66 H) of 1, is left out: it acts on the part of the torque
that the pressure's moment -(e x F)/2 carries, 1-2 % of the friction in the mixed regime of the tests).

The fits hold for H >= 0.5 (phi_x) and all H (phi_f, Phi); below 0.5 they are continued as written.

Anisotropic and unlike surfaces (:class:`SurfacePair`; the steady elastic film only, :mod:`weftsim.joint.ehl`):
Patir and Cheng's fits for Peklenik numbers gamma = 1/9 to 9 (gamma = lambda_x / lambda_y, the ratio of the
surface's correlation lengths along and across the sliding direction),

    phi_x = 1 - C exp(-r H)  (gamma <= 1),   phi_x = 1 + C H^(-r)  (gamma > 1),   phi_y(H, gamma) = phi_x(H, 1/gamma)
    Phi_s = A_1 H^a_1 exp(-a_2 H + a_3 H^2)  (H <= 5),   Phi_s = A_2 exp(-0.25 H)  (H > 5)

(1978, Table 1; 1979, Table 2: ``PRESSURE_COLUMNS``, ``SHEAR_FLOW_COLUMNS``), read linearly in gamma between
the published columns and at the nearest column outside them.  The transient kernel's table keeps the isotropic
factors above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

PRESSURE_C, PRESSURE_R = 0.90, 0.56  # phi_x = 1 - C exp(-r H), isotropic roughness (Patir and Cheng 1978)
SHEAR_EPS = 1.0 / 300.0  # eps* of phi_f (Patir and Cheng 1979)
# Above z = H / 3 = 2 phi_f is summed as its series 35/16 sum_{k>=3} c_k w^(k-3), w = 1/z^2, c_k = -1/(2k+1)
# + 3/(2k-1) - 3/(2k-3) + 1/(2k-5) (= 1 + w/9 + w^2/33 + ...: the closed form's large-z expansion); 24 terms
# leave (1/4)^24 ~ 4e-15.
SERIES_Z, SERIES_TERMS = 2.0, 24


def pressure_flow_factor(ratio):
    """phi_x(H) = 1 - 0.90 exp(-0.56 H) (isotropic, Patir and Cheng 1978); numpy or float."""
    return 1.0 - PRESSURE_C * np.exp(-PRESSURE_R * np.asarray(ratio, dtype=float))


def contact_factor(ratio):
    """dh_T/dh = Phi(H), the standard normal distribution function (Gaussian heights); numpy or float."""
    from scipy.special import ndtr

    return ndtr(np.asarray(ratio, dtype=float))


@njit(cache=True, error_model="numpy")
def shear_factor(ratio: float) -> float:
    """phi_f(H) of the Couette shear (Patir and Cheng 1979, module docstring); 0 at H <= 0."""
    if ratio <= 0.0:
        return 0.0
    z = ratio / 3.0
    if z > SERIES_Z:  # the closed form cancels to round-off for thick films: its series in w = 1 / z^2
        w = 1.0 / (z * z)
        total = 0.0
        for k in range(SERIES_TERMS + 2, 2, -1):
            c_k = -1.0 / (2 * k + 1) + 3.0 / (2 * k - 1) - 3.0 / (2 * k - 3) + 1.0 / (2 * k - 5)
            total = total * w + c_k
        return 35.0 / 16.0 * total
    cube = (1.0 - z * z) ** 3
    if ratio <= 3.0:
        poly = -55.0 + z * (132.0 + z * (345.0 + z * (-160.0 + z * (-405.0 + z * (60.0 + 147.0 * z)))))
        return 35.0 / 32.0 * z * (cube * math.log((z + 1.0) / SHEAR_EPS) + poly / 60.0)
    return 35.0 / 32.0 * z * (cube * math.log((z + 1.0) / (z - 1.0)) + z * (66.0 + z * z * (30.0 * z * z - 80.0))
                              / 15.0)  # fmt: skip


@njit(cache=True, error_model="numpy")
def couette_factor_at(eps: float, ratio: float, points: int) -> float:
    """The rough film's Couette torque over the smooth film's at eccentricity ratio eps and h_min / sigma = ``ratio``
    (> 0): (1 / 2 pi) integral of phi_f(h / sigma) dpsi.

    The smooth torque integrates dphi / H = dpsi / sqrt(1 - eps^2) (Sommerfeld's angle psi), so the ratio is the
    mean of phi_f over psi, with h / sigma = ratio (1 + eps) / (1 + eps cos psi) (defined at eps = 1 too): a
    periodic integrand, even in psi, summed by the trapezoid rule on ``points`` nodes (even: the half of them in
    (0, pi) counted twice).  The kernel interpolates it (:func:`weftsim.physics.film.couette_factor`).
    """
    total = 0.0
    for k in range(points // 2):
        psi = 2.0 * math.pi * (k + 0.5) / points
        total += shear_factor(ratio * (1.0 + eps) / (1.0 + eps * math.cos(psi)))
    return 2.0 * total / points


@njit(cache=True, error_model="numpy")
def couette_factor_nodes(eccentricities, ratios, points: int):
    """:func:`couette_factor_at` on the grid ``eccentricities`` x ``ratios`` (the kernel's table)."""
    out = np.empty((eccentricities.size, ratios.size))
    for i in range(eccentricities.size):
        for j in range(ratios.size):
            out[i, j] = couette_factor_at(eccentricities[i], ratios[j], points)
    return out


@njit(cache=True, error_model="numpy", inline="always")
def couette_factor_tail(eps: float, ratio: float) -> float:
    """:func:`couette_factor_at` of a thick film: phi_f = 1 + (sigma / h)^2 + (81 / 33) (sigma / h)^4 + ... averaged
    over psi in closed form, 1 + (1 + eps^2 / 2) / a^2 + (81 / 33) (1 + 3 eps^2 + 3 eps^4 / 8) / a^4 with
    a = ratio (1 + eps) (the next term, of (sigma / h)^6, is 1.3e-7 of the factor at h_min = 20 sigma)."""
    a2 = 1.0 / (ratio * (1.0 + eps)) ** 2
    e2 = eps * eps
    return 1.0 + a2 * (1.0 + 0.5 * e2 + a2 * (81.0 / 33.0) * (1.0 + e2 * (3.0 + 0.375 * e2)))


# Anisotropic roughness (Patir and Cheng 1978, Table 1; 1979, Table 2): the columns of the published fits, by
# Peklenik number gamma = lambda_x / lambda_y (the 0.5-correlation lengths along the sliding direction x and across
# it): gamma > 1 longitudinal (ridges along the motion), < 1 transverse.  The same constants are reproduced in the
# tribology literature and in independent implementations (foam-extend's flowFactorsPatirCheng).
PEKLENIK_COLUMNS = (1.0 / 9.0, 1.0 / 6.0, 1.0 / 3.0, 1.0, 3.0, 6.0, 9.0)
# phi_x = 1 - C exp(-r H) for gamma <= 1, 1 + C H^(-r) for gamma > 1 (their fits hold for H > 1 at gamma = 1/9 and
# 1/6, H > 0.75 at 1/3, H > 0.5 at 1-9).
PRESSURE_COLUMNS = ((1.48, 0.42), (1.38, 0.42), (1.18, 0.42), (PRESSURE_C, PRESSURE_R), (0.225, 1.5), (0.520, 1.5),
                    (0.870, 1.5))
# Below its range a transverse column (gamma < 1) would fall to 0 and below (1 - 1.48 exp(-0.42 H) < 0 at H < 0.93):
# it is held at the range's end there (phi_x 0.028, 0.093, 0.139).  The others are continued as written (the
# isotropic one as the kernel's table has it; 1 + C H^(-r) stays above 1, its conductance H^3 phi_x -> 0).
PRESSURE_HELD_BELOW = (1.0, 1.0, 0.75, 0.0, 0.0, 0.0, 0.0)
# Phi_s = A1 H^a1 exp(-a2 H + a3 H^2) for H <= 5, A2 exp(-H / 4) above: (A1, a1, a2, a3, A2).  The two branches meet
# at H = 5 to the fits' rounding (1e-3 of the value; tests/test_film.py).
SHEAR_FLOW_COLUMNS = ((2.046, 1.12, 0.78, 0.03, 1.856), (1.962, 1.08, 0.77, 0.03, 1.754),
                      (1.858, 1.01, 0.76, 0.03, 1.561), (1.899, 0.98, 0.92, 0.05, 1.126),
                      (1.560, 0.85, 1.13, 0.08, 0.556), (1.290, 0.62, 1.09, 0.08, 0.388),
                      (1.011, 0.54, 1.07, 0.08, 0.295))
SHEAR_FLOW_SPLIT, SHEAR_FLOW_DECAY = 5.0, 0.25


def _columns(gamma: float) -> tuple[tuple[int, float], ...]:
    """The published columns a Peklenik number ``gamma`` reads, with their weights: linear in gamma between the two
    neighbouring columns (as foam-extend interpolates them), the nearest column outside [1/9, 9] (the fits are not
    published beyond; an assumption, docs/lubricated-joint.md)."""
    if not (math.isfinite(gamma) and gamma > 0.0):
        raise ValueError(f"a Peklenik number must be > 0, got {gamma!r}")
    cols = PEKLENIK_COLUMNS
    if gamma <= cols[0]:
        return ((0, 1.0),)
    if gamma >= cols[-1]:
        return ((len(cols) - 1, 1.0),)
    for k in range(1, len(cols)):
        if gamma == cols[k]:
            return ((k, 1.0),)
        if gamma < cols[k]:
            w = (gamma - cols[k - 1]) / (cols[k] - cols[k - 1])
            return ((k - 1, 1.0 - w), (k, w))
    raise AssertionError("unreachable")  # pragma: no cover


def _pressure_column(k: int, ratio: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """phi_x of column k and its slope d phi_x / dH."""
    c, r = PRESSURE_COLUMNS[k]
    if PEKLENIK_COLUMNS[k] <= 1.0:
        held = ratio < PRESSURE_HELD_BELOW[k]
        decay = np.exp(-r * np.maximum(ratio, PRESSURE_HELD_BELOW[k]))
        return 1.0 - c * decay, np.where(held, 0.0, c * r * decay)
    power = ratio ** (-r)
    return 1.0 + c * power, -r * c * power / ratio


def pressure_flow_factor_of(ratio, gamma: float, slope: bool = False):
    """phi_x(H, gamma), Patir and Cheng's pressure flow factor along x at H = h / sigma for Peklenik number gamma
    (1978, Table 1; ``_columns``); gamma = 1 is :func:`pressure_flow_factor`.  phi_y(H, gamma) = phi_x(H, 1 / gamma).
    ``slope``: also d phi_x / dH.  numpy or float."""
    ratio = np.asarray(ratio, dtype=float)
    value, rate = np.zeros_like(ratio), np.zeros_like(ratio)
    for k, w in _columns(gamma):
        v, d = _pressure_column(k, ratio)
        if w == 1.0:
            value, rate = v, d
        else:
            value, rate = value + w * v, rate + w * d
    return (value, rate) if slope else value


def shear_flow_factor_of(ratio, gamma: float, order: int = 0):
    """Phi_s(H, gamma), Patir and Cheng's shear flow factor of one rough surface against a smooth one (1979,
    Table 2), H = h / sigma; ``order`` 1 or 2: its first or second derivative in H instead.  0 at H <= 0."""
    ratio = np.asarray(ratio, dtype=float)
    h = np.maximum(ratio, 1e-300)
    out = np.zeros_like(h)
    for k, w in _columns(gamma):
        a1, p1, p2, p3, a2 = SHEAR_FLOW_COLUMNS[k]
        x = np.minimum(h, SHEAR_FLOW_SPLIT)  # each branch on its own side (exp(a3 H^2) overflows far above)
        low = a1 * x**p1 * np.exp(-p2 * x + p3 * x * x)
        high = a2 * np.exp(-SHEAR_FLOW_DECAY * h)
        if order >= 1:  # d ln(low) / dH = a1 / H - a2 + 2 a3 H
            g = p1 / x - p2 + 2.0 * p3 * x
            low = low * (g if order == 1 else g * g - p1 / (x * x) + 2.0 * p3)
            high = high * (-SHEAR_FLOW_DECAY) ** order
        out = out + w * np.where(h <= SHEAR_FLOW_SPLIT, low, high)
    return np.where(ratio > 0.0, out, 0.0)


@dataclass(frozen=True)
class SurfacePair:
    """The two surfaces of Patir and Cheng's average flow: their RMS roughnesses (m) and Peklenik numbers, surface
    1 the journal (the one that moves in ``weftsim bearing``), surface 2 the bearing.

    The flow factors are taken on the composite sigma = sqrt(sigma_1^2 + sigma_2^2), H = h / sigma, with the
    variance ratios V_ri = (sigma_i / sigma)^2:

    - the pressure flow factors along the motion (x) and across it (the axis z),
      phi_x = V_r1 phi_x(H, gamma_1) + V_r2 phi_x(H, gamma_2),  phi_z = V_r1 phi_x(H, 1/gamma_1) + V_r2 phi_x(H, 1/gamma_2)
      (Patir and Cheng fitted one composite surface of one gamma; for surfaces of two gammas the variance-weighted
      mean is an assumption: it is their factor when the gammas are equal, and the one rough surface's when the
      other is smooth);
    - the shear flow factor phi_s = V_r1 Phi_s(H, gamma_1) - V_r2 Phi_s(H, gamma_2) (1979, eq. 25), which enters
      as + (U_1 - U_2) / 2 sigma d phi_s / dx with U_i the surfaces' speeds: zero for alike surfaces.

    ``isotropic(sigma)``: the alike isotropic surfaces of :func:`pressure_flow_factor` (phi_s = 0)."""

    roughness: tuple[float, float]
    peklenik: tuple[float, float] = (1.0, 1.0)

    @classmethod
    def isotropic(cls, sigma: float) -> SurfacePair:
        half = sigma / math.sqrt(2.0)
        return cls((half, half))

    @property
    def sigma(self) -> float:
        return math.hypot(*self.roughness)

    @property
    def variance_ratios(self) -> tuple[float, float]:
        s1, s2 = self.roughness
        total = s1 * s1 + s2 * s2
        return s1 * s1 / total, s2 * s2 / total

    def pressure(self, ratio, across: bool, slope: bool = False):
        """phi_x (``across`` False) or phi_z (True) at H = ``ratio``, with d/dH if ``slope``."""
        values = [pressure_flow_factor_of(ratio, 1.0 / g if across else g, True) for g in self.peklenik]
        (v1, d1), (v2, d2) = values
        w1, w2 = self.variance_ratios
        if self.peklenik[0] == self.peklenik[1]:
            return (v1, d1) if slope else v1
        return (w1 * v1 + w2 * v2, w1 * d1 + w2 * d2) if slope else w1 * v1 + w2 * v2

    def shear_flow(self, ratio, order: int = 0):
        """phi_s (``order`` 0) or its H-derivatives (1, 2) at H = ``ratio``."""
        w1, w2 = self.variance_ratios
        g1, g2 = self.peklenik
        if g1 == g2 and w1 == w2:
            return np.zeros_like(np.asarray(ratio, dtype=float))
        return w1 * shear_flow_factor_of(ratio, g1, order) - w2 * shear_flow_factor_of(ratio, g2, order)
