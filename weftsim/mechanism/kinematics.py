"""Ideal-joint kinematics of the weft insertion linkage (docs/physics.md section 1).

Pure numpy, vectorised over the crank angle theta.  Every quantity comes with its
first and second derivatives w.r.t. theta (prefixes ``d_`` and ``dd_``), computed
analytically; at constant crank speed omega a velocity is ``omega * d_x`` and an
acceleration ``omega**2 * dd_x``.

Planar four-bar O-E-F-G in the plane x = 0, coordinates (Y, Z) = (y, z)::

                 E                         theta_OE = theta_OE0 + phi  (rocker 3, arm OE)
                / \\ rod EF, theta_EF = angle of F - E
               /   \\
              /     F                      theta_FG = angle of F - G (sector 5)
             /     /
            O-----G-----> Y                G = (L_OG, 0)

The spherical 4R part (rocker angle, coupler frame and angular velocity, the
general input-output law) lives in :mod:`weftsim.mechanism.spherical` and is re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from weftsim.input.params import Geometry, Inertia
from weftsim.mechanism.spherical import (
    coupler_angular_velocity,
    coupler_frame,
    crank_axis,
    rocker_angle,
    rocker_axis,
    spherical_4r,
    spherical_4r_assembles,
)

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = [
    "rocker_angle",
    "spherical_4r",
    "spherical_4r_assembles",
    "crank_axis",
    "rocker_axis",
    "coupler_frame",
    "coupler_angular_velocity",
    "FourBarState",
    "fourbar",
    "fourbar_assembly_argument",
    "LinkageState",
    "linkage_state",
    "rapier_motion",
    "assembly_failure_angle",
    "assembly_problem",
]


def _unit(angle):
    """u(a) = (cos a, sin a), shape (..., 2)."""
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def _normal(angle):
    """n(a) = du/da = (-sin a, cos a), shape (..., 2)."""
    return np.stack([-np.sin(angle), np.cos(angle)], axis=-1)


def _cross(p, q):
    """Planar cross product p_Y q_Z - p_Z q_Y."""
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def _point_on_arm(length, angle, d_angle, dd_angle):
    """Point length * u(angle) of an arm turning about its fixed pivot, with derivatives.

    p = l u,  p' = l a' n,  p'' = l (a'' n - a'^2 u).
    """
    u, n = _unit(angle), _normal(angle)
    d1, d2 = np.asarray(d_angle)[..., None], np.asarray(dd_angle)[..., None]
    return length * u, length * d1 * n, length * (d2 * n - d1 * d1 * u)


def fourbar_assembly_argument(theta_oe: ArrayLike, geometry: Geometry) -> np.ndarray:
    """Argument of the acos in the assembly formula; the four-bar closes iff it is in [-1, 1].

    With a = L_OG - E_Y, b' = -E_Z, D = hypot(a, b'):
    (L_EF^2 - D^2 - L_FG^2) / (2 L_FG D).
    """
    theta_oe = np.asarray(theta_oe, dtype=float)
    g = geometry
    a = g.l_og - g.l_oe * np.cos(theta_oe)
    bp = -g.l_oe * np.sin(theta_oe)
    dist = np.hypot(a, bp)
    return (g.l_ef**2 - dist**2 - g.l_fg**2) / (2.0 * g.l_fg * dist)


@dataclass(frozen=True)
class FourBarState:
    """Angles of the planar four-bar O-E-F-G and their derivatives w.r.t. theta_OE.

    theta_ef is the angle of the rod vector F - E (from E to F), measured from +Y
    towards +Z; theta_fg the angle of F - G.  All in rad (derivatives rad/rad,
    rad/rad^2).  NaN where the four-bar cannot be assembled.
    """

    theta_oe: np.ndarray
    theta_fg: np.ndarray
    d_theta_fg: np.ndarray
    dd_theta_fg: np.ndarray
    theta_ef: np.ndarray
    d_theta_ef: np.ndarray
    dd_theta_ef: np.ndarray


def fourbar(theta_oe: ArrayLike, geometry: Geometry) -> FourBarState:
    """Solve the planar four-bar for the rocker-arm angle theta_OE.

    Position (docs/physics.md section 1, branch = ``geometry.fourbar_branch``, +1 = "+")::

        theta_FG = atan2(b', a) + branch * acos((L_EF^2 - D^2 - L_FG^2) / (2 L_FG D))
        F = G + L_FG u(theta_FG),  theta_EF = atan2(F_Z - E_Z, F_Y - E_Y)

    Derivatives from the loop closure L_OE u(q) + L_EF u(ef) - L_OG e_Y - L_FG u(fg) = 0,
    q = theta_OE, differentiated once and twice::

        L_EF n(ef) ef' - L_FG n(fg) fg' = -L_OE n(q)
        L_EF n(ef) ef'' - L_FG n(fg) fg'' = L_OE u(q) + L_EF ef'^2 u(ef) - L_FG fg'^2 u(fg)

    each solved by Cramer's rule; the determinant L_EF L_FG sin(fg - ef) vanishes
    only at a dead point (transmission angle 0 or 180 deg).
    """
    theta_oe = np.asarray(theta_oe, dtype=float)
    g = geometry
    if g.fourbar_branch not in (1, -1):
        raise ValueError(f"`fourbar_branch` must be +1 or -1, got {g.fourbar_branch!r}")
    point_e = g.l_oe * _unit(theta_oe)
    a = g.l_og - point_e[..., 0]
    bp = -point_e[..., 1]
    arg = fourbar_assembly_argument(theta_oe, g)
    with np.errstate(invalid="ignore"):
        arg = np.where(np.abs(arg) <= 1.0, arg, np.nan)
        fg = np.arctan2(bp, a) + g.fourbar_branch * np.arccos(arg)
    rod = np.array([g.l_og, 0.0]) + g.l_fg * _unit(fg) - point_e
    ef = np.arctan2(rod[..., 1], rod[..., 0])

    col_ef = g.l_ef * _normal(ef)
    col_fg = -g.l_fg * _normal(fg)
    det = _cross(col_ef, col_fg)
    rhs1 = -g.l_oe * _normal(theta_oe)
    d_ef = _cross(rhs1, col_fg) / det
    d_fg = _cross(col_ef, rhs1) / det
    rhs2 = (
        g.l_oe * _unit(theta_oe)
        + g.l_ef * (d_ef * d_ef)[..., None] * _unit(ef)
        - g.l_fg * (d_fg * d_fg)[..., None] * _unit(fg)
    )
    dd_ef = _cross(rhs2, col_fg) / det
    dd_fg = _cross(col_ef, rhs2) / det
    return FourBarState(theta_oe, fg, d_fg, dd_fg, ef, d_ef, dd_ef)


@dataclass(frozen=True)
class LinkageState:
    """Ideal-joint configuration of the whole linkage at crank angles theta.

    Every field ``x`` has companions ``d_x`` and ``dd_x``: first and second
    derivatives w.r.t. the crank angle theta.  Angles in rad, lengths in m,
    points of shape (..., 2) in four-bar plane coordinates (Y, Z).

    Fields: phi (rocker angle about +x); theta_oe (arm OE); theta_fg (sector arm,
    angle of F - G); theta_ef (rod, angle of F - E); rapier_displacement
    s = (d5 d7/d6)(theta_FG - theta_FG(0)), positive into the shed; gear67_angle
    = -(d5/d6)(theta_FG - theta_FG(0)), so s = -d7 * gear67_angle; point_e,
    point_f; rod_com (mid EF); rocker_com (on OE at ``rocker_com_distance`` from O).
    transmission_angle (no derivatives): interior angle at F between the rod
    F->E and the sector arm F->G, in [0, pi].
    """

    theta: np.ndarray
    phi: np.ndarray
    d_phi: np.ndarray
    dd_phi: np.ndarray
    theta_oe: np.ndarray
    d_theta_oe: np.ndarray
    dd_theta_oe: np.ndarray
    theta_fg: np.ndarray
    d_theta_fg: np.ndarray
    dd_theta_fg: np.ndarray
    theta_ef: np.ndarray
    d_theta_ef: np.ndarray
    dd_theta_ef: np.ndarray
    rapier_displacement: np.ndarray
    d_rapier_displacement: np.ndarray
    dd_rapier_displacement: np.ndarray
    gear67_angle: np.ndarray
    d_gear67_angle: np.ndarray
    dd_gear67_angle: np.ndarray
    point_e: np.ndarray
    d_point_e: np.ndarray
    dd_point_e: np.ndarray
    point_f: np.ndarray
    d_point_f: np.ndarray
    dd_point_f: np.ndarray
    rod_com: np.ndarray
    d_rod_com: np.ndarray
    dd_rod_com: np.ndarray
    rocker_com: np.ndarray
    d_rocker_com: np.ndarray
    dd_rocker_com: np.ndarray
    transmission_angle: np.ndarray


def linkage_state(theta: ArrayLike, geometry: Geometry, rocker_com_distance: float | None = None) -> LinkageState:
    """Positions, velocities and accelerations (per unit crank speed) of members 3-8.

    Chain rule through the rocker: theta_OE = theta_OE0 + phi(theta), so for any
    four-bar angle x(theta_OE): x' = x_q phi', x'' = x_qq phi'^2 + x_q phi''.

    Parameters
    ----------
    theta : array_like
        Crank angle, rad.
    geometry : Geometry
    rocker_com_distance : float, optional
        Distance of the rocker's centre of mass from O along OE, m.  Defaults to
        ``Inertia().rocker_com`` (0.040 m, docs/physics.md section 1 reference mechanism).

    Returns
    -------
    LinkageState
        NaN entries where the four-bar cannot be assembled.
    """
    g = geometry
    if rocker_com_distance is None:
        rocker_com_distance = Inertia().rocker_com
    theta = np.asarray(theta, dtype=float)
    phi, d_phi, dd_phi = rocker_angle(theta, g.crank_inclination)
    q = g.rocker_arm_angle + phi
    fb = fourbar(q, g)
    fg0 = fourbar(g.rocker_arm_angle + rocker_angle(0.0, g.crank_inclination)[0], g).theta_fg

    def chain(x_q, x_qq):
        return x_q * d_phi, x_qq * d_phi * d_phi + x_q * dd_phi

    d_fg, dd_fg = chain(fb.d_theta_fg, fb.dd_theta_fg)
    d_ef, dd_ef = chain(fb.d_theta_ef, fb.dd_theta_ef)
    k = g.rapier_ratio
    p = g.pinion_ratio
    # atan2 may put theta_FG on either side of its 2 pi cut; a rocker swings < pi,
    # so the wrapped difference is the true turn of the sector since theta = 0.
    turn = np.angle(np.exp(1j * (fb.theta_fg - fg0)))
    e, d_e, dd_e = _point_on_arm(g.l_oe, q, d_phi, dd_phi)
    r, d_r, dd_r = _point_on_arm(rocker_com_distance, q, d_phi, dd_phi)
    f, d_f, dd_f = _point_on_arm(g.l_fg, fb.theta_fg, d_fg, dd_fg)
    f = f + np.array([g.l_og, 0.0])
    with np.errstate(invalid="ignore"):
        transmission = np.arccos(np.cos(fb.theta_ef - fb.theta_fg))
    return LinkageState(
        theta=theta,
        phi=phi, d_phi=d_phi, dd_phi=dd_phi,
        theta_oe=q, d_theta_oe=d_phi, dd_theta_oe=dd_phi,
        theta_fg=fb.theta_fg, d_theta_fg=d_fg, dd_theta_fg=dd_fg,
        theta_ef=fb.theta_ef, d_theta_ef=d_ef, dd_theta_ef=dd_ef,
        rapier_displacement=k * turn,
        d_rapier_displacement=k * d_fg, dd_rapier_displacement=k * dd_fg,
        gear67_angle=-p * turn, d_gear67_angle=-p * d_fg, dd_gear67_angle=-p * dd_fg,
        point_e=e, d_point_e=d_e, dd_point_e=dd_e,
        point_f=f, d_point_f=d_f, dd_point_f=dd_f,
        rod_com=0.5 * (e + f), d_rod_com=0.5 * (d_e + d_f), dd_rod_com=0.5 * (dd_e + dd_f),
        rocker_com=r, d_rocker_com=d_r, dd_rocker_com=dd_r,
        transmission_angle=transmission,
    )  # fmt: skip


def rapier_stroke(geometry: Geometry, samples: int = 1441) -> float:
    """The rapier's stroke: the largest s of a revolution (s = 0 outermost), m, on ``samples`` crank angles."""
    theta = np.linspace(0.0, 2.0 * np.pi, samples)
    return float(np.max(linkage_state(theta, geometry).rapier_displacement))


def rapier_motion(theta: ArrayLike, omega: float, geometry: Geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rapier displacement, velocity and acceleration at constant crank speed.

    s = (d5 d7/d6)(theta_FG - theta_FG(0)),  v = omega s',  a = omega^2 s''.

    Parameters
    ----------
    theta : array_like
        Crank angle, rad.
    omega : float
        Constant crank speed, rad/s.

    Returns
    -------
    s, v, a : ndarray
        m, m/s, m/s^2; positive into the shed.
    """
    st = linkage_state(theta, geometry)
    return (
        st.rapier_displacement,
        omega * st.d_rapier_displacement,
        omega**2 * st.dd_rapier_displacement,
    )


def _assembles(theta, geometry: Geometry):
    phi, _, _ = rocker_angle(theta, geometry.crank_inclination)
    return np.abs(fourbar_assembly_argument(geometry.rocker_arm_angle + phi, geometry)) <= 1.0


def assembly_failure_angle(geometry: Geometry, samples: int = 3601) -> float | None:
    """First crank angle in [0, 2 pi) at which the four-bar cannot be assembled.

    The acos argument of :func:`fourbar_assembly_argument` is sampled on ``samples``
    equally spaced crank angles over [0, 2 pi]; the first sample outside [-1, 1]
    is refined by bisection against the previous one (to ~1e-12 rad).  A failure
    window narrower than the grid spacing 2 pi / (samples - 1) can be missed.
    Never raises.

    Returns
    -------
    float or None
        Crank angle (rad) of the first failure, 0.0 if the four-bar does not close
        at theta = 0, None if it closes over the whole revolution.
    """
    grid = np.linspace(0.0, 2.0 * np.pi, max(int(samples), 2))
    ok = _assembles(grid, geometry)
    if ok.all():
        return None
    i = int(np.argmin(ok))
    if i == 0:
        return 0.0
    lo, hi = grid[i - 1], grid[i]
    for _ in range(60):
        if hi - lo <= 1e-13:
            break
        mid = 0.5 * (lo + hi)
        if _assembles(mid, geometry):
            lo = mid
        else:
            hi = mid
    return float(hi) if hi < 2.0 * np.pi else None


def assembly_problem(geometry: Geometry, samples: int = 3601) -> str | None:
    """Message for the scene validator if the linkage cannot run a revolution, else None.

    Checks the crank inclination (the loom's spherical 4R needs 0 < beta < 90 deg)
    and the planar four-bar over a full revolution.  Never raises.
    """
    beta = geometry.crank_inclination
    if not 0.0 < beta < 0.5 * np.pi:
        return f"`crank_inclination` must be in (0, 90) deg, got {np.degrees(beta):.6g} deg"
    angle = assembly_failure_angle(geometry, samples)
    if angle is None:
        return None
    return (
        f"the four-bar O-E-F-G cannot be assembled at crank angle {np.degrees(angle):.4f} deg "
        f"(l_oe={geometry.l_oe}, l_ef={geometry.l_ef}, l_fg={geometry.l_fg}, "
        f"l_og={geometry.l_og} m): check the link lengths"
    )
