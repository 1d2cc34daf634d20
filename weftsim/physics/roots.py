"""Event search inside one accepted step of the reference engine (the one definition).

After every accepted step the reference engine looks, on the step's dense output, for the first
event that ends the segment: an onset (delta crosses 0 upwards with delta_dot > 0), a separation
(delta crosses 0 downwards with delta_dot < 0), or, under the "max_approach" rule, a maximum of the
approach rate delta_dot above the held impact velocity.  The step is sampled at :data:`SAMPLES` + 1
points; a root is accepted only where the crossing function rises, and a non-rising root (the root
the segment started from, seen through round-off) sends the search on past the lowest point that
follows it.

The dense output is the global ``state(t, *args) -> (delta, delta_dot)`` (m, m/s) and the
functions pass its extra arguments ``args`` along: the compiled path binds ``state`` to its compiled
dense output (:func:`weftsim.physics.python.specialize`), the scipy path uses the plain-Python form
(:func:`weftsim.physics.python.python_form`) with ``state`` bound to a call of a closure over scipy's
dense output.  Roots by the Illinois variant of regula falsi (Dowell & Jarratt, BIT 11, 1971),
maxima by golden-section search (Kiefer 1953).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from numba import njit

if TYPE_CHECKING:
    from collections.abc import Callable

    import numpy as np

ROOT_XTOL = 1e-13  # s: event time accuracy (delta_dot ~ 1 m/s -> 1e-13 m in delta)
# Sub-intervals sampled per step when an event is possible: the grid of the dense-output points
# that contact steps record anyway (3 substeps + 1), so a contact step pays no extra evaluation; a
# double crossing inside one sub-interval shows as a sign change of the rate.
SAMPLES = 4
# Golden-section iterations for an extremum: 0.618^60 ~ 3e-13 of the interval (a step of
# ~1e-6 s in contact: ~3e-19 s, far below ROOT_XTOL; a 0.5-deg free step at 20 rpm: ~1e-15 s).
GOLDEN_ITERATIONS = 60
INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0
# A rate maximum found within this fraction of the step from its end is the end itself: the
# rate is still rising there and the next step continues the search.
END_FRACTION = 1e-9
# What :func:`maximum` maximizes: sign * delta, -sign * delta, delta_dot.
CROSSING, MINUS_CROSSING, RATE = 0, 1, 2


@njit(cache=True, error_model="numpy")
def state(t: float, dense: Callable) -> tuple[float, float]:
    """The dense output's (delta, delta_dot) at t: a stand-in that callers bind to their own."""
    return dense(t)


@njit(cache=True, error_model="numpy")
def pick(delta_and_rate: tuple[float, float], what: int, sign: float) -> float:
    """sign * delta (``CROSSING``), -sign * delta (``MINUS_CROSSING``) or delta_dot (``RATE``)."""
    if what == CROSSING:
        return sign * delta_and_rate[0]
    if what == MINUS_CROSSING:
        return -sign * delta_and_rate[0]
    return delta_and_rate[1]


@njit(cache=True, error_model="numpy")
def locate_root(args: tuple, sign: float, lo: float, hi: float, g_lo: float, g_hi: float) -> float:
    """Root of g = sign * delta between lo (g <= 0) and hi (g > 0), returned on the positive side.

    Illinois regula falsi with the bracket kept, to :data:`ROOT_XTOL`.
    """
    last = 0
    for _ in range(200):
        if hi - lo <= ROOT_XTOL:
            break
        m = hi - g_hi * (hi - lo) / (g_hi - g_lo)
        if not lo < m < hi:
            m = 0.5 * (lo + hi)
        g_m = sign * state(m, *args)[0]
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
def maximum(args: tuple, what: int, sign: float, lo: float, hi: float) -> tuple[float, float]:
    """(t, value) of the largest :func:`pick` on [lo, hi]: golden section, the ends are candidates.

    Exact for a unimodal function; ties keep the earliest candidate (lo, x1, x2, hi).
    """
    a, b = lo, hi
    x1 = b - INV_PHI * (b - a)
    x2 = a + INV_PHI * (b - a)
    f1 = pick(state(x1, *args), what, sign)
    f2 = pick(state(x2, *args), what, sign)
    for _ in range(GOLDEN_ITERATIONS):
        if f1 < f2:
            a, x1, f1 = x1, x2, f2
            x2 = a + INV_PHI * (b - a)
            f2 = pick(state(x2, *args), what, sign)
        else:
            b, x2, f2 = x2, x1, f1
            x1 = b - INV_PHI * (b - a)
            f1 = pick(state(x1, *args), what, sign)
    best_t, best = lo, pick(state(lo, *args), what, sign)
    if f1 > best:
        best_t, best = x1, f1
    if f2 > best:
        best_t, best = x2, f2
    f_hi = pick(state(hi, *args), what, sign)
    if f_hi > best:
        best_t, best = hi, f_hi
    return best_t, best


@njit(cache=True, error_model="numpy")
def crossing_in(args: tuple, times: np.ndarray, deltas: np.ndarray, rates: np.ndarray, sign: float,
                k: int) -> tuple[bool, float, float]:
    """(found, t, sign * delta_dot) of a rising crossing of sign * delta in [times[k], times[k + 1]]."""
    lo, hi = times[k], times[k + 1]
    g_lo, g_hi = sign * deltas[k], sign * deltas[k + 1]
    if g_hi <= 0.0:
        if not (sign * rates[k] > 0.0 > sign * rates[k + 1]):
            return False, 0.0, 0.0
        # g rises and falls back inside [lo, hi]: a crossing pair hides there if its top is > 0.
        t_top, g_top = maximum(args, CROSSING, sign, lo, hi)
        if g_top <= 0.0:
            return False, 0.0, 0.0
        hi, g_hi = t_top, g_top
    root = locate_root(args, sign, lo, hi, g_lo, g_hi)
    rate = sign * state(root, *args)[1]
    if rate <= 0.0:
        # Not rising here: the root the segment started from, seen through round-off.  The
        # rising crossing comes after the lowest point of g that follows.
        t_low, minus_g_low = maximum(args, MINUS_CROSSING, sign, root, hi)
        if -minus_g_low < 0.0:
            root = locate_root(args, sign, t_low, hi, -minus_g_low, g_hi)
            rate = sign * state(root, *args)[1]
    return True, root, rate


@njit(cache=True, error_model="numpy")
def first_crossing(args: tuple, times: np.ndarray, deltas: np.ndarray, rates: np.ndarray,
                   sign: float) -> tuple[bool, float, float]:
    """First rising crossing of g = sign * delta within the sampled step.

    Parameters
    ----------
    args : extra arguments of the dense output ``state(t, *args) -> (delta, delta_dot)``.
    times, deltas, rates : the step sampled at ``SAMPLES + 1`` increasing times (first = step start,
        last = end) and delta, delta_dot there.
    sign : +1 for an onset (delta rises through 0), -1 for a separation (delta falls through 0).

    Returns
    -------
    (found, t, rate): the crossing time and sign * delta_dot there (> 0 for a genuine crossing; <= 0
    only if no rising root could be found in a bracket whose end is on the other side: the caller
    counts such an event as implausible).
    """
    if sign * deltas[0] > 0.0:  # a segment starts on its own side; if not, it ends at once
        return True, times[0], sign * rates[0]
    for k in range(len(times) - 1):
        found, t, rate = crossing_in(args, times, deltas, rates, sign, k)
        if found:
            return True, t, rate
    return False, 0.0, 0.0


@njit(cache=True, error_model="numpy")
def rate_peak(args: tuple, times: np.ndarray, rates: np.ndarray, n: int, held: float) -> tuple[bool, float, float]:
    """(found, t, delta_dot) of a maximum of delta_dot above ``held`` inside the step.

    ``times[:n]``, ``rates[:n]`` sample the step (the last is the step's end, or the separation
    that ends it).  A maximum at the end (delta_dot still rising) is not a peak: the search goes on
    in the next step.
    """
    k = 0
    for i in range(1, n):
        if rates[i] > rates[k]:
            k = i
    if rates[k] <= held:
        return False, 0.0, 0.0
    lo = times[max(k - 1, 0)]
    hi = times[min(k + 1, n - 1)]
    t_peak, r_peak = maximum(args, RATE, 1.0, lo, hi)
    end = times[n - 1]
    if end - t_peak <= END_FRACTION * (end - times[0]) or r_peak <= held:
        return False, 0.0, 0.0
    return True, t_peak, r_peak
