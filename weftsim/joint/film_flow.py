"""Oil flow through a steadily loaded journal bearing, from the finite-bearing film of the kernel's table.

The journal spins at omega in a still bearing fed at ambient pressure along its line of thickest film (the
finite film's supply, :func:`weftsim.joint.reynolds.solve` with ``supply=True``; Booker's squeeze velocity of
pure rotation, abs(V) = omega eps c / 2 at xi = -90 deg).  With p = eta (R/c)^2 (abs(V)/c) P, h = c H, z = R zeta:

- **inlet flow** Q, carried into the converging film across the supply line (Couette minus Poiseuille):
  Q / (R c N L) = pi H - (pi eps / (12 B/D)) integral H^3 dP/dphi dzeta over the half film, at the first
  cell face after the supply line (Q = pi R c N L for the centred journal, Petroff's film);
- **side flow** Qs, leaving at the two ends zeta = +-B/D from the pressurised film:
  Qs / (R c N L) = (pi eps / (12 B/D)) integral H^3 (-dP/dzeta) dphi at one end, dP/dzeta by a second-order
  one-sided difference (the first-order one is 4 % low at eps = 0.8 on the table's grid; this one agrees with
  a grid of twice the nodes to 0.2 %).

Against Raimondi and Boyd's full bearing (ASLE Trans. 1, 1958; B/D = 1, eps 0.1-0.97): Q/(RcNL) within 0.4 %,
Qs/Q within 0.3 % (tests/test_bearing.py).  Both are tabulated per B/D over eps on the film table's axis
(u = 1 - sqrt(1 - eps), 29 nodes up to eps = 0.99) and interpolated by a cubic spline in u: one table, 29
Reynolds solves of ~30 ms, per process and B/D.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from weftsim.physics.film import N_U, U_MAX

# Dimensionless flows are tabulated on u = 1 - sqrt(1 - eps), as the film force.
U_NODES = np.linspace(0.0, U_MAX, N_U)


def flows(eps: float, width: float) -> tuple[float, float]:
    """(Q, Qs) / (R c N L) of the supplied finite film at eccentricity ratio ``eps``, B/D = ``width``, from a
    Reynolds solve (module docstring)."""
    from weftsim.joint.reynolds import N_PHI, N_ZETA, operator, solve

    if eps <= 0.0:
        return math.pi, 0.0
    _, _, pressure = solve(eps, -0.5 * math.pi, width, N_PHI, N_ZETA, supply=True)
    _, nodes, _ = operator(eps, width, N_PHI, N_ZETA)
    dz = width / N_ZETA
    gap = np.diff(np.concatenate((nodes, [nodes[0] + 2.0 * math.pi])))
    cell = 0.5 * (gap + np.roll(gap, 1))
    h3 = (1.0 - eps * np.cos(nodes)) ** 3
    side = float(np.sum(h3 * cell * (4.0 * pressure[:, -1] - pressure[:, -2]) / (2.0 * dz)))
    face = nodes[0] + 0.5 * gap[0]
    h_face = 1.0 - eps * math.cos(face)
    dzeta = np.full(N_ZETA, dz)
    dzeta[0] = 0.5 * dz  # the mid-plane cell is half a cell
    poiseuille = float(np.sum(h_face**3 * (pressure[1] - pressure[0]) / gap[0] * dzeta))
    scale = math.pi * eps / (12.0 * width)
    return math.pi * h_face - scale * poiseuille, scale * side


@lru_cache(maxsize=16)
def _table(width: float):
    from scipy.interpolate import CubicSpline

    eps = 1.0 - (1.0 - U_NODES) ** 2
    values = np.array([flows(float(x), width) for x in eps])
    return CubicSpline(U_NODES, values[:, 0]), CubicSpline(U_NODES, values[:, 1])


def flow_variables(eps: float, width: float) -> tuple[float, float]:
    """(Q, Qs) / (R c N L) at ``eps`` (clamped to the table's [0, 0.99]) for B/D = ``width``, interpolated."""
    inlet, side = _table(float(width))
    u = min(max(1.0 - math.sqrt(max(1.0 - eps, 0.0)), 0.0), U_MAX)
    return float(inlet(u)), float(side(u))
