"""Linearly implicit (Rosenbrock) step of the compiled reference path (numba): RODAS4.

RODAS4 of Hairer & Wanner (Solving Ordinary Differential Equations II, 2nd ed., Springer 1996,
section IV.7; the coefficients of their code RODAS, the method of order 4 with an embedded order 3,
L-stable and stiffly accurate) in the form of that section, eq. (7.4'): with E = I / (h gamma) - J,

    E k_i = f(t + c_i h, y + sum_j a_ij k_j) + sum_j (c_ij / h) k_j + h d_i df/dt,   i = 1..6,

the embedded solution y + sum_j a_5j k_j + k_5 and the solution y_new = that + k_6, so k_6 is the
local error estimate.  Dense output: the cubic Hermite interpolant of (y, f) at both ends of the step
(f at the end is the next step's first evaluation, so it costs nothing), local error O(h^4), C^1 across
steps:

    y(t + s h) = h00(s) y + h10(s) h f(t, y) + h01(s) y_new + h11(s) h f(t + h, y_new).

With a lubricated joint the dense output is RODAS's own continuous extension from the stages instead
(:func:`dense_stiff`).

Each step solves 6 linear systems with one LU decomposition of E, so its step size is set by
accuracy, not by the stiffness of a lasting contact or of the friction ramp (the explicit DOP853
steps at ~1e-9 s where the journal sticks: the ramp's slope mu F_N / (v1 - v0) ~ 1e7-1e8 N s/m).

The Jacobian J = df/dy and df/dt come from the one kernel (:func:`weftsim.physics.chain_f.rhs_any`) by forward
differences with fixed, small perturbations (:data:`JAC_STEP_Q`, :data:`JAC_STEP_V`, :data:`JAC_STEP_T`) from
f(t, y), which the step needs anyway: n - 1 evaluations (5 for the 2-DOF chain).  The quadrature states W3 and
D are not read by the right-hand side, so their columns are zero and are not perturbed.  Accuracy, measured in
``tests/test_rosenbrock.py`` against an extrapolated central difference: relative error 5e-8-7e-6 inside a
contact with friction (central differences: 2e-8-8e-7, at twice the evaluations and no measurable gain in
steps or peaks; docs/reference-solver.md section 3, "Linearly implicit path").  At delta = 0 and at the kinks
of the friction ramp no difference is a derivative; the step's error control rejects what that spoils.
With a lubricated joint the Jacobian is a central difference (:func:`central_differences`, 2 (n - 1)
evaluations): there the forward differences' error of ~1e-4 held the step at a few microseconds in the
mixed regime (docs/performance.md, "The mixed regime").

Every function is module-level ``@njit(cache=True, error_model="numpy")``;
:mod:`weftsim.reference.compiled` drives them in its event-driven loop.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.physics.chain import OMEGA
from weftsim.physics.chain_f import JOINT_F
from weftsim.physics.joint import N_JOINT, VISCOSITY
from weftsim.physics.lubricated import is_lubricated
from weftsim.reference.compiled_rk import _f

RODAS4 = 2  # method code next to compiled_rk.DOP853 (0) and RK45 (1)
ORDER = 4  # of the solution; the error estimate k_6 is O(h^4), so the step-size exponent is 1/4
# Perturbations of the forward differences: coordinates (rad, or m for the free rod's centre) and their
# rates (rad/s, m/s), and time (s).  1e-9 rad moves the journal by ~0.3 nm, against penetrations of
# 1e-7-1e-5 m (truncation ~ (0.3 nm / delta)^2, < 1e-5); the rates by ~0.3 nm/s, far inside the
# friction ramp of 1e-4 m/s.  Round-off ~ eps |f| / 1e-9 ~ 1e-3 rad/s^2 against derivatives of 1e3-1e9;
# truncation ~ (0.3 nm / delta), 1e-5 at delta = 30 um.
JAC_STEP_Q = 1e-9
JAC_STEP_V = 1e-9
JAC_STEP_T = 1e-10
# Central differences with a lubricated joint (:func:`central_differences`): 3e-10 rad (0.1 nm at the journal),
# 3e-9 rad/s, 3e-11 s.  Against Richardson-extrapolated differences over 40 states of the mixed loom (10 mPa s,
# film ratio 0.37-23): median relative error 1.6e-7 of the rows of the accelerations (forward differences of
# the fixed steps above: 1e-4); 10x larger steps 2e-4 (truncation), 10x smaller 9e-7 (round-off).
JAC_CENTRAL_Q = 3e-10
JAC_CENTRAL_V = 3e-9
JAC_CENTRAL_T = 3e-11
N_QUADRATURES = 2  # W3 and D at the end of the state: not read by the right-hand side

GAMMA = 0.25
C = np.array([0.0, 0.386, 0.21, 0.63, 1.0, 1.0])
D = np.array([0.25, -0.1043, 0.1035, -0.3620000000000023e-01, 0.0, 0.0])
A = np.zeros((6, 6))
A[1, 0] = 0.1544000000000000e+01
A[2, 0], A[2, 1] = 0.9466785280815826e+00, 0.2557011698983284e+00
A[3, 0], A[3, 1], A[3, 2] = 0.3314825187068521e+01, 0.2896124015972201e+01, 0.9986419139977817e+00
A[4, 0], A[4, 1], A[4, 2], A[4, 3] = (0.1221224509226641e+01, 0.6019134481288629e+01, 0.1253708332932087e+02,
                                      -0.6878860361058950e+00)  # fmt: skip
A[5, :4] = A[4, :4]
A[5, 4] = 1.0
CC = np.zeros((6, 6))
CC[1, 0] = -0.5668800000000000e+01
CC[2, 0], CC[2, 1] = -0.2430093356833875e+01, -0.2063599157091915e+00
CC[3, 0], CC[3, 1], CC[3, 2] = -0.1073529058151375e+00, -0.9594562251023355e+01, -0.2047028614809616e+02
CC[4, 0], CC[4, 1], CC[4, 2], CC[4, 3] = (0.7496443313967647e+01, -0.1024680431464352e+02, -0.3399990352819905e+02,
                                          0.1170890893206160e+02)  # fmt: skip
CC[5, 0], CC[5, 1], CC[5, 2], CC[5, 3], CC[5, 4] = (0.8083246795921522e+01, -0.7981132988064893e+01,
                                                    -0.3152159432874371e+02, 0.1631930543123136e+02,
                                                    -0.6058818238834054e+01)  # fmt: skip
# Continuous extension of RODAS (Hairer & Wanner's code, its dense output of order 3): with the stages K of the
# step, y(t + s h) = (1 - s) y + s (y_new + (1 - s) (sum DENSE_2[j] K_j + s sum DENSE_3[j] K_j)).
DENSE_2 = np.array([0.1012623508344586e+02, -0.7487995877610167e+01, -0.3480091861555747e+02,
                    -0.7992771707568823e+01, 0.1025137723295662e+01])  # fmt: skip
DENSE_3 = np.array([-0.6762803392801253e+00, 0.6087714651680015e+01, 0.1643084320892478e+02,
                    0.2476722511418386e+02, -0.6594389125716872e+01])  # fmt: skip
RODAS4_STIFF_DENSE = 4  # code of the dense output from the stages (a code beside the methods', never a method)
# Step-size control of the code RODAS: factor = 0.9 err^(-1/4) within [1/5, 6].
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 6.0


@njit(cache=True, error_model="numpy")
def jacobian(prm, t, y, f0, contact, impact, ist, J, f_t, plus, minus, tmp):
    """J = df/dy (n, n) and f_t = df/dt (n,) at (t, y): central differences of the kernel with a lubricated
    joint (:func:`central_differences`), else forward differences from f0 = f(t, y).

    Columns of W3 and D stay zero (the right-hand side does not read them).  n - 1 evaluations forward,
    2 (n - 1) central.
    """
    if central_differences(prm):
        _jacobian_central(prm, t, y, contact, impact, ist, J, f_t, plus, minus, tmp)
        return
    n = y.size
    n_mech = n - N_QUADRATURES
    half = n_mech // 2
    J[:, :] = 0.0
    tmp[:] = y
    for j in range(n_mech):
        step = JAC_STEP_Q if j < half else JAC_STEP_V
        tmp[j] = y[j] + step
        _f(prm, t, tmp, contact, impact, plus, ist)
        tmp[j] = y[j]
        inv = 1.0 / step
        for i in range(n):
            J[i, j] = (plus[i] - f0[i]) * inv
    _f(prm, t + JAC_STEP_T, y, contact, impact, plus, ist)
    for i in range(n):
        f_t[i] = (plus[i] - f0[i]) * (1.0 / JAC_STEP_T)


@njit(cache=True, error_model="numpy")
def central_differences(prm) -> bool:
    """True when a joint is lubricated (film or asperities): RODAS4's Jacobian is then taken by central
    differences (:func:`_jacobian_central`).

    The film's squeeze and the asperities' load vary on the scale of the film thickness (down to 0.1 um),
    and the stiff clearance rate (Jacobian eigenvalues to -4e7 1/s, h lambda 10-100 at the accepted steps)
    follows its quasi-static value only as well as the Jacobian is known: the forward differences' relative
    error of 1e-4 left an error estimate of order 1 on psi' that did not shrink with the step (docs/performance.md,
    "The mixed regime").  Dry and friction runs keep the forward differences (their arithmetic is unchanged).
    """
    joint_f = prm[JOINT_F:JOINT_F + N_JOINT]
    return is_lubricated(prm) or is_lubricated(joint_f)


@njit(cache=True, error_model="numpy")
def _jacobian_central(prm, t, y, contact, impact, ist, J, f_t, plus, minus, tmp):
    """J and f_t by central differences with the steps JAC_CENTRAL_* (2 (n - 1) evaluations)."""
    n = y.size
    n_mech = n - N_QUADRATURES
    half = n_mech // 2
    J[:, :] = 0.0
    tmp[:] = y
    for j in range(n_mech):
        step = JAC_CENTRAL_Q if j < half else JAC_CENTRAL_V
        tmp[j] = y[j] + step
        _f(prm, t, tmp, contact, impact, plus, ist)
        tmp[j] = y[j] - step
        _f(prm, t, tmp, contact, impact, minus, ist)
        tmp[j] = y[j]
        inv = 0.5 / step
        for i in range(n):
            J[i, j] = (plus[i] - minus[i]) * inv
    _f(prm, t + JAC_CENTRAL_T, y, contact, impact, plus, ist)
    _f(prm, t - JAC_CENTRAL_T, y, contact, impact, minus, ist)
    for i in range(n):
        f_t[i] = (plus[i] - minus[i]) * (0.5 / JAC_CENTRAL_T)


@njit(cache=True, error_model="numpy")
def rate_tolerance_factor(prm) -> float:
    """Factor on atol for the rates in the error norm of :func:`step`: the drive speed (rad/s) with a
    lubricated joint with an oil film (viscosity > 0), else 1 (dry and friction runs unchanged).

    With an oil film the clearance rate (psi', or the rod's centre rates) is a stiff, quasi-static variable:
    the film's squeeze damping relaxes it in 1e-7-1e-6 s (Jacobian eigenvalues -1e5...-3e7 1/s on the loom)
    and its local error estimate k_6 grows about as h, not h^4.  Under atol = 1e-8 rad/s (2e-8 rad/s with
    rtol |psi'|) the controller then stalls at err ~ 0.66 with steps of ~1e-7 s (the loom, c = 0.02 mm,
    80 mPa s: 61,400 steps a revolution, the rate's term 1.6 of the norm, every other term < 0.01).  An
    error da' in a rate moves the coordinate by da' / Omega over a radian of the crank, so the rate's
    absolute tolerance consistent with atol on the coordinates is atol Omega (docs/performance.md,
    "Where the time goes in a lubricated run": 30x fewer steps, first-revolution peaks unchanged within
    0.1 % against rtol 1e-8, atol 1e-11).
    """
    joint_f = prm[JOINT_F:JOINT_F + N_JOINT]
    if (is_lubricated(prm) and prm[VISCOSITY] > 0.0) or (is_lubricated(joint_f) and joint_f[VISCOSITY] > 0.0):
        return prm[OMEGA]
    return 1.0


@njit(cache=True, error_model="numpy")
def lu_factor(M, piv):
    """In-place LU decomposition with partial pivoting of a small dense matrix; False if singular."""
    n = M.shape[0]
    for k in range(n):
        p = k
        big = abs(M[k, k])
        for i in range(k + 1, n):
            if abs(M[i, k]) > big:
                big = abs(M[i, k])
                p = i
        piv[k] = p
        if big == 0.0 or not math.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                M[k, j], M[p, j] = M[p, j], M[k, j]
        inv = 1.0 / M[k, k]
        for i in range(k + 1, n):
            m = M[i, k] * inv
            M[i, k] = m
            if m != 0.0:
                for j in range(k + 1, n):
                    M[i, j] -= m * M[k, j]
    return True


@njit(cache=True, error_model="numpy")
def lu_solve(M, piv, b):
    """Solve in place with the factors of :func:`lu_factor`."""
    n = M.shape[0]
    for k in range(n):
        p = piv[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
    for i in range(n):
        acc = b[i]
        for j in range(i):
            acc -= M[i, j] * b[j]
        b[i] = acc
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= M[i, j] * b[j]
        b[i] = acc / M[i, i]


@njit(cache=True, error_model="numpy")
def step(prm, t, y, h, f0, J, f_t, contact, impact, ist, K, E, piv, y_new, F, tmp, arg, rtol, atol):
    """One RODAS4 step of length h from (t, y) with f0 = f(t, y): y_new, the dense rows F[0:3], error norm.

    Returns the RMS norm of k_6 scaled by atol + rtol max(|y|, |y_new|) (as the explicit methods; with a
    lubricated joint the rates' atol times :func:`rate_tolerance_factor`), inf when the matrix is singular or
    a stage is not finite.
    """
    n = y.size
    n_mech = n - N_QUADRATURES
    half = n_mech // 2
    atol_rate = atol * rate_tolerance_factor(prm)
    inv_hg = 1.0 / (h * GAMMA)
    for i in range(n):
        for j in range(n):
            E[i, j] = -J[i, j]
        E[i, i] += inv_hg
    if not lu_factor(E, piv):
        return math.inf
    for s in range(6):
        if s == 0:
            tmp[:] = f0
        else:
            for i in range(n):
                acc = 0.0
                for r in range(s):
                    acc += A[s, r] * K[r, i]
                arg[i] = y[i] + acc
            _f(prm, t + C[s] * h, arg, contact, impact, tmp, ist)
        for i in range(n):
            acc = tmp[i] + h * D[s] * f_t[i]
            for r in range(s):
                acc += CC[s, r] / h * K[r, i]
            K[s, i] = acc
        lu_solve(E, piv, K[s])
    err = 0.0
    for i in range(n):
        y_new[i] = arg[i] + K[5, i]
        if not math.isfinite(y_new[i]):
            return math.inf
        tol = atol_rate if half <= i < n_mech else atol
        e = K[5, i] / (tol + rtol * max(abs(y[i]), abs(y_new[i])))
        err += e * e
    for i in range(n):
        F[0, i] = y_new[i]
        F[1, i] = h * f0[i]
        d2 = 0.0
        d3 = 0.0
        for r in range(5):
            d2 += DENSE_2[r] * K[r, i]
            d3 += DENSE_3[r] * K[r, i]
        F[3, i] = d2
        F[4, i] = d3
    return math.sqrt(err / n)


@njit(cache=True, error_model="numpy")
def dense_stiff(F, t_old, h, y_old, t, out):
    """RODAS's own continuous extension of the last step at time t (``DENSE_2``, ``DENSE_3``; order 3).

    Used with a lubricated joint (:func:`central_differences`): built from the stages, it follows the stiff
    clearance rate where the cubic Hermite interpolant, which bends with f at both ends, does not.  A step that
    starts off the slow manifold (from an event's state, itself interpolated) has a large psi'' (the squeeze
    film relaxes psi' at ~1e7 1/s), and the Hermite interpolant carries h f / 8 of it to mid-step: a quarter
    of psi' for a start 1 % off, against 0.2 % here (docs/performance.md, "The mixed regime").  Local error
    O(h^4) on smooth solutions, as the Hermite interpolant's.
    """
    s = (t - t_old) / h
    for i in range(y_old.size):
        out[i] = (1.0 - s) * y_old[i] + s * (F[0, i] + (1.0 - s) * (F[3, i] + s * F[4, i]))


@njit(cache=True, error_model="numpy")
def finish_dense(F, h, f_new):
    """Complete the dense rows with h f(t + h, y_new) (evaluated by the caller for the next step anyway)."""
    for i in range(f_new.size):
        F[2, i] = h * f_new[i]


@njit(cache=True, error_model="numpy")
def dense(F, t_old, h, y_old, t, out):
    """Cubic Hermite interpolation of the last step at time t (module docstring), O(h^4) locally."""
    s = (t - t_old) / h
    s2 = s * s
    s3 = s2 * s
    h00 = 2.0 * s3 - 3.0 * s2 + 1.0
    h10 = s3 - 2.0 * s2 + s
    h01 = 1.0 - h00
    h11 = s3 - s2
    for i in range(y_old.size):
        out[i] = h00 * y_old[i] + h10 * F[1, i] + h01 * F[0, i] + h11 * F[2, i]
