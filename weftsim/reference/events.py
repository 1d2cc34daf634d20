"""Contact events inside one accepted step of the reference engine (scipy path).

The integrators advance a segment of one mode (free flight or contact) step by step; after
every accepted step these functions look, on the step's dense output, for the first event
that ends the segment:

- **onset** (free flight): delta crosses 0 upwards *with delta_dot > 0*;
- **separation** (contact): delta crosses 0 downwards with delta_dot < 0;
- **rate peak** (contact, ``"max_approach"`` rule): the approach rate delta_dot reaches a maximum
  above the held impact velocity, which then becomes the new held value.

Why more than the signs at the step ends (issue 11): a new segment starts *at* the root
that ended the last one (delta ~ -1e-17 m after a separation); if its first step ends on the
other side, a root search bracketed by the step ends may converge to that starting root, where
the journal is leaving (an "onset" with a non-positive approach rate, whose held impact
velocity then collapses to the floor v_min and makes the damping term hundreds of times too
large).  And a free flight (or an impact) that starts and ends inside one step leaves the same
sign at both ends.  So the step is sampled at :data:`SAMPLES` + 1 points, a root is accepted
only where the crossing function rises, and a non-rising root sends the search on past the
lowest point that follows it.

The located times are returned; the caller takes the state there from the dense output.
``state(t) -> (delta, delta_dot)`` evaluates the dense output (m, m/s).
:mod:`weftsim.reference.compiled` mirrors this logic in numba.
"""

from __future__ import annotations

import math

ROOT_XTOL = 1e-13  # s: event time accuracy (delta_dot ~ 1 m/s -> 1e-13 m in delta)
# Sub-intervals sampled per step when an event is possible: the grid of the dense-output points
# that contact steps record anyway (integrate._CONTACT_SUBSTEPS + 1), so a contact step pays no
# extra evaluation; a double crossing inside one sub-interval shows as a sign change of the rate.
SAMPLES = 4
# Golden-section iterations for an extremum: 0.618^60 ~ 3e-13 of the interval (a step of
# ~1e-6 s in contact: ~3e-19 s, far below ROOT_XTOL; a 0.5-deg free step at 20 rpm: ~1e-15 s).
_GOLDEN_ITERATIONS = 60
_INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0
# A rate maximum found within this fraction of the step from its end is the end itself: the
# rate is still rising there and the next step continues the search.
END_FRACTION = 1e-9


def locate_root(g, lo: float, hi: float, g_lo: float, g_hi: float) -> float:
    """Root of g between lo (g <= 0) and hi (g > 0), returned on the positive side.

    Illinois regula falsi with the bracket kept, to :data:`ROOT_XTOL`.
    """
    last = 0
    for _ in range(200):
        if hi - lo <= ROOT_XTOL:
            break
        m = hi - g_hi * (hi - lo) / (g_hi - g_lo)
        if not lo < m < hi:
            m = 0.5 * (lo + hi)
        g_m = g(m)
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


def maximum(f, lo: float, hi: float) -> tuple[float, float]:
    """(t, f(t)) of the largest value of f on [lo, hi] found by golden-section search.

    Exact for a unimodal f; the end values are candidates too.
    """
    a, b = lo, hi
    x1 = b - _INV_PHI * (b - a)
    x2 = a + _INV_PHI * (b - a)
    f1, f2 = f(x1), f(x2)
    for _ in range(_GOLDEN_ITERATIONS):
        if f1 < f2:
            a, x1, f1 = x1, x2, f2
            x2 = a + _INV_PHI * (b - a)
            f2 = f(x2)
        else:
            b, x2, f2 = x2, x1, f1
            x1 = b - _INV_PHI * (b - a)
            f1 = f(x1)
    best = max((f(lo), lo), (f1, x1), (f2, x2), (f(hi), hi))
    return best[1], best[0]


def first_crossing(state, times, deltas, rates, sign: float):
    """First rising crossing of g = sign * delta within the sampled step, or None.

    Parameters
    ----------
    state : callable
        ``state(t) -> (delta, delta_dot)`` on the step's dense output.
    times, deltas, rates : sequences
        The step sampled at ``SAMPLES + 1`` increasing times (first = step start, last = end).
    sign : float
        +1 for an onset (delta rises through 0), -1 for a separation (delta falls through 0).

    Returns
    -------
    (t, rate) or None
        The crossing time and sign * delta_dot there (> 0 for a genuine crossing; <= 0 only
        if no rising root could be found in a bracket whose end is on the other side: the
        caller counts such an event as implausible).
    """

    def g(t):
        return sign * state(t)[0]

    def rate_at(t):
        return sign * state(t)[1]

    if sign * deltas[0] > 0.0:  # a segment starts on its own side; if not, it ends at once
        return times[0], rate_at(times[0])
    for k in range(len(times) - 1):
        lo, hi = times[k], times[k + 1]
        g_lo, g_hi = sign * deltas[k], sign * deltas[k + 1]
        if g_hi <= 0.0:
            if not (sign * rates[k] > 0.0 > sign * rates[k + 1]):
                continue
            # g rises and falls back inside [lo, hi]: a crossing pair hides there if its top is > 0.
            t_top, g_top = maximum(g, lo, hi)
            if g_top <= 0.0:
                continue
            hi, g_hi = t_top, g_top
        root = locate_root(g, lo, hi, g_lo, g_hi)
        rate = rate_at(root)
        if rate <= 0.0:
            # Not rising here: the root the segment started from, seen through round-off.  The
            # rising crossing comes after the lowest point of g that follows.
            t_low, g_low = maximum(lambda t: -g(t), root, hi)
            if -g_low < 0.0:
                root = locate_root(g, t_low, hi, -g_low, g_hi)
                rate = rate_at(root)
        return root, rate
    return None


def rate_peak(rate_of, times, rates, held: float):
    """Time and value of a maximum of delta_dot above ``held`` inside the step, or None.

    ``rate_of(t)`` is delta_dot on the dense output; ``times``/``rates`` sample the step (the
    last sample is the step's end).  A maximum at the step's end (delta_dot still rising) is
    not a peak: the search goes on in the next step.
    """
    k = max(range(len(times)), key=lambda i: rates[i])
    if rates[k] <= held:
        return None
    lo = times[max(k - 1, 0)]
    hi = times[min(k + 1, len(times) - 1)]
    t_peak, r_peak = maximum(rate_of, lo, hi)
    end = times[-1]
    if end - t_peak <= END_FRACTION * (end - times[0]) or r_peak <= held:
        return None
    return t_peak, r_peak
