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

import functools
import math

import numpy as np
import scipy.sparse as sp
from scipy.linalg import solveh_banded
from scipy.sparse.linalg import spsolve

from weftsim.physics.flow_factors import contact_factor, pressure_flow_factor

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


def _conductance(eps: float, angles: np.ndarray, roughness: float) -> np.ndarray:
    """H^3, times Patir and Cheng's pressure flow factor phi_x(c H / sigma) on rough surfaces.

    ``roughness`` = sigma / c (0: smooth surfaces, phi_x = 1).
    """
    return conductance_of(1.0 - eps * np.cos(angles), roughness)


def conductance_of(gap: np.ndarray, roughness: float) -> np.ndarray:
    """H^3 phi_x(c H / sigma) of the dimensionless gap H (``roughness`` = sigma / c; 0: smooth, H^3)."""
    if roughness <= 0.0:
        return gap**3
    return gap**3 * pressure_flow_factor(gap / roughness)


@functools.lru_cache(maxsize=4)  # a sweep over the squeeze angle builds it once (it is not changed)
def operator(eps: float, half_width: float, n_phi: int, n_zeta: int, roughness: float = 0.0):
    """K (sparse, SPD), the node angles and the cell volumes of the half film zeta in [0, B/D].

    Unknown (i, j) = P at phi_i, zeta_j = j dz, j = 0..n_zeta-1 (P = 0 at j = n_zeta).  ``roughness``
    = sigma / c: the average-flow conductance phi_x H^3 (:mod:`weftsim.physics.flow_factors`).
    """
    nodes, faces = _angles(eps, n_phi)
    matrix, volume = assemble(nodes, _conductance(eps, nodes, roughness), _conductance(eps, faces, roughness),
                              half_width, n_zeta)
    return matrix, nodes, volume


def assemble(nodes: np.ndarray, node_h3: np.ndarray, face_h3: np.ndarray, half_width: float, n_zeta: int):
    """K (sparse, SPD) and the cell volumes of the half film on the increasing angles ``nodes`` (one turn from
    -pi, faces midway in the mapped angle), with the conductances H^3 phi_x at the nodes (axial fluxes) and at
    the faces phi_{i+1/2} (circumferential fluxes): :func:`operator`'s, for any gap."""
    dz = half_width / n_zeta
    gap = np.diff(np.concatenate((nodes, [nodes[0] + 2.0 * math.pi])))  # phi_{i+1} - phi_i
    width = 0.5 * (gap + np.roll(gap, 1))  # control-volume width in phi
    dzeta = np.full(n_zeta, dz)
    dzeta[0] = 0.5 * dz  # the mid-plane cell is half a cell
    index = np.arange(nodes.size * n_zeta).reshape(nodes.size, n_zeta)
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
    size = nodes.size * n_zeta
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(size, size))
    volume = width[:, None] * dzeta[None, :]
    return matrix, volume


def _film_pressure(matrix, active: np.ndarray, q: np.ndarray, n_zeta: int) -> np.ndarray:
    """P solving K_AA P_A = q_A on the film's nodes A (``active``), 0 elsewhere (q: a vector, or columns).

    Where a whole line phi_i has no film, the film is a strip, not a ring: numbered from the line after that one,
    K_AA is banded (half-bandwidth n_zeta: the next line's node is at most n_zeta unknowns on) and solved by
    banded Cholesky (LAPACK), some 30 times faster than the sparse LU it equals to round-off; a ring of film
    by the sparse LU.
    """
    pressure = np.zeros_like(q)
    lines = active.reshape(-1, n_zeta).any(axis=1)
    if not lines.any():
        return pressure
    if lines.all():
        idx = np.flatnonzero(active)
        pressure[idx] = spsolve(matrix[idx][:, idx].tocsc(), q[idx])
        return pressure
    first = int(np.argmin(lines))  # a line without film: the strip starts after it
    order = np.roll(np.arange(q.shape[0]).reshape(-1, n_zeta), -first, axis=0).ravel()
    idx = order[active[order]]
    sub = matrix[idx][:, idx]
    band = np.zeros((n_zeta + 1, idx.size))
    for k in range(n_zeta + 1):
        band[n_zeta - k, k:] = sub.diagonal(k)
    pressure[idx] = solveh_banded(band, q[idx])
    return pressure


def complementary(matrix, q: np.ndarray, n_zeta: int, supply: bool, active: np.ndarray) -> np.ndarray:
    """P of the cavitating film K P = q (the complementarity problem of the module docstring), by the primal-dual
    active set from the film ``active`` (P > 0 of a first guess); ``supply``: P = 0 held on the first line of
    nodes (phi = -pi, the thickest film)."""
    active = active.copy()
    if supply:
        active[:n_zeta] = False
    for _ in range(200):
        pressure = _film_pressure(matrix, active, q, n_zeta)
        residual = matrix @ pressure - q
        new = (pressure > 0.0) | (~active & (residual < 0.0))
        new &= ~(active & (pressure <= 0.0))
        if supply:
            new[:n_zeta] = False
        if np.array_equal(new, active):
            return pressure
        active = new
    raise RuntimeError("active-set iteration did not settle")  # pragma: no cover - it terminates on M-matrices


def solve(eps: float, xi: float, half_width: float, n_phi: int = N_PHI, n_zeta: int = N_ZETA,
          cavitation: bool = True, supply: bool = False, roughness: float = 0.0, start: np.ndarray | None = None):
    """Dimensionless force (f_along_e, f_ahead) and the half-film pressure P[i, j].

    ``cavitation=False`` gives the full-Sommerfeld film (negative pressures kept); ``supply=True``
    holds P = 0 on the line of thickest film (phi = pi), Raimondi and Boyd's inlet condition.
    ``roughness`` = sigma / c > 0 solves Patir and Cheng's average-flow equation
    div(phi_x H^3 grad P) = -12 Phi(c H / sigma) cos(phi - xi) (:mod:`weftsim.physics.flow_factors`).
    ``start``: a pressure field of a neighbouring problem (the table's previous squeeze angle) whose film
    (P > 0) starts the active-set iteration in place of the uncavitated solve; the iteration ends at the
    same (unique) solution, in fewer solves.
    """
    matrix, nodes, volume = operator(eps, half_width, n_phi, n_zeta, roughness)
    source = 12.0 * np.cos(nodes - xi)
    if roughness > 0.0:
        source = source * contact_factor((1.0 - eps * np.cos(nodes)) / roughness)
    rhs = source[:, None] * volume
    q = rhs.ravel()
    pressure = spsolve(matrix.tocsc(), q) if start is None or not cavitation else start.ravel()
    if cavitation:
        pressure = complementary(matrix, q, n_zeta, supply, pressure > 0.0)
    field = pressure.reshape(volume.shape)
    load = 2.0 * field * volume  # both halves of the film
    f_along = -float(np.sum(load * np.cos(nodes)[:, None]))
    f_ahead = -float(np.sum(load * np.sin(nodes)[:, None]))
    return f_along, f_ahead, field


def rotation_source(gap: np.ndarray, slope: np.ndarray, volume: np.ndarray, roughness: float = 0.0,
                    surfaces=None) -> np.ndarray:
    """q of a journal spinning in a still bearing, any gap: -12 Phi(c H / sigma) dH/dphi per cell volume.

    Reynolds' equation of steady rotation, d/dx (h^3 dp/dx) + d/dz (h^3 dp/dz) = 6 eta U dh/dx with U = omega R
    (the mean surface speed omega_m = omega / 2 twice), becomes with p = eta (R/c)^2 omega_m P and h = c H
    div(H^3 grad P) = 12 dH/dphi, phi in the direction of the journal's surface motion (Patir and Cheng's mean
    gap: times Phi).  For H = 1 - eps cos phi this is :func:`solve`'s right-hand side at xi = -pi/2 (the squeeze
    velocity of rotation, 90 deg behind e) times eps, its pressure scale being abs(V) / c = omega_m eps.
    ``gap``, ``slope``: H and dH/dphi at the nodes; ``volume`` the cells' (:func:`assemble`).

    ``surfaces`` (a :class:`weftsim.physics.flow_factors.SurfacePair`, journal first): unlike surfaces add Patir
    and Cheng's shear flow, (U_1 - U_2) / 2 sigma d phi_s / dx on the right of the dimensional equation with the
    journal's U_1 = omega R and the bearing's U_2 = 0.  (U_1 - U_2) / 2 = U_m, so it scales as the wedge term:
    12 (sigma / c) d phi_s / dphi = 12 phi_s'(c H / sigma) dH/dphi, and the source is
    -12 (Phi + phi_s') dH/dphi.  phi_s > 0 where the moving journal is the rougher (its valleys carry oil along),
    < 0 where the still bearing is (it holds oil back)."""
    source = -12.0 * slope
    if roughness > 0.0:
        factor = contact_factor(gap / roughness)
        if surfaces is not None:
            factor = factor + surfaces.shear_flow(gap / roughness, 1)
        source = source * factor
    return (source[:, None] * volume).ravel()


def conductances_of(gap_nodes: np.ndarray, gap_faces: np.ndarray, roughness: float, surfaces=None):
    """The average-flow conductances at the nodes (the axial fluxes: phi_z H^3) and at the faces (the
    circumferential ones: phi_x H^3); ``surfaces`` None: the isotropic :func:`conductance_of` for both."""
    if surfaces is None or roughness <= 0.0:
        return conductance_of(gap_nodes, roughness), conductance_of(gap_faces, roughness)
    return (gap_nodes**3 * surfaces.pressure(gap_nodes / roughness, across=True),
            gap_faces**3 * surfaces.pressure(gap_faces / roughness, across=False))


def solve_gap(nodes: np.ndarray, gap_nodes: np.ndarray, gap_faces: np.ndarray, slope_nodes: np.ndarray,
              half_width: float, n_zeta: int = N_ZETA, roughness: float = 0.0, supply: bool = True,
              active: np.ndarray | None = None, surfaces=None):
    """The cavitating film of a journal spinning in a still bearing with the gap H(phi) (uniform along the axis;
    at the increasing ``nodes`` from -pi and at their faces, with its slope at the nodes): (f_along_e, f_ahead,
    P[i, j], K, cell volumes), dimensionless as :func:`rotation_source` (p = eta (R/c)^2 (omega / 2) P, force
    eta R^2 (R/c)^2 (omega / 2) f).  ``supply``: P = 0 on the line phi = -pi (the film fed at its thickest line,
    as the kernel's fed film); ``active``: a first guess of the film (P > 0) for the active set; ``surfaces``:
    anisotropic or unlike rough surfaces (:func:`conductances_of`, :func:`rotation_source`; ``roughness`` then
    their composite sigma / c)."""
    node_h3, face_h3 = conductances_of(gap_nodes, gap_faces, roughness, surfaces)
    matrix, volume = assemble(nodes, node_h3, face_h3, half_width, n_zeta)
    q = rotation_source(gap_nodes, slope_nodes, volume, roughness, surfaces)
    guess = np.ones(q.size, bool) if active is None else active.ravel()
    pressure = complementary(matrix, q, n_zeta, supply, guess)
    field = pressure.reshape(volume.shape)
    load = 2.0 * field * volume
    return -float(np.sum(load * np.cos(nodes)[:, None])), -float(np.sum(load * np.sin(nodes)[:, None])), field, \
        matrix, volume


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


def film(eps: float, xi: float, half_width: float, n_phi: int = N_PHI, n_zeta: int = N_ZETA, roughness: float = 0.0,
         fields: dict | None = None):
    """The finite bearing of the kernel (``MODEL_FINITE``): (f_along_e, f_ahead); ``roughness`` = sigma / c
    (0: smooth surfaces; > 0: Patir and Cheng's average flow, :func:`solve`).  ``fields``: a dict in which the
    fed and the free film's pressure fields are kept and from which the next call starts (a sweep over xi).

    The film is fed at ambient pressure along the line of thickest film, as in Raimondi and Boyd's
    full bearing, while the journal's squeeze velocity V does not point there (any rotation, and
    squeeze towards the thin side); when V points to the thick side the journal pressurises that
    side itself and the film boundary is free (Swift-Stieber everywhere).  The two are blended by
    :func:`supply_weight`, so the force is continuous in every argument.
    """
    weight = supply_weight(xi)
    kept = {} if fields is None else fields
    forces = {"fed": (0.0, 0.0), "free": (0.0, 0.0)}
    for name, used in (("fed", weight > 0.0), ("free", weight < 1.0)):
        if used:
            f_along, f_ahead, kept[name] = solve(eps, xi, half_width, n_phi, n_zeta, supply=name == "fed",
                                                 roughness=roughness, start=kept.get(name))
            forces[name] = (f_along, f_ahead)
    fed, free = forces["fed"], forces["free"]
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
