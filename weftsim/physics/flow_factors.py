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
"""

from __future__ import annotations

import math

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
