"""Impact-velocity capture at the true contact onset (pure Python, no Exudyn).

The contact laws (:mod:`weftsim.joint.contact`) scale their damping by the impact velocity
v_imp = delta_dot at the instant delta crosses zero.  A fixed-step integrator sees the
crossing only between two accepted states: the last free one (delta0 <= 0, rate0) and
the first penetrated one (delta1 > 0, rate1).  Taking rate1 as v_imp makes an O(h)
error that caps the accuracy of peak forces near 1e-3 (measured on Exudyn 1.13); interpolating
delta and delta_dot linearly within the step to the zero crossing of delta makes it
O(h^2)::

    s = delta0 / (delta0 - delta1)            in [0, 1), fraction of the step
    v_imp = rate0 + s (rate1 - rate0)         floored at v_min by the caller
    t_onset = t0 + s (t1 - t0)

The same formula runs inside the force callback (trial states of the onset step, so
the force is a smooth function of the unknowns and Newton sees it) and in the
accepted-step bookkeeping (:class:`OnsetTracker`, which then holds the value until
separation); both take it from :mod:`weftsim.physics.hold`, the rules' one definition.

Held impact velocity rules (``ClearanceJoint.impact_velocity_rule``):

- ``"max_approach"`` (default): v_imp = the largest approach rate since the onset,
  floored at v_min.  In an isolated impact delta_dot only falls after the onset, so this
  is the onset value and every law keeps its restitution; in a driven lasting contact
  delta_dot can grow far beyond the onset value, and this rule keeps the damping term
  xi delta_dot / v_imp <= xi (damping force <= xi x elastic force).
- ``"onset"``: v_imp = the approach rate at the onset alone (Lankarani and Nikravesh
  1990; Flores and Ambrosio 2004), for comparison with published results.

An onset is a crossing of delta from <= 0 to > 0 with delta_dot > 0.  Within one step
the linear interpolation can give a non-positive rate at the crossing (a graze or a
turnaround inside the step: delta and delta_dot are then not both linear); the tracker
then takes the slope of the cubic Hermite interpolant at its first rising zero
(:func:`hermite_onset_rate`), and only if that fails too (no rising zero) the best positive
estimate, counting the onset as non-positive (:func:`positive_onset_velocity`).
"""

from __future__ import annotations

import math

import numpy as np

from weftsim.physics.hold import (  # noqa: F401 - the rules' one definition, re-exported here
    RESTING_RATE_FRACTION,
    callback_impact_velocity,
    damping_rate,
    onset_fraction,
    onset_velocity,
)
from weftsim.physics.joint import contact_geometry
from weftsim.physics.python import python_form
from weftsim.input.scene import IMPACT_VELOCITY_RULES

_GEOMETRY = python_form(contact_geometry)


def positive_onset_velocity(t0: float, delta0: float, rate0: float, t1: float, delta1: float,
                            rate1: float) -> tuple[float, bool]:
    """Approach rate at an onset inside the accepted step [t0, t1], never <= 0, m/s.

    Returns ``(v, interpolated)``: the linear in-step estimate when it is positive
    (``interpolated`` True), otherwise the larger of the end-of-step rate and the secant rate
    (delta1 - delta0) / (t1 - t0), which is > 0 whenever delta crossed from <= 0 to > 0.
    """
    v = onset_velocity(delta0, rate0, delta1, rate1)
    if v > 0.0:
        return v, True
    if t1 > t0:
        v = hermite_onset_rate(delta0, rate0, delta1, rate1, t1 - t0)
        if v > 0.0:
            return v, True
    secant = (delta1 - delta0) / (t1 - t0) if t1 > t0 else 0.0
    return max(rate1, secant), False


# Scan points and bisections of hermite_onset_rate: the first sign change of the cubic is bracketed
# to 1/64 of the step, then halved 60 times (to round-off of s).
_ONSET_SCAN = 64
_ONSET_BISECTIONS = 60


def hermite_onset_rate(delta0: float, rate0: float, delta1: float, rate1: float, h: float) -> float:
    """Slope, m/s, of the cubic Hermite interpolant of delta at its first zero inside the step.

    When the linear estimate fails (the rate falls below zero within the step: the journal met the
    wall and turned back before the step ended, a whole light impact inside one explicit step), the
    cubic through (delta0, rate0) and (delta1, rate1) still enters the wall from delta0 <= 0: its
    first rising zero s* in (0, 1] has p'(s*) >= 0, the approach rate there.  Returns 0 if the
    cubic has no rising zero (delta1 <= 0, or a tangency).
    """
    a, b, m0 = hermite_cubic(delta0, rate0, delta1, rate1, h)

    def p(s: float) -> float:
        return ((a * s + b) * s + m0) * s + delta0

    lo = 0.0
    for k in range(1, _ONSET_SCAN + 1):
        hi = k / _ONSET_SCAN
        if p(hi) > 0.0:
            break
        lo = hi
    else:
        return 0.0
    for _ in range(_ONSET_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if p(mid) > 0.0:
            hi = mid
        else:
            lo = mid
    return max(0.0, ((3.0 * a * hi + 2.0 * b) * hi + m0) / h)


def hermite_cubic(delta0: float, rate0: float, delta1: float, rate1: float, h: float) -> tuple[float, float, float]:
    """(a, b, m0) of the cubic Hermite interpolant of delta over a step of length h.

    p(s) = a s^3 + b s^2 + m0 s + delta0 through (delta0, rate0) at s = 0 and (delta1, rate1) at
    s = 1 (s = time / h, so p'(s) = h delta_dot); p'(s) = 3 a s^2 + 2 b s + m0.
    """
    m0, m1 = h * rate0, h * rate1
    return 2.0 * delta0 - 2.0 * delta1 + m0 + m1, -3.0 * delta0 + 3.0 * delta1 - 2.0 * m0 - m1, m0


def hermite_extremum(delta0: float, rate0: float, delta1: float, rate1: float, h: float) -> float:
    """Interior extremum of the cubic Hermite interpolant of delta over a step of length h, m.

    The cubic through (delta0, rate0) at s = 0 and (delta1, rate1) at s = 1 (s = time / h);
    returns its smallest interior stationary value if ``rate0 < 0`` (a dip between the ends),
    its largest otherwise (a bump), or the smaller / larger end value if the cubic has no
    interior stationary point.  Used to detect a separation and a re-contact (or a contact and
    a separation) inside one accepted step.
    """
    a, b, m0 = hermite_cubic(delta0, rate0, delta1, rate1, h)
    roots = []
    if abs(a) > 1e-300:
        disc = b * b - 3.0 * a * m0
        if disc >= 0.0:
            r = math.sqrt(disc)
            roots = [(-b - r) / (3.0 * a), (-b + r) / (3.0 * a)]
    elif abs(b) > 1e-300:
        roots = [-m0 / (2.0 * b)]
    values = [((a * s + b) * s + m0) * s + delta0 for s in roots if 0.0 < s < 1.0]
    if not values:
        return min(delta0, delta1) if rate0 < 0.0 else max(delta0, delta1)
    return min(values) if rate0 < 0.0 else max(values)


def penetration_state(ex: float, ey: float, vx: float, vy: float, clearance: float) -> tuple[float, float]:
    """delta = |e| - c and delta_dot = e_dot . e/|e| of an in-plane eccentricity (m, m/s).

    delta_dot is 0 when the journal is exactly centred (e = 0: no normal defined).  The kernel's
    :func:`weftsim.physics.joint.contact_geometry`, the clearance geometry written once, in its plain-Python
    form (:func:`weftsim.physics.python.python_form`).  (Until issue 32 this was its own form,
    (e_dot . e) / |e| against the kernel's e_dot . (e / |e|): the Exudyn engine's results moved at round-off
    when it took the kernel's.)
    """
    delta, rate, _, _ = _GEOMETRY(ex, ey, vx, vy, clearance)
    return delta, rate


class OnsetTracker:
    """Accepted-step bookkeeping of one clearance joint: contact state and held v_imp.

    Call :meth:`accept` once per accepted step with the penetration and its rate.
    The state the force callback needs, ``(v_held, delta0, rate0)``, is in
    :attr:`callback_state`; the callback holds ``v_held`` when ``delta0 > 0`` (last
    accepted state in contact) and interpolates the onset otherwise
    (:func:`callback_impact_velocity`).

    Parameters
    ----------
    clearance, min_impact_velocity : float
        c (m) and v_min (m/s).
    t0, delta0, rate0 : float
        Initial time (s), penetration (m, default -c: centred) and rate (m/s).
    rule : {"max_approach", "onset"}
        Held impact velocity rule (module docstring).

    Attributes
    ----------
    time, impact_velocity, in_contact : list of float
        One entry per accepted state (including the initial one): time (s), held impact
        velocity (m/s, 0 out of contact), contact flag (1.0 / 0.0).
    contact_events : int
        Number of contact onsets.
    nonpositive_onsets : int
        Onsets whose in-step interpolated approach rate was <= 0 (a graze or turnaround
        within the step); the held value is then :func:`positive_onset_velocity`.
    separations : int
        Accepted contact -> free transitions.
    missed_separations, missed_contacts : int
        Steps in contact at both ends whose Hermite interpolant of delta dips below 0
        (a separation and re-contact inside one step), and steps free at both ends whose
        interpolant rises above 0 (a whole contact inside one step).
    first_contact_time : float or None
        Onset time of the first contact, s, located within its step.
    """

    def __init__(self, clearance: float, min_impact_velocity: float, t0: float = 0.0,
                 delta0: float | None = None, rate0: float = 0.0, rule: str = "max_approach"):
        if rule not in IMPACT_VELOCITY_RULES:
            raise ValueError(f"`impact_velocity_rule` must be one of {IMPACT_VELOCITY_RULES}, got {rule!r}")
        self.clearance = clearance
        self.min_impact_velocity = min_impact_velocity
        self.max_approach = rule == "max_approach"
        self.t = t0
        self.delta = -clearance if delta0 is None else delta0
        self.rate = rate0
        self.held = min_impact_velocity
        if self.delta > 0.0 and self.max_approach:
            self.held = max(self.held, rate0)
        self.contact_events = 0
        self.nonpositive_onsets = 0
        self.separations = 0
        self.missed_separations = 0
        self.missed_contacts = 0
        self.first_contact_time: float | None = None
        self.time = [t0]
        self.in_contact = [1.0 if self.delta > 0.0 else 0.0]
        self.impact_velocity = [self.held if self.delta > 0.0 else 0.0]

    @property
    def callback_state(self) -> list[float]:
        """[v_held, delta0, rate0] of the last accepted state (the force callback's memory)."""
        return [self.held, self.delta, self.rate]

    def accept(self, t: float, delta: float, rate: float) -> None:
        """Record an accepted state (time t, penetration delta, rate delta_dot)."""
        was_in = self.delta > 0.0
        inside = delta > 0.0
        if inside and not was_in:
            v, interpolated = positive_onset_velocity(self.t, self.delta, self.rate, t, delta, rate)
            if not interpolated:
                self.nonpositive_onsets += 1
            if self.max_approach and rate > v:
                v = rate
            self.held = max(v, self.min_impact_velocity)
            self.contact_events += 1
            if self.first_contact_time is None:
                self.first_contact_time = self.t + onset_fraction(self.delta, delta) * (t - self.t)
        elif inside:
            if self.max_approach and rate > self.held:
                self.held = rate
            if self.rate < 0.0 < rate and hermite_extremum(self.delta, self.rate, delta, rate, t - self.t) <= 0.0:
                self.missed_separations += 1
        elif was_in:
            self.separations += 1
        elif self.rate > 0.0 > rate and hermite_extremum(self.delta, self.rate, delta, rate, t - self.t) > 0.0:
            self.missed_contacts += 1
        self.t, self.delta, self.rate = t, delta, rate
        self.time.append(t)
        self.in_contact.append(1.0 if inside else 0.0)
        self.impact_velocity.append(self.held if inside else 0.0)

    def counters(self) -> dict[str, int]:
        """Contact-history counts for ``solver_stats`` (read by the run's plausibility checks)."""
        return {
            "contact_events": self.contact_events,
            "nonpositive_onsets": self.nonpositive_onsets,
            "separations": self.separations,
            "missed_separations": self.missed_separations,
            "missed_contacts": self.missed_contacts,
        }

    def history(self) -> dict[str, np.ndarray]:
        """Per-accepted-state arrays: ``time``, ``impact_velocity``, ``in_contact``."""
        return {
            "time": np.asarray(self.time),
            "impact_velocity": np.asarray(self.impact_velocity),
            "in_contact": np.asarray(self.in_contact),
        }
