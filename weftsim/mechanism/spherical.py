"""Spherical 4R part of the weft insertion linkage (members 0-3, docs/physics.md section 1).

Pure numpy kernels, vectorised over the crank angle.  Every function returns the
quantity together with its first and second derivative with respect to the input
angle, computed analytically (closed form or implicit differentiation of the
closure equation), so that at constant crank speed omega a velocity is
``omega * d`` and an acceleration ``omega**2 * dd``.

Frames (docs/physics.md section 1)::

            z = axis A (crank)
            |    b(theta): crank axis B, arc A-B = beta
            |   /
            |  /      c(phi) = (0, cos phi, sin phi): rocker axis C
            | /
            O--------- y (towards G)
           /
          x = axis D (rocker, normal of the four-bar plane)

The public names are re-exported by :mod:`weftsim.mechanism.kinematics`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

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
]


def rocker_angle(theta: ArrayLike, beta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rocker angle of the loom's spherical 4R and its derivatives.

    With arcs B-C = C-D = A-D = 90 deg the closure b . c = 0 gives

        phi = -atan(u),  u = tan(beta) cos(theta)
        phi'  = tan(beta) sin(theta) / (1 + u^2)
        phi'' = u / (1 + u^2) + 2 u u'^2 / (1 + u^2)^2,   u' = -tan(beta) sin(theta)

    Parameters
    ----------
    theta : array_like
        Crank angle, rad.
    beta : float
        Crank inclination (arc A-B), rad, in (0, pi/2).

    Returns
    -------
    phi, dphi, ddphi : ndarray
        phi (rad) and its first and second derivatives w.r.t. theta (rad/rad, rad/rad^2).
    """
    theta = np.asarray(theta, dtype=float)
    t = np.tan(beta)
    u = t * np.cos(theta)
    du = -t * np.sin(theta)
    q = 1.0 + u * u
    phi = -np.arctan(u)
    dphi = -du / q
    ddphi = u / q + 2.0 * u * du * du / (q * q)
    return phi, dphi, ddphi


def _spherical_4r_coefficients(theta_in, alpha1, alpha2, alpha3, alpha4):
    """A, B, C of the input-output law and their first two theta'-derivatives."""
    th = np.asarray(theta_in, dtype=float)
    s1, c1 = np.sin(alpha1), np.cos(alpha1)
    s2, c2 = np.sin(alpha2), np.cos(alpha2)
    s4, c4 = np.sin(alpha4), np.cos(alpha4)
    ct, st = np.cos(th), np.sin(th)
    a = s4 * (s2 * ct * c1 - c2 * s1)
    da = -s4 * s2 * st * c1
    dda = -s4 * s2 * ct * c1
    b = s4 * s2 * st
    db = s4 * s2 * ct
    ddb = -b
    c = np.cos(alpha3) - s2 * ct * s1 * c4 - c2 * c1 * c4
    dc = s2 * st * s1 * c4
    ddc = s2 * ct * s1 * c4
    return (a, da, dda), (b, db, ddb), (c, dc, ddc)


def spherical_4r_assembles(theta_in: ArrayLike, alpha1: ArrayLike, alpha2: ArrayLike, alpha3: ArrayLike,
                           alpha4: ArrayLike) -> np.ndarray:
    """True where the general spherical 4R can be assembled, C^2 <= A^2 + B^2.

    Same arguments as :func:`spherical_4r`; returns a boolean array of the shape of
    ``theta_in``.  Never raises.
    """
    (a, _, _), (b, _, _), (c, _, _) = _spherical_4r_coefficients(
        theta_in, alpha1, alpha2, alpha3, alpha4
    )
    return c * c <= a * a + b * b


def spherical_4r(theta_in: ArrayLike, alpha1: ArrayLike, alpha2: ArrayLike, alpha3: ArrayLike, alpha4: ArrayLike,
                 branch: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """General spherical 4R input-output law (docs/physics.md section 1) with derivatives.

    In the mechanism's own frame (a = z, d = R_y(alpha1) z,
    b = (sin a2 cos th', sin a2 sin th', cos a2),
    c = R_y(alpha1) (sin a4 cos ph', sin a4 sin ph', cos a4)) the closure
    b . c = cos alpha3 reads

        F(ph', th') = A cos ph' + B sin ph' - C = 0
        A = sin a4 (sin a2 cos th' cos a1 - cos a2 sin a1),  B = sin a4 sin a2 sin th'
        C = cos a3 - sin a2 cos th' sin a1 cos a4 - cos a2 cos a1 cos a4

    with the solutions ph' = atan2(B, A) + branch * acos(C / sqrt(A^2 + B^2)).
    The derivatives follow from differentiating F = 0 implicitly:

        ph'_1 = -F_th / F_ph
        ph'_2 = -(F_thth + 2 F_thph ph'_1 + F_phph ph'_1^2) / F_ph

    where F_ph = -A sin ph' + B cos ph' = -branch sqrt(A^2 + B^2 - C^2).

    Parameters
    ----------
    theta_in : array_like
        Input angle th' of link 1 about a, rad.
    alpha1, alpha2, alpha3, alpha4 : float
        Arcs A-D (frame), A-B (input link), B-C (coupler), C-D (output link), rad.
    branch : int
        +1 or -1, the sign in front of the acos.  The loom (alpha1 = alpha3 =
        alpha4 = 90 deg, alpha2 = beta, th' = theta + 90 deg, ph' = phi + 90 deg)
        is the -1 branch.

    Returns
    -------
    phi_out, dphi_out, ddphi_out : ndarray
        Output angle ph' (rad, not wrapped) and its first and second derivatives
        w.r.t. th'.  NaN where the linkage cannot be assembled (C^2 > A^2 + B^2,
        see :func:`spherical_4r_assembles`); the derivatives are infinite or NaN
        at the assembly limit itself (F_ph = 0, a dead point).
    """
    if branch not in (1, -1):
        raise ValueError(f"`branch` must be +1 or -1, got {branch!r}")
    (a, da, dda), (b, db, ddb), (c, dc, ddc) = _spherical_4r_coefficients(
        theta_in, alpha1, alpha2, alpha3, alpha4
    )
    rho = np.hypot(a, b)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = c / rho
        ratio = np.where(np.abs(ratio) <= 1.0, ratio, np.nan)
        phi = np.arctan2(b, a) + branch * np.arccos(ratio)
        cp, sp = np.cos(phi), np.sin(phi)
        f_ph = -a * sp + b * cp
        f_th = da * cp + db * sp - dc
        f_thph = -da * sp + db * cp
        f_phph = -a * cp - b * sp
        f_thth = dda * cp + ddb * sp - ddc
        dphi = -f_th / f_ph
        ddphi = -(f_thth + 2.0 * f_thph * dphi + f_phph * dphi * dphi) / f_ph
    return phi, dphi, ddphi


def crank_axis(theta: ArrayLike, beta: float) -> np.ndarray:
    """Crank axis b(theta) = (-sin beta sin theta, sin beta cos theta, cos beta), shape (..., 3)."""
    theta = np.asarray(theta, dtype=float)
    sb = np.sin(beta)
    return np.stack(
        [-sb * np.sin(theta), sb * np.cos(theta), np.full_like(theta, np.cos(beta))], axis=-1
    )


def rocker_axis(phi: ArrayLike) -> np.ndarray:
    """Rocker axis c(phi) = (0, cos phi, sin phi), shape (..., 3)."""
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.zeros_like(phi), np.cos(phi), np.sin(phi)], axis=-1)


def coupler_frame(theta: ArrayLike, beta: float) -> np.ndarray:
    """Rotation matrix of the coupler (member 2): columns [b, c, b x c].

    Parameters
    ----------
    theta : array_like
        Crank angle, rad.
    beta : float
        Crank inclination, rad.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        R with R[..., :, 0] = b(theta), R[..., :, 1] = c(phi(theta)),
        R[..., :, 2] = b x c.  Orthonormal since ``|b| = |c| = 1`` and b . c = 0.
    """
    phi, _, _ = rocker_angle(theta, beta)
    b = crank_axis(theta, beta)
    c = rocker_axis(phi)
    return np.stack([b, c, np.cross(b, c)], axis=-1)


def coupler_angular_velocity(theta: ArrayLike, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Angular velocity of the coupler per unit crank speed, in the fixed frame.

    The coupler turns relative to the crank about b and relative to the rocker
    about c, so omega_2 = theta_dot z + lambda b = phi_dot x + mu c.  Dotting with
    c (b . c = 0, x . c = 0) gives mu = theta_dot z . c = theta_dot sin phi, hence

        w(theta) = omega_2 / theta_dot = phi' x + sin(phi) c(phi)
        w'(theta) = phi'' x + phi' cos(phi) c + phi' sin(phi) c_phi,
        c_phi = (0, -sin phi, cos phi).

    (Equivalently lambda / theta_dot = phi' b_x - cos beta; and skew(w) = R' R^T
    with R from :func:`coupler_frame`; both are checked in the tests.)

    Returns
    -------
    w, dw : ndarray, shape (..., 3)
        omega_2 / theta_dot (dimensionless) and its derivative w.r.t. theta (1/rad).
        At constant speed omega_2 = omega w and its time derivative is omega^2 dw.
    """
    phi, dphi, ddphi = rocker_angle(theta, beta)
    c = rocker_axis(phi)
    c_phi = np.stack([np.zeros_like(phi), -np.sin(phi), np.cos(phi)], axis=-1)
    ex = np.zeros(phi.shape + (3,))
    ex[..., 0] = 1.0
    sphi, cphi = np.sin(phi)[..., None], np.cos(phi)[..., None]
    d1, d2 = dphi[..., None], ddphi[..., None]
    w = d1 * ex + sphi * c
    dw = d2 * ex + d1 * cphi * c + d1 * sphi * c_phi
    return w, dw
