"""Compiled path of the reference engine: the event-driven integration of
:mod:`weftsim.reference.integrate` with the whole integrator in numba.

scipy's ``DOP853`` and ``RK45`` are re-implemented step for step in :mod:`.compiled_rk` (same
tableaux, taken from scipy; same initial step, error norm, step-size control and dense output), with the
right-hand side and the contact law of :mod:`weftsim.reference.compiled_kernel`.  What
the scipy path pays per step in Python (stage combinations, error norm, dense-output
objects, event location; ~50 us per step attempt, docs/reference-solver.md section 4)
becomes a few microseconds.  Events, impact velocity, recorded steps (accepted steps,
events, ``_CONTACT_SUBSTEPS`` dense points inside contact steps) and output samples
follow :mod:`weftsim.reference.integrate` and :mod:`weftsim.reference.events` exactly, so both
paths agree to the integration tolerance (``tests/test_fast_paths.py``).

Every function is module-level ``@njit(cache=True, error_model="numpy")`` and takes the scene as a parameter
array: numba compiles once per machine (~9 s) and loads from its cache afterwards (~0.3 s).
The loop (:func:`advance`) returns to Python every 0.1 % of the run (progress) or when its step
buffer is full; :mod:`.compiled_run` drives it and builds the result.

Methods (``reference_solver.method``): ``"numba_DOP853"``, ``"numba_RK45"``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.reference.compiled_kernel import CLEARANCE, TRACK_MAX, V_MIN, penetration
from weftsim.reference.compiled_rk import (
    _MAX_FACTOR, _MIN_FACTOR, _SAFETY, DOP853, RK45, N, _dense, _dense_coefficients, _error_norm, _f,
    _initial_step, _stages,
)  # fmt: skip
from weftsim.reference.compiled_rk import DENSE as _RK_DENSE
from weftsim.reference.compiled_rk import NFEV as _RK_NFEV
from weftsim.reference.events import _GOLDEN_ITERATIONS, _INV_PHI, END_FRACTION, SAMPLES
from weftsim.reference.integrate import _CONTACT_SUBSTEPS, _ROOT_XTOL

METHODS = {"numba_DOP853": DOP853, "numba_RK45": RK45}


# Return codes of the core.
DONE, PAUSED, BUFFER_FULL, STEP_TOO_SMALL, NON_FINITE, GUARD = 0, 1, 2, -1, -2, -3
_ROWS_PER_STEP = _CONTACT_SUBSTEPS + 2  # substeps + step or event + new segment's first row
_STEP_BUFFER = 1 << 15
_SUBSTEPS = np.arange(1, _CONTACT_SUBSTEPS + 1) / (_CONTACT_SUBSTEPS + 1.0)
_GRID = np.linspace(0.0, 1.0, SAMPLES + 1)  # the event search grid of a step (integrate._GRID)

# Float state: t, h_abs, held impact velocity, max penetration rate, first contact time (-1: none),
# last accepted step, its penetration and length (for the guards of weftsim.guards).
T, H_ABS, IMPACT, MAX_RATE, FIRST_CONTACT, LAST_PENETRATION, LAST_STEP = range(7)
# Guard limits: penetration bound (m), shortest accepted step (s), step budget (0: none).
PENETRATION_LIMIT, MIN_STEP_LIMIT, STEP_BUDGET = range(3)
# Int state: mode, segment to start, counters, next output sample.
CONTACT, START, STEPS, REJECTED, NFEV, DENSE, SEGMENTS, EVENTS, IMPACTS, NEXT_SAMPLE, PEAKS, NONPOSITIVE = range(12)
N_INT_STATE = 12
assert (NFEV, DENSE) == (_RK_NFEV, _RK_DENSE)  # compiled_rk counts evaluations into the same int state
# Kinds of event (weftsim.reference.events).
NO_EVENT, ONSET, SEPARATION, PEAK = 0, 1, 2, 3
# What _maximum maximizes on the dense output: sign * delta, -sign * delta, delta_dot.
_G, _MINUS_G, _RATE = 0, 1, 2


@njit(cache=True, error_model="numpy")
def _state(prm, method, F, t_old, h, y_old, t, tmp):
    """(delta, delta_dot) on the dense output of the last step at time t."""
    _dense(method, F, t_old, h, y_old, t, tmp)
    return penetration(prm, t, tmp)


@njit(cache=True, error_model="numpy")
def _value(prm, method, F, t_old, h, y_old, t, tmp, what, sign):
    d, r = _state(prm, method, F, t_old, h, y_old, t, tmp)
    if what == _G:
        return sign * d
    if what == _MINUS_G:
        return -sign * d
    return r


@njit(cache=True, error_model="numpy")
def _locate(prm, method, F, t_old, h, y_old, sign, lo, hi, g_lo, g_hi, tmp):
    """Root of g = sign * delta in [lo, hi] on its positive side (events.locate_root)."""
    last = 0
    for _ in range(200):
        if hi - lo <= _ROOT_XTOL:
            break
        m = hi - g_hi * (hi - lo) / (g_hi - g_lo)
        if not lo < m < hi:
            m = 0.5 * (lo + hi)
        g_m = _value(prm, method, F, t_old, h, y_old, m, tmp, _G, sign)
        if g_m > 0.0:
            hi, g_hi = m, g_m
            if last == -1:
                g_lo *= 0.5
            last = -1
        else:
            lo, g_lo = m, g_m
            if last == 1:
                g_hi *= 0.5
            last = 1
    return hi


@njit(cache=True, error_model="numpy")
def _maximum(prm, method, F, t_old, h, y_old, what, sign, lo, hi, tmp):
    """(t, value) of the largest value on [lo, hi], golden section (events.maximum)."""
    a, b = lo, hi
    x1 = b - _INV_PHI * (b - a)
    x2 = a + _INV_PHI * (b - a)
    f1 = _value(prm, method, F, t_old, h, y_old, x1, tmp, what, sign)
    f2 = _value(prm, method, F, t_old, h, y_old, x2, tmp, what, sign)
    for _ in range(_GOLDEN_ITERATIONS):
        if f1 < f2:
            a, x1, f1 = x1, x2, f2
            x2 = a + _INV_PHI * (b - a)
            f2 = _value(prm, method, F, t_old, h, y_old, x2, tmp, what, sign)
        else:
            b, x2, f2 = x2, x1, f1
            x1 = b - _INV_PHI * (b - a)
            f1 = _value(prm, method, F, t_old, h, y_old, x1, tmp, what, sign)
    best_t, best = lo, _value(prm, method, F, t_old, h, y_old, lo, tmp, what, sign)
    if f1 > best:
        best_t, best = x1, f1
    if f2 > best:
        best_t, best = x2, f2
    f_hi = _value(prm, method, F, t_old, h, y_old, hi, tmp, what, sign)
    if f_hi > best:
        best_t, best = hi, f_hi
    return best_t, best


@njit(cache=True, error_model="numpy")
def _first_crossing(prm, method, F, t_old, h, y_old, times, deltas, rates, sign, tmp):
    """(found, t, sign * delta_dot) of the first rising crossing of sign * delta (events.first_crossing)."""
    if sign * deltas[0] > 0.0:
        return True, times[0], sign * rates[0]
    for k in range(times.size - 1):
        lo, hi = times[k], times[k + 1]
        g_lo, g_hi = sign * deltas[k], sign * deltas[k + 1]
        if g_hi <= 0.0:
            if not (sign * rates[k] > 0.0 > sign * rates[k + 1]):
                continue
            t_top, g_top = _maximum(prm, method, F, t_old, h, y_old, _G, sign, lo, hi, tmp)
            if g_top <= 0.0:
                continue
            hi, g_hi = t_top, g_top
        root = _locate(prm, method, F, t_old, h, y_old, sign, lo, hi, g_lo, g_hi, tmp)
        rate = sign * _state(prm, method, F, t_old, h, y_old, root, tmp)[1]
        if rate <= 0.0:
            t_low, minus_g_low = _maximum(prm, method, F, t_old, h, y_old, _MINUS_G, sign, root, hi, tmp)
            if -minus_g_low < 0.0:
                root = _locate(prm, method, F, t_old, h, y_old, sign, t_low, hi, -minus_g_low, g_hi, tmp)
                rate = sign * _state(prm, method, F, t_old, h, y_old, root, tmp)[1]
        return True, root, rate
    return False, 0.0, 0.0


@njit(cache=True, error_model="numpy")
def _rate_peak(prm, method, F, t_old, h, y_old, times, rates, n, held, tmp):
    """(found, t, delta_dot) of a maximum of delta_dot above ``held`` before times[n - 1] (events.rate_peak)."""
    k = 0
    for i in range(1, n):
        if rates[i] > rates[k]:
            k = i
    if rates[k] <= held:
        return False, 0.0, 0.0
    lo = times[max(k - 1, 0)]
    hi = times[min(k + 1, n - 1)]
    t_peak, r_peak = _maximum(prm, method, F, t_old, h, y_old, _RATE, 1.0, lo, hi, tmp)
    end = times[n - 1]
    if end - t_peak <= END_FRACTION * (end - times[0]) or r_peak <= held:
        return False, 0.0, 0.0
    return True, t_peak, r_peak


@njit(cache=True, error_model="numpy")
def _record(buf_t, buf_y, buf_c, buf_i, n, t, y, contact, impact):
    buf_t[n] = t
    buf_y[n, :] = y
    buf_c[n] = 1 if contact else 0
    buf_i[n] = impact
    return n + 1


@njit(cache=True, error_model="numpy")
def advance(prm, method, rtol, atol, max_step, t_end, t_pause, limits, y, f, fst, ist, sample_times,
            smp_t, smp_y, smp_c, smp_i, stp_t, stp_y, stp_c, stp_i):
    """Integrate from fst[T] until t_end, t >= t_pause, the step buffer is nearly full, or a guard.

    Steps, events and contact substeps go to ``stp_*`` from row 0 (count returned),
    samples to ``smp_*`` at rows ist[NEXT_SAMPLE]...  Returns (code, rows written).
    After every accepted step (as :mod:`weftsim.reference.integrate` with ``RunGuard``): the
    penetration bound, the shortest step (not the step cut to land on t_end) and the step
    budget of ``limits``; a crossing records the step and returns GUARD.
    """
    K = np.zeros((16, N))
    F = np.zeros((7, N))
    y_new = np.empty(N)
    tmp = np.empty(N)
    scale = np.empty(N)
    order = 7 if method == DOP853 else 4
    f_row = 12 if method == DOP853 else 6
    exponent = -1.0 / (order + 1)
    n_rows = 0
    capacity = stp_t.size
    n_samples = sample_times.size
    v_min = prm[V_MIN]
    track = prm[TRACK_MAX] != 0.0
    ideal = 1 if prm[CLEARANCE] <= 0.0 else 0
    grid_t = np.empty(SAMPLES + 1)
    grid_d = np.empty(SAMPLES + 1)
    grid_r = np.empty(SAMPLES + 1)
    peak_t = np.empty(SAMPLES + 2)
    peak_r = np.empty(SAMPLES + 2)
    t = fst[T]
    while t < t_end:
        contact = ist[CONTACT] == 1
        impact = fst[IMPACT]
        if ist[START] == 1:
            _f(prm, t, y, contact, impact, f, ist)
            fst[H_ABS] = _initial_step(prm, t, y, f, t_end, max_step, order, rtol, atol, contact, impact, ist, tmp)
            if not math.isfinite(fst[H_ABS]):
                return NON_FINITE, n_rows
            ist[START] = 0
            ist[SEGMENTS] += 1
        if n_rows + _ROWS_PER_STEP > capacity:
            return BUFFER_FULL, n_rows
        # One accepted step (scipy RungeKutta._step_impl).
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        h_abs = min(max(fst[H_ABS], min_step), max_step)
        rejected = False
        while True:
            if h_abs < min_step:
                return STEP_TOO_SMALL, n_rows
            if not math.isfinite(h_abs):
                return NON_FINITE, n_rows
            t_new = t + h_abs
            if t_new > t_end:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            K[0, :] = f
            g_new = _stages(prm, method, t, y, h, K, contact, impact, ist, y_new, tmp)
            for j in range(N):
                scale[j] = atol + max(abs(y[j]), abs(y_new[j])) * rtol
            err = _error_norm(method, K, h, scale)
            if not err == err:  # NaN from a non-finite stage: reject and shrink
                err = math.inf
            if err < 1.0:
                factor = _MAX_FACTOR if err == 0.0 else min(_MAX_FACTOR, _SAFETY * err ** exponent)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            h_abs *= max(_MIN_FACTOR, _SAFETY * err ** exponent)
            rejected = True
            ist[REJECTED] += 1
        fst[H_ABS] = h_abs
        for j in range(N):
            if not math.isfinite(y_new[j]):
                return NON_FINITE, n_rows
        ist[STEPS] += 1
        f_new = K[f_row]
        g_new, r_new = penetration(prm, t_new, y_new)
        fst[LAST_PENETRATION] = g_new if contact else -math.inf  # only contact steps are model states
        fst[LAST_STEP] = h if t_new < t_end else math.inf
        if (fst[LAST_PENETRATION] > limits[PENETRATION_LIMIT] or fst[LAST_STEP] < limits[MIN_STEP_LIMIT]
                or (limits[STEP_BUDGET] > 0.0 and ist[STEPS] > limits[STEP_BUDGET])):
            fst[T] = t_new
            y[:] = y_new
            n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t_new, y_new, contact, impact)
            return GUARD, n_rows
        # Events inside the step (weftsim.reference.events): first rising crossing, rate peak.
        g_old, r_old = penetration(prm, t, y)
        sign = -1.0 if contact else 1.0
        possible = (sign * g_new > 0.0 or sign * r_old > 0.0 > sign * r_new) and ideal == 0
        t_stop = t_new
        kind = NO_EVENT
        value = 0.0
        dense = False
        if contact or possible:
            _dense_coefficients(prm, method, t, y, y_new, f_new, h, K, contact, impact, ist, F, tmp)
            dense = True
            grid_d[0], grid_r[0] = g_old, r_old
            grid_d[SAMPLES], grid_r[SAMPLES] = g_new, r_new
            for i in range(SAMPLES + 1):
                grid_t[i] = t + h * _GRID[i]
            grid_t[SAMPLES] = t_new
            for i in range(1, SAMPLES):
                d, r = _state(prm, method, F, t, h, y, grid_t[i], tmp)
                grid_d[i], grid_r[i] = d, r
            if possible:
                found, t_root, rate = _first_crossing(prm, method, F, t, h, y, grid_t, grid_d, grid_r, sign, tmp)
                if found:
                    t_stop = t_root
                    kind = SEPARATION if contact else ONSET
                    value = sign * rate
            if contact and track:
                n = SAMPLES + 1
                if kind != NO_EVENT:  # the approach rate counts up to the separation only
                    n = 0
                    for i in range(SAMPLES + 1):
                        if grid_t[i] < t_stop:
                            peak_t[n], peak_r[n] = grid_t[i], grid_r[i]
                            n += 1
                    peak_t[n], peak_r[n] = t_stop, value
                    n += 1
                else:
                    peak_t[:n] = grid_t
                    peak_r[:n] = grid_r
                found, t_peak, r_peak = _rate_peak(prm, method, F, t, h, y, peak_t, peak_r, n, impact, tmp)
                if found:
                    t_stop = t_peak
                    kind = PEAK
                    value = r_peak
        k = ist[NEXT_SAMPLE]
        while k < n_samples and sample_times[k] <= t_stop:
            if not dense:
                _dense_coefficients(prm, method, t, y, y_new, f_new, h, K, contact, impact, ist, F, tmp)
                dense = True
            _dense(method, F, t, h, y, sample_times[k], tmp)
            _record(smp_t, smp_y, smp_c, smp_i, k, sample_times[k], tmp, contact, impact)
            k += 1
        ist[NEXT_SAMPLE] = k
        if contact and _CONTACT_SUBSTEPS > 0:
            for i in range(_CONTACT_SUBSTEPS):
                t_sub = t + (t_stop - t) * _SUBSTEPS[i]
                _dense(method, F, t, h, y, t_sub, tmp)
                n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t_sub, tmp, contact, impact)
        if kind != NO_EVENT:
            _dense(method, F, t, h, y, t_stop, tmp)
            t = t_stop
            y[:] = tmp
            ist[EVENTS] += 1
            if kind == SEPARATION:
                ist[CONTACT] = 0
                fst[IMPACT] = 0.0
            elif kind == PEAK:
                fst[IMPACT] = value
                ist[PEAKS] += 1
            else:
                if not value > 0.0:
                    ist[NONPOSITIVE] += 1  # no rising root found: counted, judged by weftsim.guards
                fst[MAX_RATE] = max(fst[MAX_RATE], value)
                ist[CONTACT] = 1
                fst[IMPACT] = max(value, v_min)
                ist[IMPACTS] += 1
                if fst[FIRST_CONTACT] < 0.0:
                    fst[FIRST_CONTACT] = t
            ist[START] = 1
            n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t, y, ist[CONTACT] == 1, fst[IMPACT])
        else:
            t = t_new
            y[:] = y_new
            f[:] = f_new
            n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t, y, contact, impact)
        fst[T] = t
        if t >= t_pause:
            return PAUSED, n_rows
    fst[T] = t
    return DONE, n_rows
