"""Finite-difference solution of Reynolds' equation of the finite journal bearing, with cavitation.

Solves the dimensionless squeeze-velocity problem of :mod:`weftsim.physics.film`,

    div(H^3 grad P) = -12 cos(phi - xi),   H = 1 - eps cos phi,   phi in [0, 2 pi), zeta in [-B/D, B/D],

with P = 0 at the ends zeta = +-B/D, P periodic in phi, and the cavitation condition of Reynolds
(Swift-Stieber): P >= 0, and where the film has ruptured (P = 0) the equation's residual has the
sign of a film that would pull below ambient.  That is a linear complementarity problem: with K
the (symmetric, M-matrix) finite-volume operator and q the right-hand side,

    P >= 0,   K P - q >= 0,   P . (K P - q) = 0,

solved exactly (to round-off) by the primal-dual active-set method (Hintermueller, Ito, Kunisch,
SIAM J. Optim. 13, 2003), which terminates in a few sparse direct solves on M-matrices.  The film
is symmetric about the mid-plane zeta = 0, so half of it is solved.  The grid is uniform in
Sommerfeld's angle psi of a mapping eccentricity 0.8 eps, which puts nodes where the film is
thinnest and the pressure peaks.

This module is not on any run's path: it builds the table that the kernel interpolates
(``scripts/make_film_table.py``) and the tests check it against the limits and the published
tables.  Returns the dimensionless force f = -integral P n dphi dzeta (components along e and
90 deg ahead of it).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

MAPPING_FRACTION = 0.8  # the grid clusters as Sommerfeld's angle of eps_m = 0.8 eps
# Grid of the table: 120 x 16 nodes over the half film.  Against 240 x 32 the force differs by
# 0.2-0.3 % at eps = 0.95-0.99 and < 0.1 % below (second order: the error quarters per doubling).
N_PHI, N_ZETA = 120, 16
# The supply line is held at ambient pressure while the journal does not move towards it and let
# go (smoothly) once the squeeze velocity points to it with cosine SUPPLY_RELEASE: see film().
SUPPLY_RELEASE = 0.3


def _angles(eps: float, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes phi_i and cell-face angles phi_{i+1/2} (uniform in psi of eps_m), both increasing."""
    eps_m = MAPPING_FRACTION * eps
    ratio = math.sqrt((1.0 - eps_m) / (1.0 + eps_m))
    psi = -math.pi + 2.0 * math.pi * np.arange(2 * n_phi + 1) / (2 * n_phi)
    phi = 2.0 * np.arctan2(ratio * np.sin(0.5 * psi), np.cos(0.5 * psi))
    phi[-1] = math.pi  # arctan2 gives -pi there
    return phi[0:-1:2], phi[1::2]  # nodes from -pi, faces at i + 1/2


def operator(eps: float, half_width: float, n_phi: int, n_zeta: int):
    """K (sparse, SPD), the node angles and the cell volumes of the half film zeta in [0, B/D].

    Unknown (i, j) = P at phi_i, zeta_j = j dz, j = 0..n_zeta-1 (P = 0 at j = n_zeta).
    """
    nodes, faces = _angles(eps, n_phi)
    dz = half_width / n_zeta
    gap = np.diff(np.concatenate((nodes, [nodes[0] + 2.0 * math.pi])))  # phi_{i+1} - phi_i
    face_h3 = (1.0 - eps * np.cos(faces)) ** 3
    width = 0.5 * (gap + np.roll(gap, 1))  # control-volume width in phi
    node_h3 = (1.0 - eps * np.cos(nodes)) ** 3
    dzeta = np.full(n_zeta, dz)
    dzeta[0] = 0.5 * dz  # the mid-plane cell is half a cell
    index = np.arange(n_phi * n_zeta).reshape(n_phi, n_zeta)
    rows, cols, vals = [], [], []
    # Circumferential fluxes: conductance H^3 / gap times the cell height in zeta.
    g_phi = (face_h3 / gap)[:, None] * dzeta[None, :]
    here = index.ravel()
    right = np.roll(index, -1, axis=0).ravel()
    rows += [here, right, here, right]
    cols += [here, right, right, here]
    vals += [g_phi.ravel(), g_phi.ravel(), -g_phi.ravel(), -g_phi.ravel()]
    # Axial fluxes between j and j+1 (conductance H^3 / dz times the cell width in phi).
    g_z = np.repeat((node_h3 * width / dz)[:, None], n_zeta, axis=1)
    up = index[:, 1:]
    low = index[:, :-1]
    g_inner = g_z[:, :-1]
    rows += [low.ravel(), up.ravel(), low.ravel(), up.ravel()]
    cols += [low.ravel(), up.ravel(), up.ravel(), low.ravel()]
    vals += [g_inner.ravel(), g_inner.ravel(), -g_inner.ravel(), -g_inner.ravel()]
    # Last row to the end P = 0.
    rows.append(index[:, -1])
    cols.append(index[:, -1])
    vals.append(g_z[:, -1])
    size = n_phi * n_zeta
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(size, size))
    volume = width[:, None] * dzeta[None, :]
    return matrix, nodes, volume


def solve(eps: float, xi: float, half_width: float, n_phi: int = N_PHI, n_zeta: int = N_ZETA,
          cavitation: bool = True, supply: bool = False):
    """Dimensionless force (f_along_e, f_ahead) and the half-film pressure P[i, j].

    ``cavitation=False`` gives the full-Sommerfeld film (negative pressures kept); ``supply=True``
    holds P = 0 on the line of thickest film (phi = pi), Raimondi and Boyd's inlet condition.
    """
    matrix, nodes, volume = operator(eps, half_width, n_phi, n_zeta)
    rhs = (12.0 * np.cos(nodes - xi))[:, None] * volume
    q = rhs.ravel()
    pressure = spsolve(matrix.tocsc(), q)
    if cavitation:
        active = pressure > 0.0
        if supply:
            active[:n_zeta] = False
        for _ in range(200):
            pressure = np.zeros_like(q)
            idx = np.flatnonzero(active)
            if idx.size:
                sub = matrix[idx][:, idx].tocsc()
                pressure[idx] = spsolve(sub, q[idx])
            residual = matrix @ pressure - q
            new = (pressure > 0.0) | (~active & (residual < 0.0))
            new &= ~(active & (pressure <= 0.0))
            if supply:
                new[:n_zeta] = False
            if np.array_equal(new, active):
                break
            active = new
        else:  # pragma: no cover - the method terminates on M-matrices
            raise RuntimeError("active-set iteration did not settle")
    field = pressure.reshape(volume.shape)
    load = 2.0 * field * volume  # both halves of the film
    f_along = -float(np.sum(load * np.cos(nodes)[:, None]))
    f_ahead = -float(np.sum(load * np.sin(nodes)[:, None]))
    return f_along, f_ahead, field


def supply_weight(xi: float) -> float:
    """Weight of the supplied film: 1 while V does not point to the thickest film, 0 from SUPPLY_RELEASE on.

    s = -cos(xi) is the cosine between V and the direction of the thickest film; the weight falls as
    a smoothstep (C1) from s = 0 to s = SUPPLY_RELEASE.
    """
    s = -math.cos(xi) / SUPPLY_RELEASE
    if s <= 0.0:
        return 1.0
    if s >= 1.0:
        return 0.0
    return 1.0 - s * s * (3.0 - 2.0 * s)


def film(eps: float, xi: float, half_width: float, n_phi: int = N_PHI, n_zeta: int = N_ZETA):
    """The finite bearing of the kernel (``MODEL_FINITE``): (f_along_e, f_ahead).

    The film is fed at ambient pressure along the line of thickest film, as in Raimondi and Boyd's
    full bearing, while the journal's squeeze velocity V does not point there (any rotation, and
    squeeze towards the thin side); when V points to the thick side the journal pressurises that
    side itself and the film boundary is free (Swift-Stieber everywhere).  The two are blended by
    :func:`supply_weight`, so the force is continuous in every argument.
    """
    weight = supply_weight(xi)
    fed = solve(eps, xi, half_width, n_phi, n_zeta, supply=True)[:2] if weight > 0.0 else (0.0, 0.0)
    free = solve(eps, xi, half_width, n_phi, n_zeta)[:2] if weight < 1.0 else (0.0, 0.0)
    return (weight * fed[0] + (1.0 - weight) * free[0], weight * fed[1] + (1.0 - weight) * free[1])


# Raimondi and Boyd (ASLE Transactions 1(1), 1958), full (360 deg) journal bearing, Reynolds boundary
# conditions, as reproduced in the machine-design textbooks (e.g. Shigley's Mechanical Engineering
# Design, the table of dimensionless performance parameters for full journal bearings): per B/D, rows
# (eccentricity ratio, Sommerfeld number S = (R/c)^2 eta N / P, attitude angle in degrees), with N the
# journal speed in rev/s and P = W / (D B) the projected pressure.
RAIMONDI_BOYD = {
    1.0: ((0.1, 1.33, 79.5), (0.2, 0.631, 74.02), (0.4, 0.264, 63.10), (0.6, 0.121, 50.58), (0.8, 0.0446, 36.24),
          (0.9, 0.0188, 26.45), (0.97, 0.00474, 15.47)),
    0.5: ((0.1, 4.31, 81.62), (0.2, 2.03, 74.94), (0.4, 0.779, 61.45), (0.6, 0.319, 48.14), (0.8, 0.0923, 33.31),
          (0.9, 0.0313, 23.66)),
}


def steady_load(eps: float, width: float, model: int) -> tuple[float, float]:
    """Sommerfeld number and attitude angle (deg) of a journal spinning at eccentricity ratio eps in a
    still bearing of B/D = ``width``, from the kernel's film force (:func:`weftsim.physics.film.film_force`).

    Dimensionless: S = (R/c)^2 eta N / P does not depend on the numbers chosen here.
    """
    from weftsim.physics.film import film_force

    radius, clearance, viscosity, omega = 0.01, 2e-5, 0.05, 100.0
    length = 2.0 * width * radius
    fy, fz, _, _ = film_force(eps * clearance, 0.0, 0.0, 0.0, omega, 0.0, clearance, radius, length, viscosity,
                              model)
    load = math.hypot(fy, fz)
    sommerfeld = (radius / clearance) ** 2 * viscosity * (omega / (2.0 * math.pi)) * (2.0 * radius * length) / load
    return sommerfeld, math.degrees(math.atan2(fz, -fy))


def equilibrium(sommerfeld: float, width: float, model: int) -> tuple[float, float]:
    """Eccentricity ratio and attitude angle (deg) at which the film carries a steady load of Sommerfeld
    number ``sommerfeld`` (S falls monotonically with eps; root by Brent's method)."""
    from scipy.optimize import brentq

    eps = brentq(lambda x: math.log(steady_load(x, width, model)[0] / sommerfeld), 1e-4, 0.995, xtol=1e-12)
    return eps, steady_load(eps, width, model)[1]
