"""Wear of a clearance joint: the worn clearance and Archard's law on the contact arc (the one definition).

Geometry (small wear, docs/wear.md section 2)::

        bearing (rocker 3), worn by h_b(psi_b)      c(n) = c0 + h_b(psi_b) + h_j(psi_j)
          .-----------.                            psi_b = angle(n) - theta_OE   (bearing frame)
        /  journal     \\ <- h_b                    psi_j = angle(n) - theta_rod  (journal frame)
       |  P_b --e--> P_j|   n = e / |e|            delta = |e| - c(n)
        \\   (rod 4)    /

Both wear profiles are tables of depth (m) at ``n`` equally spaced angles over one turn of their
body's frame, read by periodic cubic Hermite interpolation (C1: :func:`periodic_value`).  They reach
the compiled right-hand side as a block appended to the kernel's parameter array (:func:`wear_block`): ``[n_b, n_j, h_b..., h_j...]``
after the ``start`` index the caller owns.  A round joint appends nothing, and
:func:`worn_clearance` then returns c0 itself (one size test: the round path is unchanged).

Archard (J. Appl. Phys. 24, 1953): a surface of hardness H loses the volume dV = (k / H) F_N ds
while the contact slides by ds = |v_T| dt.  The volume is spread over the contact arc with the
pressure of the elastic foundation the joint's laws derive from (Liu et al. 2007): the radial
overlap of journal and bearing at the angle phi from the contact line is (c + delta) cos phi - c,
so p(phi) ~ cos phi - cos phi0 on |phi| < phi0 = acos(c / (c + delta)) (:func:`deposit`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

WEAR_HEADER = 2  # n_b, n_j before the two tables


def wear_block(bearing_wear: ArrayLike, journal_wear: ArrayLike) -> np.ndarray:
    """``[n_b, n_j, h_b..., h_j...]`` (m) to append to a kernel parameter array; empty when both are empty."""
    bearing = np.asarray(bearing_wear, dtype=float)
    journal = np.asarray(journal_wear, dtype=float)
    if bearing.size == 0 and journal.size == 0:
        return np.zeros(0)
    return np.concatenate([[float(bearing.size), float(journal.size)], bearing, journal])


@njit(cache=True, error_model="numpy", inline="always")
def _cell(n, angle):
    """(i, f): the interval [i, i + 1) of a periodic table of n values holding ``angle`` and the fraction in it."""
    x = angle * (n / (2.0 * math.pi))
    x -= n * math.floor(x / n)
    i = int(x)
    if i >= n:
        i = n - 1
    return i, x - i


@njit(cache=True, error_model="numpy", inline="always")
def _knots(table, first, n, i):
    """Values at i - 1, i, i + 1, i + 2 (periodic)."""
    return (table[first + (i - 1) % n], table[first + i], table[first + (i + 1) % n],
            table[first + (i + 2) % n])


@njit(cache=True, error_model="numpy", inline="always")
def periodic_value(table: np.ndarray, first: int, n: int, angle: float) -> float:
    """Periodic cubic Hermite (Catmull-Rom) interpolation of ``table[first:first + n]`` at ``angle`` (rad).

    The table holds values at the angles 2 pi i / n; the slopes at the knots are the central
    differences, so the interpolant and its first derivative are continuous: the penetration rate
    delta_dot = e_dot . n - dc/dt of a worn joint then has no jumps for the integrator to resolve
    (with linear interpolation every cell boundary crossed in a sliding contact was a jump of dc/dt,
    and the separation search missed exits; measured on the reference loom).
    """
    i, f = _cell(n, angle)
    p0, p1, p2, p3 = _knots(table, first, n, i)
    m1 = 0.5 * (p2 - p0)
    m2 = 0.5 * (p3 - p1)
    f2 = f * f
    f3 = f2 * f
    return (2.0 * f3 - 3.0 * f2 + 1.0) * p1 + (f3 - 2.0 * f2 + f) * m1 + (-2.0 * f3 + 3.0 * f2) * p2 + (f3 - f2) * m2


@njit(cache=True, error_model="numpy", inline="always")
def periodic_slope(table: np.ndarray, first: int, n: int, angle: float) -> float:
    """d/d(angle) of :func:`periodic_value`, per rad."""
    i, f = _cell(n, angle)
    p0, p1, p2, p3 = _knots(table, first, n, i)
    m1 = 0.5 * (p2 - p0)
    m2 = 0.5 * (p3 - p1)
    f2 = f * f
    d = ((6.0 * f2 - 6.0 * f) * p1 + (3.0 * f2 - 4.0 * f + 1.0) * m1 + (-6.0 * f2 + 6.0 * f) * p2
         + (3.0 * f2 - 2.0 * f) * m2)
    return d * (n / (2.0 * math.pi))


@njit(cache=True, error_model="numpy", inline="always")
def worn_clearance(prm: np.ndarray, start: int, c0: float, angle_b: float, angle_j: float, rate_b: float,
                   rate_j: float) -> tuple[float, float]:
    """(c, dc/dt): c = c0 + h_b(angle_b) + h_j(angle_j), m, from the wear block at ``prm[start:]``.

    ``angle_b``, ``angle_j``: direction of the eccentricity in the bearing's and the journal's frame,
    rad; ``rate_b``, ``rate_j``: their rates, rad/s.  (c0, 0) if there is no block.  dc/dt enters the
    penetration rate, delta_dot = e_dot . n - dc/dt, so that a contact which starts because the
    journal slides onto an unworn part of the wall has the approach rate it really has.
    """
    if len(prm) <= start:  # len: a list on the Exudyn engine's plain-Python callback route
        return c0, 0.0
    n_b = int(prm[start])
    n_j = int(prm[start + 1])
    c = c0
    rate = 0.0
    if n_b > 0:
        c += periodic_value(prm, start + WEAR_HEADER, n_b, angle_b)
        rate += periodic_slope(prm, start + WEAR_HEADER, n_b, angle_b) * rate_b
    if n_j > 0:
        c += periodic_value(prm, start + WEAR_HEADER + n_b, n_j, angle_j)
        rate += periodic_slope(prm, start + WEAR_HEADER + n_b, n_j, angle_j) * rate_j
    return c, rate


@njit(cache=True, error_model="numpy", inline="always")
def block_end(prm: np.ndarray, start: int) -> int:
    """Index just after the wear block at ``prm[start:]`` (``start`` itself when there is none).

    The blocks of several joints follow each other (E's, then F's: :func:`weftsim.model.dynamics.pack_parameters`);
    a joint that does not wear but precedes one that does has the empty block ``[0, 0]``.
    """
    if len(prm) <= start:
        return start
    return start + WEAR_HEADER + int(prm[start]) + int(prm[start + 1])


@njit(cache=True, error_model="numpy", inline="always")
def clearance_along(prm: np.ndarray, start: int, c0: float, ecc_y: float, ecc_z: float, v_y: float, v_z: float,
                    frame_b: float, rate_b: float, frame_j: float, rate_j: float) -> tuple[float, float]:
    """(c, dc/dt) of a joint along its eccentricity e = (ecc_y, ecc_z) with rate (v_y, v_z), m and m/s.

    ``frame_b``, ``frame_j``: angles of the bearing's and the journal's body frames (rad), ``rate_b``,
    ``rate_j`` their rates (rad/s); the direction of e turns at (e x e_dot) / |e|^2.  The contact
    direction in each frame is the direction of e less the frame's angle (:func:`worn_clearance`,
    block at ``prm[start:]``); (c0, 0) when there is no block.
    """
    if len(prm) <= start:  # len: as in worn_clearance
        return c0, 0.0
    direction = math.atan2(ecc_z, ecc_y)
    length2 = ecc_y * ecc_y + ecc_z * ecc_z
    turn = (ecc_y * v_z - ecc_z * v_y) / length2 if length2 > 0.0 else 0.0
    return worn_clearance(prm, start, c0, direction - frame_b, direction - frame_j, turn - rate_b, turn - rate_j)


@njit(cache=True, error_model="numpy", inline="always")
def contact_half_angle(clearance: float, delta: float) -> float:
    """phi0 = acos(c / (c + delta)): half the arc over which journal and bearing overlap, rad (0 if delta <= 0)."""
    if delta <= 0.0:
        return 0.0
    return math.acos(clearance / (clearance + delta))


@njit(cache=True, error_model="numpy", inline="always")
def _pressure_share(phi, cos0, norm):
    """Share of the contact force on [-phi0, phi]: (sin phi - phi cos phi0) / (2 (sin phi0 - phi0 cos phi0)) + const."""
    return (math.sin(phi) - phi * cos0) / norm


@njit(cache=True, error_model="numpy")
def deposit(profile: np.ndarray, angle: float, half_angle: float, depth: float) -> None:
    """Add the depth ``depth`` (m, if it all fell on one cell) to ``profile`` spread over the contact arc.

    ``profile`` (n,): depths at angles 2 pi i / n, cell i covering +-pi/n around its angle; the arc is
    ``angle`` +- ``half_angle`` with the elastic-foundation pressure p ~ cos phi - cos phi0 (module
    docstring).  Each cell receives ``depth`` times its share of the force, the shares summing to 1,
    so sum(profile) grows by ``depth`` to round-off (conservation of the Archard volume).  An arc
    narrower than 1e-6 rad falls on the one cell holding ``angle``.
    """
    n = profile.size
    width = 2.0 * math.pi / n
    if half_angle < 1e-6:
        i = int(math.floor(angle / width + 0.5)) % n
        profile[i] += depth
        return
    cos0 = math.cos(half_angle)
    norm = 2.0 * (math.sin(half_angle) - half_angle * cos0)
    if not norm > 0.0:  # below round-off of the closed form: one cell
        i = int(math.floor(angle / width + 0.5)) % n
        profile[i] += depth
        return
    first = int(math.floor((angle - half_angle) / width + 0.5))
    last = int(math.floor((angle + half_angle) / width + 0.5))
    low = -half_angle
    below = _pressure_share(low, cos0, norm)
    total = _pressure_share(half_angle, cos0, norm) - below
    for k in range(first, last + 1):
        high = min((k + 0.5) * width - angle, half_angle)
        above = _pressure_share(high, cos0, norm)
        profile[k % n] += depth * ((above - below) / total)
        below = above
