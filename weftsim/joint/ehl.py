"""The steadily loaded plain bearing with an elastic film (EHL): ``weftsim bearing`` with ``elastic_film = true``.

A journal of radius R spinning at omega in a still bearing (radial clearance c, length L) carries a steady load W.
The gap between the deformed surfaces is (:mod:`weftsim.joint.elastic_film`, plane strain under the axially
averaged pressure)

    h(phi) = c H(phi),   H = 1 - eps cos phi + D(phi),   D = (Gamma s)(phi),   s = mean_z P + P_a,

phi from the line of centres in the direction of the journal's surface motion, eps = abs(e) / c (which may pass
1: the flattened surfaces keep a film where the rigid ones would touch), Gamma the pair's compliance in the
pressure scale p_s = eta (R/c)^2 omega / 2 over c, s the total pressure the surfaces carry: the film's P of
Reynolds' equation on that gap (:func:`weftsim.joint.reynolds.solve_gap`: Patir and Cheng's average flow,
Swift-Stieber cavitation, the film fed at its thickest line, as the kernel's film) and the asperities' Greenwood-
Tripp pressure on the local gap less the summits' mean height delta (p_a = K E* F_5/2((h - delta) / sigma),
:mod:`weftsim.physics.asperity`; delta as MBDyn's "asperity mean height" of its hydrodynamic plain bearing
element, whose contact pressure takes H = h / sigma - delta / sigma).  The point solves, for the n_phi values of s
and eps,

    s - (mean_z P(H) + P_a(H)) = 0,    abs(f(H)) - W / (p_s R^2) = 0,    f = -integral (P + P_a) n dphi dzeta,

by Newton's method with a backtracking line search: the film's P is the exact complementarity solution on each
iterate's gap, and its derivative in the gap that of the linear system on its film (the active set held), K_AA
dP = -(d(K P - q)/dH) dH: one sparse factorisation and n_phi + 1 solves per iteration.  It starts from the rigid
film (D = 0) at the kernel's eccentricity, and where Newton does not converge from there it continues in the
compliance (Gamma scaled by 1/8, 1/4, 1/2, 1); a caller that solves neighbouring points in turn (the heat
balance's temperatures, the Stribeck curve's speeds) passes ``warm`` and Newton starts from the last converged
pressures and eccentricity instead, falling back to the cold start when that fails.  The Jacobian is formed at
accepted iterates only.  Converged when the pressure residual is below ``TOLERANCE`` of the
mean pressure W / (2 R L) and the load's below ``TOLERANCE`` of W; otherwise one line naming the point refuses it.

The friction torque on the journal (reported positive, as ``weftsim bearing``'s):

- Couette shear over the whole film, eta omega R^3 L / c integral phi_f(h / sigma) / H dphi (Patir and Cheng's
  shear factor, :func:`weftsim.physics.flow_factors.shear_factor`), on a uniform grid of
  :data:`weftsim.joint.elastic_film.FINE_POINTS` points;
- the pressure gradient's shear, -(R^2 / 2) integral p dh/dphi dphi dzeta (for the rigid film the kernel's
  (e x F)_x / 2, :mod:`weftsim.physics.film`);
- boundary friction mu_b R times the asperities' normal load integral p_a dA (at the journal's surface).

Surfaces (``Pair.surfaces``, the keys ``surface_roughness_um`` and ``peklenik_numbers``): Patir and Cheng's
average flow of anisotropic, unlike surfaces (:class:`weftsim.physics.flow_factors.SurfacePair`, journal first):
phi_z H^3 on the axial fluxes and phi_x H^3 on the circumferential ones, H = h / sigma on the surfaces' composite
sigma (also in Phi and phi_f; the asperities keep the contact's sigma), and the shear flow of the moving journal
against the still bearing, (U_1 - U_2) / 2 sigma d phi_s / dx = U_m sigma d phi_s / dx with U_1 = omega R, U_2 = 0,
so that the source is -12 (Phi + phi_s') dH/dphi (:func:`weftsim.joint.reynolds.rotation_source`): with the rougher
surface still (phi_s < 0, rising to 0 as the film thickens) the shear flow falls along the converging gap and adds
pressure.  Unset: isotropic alike surfaces on ``sigma``, the film as before bit for bit.

With Gamma = 0 (``rigid=True``) the same solve is the rigid film of the kernel's discretisation, solved directly
instead of interpolated from the kernel's table (tests/test_ehl.py measures the difference).  Not modelled:
mass-conserving cavitation, Patir and Cheng's shear-stress factor phi_fs of unlike surfaces, the deformation's
variation along the axis, the housing's stiffness beyond an infinite plate.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import SceneError

if TYPE_CHECKING:
    from weftsim.physics.flow_factors import SurfacePair

TOLERANCE = 1e-9  # relative residuals of the pressure (to the mean pressure) and the load at convergence
MAX_ITERATIONS = 60
CONTINUATION = (0.125, 0.25, 0.5, 1.0)  # compliance fractions tried in turn when the direct start fails


@dataclass(frozen=True)
class ElasticPoint:
    """One steady operating point of the elastic film (SI units; module docstring)."""

    eccentricity_ratio: float
    attitude_angle_deg: float
    min_film_m: float
    film_force_n: float
    asperity_load_n: float
    carried_load_n: float  # abs(film force + asperity force): the load, to the residual
    friction_torque_nm: float
    couette_torque_nm: float
    pressure_torque_nm: float
    boundary_torque_nm: float
    peak_pressure_pa: float
    max_opening_m: float
    iterations: int
    residual: float

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Pair:
    """What the elastic point needs of a lubricated joint (SI units)."""

    radius: float
    bearing_radius: float
    clearance: float
    length: float
    sigma: float
    asperity_coef: float  # K E*, Pa
    boundary_mu: float
    summit_height: float  # delta, m
    moduli: tuple[float, float, float, float]  # E_j, nu_j, E_b, nu_b
    pressure_viscosity: float = 0.0  # Barus' alpha, 1/Pa
    surfaces: SurfacePair | None = None  # weftsim.physics.flow_factors.SurfacePair (journal, bearing); None: isotropic, alike

    @property
    def flow_sigma(self) -> float:
        """The roughness of the average flow's H = h / sigma: the surfaces' composite, or ``sigma``."""
        return self.sigma if self.surfaces is None else self.surfaces.sigma

    @classmethod
    def of(cls, joint) -> Pair:
        from weftsim.joint.contact import make_law
        from weftsim.physics.joint import ASPERITY_COEF, joint_parameters

        lub = joint.lubrication
        prm = joint_parameters(joint, make_law(joint))  # the kernel's block (not steady.joint_block: no cycle)
        surfaces = None
        if lub.surface_roughness is not None or lub.peklenik_numbers is not None:
            from weftsim.physics.flow_factors import SurfacePair

            half = lub.roughness / math.sqrt(2.0)
            surfaces = SurfacePair(lub.surface_roughness or (half, half), lub.peklenik_numbers or (1.0, 1.0))
        return cls(joint.journal_radius, joint.bearing_radius, joint.clearance, joint.bearing_length, lub.roughness,
                   float(prm[ASPERITY_COEF]), lub.boundary_friction_coefficient, lub.summit_height,
                   (joint.journal_material.youngs_modulus, joint.journal_material.poisson_ratio,
                    joint.bearing_material.youngs_modulus, joint.bearing_material.poisson_ratio),
                   lub.pressure_viscosity, surfaces)


def _f52(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """F_5/2(H) and its derivative, vectorised (:func:`weftsim.physics.asperity.f52`'s law)."""
    from weftsim.physics.asperity import F52_EXPONENT, F52_SCALE, H_CUTOFF

    base = np.maximum(H_CUTOFF - x, 0.0)
    return F52_SCALE * base**F52_EXPONENT, -F52_EXPONENT * F52_SCALE * base ** (F52_EXPONENT - 1.0)


def _conductance_slope(gap: np.ndarray, roughness: float, surfaces=None, across: bool = False) -> np.ndarray:
    """d(H^3 phi_x(H / r)) / dH (:func:`weftsim.joint.reynolds.conductance_of`); with ``surfaces`` phi_x or
    (``across``) phi_z of :class:`weftsim.physics.flow_factors.SurfacePair`."""
    from weftsim.physics.flow_factors import PRESSURE_C, PRESSURE_R

    if roughness <= 0.0:
        return 3.0 * gap**2
    if surfaces is not None:
        value, rate = surfaces.pressure(gap / roughness, across, slope=True)
        return 3.0 * gap**2 * value + gap**3 * rate / roughness
    decay = np.exp(-PRESSURE_R * gap / roughness)
    return 3.0 * gap**2 * (1.0 - PRESSURE_C * decay) + gap**3 * PRESSURE_C * PRESSURE_R / roughness * decay


class _Film:
    """The discrete problem of one operating point: grid, compliance, scales (module docstring)."""

    def __init__(self, pair: Pair, load: float, omega: float, viscosity: float, eps0: float, rigid: bool,
                 grid: tuple[int, int]):
        from weftsim.joint.elastic_film import FINE_POINTS, film_compliance
        from weftsim.joint.reynolds import _angles
        from weftsim.physics.lubricated import FILM_WALL_RATIO

        self.pair, self.n_zeta = pair, grid[1]
        c, radius = pair.clearance, pair.radius
        self.nodes, self.faces = _angles(min(eps0, 0.99), grid[0])
        self.half_width = 0.5 * pair.length / radius
        self.scale = viscosity * (radius / c) ** 2 * 0.5 * omega  # p_s, Pa
        self.load = load / (self.scale * radius**2)
        self.r = pair.sigma / c  # the asperities' (and the wall's) roughness
        self.r_flow = pair.flow_sigma / c  # the average flow's
        self.surfaces = pair.surfaces
        self.wall = FILM_WALL_RATIO * self.r
        self.offset = pair.summit_height / pair.sigma
        self.asperity = pair.asperity_coef / self.scale
        self.alpha_full = pair.pressure_viscosity * self.scale  # Barus' alpha in the pressure scale
        n = self.nodes.size
        if rigid:
            self.gamma = (np.zeros((n, n)),) * 3
        else:
            comp = film_compliance(self.nodes, self.faces, radius, pair.bearing_radius, *pair.moduli)
            k = self.scale / c
            self.gamma = (k * comp.nodes, k * comp.faces, k * comp.slope)
        fine = -math.pi + 2.0 * math.pi * np.arange(FINE_POINTS) / FINE_POINTS
        self.fine = fine
        if rigid:
            self.gamma_fine = np.zeros((fine.size, n))
        else:
            from weftsim.joint.elastic_film import _periodic_interpolation, pair_gain

            gains = pair_gain(np.arange(FINE_POINTS // 2 + 1), radius, pair.bearing_radius, *pair.moduli)
            gains[-1] = 0.0
            up = _periodic_interpolation(self.nodes, fine)
            self.gamma_fine = (self.scale / c) * np.fft.irfft(gains[:, None] * np.fft.rfft(up, axis=0),
                                                              n=FINE_POINTS, axis=0)
        self.fraction = 1.0  # the continuation's share of the compliance and of alpha
        self.active = None

    @property
    def alpha(self) -> float:
        return self.fraction * self.alpha_full

    def heights(self) -> np.ndarray:
        """The cells' heights in zeta (half a cell at the mid-plane; :func:`weftsim.joint.reynolds.assemble`)."""
        dzeta = np.full(self.n_zeta, self.half_width / self.n_zeta)
        dzeta[0] *= 0.5
        return dzeta

    def gaps(self, s: np.ndarray, eps: float):
        gn, gf, gd = self.gamma
        f = self.fraction
        return (1.0 - eps * np.cos(self.nodes) + f * (gn @ s), 1.0 - eps * np.cos(self.faces) + f * (gf @ s),
                eps * np.sin(self.nodes) + f * (gd @ s))

    def evaluate(self, s: np.ndarray, eps: float, jacobian: bool):
        """Residuals (pressure, load) at (s, eps), the state, and (if asked) the Jacobian."""
        from weftsim.joint.reynolds import solve_gap

        hn, hf, hd = self.gaps(s, eps)
        hn_film, hf_film = np.maximum(hn, self.wall), np.maximum(hf, self.wall)
        _, _, reduced, matrix, volume = solve_gap(self.nodes, hn_film, hf_film, hd, self.half_width, self.n_zeta,
                                                  self.r_flow, True, self.active, self.surfaces)
        self.active = reduced > 0.0
        # Barus: the film's pressure from the reduced pressure Q that Reynolds' equation of eta_0 gives
        # (Q = (1 - exp(-alpha p)) / alpha), P = -ln(1 - alpha Q) / alpha; no finite P where alpha Q >= 1.
        if self.alpha > 0.0:
            inner = 1.0 - self.alpha * reduced
            if inner.min() <= 0.0:
                res = np.full(s.size + 1, np.inf)
                return (res, None, None) if jacobian else (res, None)
            field, stretch = -np.log(inner) / self.alpha, 1.0 / inner
        else:
            field, stretch = reduced, None
        dzeta = self.heights()
        width = volume[:, 0] / dzeta[0]
        mean = field @ dzeta / self.half_width
        load = 2.0 * field * volume
        f_along = -float(np.sum(load * np.cos(self.nodes)[:, None]))
        f_ahead = -float(np.sum(load * np.sin(self.nodes)[:, None]))
        fa, dfa = _f52(hn / self.r - self.offset)
        p_a = self.asperity * fa
        ring = 2.0 * self.half_width * width  # the asperity pressure's area weight per node (both halves)
        f_along -= float(np.sum(ring * p_a * np.cos(self.nodes)))
        f_ahead -= float(np.sum(ring * p_a * np.sin(self.nodes)))
        force = math.hypot(f_along, f_ahead)
        res = np.concatenate((s - (mean + p_a), [force - self.load]))
        state = {"hn": hn, "hd": hd, "field": field, "reduced": reduced, "volume": volume, "p_a": p_a, "ring": ring, "width": width,
                 "force": (f_along, f_ahead),
                 "parts": (hn, hf, hd, hn_film, hf_film, reduced, stretch, matrix, volume, dzeta, width, dfa, ring,
                           (f_along, f_ahead), force)}
        if not jacobian:
            return res, state
        return res, state, self.jacobian(state)

    def jacobian(self, state: dict) -> np.ndarray:
        """The Jacobian at the point :meth:`evaluate` gave ``state`` of (at this compliance fraction)."""
        return self._jacobian(*state["parts"])

    def _jacobian(self, hn, hf, hd, hn_film, hf_film, field, stretch, matrix, volume, dzeta, width, dfa, ring,
                  forces, force):
        from weftsim.joint.reynolds import _film_pressure
        from weftsim.physics.flow_factors import contact_factor

        n, nz = field.shape
        dz = self.half_width / nz
        gn, gf, gd = (self.fraction * g for g in self.gamma)
        # Columns of the unknowns x = (s, eps): the gap's derivatives at nodes, faces and its slope.
        x_n = np.column_stack((gn, -np.cos(self.nodes)))
        x_f = np.column_stack((gf, -np.cos(self.faces)))
        x_d = np.column_stack((gd, np.sin(self.nodes)))
        r = self.r_flow
        clamp_n, clamp_f = hn > self.wall, hf > self.wall
        # d(K P)/d(face conductance k): rows of line k (+) and line k+1 (-).
        step = np.diff(np.concatenate((self.nodes, [self.nodes[0] + 2.0 * math.pi])))
        flux = (field - np.roll(field, -1, axis=0)) * dzeta[None, :] / step[:, None]
        dcf = _conductance_slope(hf_film, r, self.surfaces) * clamp_f
        face = (flux * dcf[:, None])[:, :, None] * x_f[:, None, :]
        b = face - np.roll(face, 1, axis=0)
        # d(K P)/d(node conductance i): the axial fluxes of line i.
        ax = np.zeros_like(field)
        ax[:, :-1] = field[:, :-1] - field[:, 1:]
        ax[:, -1] = field[:, -1]
        ax *= (width / dz)[:, None]
        row = ax.copy()
        row[:, 1:] -= ax[:, :-1]
        dcn = _conductance_slope(hn_film, r, self.surfaces, across=True) * clamp_n
        coef_n = row * dcn[:, None]
        # the source q = -12 (Phi(H / r) + phi_s'(H / r)) H' vol: minus its derivatives
        if r > 0.0:
            phi = contact_factor(hn_film / r)
            density = np.exp(-0.5 * (hn_film / r) ** 2) / math.sqrt(2.0 * math.pi) / r * clamp_n
            if self.surfaces is not None:
                phi = phi + self.surfaces.shear_flow(hn_film / r, 1)
                density = density + self.surfaces.shear_flow(hn_film / r, 2) / r * clamp_n
        else:
            phi, density = np.ones(n), np.zeros(n)
        coef_n = coef_n + 12.0 * (density * hd)[:, None] * volume
        coef_d = 12.0 * phi[:, None] * volume
        b += coef_n[:, :, None] * x_n[:, None, :] + coef_d[:, :, None] * x_d[:, None, :]
        b = b.reshape(n * nz, n + 1)
        active = field.ravel() > 0.0
        dp = -_film_pressure(matrix, active, b, nz)  # K_AA dP_A = -b_A (banded Cholesky on the film's strip)
        dp = dp.reshape(n, nz, n + 1)
        if stretch is not None:  # dP = dQ / (1 - alpha Q)
            dp *= stretch[:, :, None]
        dmean = np.einsum("ijk,j->ik", dp, dzeta) / self.half_width
        dpa = (self.asperity * dfa / self.r)[:, None] * x_n
        top = -(dmean + dpa)
        top[:, :n] += np.eye(n)
        cos, sin = np.cos(self.nodes), np.sin(self.nodes)
        d_along = -2.0 * np.einsum("ijk,ij,i->k", dp, volume, cos) - (ring * cos) @ dpa
        d_ahead = -2.0 * np.einsum("ijk,ij,i->k", dp, volume, sin) - (ring * sin) @ dpa
        bottom = (forces[0] * d_along + forces[1] * d_ahead) / force
        return np.vstack((top, bottom))

    def norm(self, res: np.ndarray) -> float:
        mean = self.load / (4.0 * self.half_width)  # the projected pressure, dimensionless
        return max(float(np.max(np.abs(res[:-1]))) / mean, abs(float(res[-1])) / self.load)


def _newton(film: _Film, s: np.ndarray, eps: float):
    """Newton with backtracking on (s, eps) at the film's current compliance fraction; (s, eps, its, norm).

    The Jacobian is formed at accepted iterates only (the line search's trials need the residual alone)."""
    res, state = film.evaluate(s, eps, False)
    norm = film.norm(res)
    if state is None:
        return s, eps, 0, norm
    jac = film.jacobian(state)
    for it in range(1, MAX_ITERATIONS + 1):
        step = np.linalg.solve(jac, -res)
        alpha = 1.0
        while True:
            s_new, eps_new = s + alpha * step[:-1], eps + alpha * step[-1]
            res_new, state_new = film.evaluate(s_new, eps_new, False)
            norm_new = film.norm(res_new)
            if norm_new < norm or (alpha < 1e-3 and state_new is not None):
                break
            if alpha < 1e-6:
                return s, eps, it, norm
            alpha *= 0.5
        s, eps, res, norm = s_new, eps_new, res_new, norm_new
        if norm <= TOLERANCE:
            return s, eps, it, norm
        jac = film.jacobian(state_new)
    return s, eps, MAX_ITERATIONS, norm


def elastic_point(pair: Pair, load: float, omega: float, viscosity: float, eps0: float, rigid: bool = False,
                  grid: tuple[int, int] | None = None, warm: dict | None = None) -> ElasticPoint:
    """The :class:`ElasticPoint` of ``pair`` under ``load`` (N) at journal speed ``omega`` (rad/s), viscosity
    ``viscosity`` (Pa s), from the rigid film's eccentricity ratio ``eps0`` (the kernel's,
    :func:`weftsim.joint.steady.steady_point`); ``rigid``: no deformation (Gamma = 0).  Refuses (SceneError, one
    line) a point Newton does not converge on.  ``grid``: (n_phi, n_zeta) of the Reynolds grid (default the
    kernel table's, :data:`weftsim.joint.reynolds.N_PHI` x ``N_ZETA``).

    ``warm``: a dict the caller keeps between neighbouring points (the heat balance's temperatures): the converged
    solution is left in it, and a later call starts Newton from it (its pressures, in pascals, interpolated onto
    this point's nodes; its eccentricity) before the cold start below, which it falls back to.  Only the start
    differs: the grid, the equations and the tolerance are the cold start's, so the point agrees with it to the
    tolerance (tests/test_ehl.py)."""
    from weftsim.joint.reynolds import N_PHI, N_ZETA
    from weftsim.physics.flow_factors import shear_factor

    film = _Film(pair, load, omega, viscosity, eps0, rigid, (N_PHI, N_ZETA) if grid is None else grid)
    n = film.nodes.size
    total, norm = 0, math.inf
    if warm and not rigid and warm["nodes"].size == n:
        film.active = None
        start = np.interp(film.nodes, warm["nodes"], warm["pressure_pa"], period=2.0 * math.pi) / film.scale
        s, eps, total, norm = _newton(film, start, warm["eps"])
    if norm > TOLERANCE:
        film.fraction = 0.0  # the rigid isoviscous film's pressure starts the iteration
        film.active = None
        _, state = film.evaluate(np.zeros(n), eps0, False)
        s0 = state["field"] @ film.heights() / film.half_width + state["p_a"]
        film.fraction, film.active = 1.0, None
        s, eps, its, norm = _newton(film, s0, eps0)
        total += its
        if norm > TOLERANCE and not rigid:
            s, eps = s0, eps0
            for fraction in CONTINUATION:
                film.fraction = fraction
                film.active = None
                s, eps, its, norm = _newton(film, s, eps)
                total += its
                if norm > TOLERANCE:
                    break
    if norm > TOLERANCE:
        raise SceneError(f"bearing: the elastic film does not converge at {load / 1e3:.4g} kN, "
                         f"{omega * 30.0 / math.pi:.4g} rpm (residual {norm:.2g} after {total} Newton iterations)")
    if warm is not None and not rigid:
        warm.update(nodes=film.nodes, pressure_pa=s * film.scale, eps=float(eps))
    res, state = film.evaluate(s, eps, False)
    c, radius = pair.clearance, pair.radius
    f_along, f_ahead = state["force"]
    # film and asperity forces apart
    film_along = -2.0 * float(np.sum(state["field"] * state["volume"] * np.cos(film.nodes)[:, None]))
    film_ahead = -2.0 * float(np.sum(state["field"] * state["volume"] * np.sin(film.nodes)[:, None]))
    ring, p_a = state["ring"], state["p_a"]
    asp = math.hypot(float(np.sum(ring * p_a * np.cos(film.nodes))), float(np.sum(ring * p_a * np.sin(film.nodes))))
    scale_f = film.scale * radius**2
    # Couette on the uniform fine grid (the gap there from the same compliance)
    fine = film.fine
    h_fine = 1.0 - eps * np.cos(fine) + film.gamma_fine @ s
    h_fine = np.maximum(h_fine, film.wall)
    if pair.sigma > 0.0:
        phi_f = np.array([shear_factor(h / film.r_flow) for h in h_fine])
    else:
        phi_f = np.ones_like(h_fine)
    couette = viscosity * omega * radius**3 * pair.length / c * float(np.mean(phi_f / h_fine)) * 2.0 * math.pi
    if film.alpha > 0.0:  # the film's viscosity exp(alpha p) over eta_0 where it is pressed: its excess on the nodes
        hn = np.maximum(state["hn"], film.wall)
        phi_n = np.array([shear_factor(h / film.r_flow) for h in hn]) if pair.sigma > 0.0 else np.ones_like(hn)
        excess = np.expm1(film.alpha * state["field"]) * (phi_n / hn)[:, None] * state["volume"]
        couette += viscosity * omega * radius**3 * pair.length / c * float(np.sum(excess)) / film.half_width
    pressure_torque = -film.scale * c * radius**2 * float(np.sum(state["field"] * state["volume"]
                                                                  * state["hd"][:, None])) * 2.0 / 2.0
    normal = film.scale * radius**2 * float(np.sum(ring * p_a))
    boundary = pair.boundary_mu * radius * normal
    opening = film.gamma_fine @ s
    return ElasticPoint(float(eps), float(math.degrees(math.atan2(abs(f_ahead), -f_along))),
                        float(c * h_fine.min()), float(scale_f * math.hypot(film_along, film_ahead)),
                        float(scale_f * asp), float(scale_f * math.hypot(f_along, f_ahead)),
                        float(couette + pressure_torque + boundary), float(couette),
                        float(pressure_torque), float(boundary),
                        float(film.scale * (state["field"].max() + p_a.max())), float(c * opening.max()),
                        int(total), float(norm))
