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

The search itself is written once, in :mod:`weftsim.physics.roots` (the compiled path calls it
compiled); this module calls its plain-Python form with a closure over scipy's dense output.
The located times are returned; the caller takes the state there from the dense output.
``state(t) -> (delta, delta_dot)`` evaluates the dense output (m, m/s).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from weftsim.physics import roots
from weftsim.physics.python import python_form
from weftsim.physics.roots import END_FRACTION, ROOT_XTOL, SAMPLES  # noqa: F401 - the search's constants

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    import numpy as np

_FIRST_CROSSING = python_form(roots.first_crossing)
_RATE_PEAK = python_form(roots.rate_peak)


def first_crossing(state: Callable[[float], tuple[float, float]], times: np.ndarray,
                   deltas: np.ndarray | Sequence[float], rates: np.ndarray | Sequence[float], sign: float) -> tuple[float, float] | None:
    """First rising crossing of g = sign * delta within the sampled step, or None.

    ``state(t) -> (delta, delta_dot)``; ``times``, ``deltas``, ``rates`` sample the step at
    ``SAMPLES + 1`` increasing times; ``sign`` +1 for an onset, -1 for a separation.  Returns
    ``(t, rate)`` (rate = sign * delta_dot there; :func:`weftsim.physics.roots.first_crossing`).
    """
    found, t, rate = _FIRST_CROSSING((state,), times, deltas, rates, sign)
    return (t, rate) if found else None


def rate_peak(rate_of: Callable[[float], float], times: np.ndarray | Sequence[float],
              rates: np.ndarray | Sequence[float], held: float) -> tuple[float, float] | None:
    """Time and value of a maximum of delta_dot above ``held`` inside the step, or None.

    ``rate_of(t)`` is delta_dot on the dense output (:func:`weftsim.physics.roots.rate_peak`).
    """
    found, t, rate = _RATE_PEAK((lambda s: (0.0, rate_of(s)),), times, rates, len(times), held)
    return (t, rate) if found else None
