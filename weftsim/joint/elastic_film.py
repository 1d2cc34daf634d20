"""The elastic compliance of a plain bearing's conformal pair: how the film's pressure opens the gap.

Plane strain (the bearing long enough that its section deforms as a slice, under the film's pressure averaged
along the bearing's length: an approximation, the one the reduced models of Sander et al., Tribol. Int. 96, 2016,
make too).  A normal pressure p(phi) = sum p_n cos(n phi) + q_n sin(n phi) acts on the journal (a solid disk of
radius R, modulus E_j, Poisson's ratio nu_j) and on the bore (a hole of radius R_b in an infinite plate, E_b,
nu_b).  Michell's solution of each (Airy stress functions r^n cos(n phi), r^(n+2) cos(n phi) in the disk,
r^-n cos(n phi), r^(2-n) cos(n phi) in the plate; shear-free surface, sigma_rr = -p_n; J. R. Barber, Elasticity,
3rd ed., 2010, ch. 9 and table 9.1) gives the radial surface displacement of mode n >= 2, with kappa = 3 - 4 nu
and G = E / (2 (1 + nu)):

    disk (inward)     u_r = -p_n R   / (4 G_j) [kappa_j / (n + 1) + 1 / (n - 1)],
    hole (outward)    u_r = +p_n R_b / (4 G_b) [kappa_b / (n - 1) + 1 / (n + 1)],

both tending to the half-space's 2 (1 - nu^2) p_n / (E k), k = n / R, as n grows (Johnson, Contact Mechanics,
1985, eq. 2.25b for a periodic pressure).  Mode n = 0 (a uniform pressure) is Lame's: the disk shrinks by
p R (1 - 2 nu_j) / (2 G_j), the hole grows by p R_b / (2 G_b); it changes the clearance uniformly.  Mode n = 1
carries the net force: it moves each body as a whole (the hole in the infinite plate has no finite n = 1
solution; the disk's reaction is the load through its section), and a cos(phi) / sin(phi) change of the radial
gap is only a shift of the eccentricity, which the load balance absorbs: its gain is 0 here.

The gap opens by D(phi) = u_bore - u_journal = sum g_n (p_n cos(n phi) + q_n sin(n phi)) with the pair's gain
g_n (m/Pa, :func:`pair_gain`).  :class:`FilmCompliance` applies it to a pressure known at the nodes of a
non-uniform grid in phi: the pressure, piecewise linear between the nodes, is sampled on a uniform periodic grid
of :data:`FINE_POINTS` points, its discrete Fourier modes multiplied by g_n (the Nyquist mode dropped), and the
opening, and its slope dD/dphi (the modes times i n), taken back to the wanted angles by linear interpolation:
three dense matrices, built once per grid and pair.

A ring in a housing, or a conrod's eye, is stiffer or softer than the infinite plate; the plate is the model
here (the source's FE conrod is not given as numbers).  Checked against the plane-strain FE model of
:mod:`weftsim.studies.cylinder_fe` (tests/test_elastic_film.py).
"""

from __future__ import annotations

import functools
import math

import numpy as np

# Uniform periodic grid on which the pressure's Fourier modes are taken: its spacing (2 pi / 4096 = 0.09 deg) is
# below a sixth of the Reynolds grid's finest cell at eps = 0.99 (0.6 deg at 120 nodes).
FINE_POINTS = 4096


def shear_modulus(modulus: float, poisson: float) -> float:
    """G = E / (2 (1 + nu)), Pa."""
    return modulus / (2.0 * (1.0 + poisson))


def disk_gain(n: np.ndarray | int, radius: float, modulus: float, poisson: float) -> np.ndarray:
    """Inward radial surface displacement of a solid disk per unit pressure of mode n (m/Pa; module docstring):
    n = 0 Lame's, n = 1 zero (a rigid shift), n >= 2 Michell's."""
    n = np.asarray(n, dtype=float)
    g, kappa = shear_modulus(modulus, poisson), 3.0 - 4.0 * poisson
    out = np.zeros_like(n)
    high = n >= 2.0
    out[high] = radius / (4.0 * g) * (kappa / (n[high] + 1.0) + 1.0 / (n[high] - 1.0))
    out[n == 0.0] = radius * (1.0 - 2.0 * poisson) / (2.0 * g)
    return out


def hole_gain(n: np.ndarray | int, radius: float, modulus: float, poisson: float) -> np.ndarray:
    """Outward radial displacement of a hole of radius ``radius`` in an infinite plate per unit pressure of mode n
    (m/Pa; module docstring): n = 0 Lame's, n = 1 zero, n >= 2 Michell's."""
    n = np.asarray(n, dtype=float)
    g, kappa = shear_modulus(modulus, poisson), 3.0 - 4.0 * poisson
    out = np.zeros_like(n)
    high = n >= 2.0
    out[high] = radius / (4.0 * g) * (kappa / (n[high] - 1.0) + 1.0 / (n[high] + 1.0))
    out[n == 0.0] = radius / (2.0 * g)
    return out


def pair_gain(n, journal_radius: float, bearing_radius: float, journal_modulus: float, journal_poisson: float,
              bearing_modulus: float, bearing_poisson: float) -> np.ndarray:
    """g_n: the gap's opening per unit pressure of mode n on both surfaces, m/Pa (hole outward + disk inward)."""
    return (hole_gain(n, bearing_radius, bearing_modulus, bearing_poisson)
            + disk_gain(n, journal_radius, journal_modulus, journal_poisson))


def _periodic_interpolation(x_from: np.ndarray, x_to: np.ndarray) -> np.ndarray:
    """Matrix of the periodic (2 pi) piecewise-linear interpolation from the increasing angles ``x_from`` (within
    one turn) to ``x_to``."""
    n = x_from.size
    ext = np.concatenate((x_from, [x_from[0] + 2.0 * math.pi]))
    base = x_from[0]
    t = np.mod(x_to - base, 2.0 * math.pi) + base
    i = np.clip(np.searchsorted(ext, t, side="right") - 1, 0, n - 1)
    frac = (t - ext[i]) / (ext[i + 1] - ext[i])
    out = np.zeros((x_to.size, n))
    rows = np.arange(x_to.size)
    out[rows, i] += 1.0 - frac
    out[rows, (i + 1) % n] += frac
    return out


class FilmCompliance:
    """The gap's opening D (m) and its slope dD/dphi at given angles per unit nodal pressure (Pa): ``nodes``
    (matrix n x n), ``faces`` (at the cell faces) and ``slope`` (at the nodes), for a pressure known at the
    increasing angles ``nodes`` (one turn) and piecewise linear between them (module docstring)."""

    def __init__(self, nodes: np.ndarray, faces: np.ndarray, gains: np.ndarray):
        fine = -math.pi + 2.0 * math.pi * np.arange(FINE_POINTS) / FINE_POINTS
        up = _periodic_interpolation(nodes, fine)  # (FINE_POINTS, n)
        modes = np.fft.rfft(up, axis=0)
        k = np.arange(modes.shape[0])
        g = gains[k].copy()
        g[-1] = 0.0  # the Nyquist mode
        opening = np.fft.irfft(g[:, None] * modes, n=FINE_POINTS, axis=0)
        slope = np.fft.irfft((1j * k * g)[:, None] * modes, n=FINE_POINTS, axis=0)
        to_nodes, to_faces = _periodic_interpolation(fine, nodes), _periodic_interpolation(fine, faces)
        self.nodes = to_nodes @ opening
        self.faces = to_faces @ opening
        self.slope = to_nodes @ slope


@functools.lru_cache(maxsize=16)
def _cached(nodes: bytes, faces: bytes, pair: tuple) -> FilmCompliance:
    n = np.frombuffer(nodes)
    gains = pair_gain(np.arange(FINE_POINTS // 2 + 1), *pair)
    return FilmCompliance(n, np.frombuffer(faces), gains)


def film_compliance(nodes: np.ndarray, faces: np.ndarray, journal_radius: float, bearing_radius: float,
                    journal_modulus: float, journal_poisson: float, bearing_modulus: float,
                    bearing_poisson: float) -> FilmCompliance:
    """The :class:`FilmCompliance` of a grid and a pair (kept: a Stribeck sweep reuses it)."""
    pair = (journal_radius, bearing_radius, journal_modulus, journal_poisson, bearing_modulus, bearing_poisson)
    return _cached(np.ascontiguousarray(nodes, float).tobytes(), np.ascontiguousarray(faces, float).tobytes(),
                   tuple(float(v) for v in pair))
