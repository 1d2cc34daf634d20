"""Impact-velocity rules of the contact laws' damping term (the one definition).

The damping term xi delta_dot / v_imp of every law (:mod:`.laws`) needs the impact velocity
v_imp: the penetration rate delta_dot at the contact onset (Lankarani & Nikravesh 1990), held
until separation and floored at v_min > 0.  Rules (``ClearanceJoint.impact_velocity_rule``):

- ``"max_approach"`` (default): v_imp = the largest approach rate since the onset.  In an isolated
  impact delta_dot only falls after the onset, so this is the onset value and every law keeps its
  restitution; in a driven lasting contact delta_dot can grow far beyond it, and the rule keeps
  the damping term xi delta_dot / v_imp <= xi (damping force <= xi x elastic force).
  :func:`effective_impact_velocity` applies it between the engines' updates of the held value.
- ``"onset"``: the onset rate alone (Flores & Ambrosio 2004), for comparison with the literature.

A fixed-step integrator sees the onset only between the last free state (delta0 <= 0, rate0)
and a penetrated one (delta > 0, rate); linear interpolation in the step to the zero of delta,

    s = delta0 / (delta0 - delta),    v_imp = rate0 + s (rate - rate0),

makes the error O(h^2) instead of O(h) (:func:`onset_fraction`, :func:`callback_impact_velocity`).
"""

from __future__ import annotations

from numba import njit

# Half-width of the dead zone of the damping rate, as a fraction of v_min (1e-10 m/s by default).
# A journal resting under load is otherwise locked by its own damper onto a round-off limit cycle
# that generalized-alpha's Newton cannot leave (docs/clearance-joint.md, "Resting contact"): the
# elastic force jumps by K'(delta) x one ulp of the marker positions between neighbouring floats, and
# the damper holds the journal exactly there.  Removing rates below 1e-6 v_min from the damping term
# changes the normal force by at most xi 1e-6 F_el.
RESTING_RATE_FRACTION = 1e-6


@njit(cache=True, error_model="numpy", inline="always")
def effective_impact_velocity(held: float, penetration_rate: float, max_approach: bool) -> float:
    """v_imp of the damping term, m/s: ``max(held, delta_dot)`` under "max_approach", else ``held``."""
    if max_approach and penetration_rate > held:
        return penetration_rate
    return held


@njit(cache=True, error_model="numpy")
def onset_fraction(delta0: float, delta1: float) -> float:
    """Fraction s in [0, 1] of the step at which delta crosses 0 (linear in delta).

    ``delta0`` (<= 0) and ``delta1`` (> 0): penetration at the start and end of the step, m;
    1 (the end of the step) when delta does not rise across the step.
    """
    span = delta0 - delta1
    if span >= 0.0:
        return 1.0
    s = delta0 / span
    return 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)


@njit(cache=True, error_model="numpy")
def onset_velocity(delta0: float, rate0: float, delta1: float, rate1: float) -> float:
    """Penetration rate at the zero crossing of delta, linear in-step interpolation, m/s."""
    return rate0 + onset_fraction(delta0, delta1) * (rate1 - rate0)


@njit(cache=True, error_model="numpy")
def callback_impact_velocity(held: float, delta0: float, rate0: float, delta: float, rate: float, v_min: float,
                             max_approach: bool) -> float:
    """Impact velocity the force law uses at a trial state in contact (delta > 0), m/s.

    ``held``, ``delta0``, ``rate0``: held v_imp, penetration and rate of the last accepted state;
    ``delta0 > 0`` means the contact was already on, otherwise the onset lies inside this step and
    is interpolated at the trial state (``delta``, ``rate``), so the force is a smooth function of
    the unknowns and Newton sees it.  A non-positive interpolated onset rate (a graze within the
    step) is replaced by the trial rate.  Under "max_approach" (``max_approach`` True) v_imp is
    raised to ``rate``; the result is floored at ``v_min``.
    """
    if delta0 > 0.0:
        v = held
    else:
        v = onset_velocity(delta0, rate0, delta, rate)
        if v <= 0.0:
            v = rate
    if max_approach and rate > v:
        v = rate
    return v if v > v_min else v_min


@njit(cache=True, error_model="numpy")
def damping_rate(rate: float, dead_rate: float) -> float:
    """Penetration rate that drives the damping term: delta_dot less a dead zone +-dead_rate, m/s.

    Continuous and piecewise linear: 0 for |rate| <= dead_rate, rate -+ dead_rate outside
    (``dead_rate`` = :data:`RESTING_RATE_FRACTION` x v_min in the Exudyn callbacks).
    """
    if rate > dead_rate:
        return rate - dead_rate
    if rate < -dead_rate:
        return rate + dead_rate
    return 0.0
