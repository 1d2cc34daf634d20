"""Oil-film force and friction torque of a lubricated journal bearing (the one definition).

Geometry and signs (the joint's plane is y-z, the joint axis x; angles turn y towards z)::

          bearing, centre O                e = (ey, ez) = journal centre - O, m;  eps = |e| / c
        .-----------.                      n(theta) = (cos theta, sin theta) outward normal
      /   .-------.   \\                    h(theta) = c - e . n(theta)   film thickness, m
     |   |  J -e->  |   |  <- thinnest     omega_j, omega_b  angular velocities about +x, rad/s
      \\   '-------'   /                    F = (fy, fz)  film force ON THE JOURNAL, N
        '-----------'

Reynolds' equation of the thin film, with x = R theta along the surface and z along the axis,

    d/dx (h^3 dp/dx) + d/dz (h^3 dp/dz) = 12 eta (omega_m dh/dtheta + dh/dt),  omega_m = (omega_j + omega_b) / 2,

has a right-hand side that depends on the motion only through one vector (Booker's squeeze velocity):
``omega_m dh/dtheta + dh/dt = -V . n`` with ``V = e_dot - omega_m x e``.  A journal spinning in a
bearing therefore makes the same film as a journal translating with V in a still bearing, and the
rotation (wedge) term carries the effective speed omega_j + omega_b - 2 dgamma/dt (gamma the
direction of e) of the multibody literature.  With h = c H, p = eta (R/c)^2 (|V|/c) P, the axial
coordinate z = R zeta and the angle phi from e, the dimensionless problem is

    div(H^3 grad P) = -12 cos(phi - xi),   H = 1 - eps cos phi,   zeta in [-B/D, B/D],

with xi the angle of V from e, P = 0 at the bearing's ends and P >= 0 (cavitation: the film
ruptures where the pressure would fall below ambient).  Its force is

    F = eta R^2 (R/c)^2 (|V|/c) f(eps, xi, B/D),   f = -integral P n dphi dzeta,

one dimensionless vector (component along e, component 90 deg ahead of e) of three numbers, for
any mix of rotation and squeeze, exact in both directions of the squeeze.  ``model`` picks f:

``MODEL_SHORT`` (Ocvirk)
    d^2P/dzeta^2 alone (B/D -> 0): P = 6 cos(phi - xi) ((B/D)^2 - zeta^2) / H^3 where positive
    (half-Sommerfeld, Gumbel's condition).  Closed form through Sommerfeld's substitution.
``MODEL_LONG`` (Sommerfeld)
    d/dphi(H^3 dP/dphi) alone (B/D -> infinity), periodic pressure zero at the thickest film,
    negative part discarded (Gumbel).
``MODEL_FINITE``
    the finite bearing.  [First commit: evaluates the short bearing; the finite-length solution
    replaces it.]

Film friction: the shear stress of the film on each surface (Couette part over the full film,
Petroff's term with the eccentricity factor 1/sqrt(1 - eps^2); pressure-gradient part from the
force).  About the bearing centre the film has no angular momentum, so the torques satisfy
torque_j + torque_b + (e x F)_x = 0:

    torque_j = eta R^3 L (omega_b - omega_j) 2 pi / (c sqrt(1 - eps^2)) - (e x F)_x / 2
    torque_b = -eta R^3 L (omega_b - omega_j) 2 pi / (c sqrt(1 - eps^2)) - (e x F)_x / 2

Sources: Ocvirk (NACA TN 2808, 1952) and Sommerfeld (1904) for the limits; Gumbel's half-Sommerfeld
condition and the multibody use of both (Flores, Ambrosio, Claro, Lankarani, Mech. Mach. Theory 41,
2006; Nonlinear Dyn. 56, 2009); Booker's mobility/impedance view of the squeeze velocity
(J. Lubr. Technol. 87, 1965; Childs, Moes, van der Bosch, J. Lubr. Technol. 99, 1977).

The functions take floats and return floats, never check their arguments (the caller keeps
eps < 1: at e >= c the asperity and dry contact take over), and are compiled with numba.
"""

from __future__ import annotations

import math

from numba import njit

MODEL_FINITE, MODEL_SHORT, MODEL_LONG = 0, 1, 2

TWO_PI = 2.0 * math.pi


@njit(cache=True, error_model="numpy", inline="always")
def sommerfeld_angle(phi: float, eps: float) -> float:
    """psi(phi) of Sommerfeld's substitution 1 - eps cos phi = (1 - eps^2) / (1 + eps cos psi).

    tan(psi/2) = sqrt((1 + eps) / (1 - eps)) tan(phi/2), continued monotonically over all phi
    (psi(phi + 2 pi) = psi(phi) + 2 pi).
    """
    turns = math.floor(phi / TWO_PI + 0.5)
    base = phi - TWO_PI * turns
    ratio = math.sqrt((1.0 + eps) / (1.0 - eps))
    return 2.0 * math.atan2(ratio * math.sin(0.5 * base), math.cos(0.5 * base)) + TWO_PI * turns


@njit(cache=True, error_model="numpy", inline="always")
def _short_antiderivatives(psi: float, eps: float):
    """Antiderivatives in psi of cos^2, sin cos, sin^2 (of phi) / H^3 dphi, times (1 - eps^2)^(5/2)."""
    s1 = math.sin(psi)
    s2 = math.sin(2.0 * psi)
    root = math.sqrt(1.0 - eps * eps)
    cc = 0.5 * psi + 0.25 * s2 + 2.0 * eps * s1 + eps * eps * psi
    cs = root * (0.5 * s1 * s1 - eps * math.cos(psi))
    ss = (1.0 - eps * eps) * (0.5 * psi - 0.25 * s2)
    return cc, cs, ss


@njit(cache=True, error_model="numpy")
def short_force(eps: float, xi: float, half_width: float):
    """Dimensionless film force f = (f_along_e, f_ahead) of the short bearing, Gumbel cavitation.

    ``half_width`` = B/D (zeta runs over [-B/D, B/D]).  The axially integrated pressure is
    8 (B/D)^3 cos(phi - xi) / H^3, kept over the half circle |phi - xi| < pi/2 where it is positive.
    """
    a = sommerfeld_angle(xi - 0.5 * math.pi, eps)
    b = sommerfeld_angle(xi + 0.5 * math.pi, eps)
    cc_a, cs_a, ss_a = _short_antiderivatives(a, eps)
    cc_b, cs_b, ss_b = _short_antiderivatives(b, eps)
    scale = 8.0 * half_width * half_width * half_width / (1.0 - eps * eps) ** 2.5
    j_cc = (cc_b - cc_a) * scale
    j_cs = (cs_b - cs_a) * scale
    j_ss = (ss_b - ss_a) * scale
    cx = math.cos(xi)
    sx = math.sin(xi)
    return -(cx * j_cc + sx * j_cs), -(cx * j_cs + sx * j_ss)


@njit(cache=True, error_model="numpy")
def film_force(ey: float, ez: float, vy: float, vz: float, omega_j: float, omega_b: float, c: float,
               radius: float, length: float, viscosity: float, model: int):
    """Film force on the journal and film friction torques: (fy, fz, torque_j, torque_b).

    Parameters
    ----------
    ey, ez : float
        Eccentricity, journal centre - bearing centre, m (|e| < c).
    vy, vz : float
        Its rate, m/s.
    omega_j, omega_b : float
        Angular velocities of journal and bearing about the joint axis x, rad/s.
    c, radius, length : float
        Radial clearance, journal radius, bearing length, m.
    viscosity : float
        Dynamic viscosity, Pa s.
    model : int
        ``MODEL_FINITE``, ``MODEL_SHORT`` or ``MODEL_LONG``.

    Returns
    -------
    fy, fz : float
        Film force on the journal, N.
    torque_j, torque_b : float
        Film friction torques about +x on journal and bearing, N m.
    """
    omega_m = 0.5 * (omega_j + omega_b)
    # Booker's squeeze velocity V = e_dot - omega_m x e  (x e = (-ez, ey)).
    sy = vy + omega_m * ez
    sz = vz - omega_m * ey
    e = math.sqrt(ey * ey + ez * ez)
    speed = math.sqrt(sy * sy + sz * sz)
    eps = e / c
    fy = 0.0
    fz = 0.0
    if speed > 0.0 and viscosity > 0.0:
        if e > 0.0:
            ny = ey / e
            nz = ez / e
        else:  # the film is round: any frame; take V's direction
            ny = sy / speed
            nz = sz / speed
        xi = math.atan2(ny * sz - nz * sy, ny * sy + nz * sz)
        half_width = 0.5 * length / radius
        f_along, f_ahead = short_force(eps, xi, half_width)
        ratio = radius / c
        scale = viscosity * radius * radius * ratio * ratio * speed / c
        fy = scale * (f_along * ny - f_ahead * nz)
        fz = scale * (f_along * nz + f_ahead * ny)
    couette = viscosity * radius ** 3 * length * (omega_b - omega_j) * TWO_PI / (c * math.sqrt(1.0 - eps * eps))
    pressure = -0.5 * (ey * fz - ez * fy)
    return fy, fz, couette + pressure, -couette + pressure
