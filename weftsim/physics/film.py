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
direction of e) of the multibody literature.  With h = c H, p = eta (R/c)^2 (abs(V)/c) P, the axial
coordinate z = R zeta and the angle phi from e, the dimensionless problem is

    div(H^3 grad P) = -12 cos(phi - xi),   H = 1 - eps cos phi,   zeta in [-B/D, B/D],

with xi the angle of V from e, P = 0 at the bearing's ends and P >= 0 (cavitation: the film
ruptures where the pressure would fall below ambient).  Its force is

    F = eta R^2 (R/c)^2 (abs(V)/c) f(eps, xi, B/D),   f = -integral P n dphi dzeta,

one dimensionless vector (component along e, component 90 deg ahead of e) of three numbers, for
any mix of rotation and squeeze, exact in both directions of the squeeze.  ``model`` picks f:

``MODEL_SHORT`` (Ocvirk)
    d^2P/dzeta^2 alone (B/D -> 0): P = 6 cos(phi - xi) ((B/D)^2 - zeta^2) / H^3 where positive
    (half-Sommerfeld, Gumbel's condition).  Closed form through Sommerfeld's substitution.
``MODEL_LONG`` (Sommerfeld)
    d/dphi(H^3 dP/dphi) alone (B/D -> infinity), periodic pressure zero at the thickest film,
    negative part discarded (Gumbel).
``MODEL_FINITE``
    the finite bearing: Reynolds' equation with Reynolds' cavitation condition solved on a grid
    (:mod:`weftsim.joint.reynolds`) and tabulated over eps, xi and B/D (``film_table.npz``,
    interpolated by :func:`finite_force`).
``MODEL_SHORT_HALF``
    the short bearing as the multibody papers write it: wedge and squeeze pressure over the fixed
    half film of the wedge (:func:`short_half_force`).

Film friction: the shear stress of the film on each surface (Couette part over the full film,
Petroff's term with the eccentricity factor 1/sqrt(1 - eps^2); pressure-gradient part from the
force).  About the bearing centre the film has no angular momentum, so the torques satisfy
torque_j + torque_b + (e x F)_x = 0:

    torque_j = eta R^3 L (omega_b - omega_j) 2 pi / (c sqrt(1 - eps^2)) - (e x F)_x / 2
    torque_b = -eta R^3 L (omega_b - omega_j) 2 pi / (c sqrt(1 - eps^2)) - (e x F)_x / 2

Sources: Ocvirk (NACA TN 2808, 1952) and Sommerfeld (1904) for the limits; Gumbel's half-Sommerfeld
condition and the multibody use of both (Flores, Ambrosio, Claro, Lankarani, Mech. Mach. Theory 41,
2006; Nonlinear Dyn. 56, 2009); Booker's mobility/impedance view of the squeeze velocity
(J. Basic Eng. 87, 1965; Childs, Moes, van der Bosch, J. Lubr. Technol. 99, 1977).

The functions take floats and return floats, never check their arguments, and are compiled with
numba.  The caller keeps eps < 1 (at e >= c the result is NaN; the asperity and dry contact take
over before the wall).  The force grows without bound towards the wall (the squeeze film as
(1 - eps^2)^-1.5, its stiffness one power of (1 - eps) faster), which sets the step of explicit
integrators near the wall.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
from numba import njit

from weftsim.physics.flow_factors import couette_factor_nodes, couette_factor_tail

MODEL_FINITE, MODEL_SHORT, MODEL_LONG, MODEL_SHORT_HALF = 0, 1, 2, 3
# MODEL_SHORT_HALF: width in sin(xi) of the blend between the two half films (short_half_force).
SHORT_HALF_BAND = 0.1

TWO_PI = 2.0 * math.pi

# Grid of the finite-bearing table (scripts/make_film_table.py solves Reynolds' equation on it).
# eps = 1 - (1 - u)^2 with u uniform on [0, U_MAX] (nodes crowd towards eps = 1: eps_max = 0.99);
# xi uniform on [0, pi] (the mirror image about e gives [-pi, 0]); B/D geometric on [WIDTH_MIN, WIDTH_MAX].
N_U, U_MAX = 29, 0.9
N_XI = 49
N_WIDTH, WIDTH_MIN, WIDTH_MAX = 9, 0.25, 4.0
LOG_WIDTH_STEP = math.log(WIDTH_MAX / WIDTH_MIN) / (N_WIDTH - 1)
# Rough surfaces (Patir and Cheng's average flow, weftsim.physics.flow_factors): the fourth axis is
# s = exp(-0.56 h_min / sigma), uniform on [0, S_MAX] (s = 0 the smooth film, S_MAX a minimum film of sigma / 4):
# the pressure flow factor is 1 - 0.9 s at the thinnest film, so the force is close to linear in s, flat where the
# film is thick (nodes at h_min / sigma = inf, 2.73, 1.49, 0.76, 0.25).
N_R, ROUGH_DECAY, RATIO_MIN = 5, 0.56, 0.25
S_MAX = math.exp(-ROUGH_DECAY * RATIO_MIN)
# The rough film's Couette factor (flow_factors.couette_factor_at, the mean of phi_f over Sommerfeld's angle) is
# tabulated at import over u = 1 - sqrt(1 - eps) uniform on [0, 1] and log(h_min / sigma) uniform on
# [COUETTE_RATIO_MIN, COUETTE_RATIO_MAX] (bicubic Catmull-Rom; thicker films: its closed-form tail, thinner: held),
# each node summed on COUETTE_POINTS nodes of psi (9e-6 from 4096 nodes; 128: 1.2e-4).
N_CU, N_CR, COUETTE_POINTS = 49, 97, 256
COUETTE_RATIO_MIN, COUETTE_RATIO_MAX = 1.0 / 16.0, 20.0
LOG_COUETTE_STEP = math.log(COUETTE_RATIO_MAX / COUETTE_RATIO_MIN) / (N_CR - 1)
# First 16 hex digits of the SHA-256 of the stored table (scripts/make_film_table.py writes this
# line).  numba freezes the table into the compiled code and keys its cache by this file, so a new
# table must change this file; a table that does not match is not used (NaN forces).
TABLE_DIGEST = "83a888962a89feaf"


def table_eccentricities() -> np.ndarray:
    """The table's eccentricity ratios."""
    u = np.linspace(0.0, U_MAX, N_U)
    return 1.0 - (1.0 - u) ** 2


def table_angles() -> np.ndarray:
    """The table's squeeze-velocity angles xi, rad."""
    return np.linspace(0.0, math.pi, N_XI)


def table_widths() -> np.ndarray:
    """The table's B/D."""
    return WIDTH_MIN * np.exp(LOG_WIDTH_STEP * np.arange(N_WIDTH))


def table_roughness_axis() -> np.ndarray:
    """The table's s = exp(-0.56 h_min / sigma) (0: smooth surfaces)."""
    return np.linspace(0.0, S_MAX, N_R)


def roughness_of(eps: float, s: float) -> float:
    """sigma / c of the film of eccentricity ratio eps and s = exp(-0.56 h_min / sigma), h_min = c (1 - eps)."""
    return 0.0 if s <= 0.0 else -ROUGH_DECAY * (1.0 - eps) / math.log(s)


@njit(cache=True, error_model="numpy")
def table_scale(eps: float, width: float) -> float:
    """The table stores f (1 - eps^2)^1.5 (1 + (B/D)^2) / (B/D)^3: bounded and smooth on the grid.

    (1 - eps^2)^-1.5 is the growth of the long bearing's squeeze force as eps -> 1; the width factor
    takes out the short bearing's (B/D)^3 and the long bearing's B/D.
    """
    return (1.0 - eps * eps) ** 1.5 * (1.0 + width * width) / (width * width * width)


def table_digest(table: np.ndarray) -> str:
    """First 16 hex digits of the SHA-256 of the table's float64 bytes."""
    return hashlib.sha256(np.ascontiguousarray(table, dtype=np.float64).tobytes()).hexdigest()[:16]


def stored_table() -> np.ndarray | None:
    """The stored table (s x B/D x eps x xi x 2, float64), or None if it is missing or is not the one of
    ``TABLE_DIGEST`` (while scripts/make_film_table.py builds it)."""
    path = Path(__file__).with_name("film_table.npz")
    if not path.exists():
        return None
    with np.load(path) as data:
        core = np.asarray(data["force"], dtype=np.float64)
    if core.shape != (N_R, N_WIDTH, N_U, N_XI, 2) or table_digest(core) != TABLE_DIGEST:
        return None
    return core


def _padded_table() -> np.ndarray:
    """The stored table with one ghost node on each side of each axis (Catmull-Rom needs four nodes).

    xi: mirror images (the component along e is even in xi about 0 and pi, the one ahead odd);
    s, eps and B/D: linear extrapolation.  NaN if there is no table of ``TABLE_DIGEST``.
    """
    core = stored_table()
    padded = (N_R + 2, N_WIDTH + 2, N_U + 2, N_XI + 2, 2)
    if core is None:
        return np.full(padded, np.nan)
    out = np.empty(padded)
    out[1:-1, 1:-1, 1:-1, 1:-1] = core
    mirror = np.array([1.0, -1.0])
    out[1:-1, 1:-1, 1:-1, 0] = core[:, :, :, 1] * mirror
    out[1:-1, 1:-1, 1:-1, -1] = core[:, :, :, -2] * mirror
    out[1:-1, 1:-1, 0] = 2.0 * out[1:-1, 1:-1, 1] - out[1:-1, 1:-1, 2]
    out[1:-1, 1:-1, -1] = 2.0 * out[1:-1, 1:-1, -2] - out[1:-1, 1:-1, -3]
    out[1:-1, 0] = 2.0 * out[1:-1, 1] - out[1:-1, 2]
    out[1:-1, -1] = 2.0 * out[1:-1, -2] - out[1:-1, -3]
    out[0] = 2.0 * out[1] - out[2]
    out[-1] = 2.0 * out[-2] - out[-3]
    return out


# numba freezes global arrays into the compiled code and caches it only for arrays under 1e6 bytes: the smooth
# slice (padded, float64: the smooth film exactly as tabulated) and the rough slices as their difference from it in
# float32 (973 kB; rounding 6e-8 of the roughness's share, far below the interpolation error; exactly 0 at s = 0).
_PADDED = _padded_table()
FINITE_TABLE = np.ascontiguousarray(_PADDED[1])
ROUGH_TABLE = np.ascontiguousarray(_PADDED - _PADDED[1]).astype(np.float32)
del _PADDED


def _couette_table() -> np.ndarray:
    """The Couette factor's nodes (u x log ratio) with one ghost node on each side (linear extrapolation)."""
    u = np.linspace(0.0, 1.0, N_CU)
    ratios = COUETTE_RATIO_MIN * np.exp(LOG_COUETTE_STEP * np.arange(N_CR))
    out = np.empty((N_CU + 2, N_CR + 2))
    out[1:-1, 1:-1] = couette_factor_nodes(1.0 - (1.0 - u) ** 2, ratios, COUETTE_POINTS)
    out[0] = 2.0 * out[1] - out[2]
    out[-1] = 2.0 * out[-2] - out[-3]
    out[:, 0] = 2.0 * out[:, 1] - out[:, 2]
    out[:, -1] = 2.0 * out[:, -2] - out[:, -3]
    return out


COUETTE_TABLE = _couette_table()


@njit(cache=True, error_model="numpy", inline="always")
def _catmull_rom(t: float):
    """Weights of the four nodes i-1, i, i+1, i+2 at the fraction t in [0, 1] of the interval (i, i+1)."""
    t2 = t * t
    t3 = t2 * t
    return (0.5 * (-t3 + 2.0 * t2 - t), 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0), 0.5 * (-3.0 * t3 + 4.0 * t2 + t),
            0.5 * (t3 - t2))


@njit(cache=True, error_model="numpy", inline="always")
def _cell(x: float, n: int):
    """Interval index i in [0, n-2] and fraction t (clamped to [0, 1]) of the node coordinate x."""
    if x <= 0.0:
        return 0, 0.0
    i = int(x)
    if i >= n - 1:
        return n - 2, 1.0
    return i, x - i


@njit(cache=True, error_model="numpy", inline="always")
def _table_cells(eps: float, xi: float, width: float):
    """(factor, sign, (iw, iu, ix), Catmull-Rom weights in B/D, u and xi) of the table's point (eps, xi, B/D)."""
    factor = 1.0
    w = width
    if w < WIDTH_MIN:
        factor = (w / WIDTH_MIN) ** 3
        w = WIDTH_MIN
    elif w > WIDTH_MAX:
        factor = w / WIDTH_MAX
        w = WIDTH_MAX
    sign = 1.0
    x = xi
    if x < 0.0:
        x = -x
        sign = -1.0
    u = 1.0 - math.sqrt(1.0 - eps)
    iu, tu = _cell(u / U_MAX * (N_U - 1), N_U)
    ix, tx = _cell(x / math.pi * (N_XI - 1), N_XI)
    iw, tw = _cell(math.log(w / WIDTH_MIN) / LOG_WIDTH_STEP, N_WIDTH)
    return factor / table_scale(eps, w), sign, iw, iu, ix, _catmull_rom(tw), _catmull_rom(tu), _catmull_rom(tx)


@njit(cache=True, error_model="numpy", inline="always")
def _tricubic(table, iw: int, iu: int, ix: int, ww, wu, wx):
    """Both components of the 4 x 4 x 4 Catmull-Rom sum of ``table`` (B/D x u x xi x 2, padded) from node
    (iw, iu, ix) on."""
    g0 = 0.0
    g1 = 0.0
    for a in range(4):
        for b in range(4):
            wab = ww[a] * wu[b]
            for d in range(4):
                weight = wab * wx[d]
                g0 += weight * table[iw + a, iu + b, ix + d, 0]
                g1 += weight * table[iw + a, iu + b, ix + d, 1]
    return g0, g1


@njit(cache=True, error_model="numpy")
def finite_force(eps: float, xi: float, width: float):
    """Dimensionless film force (f_along_e, f_ahead) of the finite bearing, smooth surfaces: the table's s = 0
    slice, tricubic.

    Catmull-Rom in u = 1 - sqrt(1 - eps), in xi and in log(B/D).  Past eps = 0.99 the scaled force
    of eps = 0.99 is kept (f grows as (1 - eps^2)^-1.5); below B/D = 1/4 the force scales as the short
    bearing's (B/D)^3, above B/D = 4 as the long bearing's B/D.
    """
    scale, sign, iw, iu, ix, ww, wu, wx = _table_cells(eps, xi, width)
    g0, g1 = _tricubic(FINITE_TABLE, iw, iu, ix, ww, wu, wx)
    return g0 * scale, sign * g1 * scale


@njit(cache=True, error_model="numpy", inline="always")
def roughness_coordinate(eps: float, roughness: float) -> float:
    """s = exp(-0.56 h_min / sigma) of the film at eccentricity ratio eps, ``roughness`` = sigma / c (0: smooth)."""
    if roughness <= 0.0:
        return 0.0
    return math.exp(-ROUGH_DECAY * (1.0 - eps) / roughness)


@njit(cache=True, error_model="numpy")
def rough_finite_force(eps: float, xi: float, width: float, roughness: float):
    """Dimensionless film force (f_along_e, f_ahead) of the finite bearing between rough surfaces (Patir and
    Cheng's average flow), ``roughness`` = sigma / c: the smooth film plus the rough slices' difference from it,
    Catmull-Rom in s as well.

    s = 0 (smooth surfaces, or a film so thick that s underflows) is :func:`finite_force` exactly.  Beyond
    s = S_MAX (h_min < sigma / 4, below the film floor's least value) the flow factors of sigma / 4 are kept.
    """
    scale, sign, iw, iu, ix, ww, wu, wx = _table_cells(eps, xi, width)
    g0, g1 = _tricubic(FINITE_TABLE, iw, iu, ix, ww, wu, wx)
    s = roughness_coordinate(eps, roughness)
    if s <= 0.0:
        return g0 * scale, sign * g1 * scale
    ir, tr = _cell(s / S_MAX * (N_R - 1), N_R)
    wr = _catmull_rom(tr)
    r0 = 0.0
    r1 = 0.0
    for m in range(4):
        h0, h1 = _tricubic(ROUGH_TABLE[ir + m], iw, iu, ix, ww, wu, wx)
        r0 += wr[m] * h0
        r1 += wr[m] * h1
    return g0 * scale + r0 * scale, sign * g1 * scale + sign * r1 * scale


@njit(cache=True, error_model="numpy")
def couette_factor(eps: float, roughness: float) -> float:
    """The rough film's Couette torque over the smooth film's (Patir and Cheng's phi_f averaged over the film,
    :func:`weftsim.physics.flow_factors.couette_factor_at`) at eccentricity ratio eps and ``roughness`` = sigma / c
    > 0: the table ``COUETTE_TABLE`` in u = 1 - sqrt(1 - eps) and log(h_min / sigma), bicubic; thicker than
    COUETTE_RATIO_MAX its closed-form tail, thinner than COUETTE_RATIO_MIN the factor of that film kept."""
    ratio = (1.0 - eps) / roughness
    if ratio >= COUETTE_RATIO_MAX:
        return couette_factor_tail(eps, ratio)
    ratio = max(ratio, COUETTE_RATIO_MIN)
    iu, tu = _cell((1.0 - math.sqrt(max(1.0 - eps, 0.0))) * (N_CU - 1), N_CU)
    ir, tr = _cell(math.log(ratio / COUETTE_RATIO_MIN) / LOG_COUETTE_STEP, N_CR)
    wu = _catmull_rom(tu)
    wr = _catmull_rom(tr)
    total = 0.0
    for a in range(4):
        row = 0.0
        for b in range(4):
            row += wr[b] * COUETTE_TABLE[iu + a, ir + b]
        total += wu[a] * row
    return total


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


@njit(cache=True, error_model="numpy", inline="always")
def _short_integrals(eps: float, xi: float, half_width: float, lo: float, hi: float):
    """f of the axially integrated short-bearing pressure 8 (B/D)^3 cos(phi - xi) / H^3 over phi in [lo, hi]."""
    a = sommerfeld_angle(lo, eps)
    b = sommerfeld_angle(hi, eps)
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
def short_force(eps: float, xi: float, half_width: float):
    """Dimensionless film force f = (f_along_e, f_ahead) of the short bearing, Gumbel cavitation.

    ``half_width`` = B/D (zeta runs over [-B/D, B/D]).  The axially integrated pressure is
    8 (B/D)^3 cos(phi - xi) / H^3, kept over the half circle abs(phi - xi) < pi/2 where it is positive.
    """
    return _short_integrals(eps, xi, half_width, xi - 0.5 * math.pi, xi + 0.5 * math.pi)


@njit(cache=True, error_model="numpy")
def short_half_force(eps: float, xi: float, half_width: float):
    """The short bearing of the multibody papers (``MODEL_SHORT_HALF``): (f_along_e, f_ahead).

    Flores, Ambrosio, Claro and Lankarani integrate the wedge and the squeeze pressure over one
    fixed half of the film, the half where the wedge's pressure is positive (phi in [-pi, 0] for
    omega_j + omega_b - 2 dgamma/dt >= 0, i.e. sin xi <= 0; [0, pi] otherwise), without clipping the
    squeeze pressure.  Their closed forms follow: with w the effective speed,
    F_r = -(eta R B^3 / (2 c^2)) (2 eps^2 abs(w) / (1-eps^2)^2 + pi (1 + 2 eps^2) deps/dt / (1-eps^2)^2.5),
    F_t = (eta R B^3 / (2 c^2)) (pi eps w / (2 (1-eps^2)^1.5) + 4 eps deps/dt / (1-eps^2)^2) for w >= 0;
    a journal leaving the wall is pulled back by a pressure below ambient.

    Their half flips with the sign of w, and with it the squeeze's tangential force (the term
    4 eps deps/dt): a jump, at w = 0, that a journal squeezed straight out of the centre rides (w stays
    at 0, the force chatters between the halves) and Newton cannot converge on at any step (measured in
    the slider-crank of examples/plot_lubricated_slider_crank.py: Exudyn stops at t = 21 us, eps =
    0.007, at h = 2e-6 s down to 1e-8 s).  Here the halves are blended linearly over 0 < sin xi <
    ``SHORT_HALF_BAND`` (= 0.1: where the wedge velocity is under a tenth of the squeeze velocity and
    the paper's choice of half is arbitrary); outside that band, and at pure squeeze (sin xi = 0), the
    forces are the paper's.  Narrower bands fail later in the same run (1e-2: at 1.7 crank revolutions).
    """
    blend = (math.sin(xi) - 1e-9) / SHORT_HALF_BAND  # no wedge (sin xi = 1e-16 at xi = pi from atan2): w > 0
    if blend <= 0.0:
        return _short_integrals(eps, xi, half_width, -math.pi, 0.0)
    if blend >= 1.0:
        return _short_integrals(eps, xi, half_width, 0.0, math.pi)
    fa0, ft0 = _short_integrals(eps, xi, half_width, -math.pi, 0.0)
    fa1, ft1 = _short_integrals(eps, xi, half_width, 0.0, math.pi)
    return fa0 + blend * (fa1 - fa0), ft0 + blend * (ft1 - ft0)


@njit(cache=True, error_model="numpy", inline="always")
def _long_coefficients(eps: float, xi: float):
    """Coefficients (a1, b1, a2, d) of the long bearing's pressure, see :func:`_long_pressure`."""
    k = 1.0 - eps * eps
    root = math.sqrt(k)
    scale = 1.0 / (k * k * root)
    sx = math.sin(xi)
    cx = math.cos(xi)
    c0 = -36.0 * eps * sx / (2.0 + eps * eps)
    a1 = (12.0 * sx * (1.0 + eps * eps) + 2.0 * eps * c0) * scale
    b1 = 12.0 * cx * root * scale
    a2 = (3.0 * eps * sx + 0.25 * eps * eps * c0) * scale
    d = -6.0 * eps * cx * root * scale
    return a1, b1, a2, d


@njit(cache=True, error_model="numpy", inline="always")
def _long_pressure_at(psi: float, a1: float, b1: float, a2: float, d: float) -> float:
    s = math.sin(psi)
    c = math.cos(psi)
    return a1 * s + b1 * (c + 1.0) + 2.0 * a2 * s * c + d * s * s


@njit(cache=True, error_model="numpy")
def _long_pressure(psi: float, eps: float, xi: float) -> float:
    """Full-Sommerfeld pressure of the long bearing at Sommerfeld angle psi, zero at the thickest film.

    H^3 dP/dphi = -12 sin(phi - xi) + C with C = -36 eps sin(xi) / (2 + eps^2) (periodic P), integrated
    from phi = psi = pi through Sommerfeld's substitution: the terms linear in psi cancel, leaving
    P = (a1 sin psi + b1 (cos psi + 1) + a2 sin 2psi + d sin^2 psi) with
    a1 = 12 sin xi (1 + eps^2) + 2 eps C, b1 = 12 cos xi sqrt(1 - eps^2), a2 = 3 eps sin xi + eps^2 C / 4,
    d = -6 eps cos xi sqrt(1 - eps^2), all over (1 - eps^2)^2.5.
    """
    a1, b1, a2, d = _long_coefficients(eps, xi)
    return _long_pressure_at(psi, a1, b1, a2, d)


LONG_SAMPLES = 32  # sign changes of the (degree-2 trigonometric) pressure are found on this many intervals
LONG_ROOT_TOL = 1e-13  # rad: the edges of the pressure lobe (Illinois' regula falsi)
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(24)


@njit(cache=True, error_model="numpy", inline="always")
def _long_edge(a: float, b: float, fa: float, fb: float, a1: float, b1: float, a2: float, d: float) -> float:
    """Zero of the long bearing's pressure between a and b (signs of fa and fb differ): Illinois."""
    side = 0
    for _ in range(60):
        x = b - fb * (b - a) / (fb - fa)
        fx = _long_pressure_at(x, a1, b1, a2, d)
        if (fx > 0.0) == (fb > 0.0):
            b, fb = x, fx
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = x, fx
            if side == 1:
                fb *= 0.5
            side = 1
        if abs(b - a) < LONG_ROOT_TOL or fx == 0.0:
            return x
    return 0.5 * (a + b)


@njit(cache=True, error_model="numpy", inline="always")
def _long_lobe(lo: float, hi: float, eps: float, a1: float, b1: float, a2: float, d: float):
    """Integral of P (cos phi, sin phi) dphi over psi in [lo, hi], 24-point Gauss-Legendre in psi."""
    root = math.sqrt(1.0 - eps * eps)
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    f0 = 0.0
    f1 = 0.0
    for g in range(_GAUSS_X.size):
        q = mid + half * _GAUSS_X[g]
        den = 1.0 + eps * math.cos(q)
        weight = _long_pressure_at(q, a1, b1, a2, d) * half * _GAUSS_W[g] * root / (den * den)
        f0 += weight * (math.cos(q) + eps)
        f1 += weight * root * math.sin(q)
    return f0, f1


@njit(cache=True, error_model="numpy")
def long_force(eps: float, xi: float, half_width: float):
    """Dimensionless film force (f_along_e, f_ahead) of the long bearing, Gumbel cavitation.

    The full-Sommerfeld pressure (:func:`_long_pressure`, zero at psi = +-pi) where positive, times
    the length 2 B/D: its sign changes are bracketed on LONG_SAMPLES intervals of psi, located by
    Illinois' method, and each positive lobe integrated by Gauss-Legendre (dphi = sqrt(1 - eps^2)
    dpsi / (1 + eps cos psi), cos phi = (cos psi + eps) / (1 + eps cos psi)).
    """
    a1, b1, a2, d = _long_coefficients(eps, xi)
    step = TWO_PI / LONG_SAMPLES
    f0 = 0.0
    f1 = 0.0
    prev = -math.pi + 0.5 * step
    p_prev = _long_pressure_at(prev, a1, b1, a2, d)
    inside = p_prev > 0.0
    lo = -math.pi
    for n in range(1, LONG_SAMPLES):
        psi = -math.pi + (n + 0.5) * step
        p = _long_pressure_at(psi, a1, b1, a2, d)
        if (p > 0.0) != inside:
            edge = _long_edge(prev, psi, p_prev, p, a1, b1, a2, d)
            if inside:
                g0, g1 = _long_lobe(lo, edge, eps, a1, b1, a2, d)
                f0 += g0
                f1 += g1
            lo = edge
            inside = not inside
        prev = psi
        p_prev = p
    if inside:
        g0, g1 = _long_lobe(lo, math.pi, eps, a1, b1, a2, d)
        f0 += g0
        f1 += g1
    return -2.0 * half_width * f0, -2.0 * half_width * f1


@njit(cache=True, error_model="numpy")
def film_force(ey: float, ez: float, vy: float, vz: float, omega_j: float, omega_b: float, c: float,
               radius: float, length: float, viscosity: float, model: int):
    """Film force on the journal and film friction torques between smooth surfaces: (fy, fz, torque_j, torque_b).

    Parameters
    ----------
    ey, ez : float
        Eccentricity, journal centre - bearing centre, m (abs(e) < c).
    vy, vz : float
        Its rate, m/s.
    omega_j, omega_b : float
        Angular velocities of journal and bearing about the joint axis x, rad/s.
    c, radius, length : float
        Radial clearance, journal radius, bearing length, m.
    viscosity : float
        Dynamic viscosity, Pa s.
    model : int
        ``MODEL_FINITE``, ``MODEL_SHORT``, ``MODEL_LONG`` or ``MODEL_SHORT_HALF`` (any other: short).

    Returns
    -------
    fy, fz : float
        Film force on the journal, N.
    torque_j, torque_b : float
        Film friction torques about +x on journal and bearing, N m.
    """
    return rough_film_force(ey, ez, vy, vz, omega_j, omega_b, c, radius, length, viscosity, model, 0.0)


@njit(cache=True, error_model="numpy")
def couette_torque(eps: float, omega_j: float, omega_b: float, c: float, radius: float, length: float,
                   viscosity: float, model: int, roughness: float) -> float:
    """The Couette (Petroff) part of the film's torque on the journal, N m (module docstring), times
    :func:`couette_factor` for the finite film between rough surfaces (``roughness`` = sigma, m, > 0)."""
    couette = viscosity * radius ** 3 * length * (omega_b - omega_j) * TWO_PI / (c * math.sqrt(1.0 - eps * eps))
    if model == MODEL_FINITE and roughness > 0.0:
        couette *= couette_factor(eps, roughness / c)
    return couette


@njit(cache=True, error_model="numpy")
def rough_film_force(ey: float, ez: float, vy: float, vz: float, omega_j: float, omega_b: float, c: float,
                     radius: float, length: float, viscosity: float, model: int, roughness: float):
    """:func:`film_force` between rough surfaces of combined RMS roughness ``roughness`` (sigma, m; 0: smooth).

    ``MODEL_FINITE``: Patir and Cheng's average-flow film (:func:`rough_finite_force`) and their shear factor on
    the Couette torque (:func:`couette_factor`, tabulated); the
    pressure-gradient torque -(e x F)_x / 2 keeps its smooth form.  The other models stay smooth.  sigma = 0
    is the smooth film bit for bit.
    """
    omega_m = 0.5 * (omega_j + omega_b)
    # Booker's squeeze velocity V = e_dot - omega_m x e  (x e = (-ez, ey)).
    sy = vy + omega_m * ez
    sz = vz - omega_m * ey
    e = math.sqrt(ey * ey + ez * ez)
    speed = math.sqrt(sy * sy + sz * sz)
    eps = e / c
    rough = model == MODEL_FINITE and roughness > 0.0
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
        if rough:
            f_along, f_ahead = rough_finite_force(eps, xi, half_width, roughness / c)
        elif model == MODEL_FINITE:
            f_along, f_ahead = finite_force(eps, xi, half_width)
        elif model == MODEL_LONG:
            f_along, f_ahead = long_force(eps, xi, half_width)
        elif model == MODEL_SHORT_HALF:
            f_along, f_ahead = short_half_force(eps, xi, half_width)
        else:
            f_along, f_ahead = short_force(eps, xi, half_width)
        ratio = radius / c
        scale = viscosity * radius * radius * ratio * ratio * speed / c
        fy = scale * (f_along * ny - f_ahead * nz)
        fz = scale * (f_along * nz + f_ahead * ny)
    couette = couette_torque(eps, omega_j, omega_b, c, radius, length, viscosity, model, roughness)
    pressure = -0.5 * (ey * fz - ez * fy)
    return fy, fz, couette + pressure, -couette + pressure
