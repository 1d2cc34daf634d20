"""The updates of a wear prediction: each wearing joint's worn profiles and rates, and their advance over
the N revolutions an update extrapolates (the data :mod:`.extrapolate` produces and :mod:`.store` writes).

Every loose joint wears (:func:`wearing_joints`: E, F, or E and F); an :class:`Update` carries the first
wearing joint's profiles in its own fields and F's in :attr:`Update.second` when both wear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Sequence

    from weftsim.input.params import Scene

SECONDS_PER_HOUR = 3600.0


@dataclass(frozen=True)
class JointWear:
    """One joint's part of an :class:`Update`: its profiles (m), their rates (m/rev) and its volume rate (m^3/rev)."""

    joint: str
    bearing: np.ndarray
    journal: np.ndarray
    rate_bearing: np.ndarray
    rate_journal: np.ndarray
    volume_rate: float


@dataclass(frozen=True)
class Update:
    """One geometry update: the geometry simulated, the response on it, the wear it predicts.

    ``bearing``, ``journal``: worn depth profiles (m) of joint ``joint`` (the first wearing joint:
    E, or F when E is ideal) *at the start* of the update (the geometry that was simulated);
    ``revolutions`` (crank revolutions before it, float) and ``hours``; ``step_revolutions``: N,
    the revolutions it extrapolates over; ``rate_bearing``, ``rate_journal``: worn depth per
    revolution (m); ``volume_rate``: that joint's bearing + journal wear volume per revolution
    (m^3); ``response``: statistics of the steady revolutions; ``second``: joint F's part when E and
    F both wear (None otherwise).  :meth:`worn` gives every joint's part alike.
    """

    hours: float
    revolutions: float
    bearing: np.ndarray
    journal: np.ndarray
    step_revolutions: float
    rate_bearing: np.ndarray
    rate_journal: np.ndarray
    volume_rate: float
    response: dict
    joint: str = "e"
    second: JointWear | None = None

    def worn(self) -> tuple[JointWear, ...]:
        """Each wearing joint's part, E before F."""
        first = JointWear(self.joint, self.bearing, self.journal, self.rate_bearing, self.rate_journal,
                          self.volume_rate)
        return (first,) if self.second is None else (first, self.second)

    def part(self, joint: str) -> JointWear:
        """The part of ``joint`` ("e" or "f")."""
        for part in self.worn():
            if part.joint == joint:
                return part
        raise KeyError(f"joint {joint!r} does not wear in this prediction")

    @property
    def total_volume_rate(self) -> float:
        """Wear volume of every joint per revolution, m^3."""
        return sum(p.volume_rate for p in self.worn())


def wearing_joints(scene: Scene) -> tuple[str, ...]:
    """The joints that wear: every loose one (``"e"``, ``"f"``), E first."""
    return scene.loose_joints


def joint_of(scene: Scene, joint: str):
    """The :class:`~weftsim.input.params.ClearanceJoint` of ``joint`` ("e" or "f")."""
    return scene.joint if joint == "e" else scene.joint_f


def _with_parts(update: Update, parts: Sequence[JointWear], **changes) -> Update:
    """``update`` with its joints' parts replaced by ``parts`` (same joints, same order) and ``changes``."""
    first = parts[0]
    return replace(update, bearing=first.bearing, journal=first.journal, rate_bearing=first.rate_bearing,
                   rate_journal=first.rate_journal, volume_rate=first.volume_rate, joint=first.joint,
                   second=parts[1] if len(parts) > 1 else None, **changes)


def advance_update(update: Update, scene: Scene) -> Update:
    """``update`` after its N revolutions: hours, revolutions and every joint's profiles advanced (rates kept)."""
    hours, revolutions = advance(update, scene)[:2]
    n = update.step_revolutions
    parts = [replace(p, bearing=p.bearing + n * p.rate_bearing, journal=p.journal + n * p.rate_journal)
             for p in update.worn()]
    return _with_parts(update, parts, hours=hours, revolutions=revolutions)


def effective_clearance(c0: float, bearing: np.ndarray, journal: np.ndarray) -> float:
    """c0 + max h_b + max h_j, m: the clearance where the two worn spots face each other (the load line)."""
    return c0 + float(np.max(bearing, initial=0.0)) + float(np.max(journal, initial=0.0))


def advance(update: Update, scene: Scene) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(hours, revolutions, bearing, journal) after the update's N revolutions (the first joint's profiles;
    :func:`advance_update` advances every joint)."""
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    n = update.step_revolutions
    return (update.hours + n / revs_per_hour, update.revolutions + n,
            update.bearing + n * update.rate_bearing, update.journal + n * update.rate_journal)


def limit_hours(updates: Sequence[Update], c0: float, limit: float, joint: str | None = None) -> float | None:
    """Operating hours at which c_eff of ``joint`` (default: the first wearing joint's profiles; ``c0`` its
    initial clearance) first reaches ``limit`` (m), linear between updates; None if never."""
    pairs = [(u.bearing, u.journal) if joint is None else (u.part(joint).bearing, u.part(joint).journal)
             for u in updates]
    c = [effective_clearance(c0, b, j) for b, j in pairs]
    h = [u.hours for u in updates]
    for i in range(1, len(c)):
        if c[i] >= limit > c[i - 1]:
            return h[i - 1] + (h[i] - h[i - 1]) * (limit - c[i - 1]) / (c[i] - c[i - 1])
    if c and c[0] >= limit:
        return 0.0
    return None
