"""Impact-velocity capture at the true contact onset (pure Python, no Exudyn).

The contact laws (:mod:`weftsim.contact`) scale their damping by the impact velocity
v_imp = delta_dot at the instant delta crosses zero.  A fixed-step integrator sees the
crossing only between two accepted states: the last free one (delta0 <= 0, rate0) and
the first penetrated one (delta1 > 0, rate1).  Taking rate1 as v_imp makes an O(h)
error that caps the accuracy of peak forces near 1e-3 (EXUDYN.md); interpolating
delta and delta_dot linearly within the step to the zero crossing of delta makes it
O(h^2)::

    s = delta0 / (delta0 - delta1)            in [0, 1), fraction of the step
    v_imp = rate0 + s (rate1 - rate0)         floored at v_min by the caller
    t_onset = t0 + s (t1 - t0)

The same formula runs inside the force callback (trial states of the onset step, so
the force is a smooth function of the unknowns and Newton sees it) and in the
accepted-step bookkeeping (:class:`OnsetTracker`, which then holds the value until
separation).
"""

from __future__ import annotations

import math

import numpy as np


def onset_fraction(delta0: float, delta1: float) -> float:
    """Fraction s in [0, 1] of the step at which delta crosses 0 (linear in delta).

    Parameters
    ----------
    delta0, delta1 : float
        Penetration at the start (<= 0) and end (> 0) of the step, m.
    """
    span = delta0 - delta1
    if span >= 0.0:  # no crossing from below: the end of the step is the best estimate
        return 1.0
    s = delta0 / span
    return 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)


def onset_velocity(delta0: float, rate0: float, delta1: float, rate1: float) -> float:
    """Penetration rate at the zero crossing of delta, linear in-step interpolation, m/s."""
    s = onset_fraction(delta0, delta1)
    return rate0 + s * (rate1 - rate0)


def penetration_state(ex: float, ey: float, vx: float, vy: float, clearance: float):
    """delta = |e| - c and delta_dot = e_dot . e/|e| of an in-plane eccentricity (m, m/s).

    delta_dot is 0 when the journal is exactly centred (e = 0: no normal defined).
    """
    length = math.sqrt(ex * ex + ey * ey)
    if length <= 0.0:
        return -clearance, 0.0
    return length - clearance, (vx * ex + vy * ey) / length


class OnsetTracker:
    """Accepted-step bookkeeping of one clearance joint: contact state and held v_imp.

    Call :meth:`accept` once per accepted step with the eccentricity and its rate.
    The state the force callback needs, ``(v_held, delta0, rate0)``, is in
    :attr:`callback_state`; the callback holds ``v_held`` when ``delta0 > 0`` (last
    accepted state in contact) and interpolates the onset otherwise.

    Attributes
    ----------
    time, impact_velocity, in_contact : list of float
        One entry per accepted state (including the initial one): time (s), held impact
        velocity (m/s, 0 out of contact), contact flag (1.0 / 0.0).
    contact_events : int
        Number of contact onsets.
    first_contact_time : float or None
        Onset time of the first contact, s, located within its step.
    """

    def __init__(self, clearance: float, min_impact_velocity: float, t0: float = 0.0,
                 delta0: float | None = None, rate0: float = 0.0):
        self.clearance = clearance
        self.min_impact_velocity = min_impact_velocity
        self.t = t0
        self.delta = -clearance if delta0 is None else delta0
        self.rate = rate0
        self.held = min_impact_velocity
        self.contact_events = 0
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
        if delta > 0.0 and self.delta <= 0.0:
            s = onset_fraction(self.delta, delta)
            self.held = max(self.rate + s * (rate - self.rate), self.min_impact_velocity)
            self.contact_events += 1
            if self.first_contact_time is None:
                self.first_contact_time = self.t + s * (t - self.t)
        self.t, self.delta, self.rate = t, delta, rate
        inside = delta > 0.0
        self.time.append(t)
        self.in_contact.append(1.0 if inside else 0.0)
        self.impact_velocity.append(self.held if inside else 0.0)

    def history(self) -> dict[str, np.ndarray]:
        """Per-accepted-state arrays: ``time``, ``impact_velocity``, ``in_contact``."""
        return {
            "time": np.asarray(self.time),
            "impact_velocity": np.asarray(self.impact_velocity),
            "in_contact": np.asarray(self.in_contact),
        }
