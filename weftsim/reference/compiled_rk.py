"""Explicit Runge-Kutta machinery of the compiled reference path (numba): scipy's DOP853 and RK45.

Re-implemented step for step from scipy (same tableaux, copied from scipy in :mod:`.rk_tableaux`; same initial step, error
norm, step-size control and dense output), with the right-hand side of
:mod:`weftsim.physics.chain_f` (which is :mod:`weftsim.physics.chain`'s with clearance at E alone); the
state has 6 entries (2 coordinates) or 10 (clearance at E and F).  :mod:`weftsim.reference.compiled` drives these in its
event-driven loop.  Every function is module-level ``@njit(cache=True, error_model="numpy")``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from weftsim.physics.chain_f import rhs_any
from weftsim.reference import rk_tableaux as _T

DOP853, RK45 = 0, 1
NFEV, DENSE = 4, 5  # counters in the int state of weftsim.reference.compiled (ist)
# Tableaux (scipy's own coefficients, copied by scripts/make_rk_tableaux.py so that a run need not
# import scipy.integrate; DOP853 stages 12, f_new at row 12, 3 extra dense stages).
_S = _T.DOP853_N_STAGES
_A853 = np.ascontiguousarray(_T.DOP853_A[:_S, :_S])
_B853, _C853 = _T.DOP853_B.copy(), _T.DOP853_C[:_S].copy()
_E3, _E5, _D = _T.DOP853_E3.copy(), _T.DOP853_E5.copy(), np.ascontiguousarray(_T.DOP853_D)
_A853X = np.ascontiguousarray(_T.DOP853_A[_S + 1:])
_C853X = _T.DOP853_C[_S + 1:].copy()
_A45, _B45, _C45 = _T.RK45_A.copy(), _T.RK45_B.copy(), _T.RK45_C.copy()
_E45, _P45 = _T.RK45_E.copy(), np.ascontiguousarray(_T.RK45_P)
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0  # scipy's step-size control


@njit(cache=True, error_model="numpy")
def _rms(v):
    s = 0.0
    for i in range(v.size):
        s += v[i] * v[i]
    return math.sqrt(s / v.size)


@njit(cache=True, error_model="numpy")
def _f(prm, t, y, contact, impact, out, ist):
    """y' into out; returns delta at (t, y) (the kernel computes it anyway).

    ``contact``: mask of the joints in a contact segment (bit 0 E, bit 1 F); ``impact`` (2,): their
    held impact velocities (:func:`weftsim.physics.chain_f.rhs_any`).
    """
    ist[NFEV] += 1
    return rhs_any(prm, t, y, contact, impact, out)


@njit(cache=True, error_model="numpy")
def _initial_step(prm, t0, y0, f0, t_end, max_step, order, rtol, atol, contact, impact, ist, tmp):
    """scipy.integrate._ivp.common.select_initial_step (one extra evaluation)."""
    scale = atol + np.abs(y0) * rtol
    d0 = _rms(y0 / scale)
    d1 = _rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, t_end - t0)
    _f(prm, t0 + h0, y0 + h0 * f0, contact, impact, tmp, ist)
    d2 = _rms((tmp - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100.0 * h0, h1, t_end - t0, max_step)


@njit(cache=True, error_model="numpy")
def _stages(prm, method, t, y, h, K, contact, impact, ist, y_new, tmp):
    """One explicit RK step from K[0] = f(t, y): fills K (stages, f_new last), y_new.

    Returns delta at the end of the step (from the last evaluation, f_new).
    """
    if method == DOP853:
        A, B, C, n_st = _A853, _B853, _C853, 12
    else:
        A, B, C, n_st = _A45, _B45, _C45, 6
    n = y.size
    for s in range(1, n_st):  # as scipy's rk_step: y + (K^T a) h, y + h (K^T b)
        tmp[:] = 0.0
        for r in range(s):
            a = A[s, r]
            for j in range(n):
                tmp[j] += K[r, j] * a
        for j in range(n):
            tmp[j] = y[j] + tmp[j] * h
        _f(prm, t + C[s] * h, tmp, contact, impact, K[s], ist)
    y_new[:] = 0.0
    for r in range(n_st):
        b = B[r]
        for j in range(n):
            y_new[j] += K[r, j] * b
    for j in range(n):
        y_new[j] = y[j] + h * y_new[j]
    return _f(prm, t + h, y_new, contact, impact, K[n_st], ist)


@njit(cache=True, error_model="numpy")
def _error_norm(method, K, h, scale):
    n = scale.size
    if method == DOP853:
        e5 = 0.0
        e3 = 0.0
        for j in range(n):
            a5 = 0.0
            a3 = 0.0
            for r in range(13):
                a5 += K[r, j] * _E5[r]
                a3 += K[r, j] * _E3[r]
            a5 /= scale[j]
            a3 /= scale[j]
            e5 += a5 * a5
            e3 += a3 * a3
        if e5 == 0.0 and e3 == 0.0:
            return 0.0
        return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)
    s = 0.0
    for j in range(n):
        a = 0.0
        for r in range(7):
            a += K[r, j] * _E45[r]
        a *= h / scale[j]
        s += a * a
    return math.sqrt(s / n)


@njit(cache=True, error_model="numpy")
def _dense_coefficients(prm, method, t_old, y_old, y_new, f_new, h, K, contact, impact, ist, F, tmp):
    """Interpolant of the last step into F (DOP853: 7 rows of scipy's F; RK45: Q^T, 4 rows)."""
    ist[DENSE] += 1
    n = y_old.size
    if method == DOP853:
        for s in range(13, 16):
            for j in range(n):
                acc = 0.0
                for r in range(s):
                    acc += K[r, j] * _A853X[s - 13, r]
                tmp[j] = y_old[j] + acc * h
            _f(prm, t_old + _C853X[s - 13] * h, tmp, contact, impact, K[s], ist)
        for j in range(n):
            dy = y_new[j] - y_old[j]
            F[0, j] = dy
            F[1, j] = h * K[0, j] - dy
            F[2, j] = 2.0 * dy - h * (f_new[j] + K[0, j])
            for i in range(4):
                acc = 0.0
                for r in range(16):
                    acc += _D[i, r] * K[r, j]
                F[3 + i, j] = h * acc
    else:
        for i in range(4):
            for j in range(n):
                acc = 0.0
                for r in range(7):
                    acc += K[r, j] * _P45[r, i]
                F[i, j] = acc


@njit(cache=True, error_model="numpy")
def _dense(method, F, t_old, h, y_old, t, out):
    x = (t - t_old) / h
    n = y_old.size
    if method == DOP853:
        for j in range(n):
            acc = 0.0
            for i in range(7):
                acc += F[6 - i, j]
                acc *= x if i % 2 == 0 else 1.0 - x
            out[j] = acc + y_old[j]
    else:
        for j in range(n):
            acc = 0.0
            p = x
            for i in range(4):
                acc += F[i, j] * p
                p *= x
            out[j] = y_old[j] + h * acc
