"""Compiled path of the reference engine: the event-driven integration of
:mod:`weftsim.reference.integrate` with the whole integrator in numba.

scipy's ``DOP853`` and ``RK45`` are re-implemented step for step in :mod:`.compiled_rk` (same
tableaux, taken from scipy; same initial step, error norm, step-size control and dense output), with the
right-hand side and the contact law of :mod:`weftsim.physics.chain` (:mod:`weftsim.physics.chain_f` with a
clearance at F: one contact mode and held impact velocity per joint, events searched per joint).  What
the scipy path pays per step in Python (stage combinations, error norm, dense-output
objects, event location; ~50 us per step attempt, docs/reference-solver.md section 4)
becomes a few microseconds.  The event search is that of :mod:`weftsim.physics.roots` (compiled here,
in plain Python on the scipy path).  Events, impact velocity, recorded steps (accepted steps,
events, ``_CONTACT_SUBSTEPS`` dense points inside contact steps) and output samples
follow :mod:`weftsim.reference.integrate` and :mod:`weftsim.reference.events` exactly, so both
paths agree to the integration tolerance (``tests/test_fast_paths.py``).

Every function is module-level ``@njit(cache=True, error_model="numpy")`` and takes the scene as a parameter
array: numba compiles once per machine (~9 s) and loads from its cache afterwards (~0.3 s).
The loop (:func:`advance`) returns to Python every 0.1 % of the run (progress) or when its step
buffer is full; :mod:`.compiled_run` drives it and builds the result.

Methods (``reference_solver.method``): ``"numba_DOP853"``, ``"numba_RK45"``, ``"numba_RODAS4"`` (linearly implicit,
:mod:`.compiled_ros`) and ``"numba_DOP853_RODAS4"`` (DOP853 in free flight, RODAS4 in contact segments; with dry friction at E alone
RODAS4 only while the sliding speed is near the friction ramp, :data:`RAMP_SWITCH`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.physics.chain import OMEGA, TRACK_MAX, V_MIN, eccentricity
from weftsim.physics.joint import BEARING_RADIUS, MU, V1, tangential_velocity
from weftsim.physics.lubricated import is_lubricated
from weftsim.physics.chain_f import BLOCKS, N_JOINTS, PLAIN, joint_is_loose, penetration_at
from weftsim.reference.compiled_rk import (
    _MAX_FACTOR, _MIN_FACTOR, _SAFETY, DOP853, RK45, _dense, _dense_coefficients, _error_norm, _f,
    _initial_step, _stages,
)  # fmt: skip
from weftsim.reference.compiled_rk import DENSE as _RK_DENSE
from weftsim.reference.compiled_rk import NFEV as _RK_NFEV
from weftsim.reference import compiled_ros as ros
from weftsim.physics import roots
from weftsim.physics.python import specialize
from weftsim.physics.roots import SAMPLES
from weftsim.reference.integrate import _CONTACT_SUBSTEPS, _ROOT_XTOL

# RODAS4 (linearly implicit, :mod:`.compiled_ros`) on every step, or only in contact segments with DOP853 in
# free flight (HYBRID: the stiffness is the contact's and the friction ramp's; free flight is not stiff).
RODAS4 = ros.RODAS4
HYBRID = 3
# HYBRID with dry friction at E: RODAS4 only while the sliding speed is within RAMP_SWITCH v1 of the ramp (the
# modified Coulomb law's slope mu F_N / (v1 - v0) gives the one stiff eigenvalue, ~-3e7 1/s on the loom, while
# the rocker reverses); in full sliding the contact's eigenvalues are the dry joint's (within 10 %, +-1e4 i 1/s),
# where RODAS4 (order 4) needs ~15x the steps of DOP853 (order 8) for the same tolerance: the worn loom is in
# contact 95-99 % of the time, so contact segments all on RODAS4 cost 16 340 steps a revolution against 938 dry.
RAMP_SWITCH = 10.0
METHODS = {"numba_DOP853": DOP853, "numba_RK45": RK45, "numba_RODAS4": RODAS4, "numba_DOP853_RODAS4": HYBRID}


# Return codes of the core.
DONE, PAUSED, BUFFER_FULL, STEP_TOO_SMALL, NON_FINITE, GUARD = 0, 1, 2, -1, -2, -3
_ROWS_PER_STEP = _CONTACT_SUBSTEPS + 2  # substeps + step or event + new segment's first row
_STEP_BUFFER = 1 << 15
_SUBSTEPS = np.arange(1, _CONTACT_SUBSTEPS + 1) / (_CONTACT_SUBSTEPS + 1.0)
_GRID = np.linspace(0.0, 1.0, SAMPLES + 1)  # the event search grid of a step (integrate._GRID)

# Float state: t, h_abs, held impact velocity at E, max penetration rate, first contact time (-1: none),
# penetration at E of the last accepted step and its length (for the guards of weftsim.checks.guards); then the
# held impact velocity, penetration and first contact time at F.  IMPACT + joint, LAST_PENETRATION + joint
# and FIRST_CONTACT + joint are read through JOINT_SLOTS.
T, H_ABS, IMPACT, MAX_RATE, FIRST_CONTACT, LAST_PENETRATION, LAST_STEP, IMPACT_F, LAST_PENETRATION_F, \
    FIRST_CONTACT_F = range(10)
N_FLOAT_STATE = 10
JOINT_SLOTS = np.array([[IMPACT, LAST_PENETRATION, FIRST_CONTACT], [IMPACT_F, LAST_PENETRATION_F, FIRST_CONTACT_F]])
# Guard limits: penetration bound at E (m), shortest accepted step (s), step budget (0: none), bound at F.
PENETRATION_LIMIT, MIN_STEP_LIMIT, STEP_BUDGET, PENETRATION_LIMIT_F = range(4)
# Int state: mode (mask of the joints in contact: bit 0 E, bit 1 F), segment to start, counters, next sample.
CONTACT, START, STEPS, REJECTED, NFEV, DENSE, SEGMENTS, EVENTS, IMPACTS, NEXT_SAMPLE, PEAKS, NONPOSITIVE, \
    JACOBIANS, DECOMPOSITIONS, IMPLICIT_STEPS = range(15)
N_INT_STATE = 15
assert (NFEV, DENSE) == (_RK_NFEV, _RK_DENSE)  # compiled_rk counts evaluations into the same int state
# Kinds of event (weftsim.reference.events).
NO_EVENT, ONSET, SEPARATION, PEAK = 0, 1, 2, 3


@njit(cache=True, error_model="numpy")
def _dense_any(method, F, t_old, h, y_old, t, out):
    """Dense output of the last step of ``method`` (an explicit one or RODAS4) at time t into out."""
    if method == RODAS4:
        ros.dense(F, t_old, h, y_old, t, out)
    elif method == ros.RODAS4_STIFF_DENSE:
        ros.dense_stiff(F, t_old, h, y_old, t, out)
    else:
        _dense(method, F, t_old, h, y_old, t, out)


@njit(cache=True, error_model="numpy")
def _state(t, prm, method, F, t_old, h, y_old, tmp, joint):
    """(delta, delta_dot) of ``joint`` on the dense output of the last step at time t."""
    _dense_any(method, F, t_old, h, y_old, t, tmp)
    return penetration_at(prm, t, tmp, joint)


# The event search of weftsim.physics.roots on the dense output of the last step, compiled; its
# ``args`` are (prm, method, F, t_old, h, y_old, tmp, joint).
_first_crossing = specialize(roots.first_crossing, state=_state)
_rate_peak = specialize(roots.rate_peak, state=_state)


@njit(cache=True, error_model="numpy")
def _record(buf_t, buf_y, buf_c, buf_i, n, t, y, contact, impact):
    buf_t[n] = t
    for j in range(y.size):  # element by element: a slice copy needs numba's reference counting (lean forms)
        buf_y[n, j] = y[j]
    buf_c[n] = contact
    for j in range(impact.size):
        buf_i[n, j] = impact[j]
    return n + 1


@njit(cache=True, error_model="numpy")
def _events_of_joint(prm, method, F, t, h, y, tmp, joint, in_contact, held, g_old, r_old, g_new, r_new, t_new,
                     grid_t, grid_d, grid_r, peak_t, peak_r):
    """The first event of one joint inside the step: (kind, time, value) (:mod:`weftsim.reference.events`).

    Onset or separation (the first rising crossing of sign * delta), then under "max_approach" a
    maximum of the approach rate above ``held`` before it.  ``grid_t`` holds the step's sample times.
    """
    args = (prm, method, F, t, h, y, tmp, joint)
    sign = -1.0 if in_contact else 1.0
    possible = sign * g_new > 0.0 or sign * r_old > 0.0 > sign * r_new
    t_stop = t_new
    kind = NO_EVENT
    value = 0.0
    grid_d[0], grid_r[0] = g_old, r_old
    grid_d[SAMPLES], grid_r[SAMPLES] = g_new, r_new
    for i in range(1, SAMPLES):
        d, r = _state(grid_t[i], prm, method, F, t, h, y, tmp, joint)
        grid_d[i], grid_r[i] = d, r
    if possible:
        found, t_root, rate = _first_crossing(args, grid_t, grid_d, grid_r, sign)
        if found:
            t_stop = t_root
            kind = SEPARATION if in_contact else ONSET
            value = sign * rate
    if in_contact and prm[BLOCKS[joint] + TRACK_MAX] != 0.0:
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
            for i in range(n):  # element by element: a slice copy needs numba's reference counting (lean forms)
                peak_t[i], peak_r[i] = grid_t[i], grid_r[i]
        found, t_peak, r_peak = _rate_peak(args, peak_t, peak_r, n, held)
        if found:
            t_stop = t_peak
            kind = PEAK
            value = r_peak
    return kind, t_stop, value


@njit(cache=True, error_model="numpy")
def _near_ramp(prm: np.ndarray, t: float, y: np.ndarray) -> bool:
    """True when joint E's sliding speed |v_T| is below RAMP_SWITCH v1 (or the journal is centred)."""
    ecc_y, ecc_z, v_y, v_z, _, _, dphi = eccentricity(prm, t, y)[:7]
    length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
    if length <= 0.0:
        return True
    v_t = tangential_velocity(ecc_y, ecc_z, v_y, v_z, length, y[3], prm[OMEGA] * dphi, prm[BEARING_RADIUS])
    return abs(v_t) < RAMP_SWITCH * prm[V1]


@njit(cache=True, error_model="numpy")
def advance(prm: np.ndarray, method: int, rtol: float, atol: float, max_step: float, t_end: float, t_pause: float,
            limits: np.ndarray, y: np.ndarray, f: np.ndarray, fst: np.ndarray, ist: np.ndarray,
            sample_times: np.ndarray, smp_t: np.ndarray, smp_y: np.ndarray, smp_c: np.ndarray, smp_i: np.ndarray,
            stp_t: np.ndarray, stp_y: np.ndarray, stp_c: np.ndarray, stp_i: np.ndarray) -> tuple[int, int]:
    """Integrate from fst[T] until t_end, t >= t_pause, the step buffer is nearly full, or a guard.

    Steps, events and contact substeps go to ``stp_*`` from row 0 (count returned),
    samples to ``smp_*`` at rows ist[NEXT_SAMPLE]...  Returns (code, rows written).
    After every accepted step (as :mod:`weftsim.reference.integrate` with ``RunGuard``): the
    penetration bound of each joint, the shortest step (not the step cut to land on t_end) and the
    step budget of ``limits``; a crossing records the step and returns GUARD.  Each joint with a
    clearance has its own contact mode and held impact velocity (bit ``joint`` of ist[CONTACT],
    fst[JOINT_SLOTS[joint, 0]]); the earliest event of any joint ends the step.
    """
    n_y = y.size
    K = np.zeros((16, n_y))
    F = np.zeros((7, n_y))
    y_new = np.empty(n_y)
    tmp = np.empty(n_y)
    scale = np.empty(n_y)
    J = np.zeros((n_y, n_y))
    E = np.zeros((n_y, n_y))
    piv = np.zeros(n_y, dtype=np.int64)
    f_t = np.empty(n_y)
    plus = np.empty(n_y)
    minus = np.empty(n_y)
    arg = np.empty(n_y)
    n_rows = 0
    capacity = stp_t.size
    n_samples = sample_times.size
    loose = np.zeros(N_JOINTS, dtype=np.bool_)
    for j in range(N_JOINTS):
        loose[j] = joint_is_loose(prm, j)
    impact = np.zeros(N_JOINTS)
    g_old = np.empty(N_JOINTS)
    r_old = np.empty(N_JOINTS)
    g_new = np.empty(N_JOINTS)
    r_new = np.empty(N_JOINTS)
    grid_t = np.empty(SAMPLES + 1)
    grid_d = np.empty(SAMPLES + 1)
    grid_r = np.empty(SAMPLES + 1)
    peak_t = np.empty(SAMPLES + 2)
    peak_r = np.empty(SAMPLES + 2)
    stiff_dense = ros.central_differences(prm)  # a lubricated joint: RODAS4's dense output from its stages
    # HYBRID: dry friction at E alone (no film, no clearance at F) switches on the sliding speed (RAMP_SWITCH)
    by_sliding = prm[MU] > 0.0 and not is_lubricated(prm) and not loose[N_JOINTS - 1]
    t = fst[T]
    while t < t_end:
        contact = ist[CONTACT]
        for j in range(N_JOINTS):
            impact[j] = fst[JOINT_SLOTS[j, 0]]
        m = method
        if method == HYBRID:
            m = RODAS4 if contact != 0 else DOP853
            if m == RODAS4 and by_sliding and not _near_ramp(prm, t, y):
                m = DOP853
        # the dense output's code: RODAS's continuous extension with a film, and with friction switched by the
        # sliding speed (its RODAS4 steps are in the ramp, where the Hermite cubic bends with f: 13 % of torque)
        md = ros.RODAS4_STIFF_DENSE if (m == RODAS4 and (stiff_dense or by_sliding)) else m
        order = 7 if m == DOP853 else 4
        f_row = 12 if m == DOP853 else 6
        if m == RODAS4:  # the error estimate k_6 is O(h^4): exponent -1/4 as in the code RODAS
            exponent, safety, min_factor, max_factor = -1.0 / ros.ORDER, ros.SAFETY, ros.MIN_FACTOR, ros.MAX_FACTOR
        else:
            exponent, safety, min_factor, max_factor = -1.0 / (order + 1), _SAFETY, _MIN_FACTOR, _MAX_FACTOR
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
        if m == RODAS4:  # one Jacobian per step, kept through rejected attempts from the same (t, y)
            ros.jacobian(prm, t, y, f, contact, impact, ist, J, f_t, plus, minus, tmp)
            ist[JACOBIANS] += 1
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
            if m == RODAS4:
                err = ros.step(prm, t, y, h, f, J, f_t, contact, impact, ist, K, E, piv, y_new, F, tmp, arg, rtol,
                               atol)  # fmt: skip
                ist[DECOMPOSITIONS] += 1
            else:
                K[0, :] = f
                _stages(prm, m, t, y, h, K, contact, impact, ist, y_new, tmp)
                for j in range(n_y):
                    scale[j] = atol + max(abs(y[j]), abs(y_new[j])) * rtol
                err = _error_norm(m, K, h, scale)
            if not err == err:  # NaN from a non-finite stage: reject and shrink
                err = math.inf
            if err < 1.0:
                factor = max_factor if err == 0.0 else min(max_factor, safety * err ** exponent)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            h_abs *= max(min_factor, safety * err ** exponent)
            rejected = True
            ist[REJECTED] += 1
        fst[H_ABS] = h_abs
        for j in range(n_y):
            if not math.isfinite(y_new[j]):
                return NON_FINITE, n_rows
        ist[STEPS] += 1
        f_new = K[f_row]
        if m == RODAS4:  # f at the new point: the dense output's last row and the next step's first evaluation
            ist[IMPLICIT_STEPS] += 1
            _f(prm, t_new, y_new, contact, impact, f_new, ist)
            ros.finish_dense(F, h, f_new)
        fst[LAST_STEP] = h if t_new < t_end else math.inf
        breach = limits[STEP_BUDGET] > 0.0 and ist[STEPS] > limits[STEP_BUDGET]
        breach = breach or fst[LAST_STEP] < limits[MIN_STEP_LIMIT]
        for j in range(N_JOINTS):
            slot = JOINT_SLOTS[j, 1]
            fst[slot] = -math.inf
            if loose[j]:
                g_old[j], r_old[j] = penetration_at(prm, t, y, j)
                g_new[j], r_new[j] = penetration_at(prm, t_new, y_new, j)
                if (contact >> j) & 1:  # only contact steps are model states
                    fst[slot] = g_new[j]
        breach = (breach or fst[LAST_PENETRATION] > limits[PENETRATION_LIMIT]
                  or fst[LAST_PENETRATION_F] > limits[PENETRATION_LIMIT_F])
        if breach:
            fst[T] = t_new
            y[:] = y_new
            n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t_new, y_new, contact, impact)
            return GUARD, n_rows
        # Events inside the step (weftsim.reference.events), per joint; the earliest ends the step.
        t_stop = t_new
        kind = NO_EVENT
        value = 0.0
        event_joint = -1
        dense = False
        for i in range(SAMPLES + 1):
            grid_t[i] = t + h * _GRID[i]
        grid_t[SAMPLES] = t_new
        for j in range(N_JOINTS):
            if not loose[j]:
                continue
            in_contact = ((contact >> j) & 1) == 1
            sign = -1.0 if in_contact else 1.0
            possible = sign * g_new[j] > 0.0 or sign * r_old[j] > 0.0 > sign * r_new[j]
            if not (in_contact or possible):
                continue
            if not dense and m != RODAS4:
                _dense_coefficients(prm, m, t, y, y_new, f_new, h, K, contact, impact, ist, F, tmp)
            dense = True
            j_kind, j_stop, j_value = _events_of_joint(prm, md, F, t, h, y, tmp, j, in_contact, impact[j],
                                                       g_old[j], r_old[j], g_new[j], r_new[j], t_new, grid_t, grid_d,
                                                       grid_r, peak_t, peak_r)  # fmt: skip
            if j_kind != NO_EVENT and (kind == NO_EVENT or j_stop < t_stop):
                kind, t_stop, value, event_joint = j_kind, j_stop, j_value, j
        k = ist[NEXT_SAMPLE]
        while k < n_samples and sample_times[k] <= t_stop:
            if not dense and m != RODAS4:
                _dense_coefficients(prm, m, t, y, y_new, f_new, h, K, contact, impact, ist, F, tmp)
            dense = True
            _dense_any(md, F, t, h, y, sample_times[k], tmp)
            _record(smp_t, smp_y, smp_c, smp_i, k, sample_times[k], tmp, contact, impact)
            k += 1
        ist[NEXT_SAMPLE] = k
        if contact != 0 and m == RODAS4:  # its steps are 3-5x shorter than DOP853's: the midpoint only
            t_sub = 0.5 * (t + t_stop)
            _dense_any(md, F, t, h, y, t_sub, tmp)
            n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t_sub, tmp, contact, impact)
        elif contact != 0 and _CONTACT_SUBSTEPS > 0:
            for i in range(_CONTACT_SUBSTEPS):
                t_sub = t + (t_stop - t) * _SUBSTEPS[i]
                _dense_any(md, F, t, h, y, t_sub, tmp)
                n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t_sub, tmp, contact, impact)
        if kind != NO_EVENT:
            _dense_any(md, F, t, h, y, t_stop, tmp)
            t = t_stop
            y[:] = tmp
            ist[EVENTS] += 1
            held = JOINT_SLOTS[event_joint, 0]
            if kind == SEPARATION:
                ist[CONTACT] = contact & ~(1 << event_joint)
                fst[held] = 0.0
            elif kind == PEAK:
                fst[held] = value
                ist[PEAKS] += 1
            else:
                if not value > 0.0:
                    ist[NONPOSITIVE] += 1  # no rising root found: counted, judged by weftsim.checks.guards
                fst[MAX_RATE] = max(fst[MAX_RATE], value)
                ist[CONTACT] = contact | (1 << event_joint)
                fst[held] = max(value, prm[BLOCKS[event_joint] + V_MIN])
                ist[IMPACTS] += 1
                first = JOINT_SLOTS[event_joint, 2]
                if fst[first] < 0.0:
                    fst[first] = t
            ist[START] = 1
            for j in range(N_JOINTS):
                impact[j] = fst[JOINT_SLOTS[j, 0]]
            n_rows = _record(stp_t, stp_y, stp_c, stp_i, n_rows, t, y, ist[CONTACT], impact)
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


# advance for a plain scene (weftsim.physics.chain_f.PLAIN): the same loop, compiled on first use.
advance_plain = specialize(advance, "plain", lean=True, counted=("_initial_step", "jacobian", "_jacobian_central", "step"), **PLAIN)
