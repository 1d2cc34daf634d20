"""Output channels of a compiled run, computed in numba (the compiled path's post-processing).

The same channels, from the same equations, as :func:`weftsim.reference.channels.clearance_channels`
(see its docstring for the energy bookkeeping), at ~0.1 us per row instead of ~3 us:

- the chain terms (a'', F_N, delta, e, Q3) from the compiled right-hand side
  (:mod:`.compiled_kernel`), the elastic energy from :func:`elastic_energy`;
- the crank-side terms J13, J13', U13, U13' of :mod:`weftsim.reference.ideal`, which depend on
  theta only and are periodic and analytic: they are sampled from those functions once per
  mechanism (:data:`TABLE_POINTS` per revolution) and read back through a periodic cubic
  spline, exact to ~1e-12 of their range (:func:`crank_side_table`; the closed forms are not
  written a second time).

``tests/test_fast_paths.py`` checks these channels against ``clearance_channels``.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit

from weftsim.params import Geometry, Inertia, Scene
from weftsim.reference.compiled_kernel import (
    CLEARANCE, COUPLING, GRAVITY, L_EF, L_FG, LAW_COEF, LAW_CONSTANT, LAW_ID, LAW_VARIABLE_KD, M11, M22, OMEGA,
    ROD_MASS, chain, pack_parameters,
)  # fmt: skip
from weftsim.reference.dynamics import initial_state
from weftsim.results import CHANNELS

TABLE_POINTS = 4096  # spline knots per revolution: interpolation error ~ 5/384 h^4 |f''''| ~ 1e-12 relative
_SERIES_LIMIT = 0.25  # as weftsim.contact: binomial series below x = delta/c = 1/4
_SERIES_TERMS = 40


@functools.lru_cache(maxsize=16)
def _table(geometry: Geometry, inertia: Inertia) -> np.ndarray:
    from scipy.interpolate import CubicSpline

    from weftsim.reference.ideal import crank_side_inertia, crank_side_potential

    scene = Scene(geometry=geometry, inertia=inertia)
    theta = np.linspace(0.0, 2.0 * math.pi, TABLE_POINTS + 1)
    j13, dj13 = crank_side_inertia(theta, scene)
    u13, du13 = crank_side_potential(theta, scene)
    values = np.stack([j13, dj13, u13, du13], axis=1)
    values[-1] = values[0]  # periodic to round-off
    spline = CubicSpline(theta, values, bc_type="periodic")
    return np.ascontiguousarray(np.transpose(spline.c, (2, 1, 0)))  # (function, interval, power)


def crank_side_table(scene: Scene) -> np.ndarray:
    """Spline coefficients (4, TABLE_POINTS, 4) of J13, J13', U13, U13' over one revolution.

    Built from :func:`weftsim.reference.ideal.crank_side_inertia` and
    :func:`~weftsim.reference.ideal.crank_side_potential` once per mechanism (cached).
    """
    return _table(scene.geometry, scene.inertia)


@njit(cache=True, error_model="numpy")
def crank_side_eval(table, theta, out):
    """(J13, J13', U13, U13') at crank angle theta from :func:`crank_side_table` into out (4,)."""
    n = table.shape[1]
    h = 2.0 * math.pi / n
    x = theta - 2.0 * math.pi * math.floor(theta / (2.0 * math.pi))
    i = int(x / h)
    if i >= n:
        i = n - 1
    x -= i * h
    for k in range(4):
        out[k] = ((table[k, i, 0] * x + table[k, i, 1]) * x + table[k, i, 2]) * x + table[k, i, 3]


@njit(cache=True, error_model="numpy")
def _binomial_moment(y, m, p):
    """sum_k C(p, k) y^(m+k+1) / (m+k+1), k < 40 (weftsim.contact._binomial_moment)."""
    total = 0.0
    coeff = 1.0
    power = y ** (m + 1.0)
    for k in range(_SERIES_TERMS):
        term = coeff * power / (m + k + 1.0)
        total += term
        if abs(term) < 1e-17 * abs(total):  # the rest is below round-off (|y| <= 1/4)
            break
        coeff *= (p - k) / (k + 1.0)
        power *= y
    return total


@njit(cache=True, error_model="numpy")
def elastic_energy(prm, delta):
    """integral_0^delta F_el, J (0 for delta <= 0): the laws' ``elastic_energy`` in numba."""
    if delta <= 0.0:
        return 0.0
    law, coef, c = prm[LAW_ID], prm[LAW_COEF], prm[CLEARANCE]
    if law == LAW_CONSTANT:
        return coef * delta**2.5 / 2.5
    x = delta / c
    if law == LAW_VARIABLE_KD:
        if x <= _SERIES_LIMIT:
            g = 3.0 * _binomial_moment(x, 2.0, -1.5) + 2.0 * _binomial_moment(x, 3.0, -1.5)
        else:
            u = 1.0 + x
            g = 0.8 * u**2.5 - 2.0 * u**1.5 - 2.0 / math.sqrt(u) + 3.2
        return coef * math.sqrt(2.0) * c**2.5 * g
    if x <= _SERIES_LIMIT:
        h = _binomial_moment(x, 1.5, -0.5)
    else:
        h = 0.25 * math.sqrt(x * (1.0 + x)) * (2.0 * x - 3.0) + 0.75 * math.asinh(math.sqrt(x))
    return coef / math.sqrt(2.0) * c * c * h


@njit(cache=True, error_model="numpy")
def _fill(prm, table, a0, ratio, time, states, contact, impact, out):
    """Rows of :data:`CHANNELS` (in that order) into out (17, n)."""
    omega = prm[OMEGA]
    d = np.empty(6)
    start = np.empty(4)
    crank = np.empty(4)
    crank_side_eval(table, 0.0, start)
    work0 = 0.5 * start[0] * omega * omega + start[2]
    for i in range(time.size):
        t = time[i]
        y = states[i]
        q3, f_n, delta, ecc_y, ecc_z = chain(prm, t, y, contact[i], impact[i], d)
        crank_side_eval(table, omega * t, crank)
        a, psi, da, dpsi = y[0], y[1], y[2], y[3]
        m12 = -prm[COUPLING] * math.cos(psi - a)
        kin48 = 0.5 * (prm[M11] * da * da + 2.0 * m12 * da * dpsi + prm[M22] * dpsi * dpsi)
        pot48 = prm[ROD_MASS] * prm[GRAVITY] * (prm[L_FG] * math.sin(a) - 0.5 * prm[L_EF] * math.sin(psi))
        kin13 = 0.5 * crank[0] * omega * omega
        out[0, i] = t
        out[1, i] = omega * t * (180.0 / math.pi)
        out[2, i] = ratio * (a - a0)
        out[3, i] = ratio * da
        out[4, i] = ratio * d[2]
        out[5, i] = 0.5 * crank[1] * omega * omega + crank[3] - q3
        out[6, i] = f_n
        out[7, i] = delta
        out[8, i] = ecc_y
        out[9, i] = ecc_z
        out[10, i] = impact[i] if contact[i] else 0.0
        out[11, i] = 1.0 if (contact[i] and delta > 0.0) else 0.0
        out[12, i] = kin13 + kin48
        out[13, i] = crank[2] + pot48
        out[14, i] = elastic_energy(prm, delta)
        out[15, i] = kin13 + crank[2] - work0 + y[4]
        out[16, i] = y[5]


def compiled_channels(scene: Scene, time, states, contact, impact) -> dict[str, np.ndarray]:
    """All :data:`~weftsim.results.CHANNELS` at the given rows (arguments as ``clearance_channels``)."""
    time = np.ascontiguousarray(time, dtype=float)
    out = np.empty((len(CHANNELS), time.size))
    _fill(pack_parameters(scene), crank_side_table(scene), float(initial_state(scene)[0]),
          scene.geometry.rapier_ratio, time, np.ascontiguousarray(states, dtype=float).reshape(time.size, 6),
          np.asarray(contact, dtype=np.bool_), np.asarray(impact, dtype=float), out)  # fmt: skip
    return dict(zip(CHANNELS, out))
