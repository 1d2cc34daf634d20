"""Plane-strain finite-element model of the pin in its bushing: load against approach (issue 37).

The check of the cylindrical contact law against elasticity.  A steel pin (a disk of radius R) rests
in a bronze bushing (a ring of inner radius R_b = R + c and wall t) whose outer boundary is held by a
rigid housing (zero displacement).  Both bodies are linear elastic in plane strain (the bushing is as
long as the pin, L = 30 mm = 2 R, and held along its length), the contact is frictionless, and the
problem is symmetric about the load's line (a half model, u_y = 0 on y = 0).

The pin carries its load P' (N per metre of length) as a uniform body force: in the joint the load
comes from the link through the pin's own section, not through a point.  Its **approach** is

    delta = <u_x>_pin - u_housing = <u_x>_pin,

the area-mean displacement of the pin along the load (its rigid-body translation) from the position
where it first touches the bushing, relative to the housing: the same quantity as the multibody
joint's penetration delta = |e| - c, where e is the distance between the centres of the rigid pin
and the rigid eye that holds the bushing.

Discretisation: linear triangles (scikit-fem: ``ElementTriP1``) on graded Delaunay meshes, fine
(h0) along the arc where contact may occur and growing by ``grading`` per unit distance from it;
the pin's and the bushing's surface nodes lie on the same rays from the bushing's centre, so each
pair has a radial gap g0 = R_b - |x_pin| (exact geometry) and the frictionless contact is
node-to-node along the ray (small displacements: delta / R < 0.4 %).  Contact is solved exactly on
the condensed system: the compliance of each body at its candidate surface nodes (one sparse
factorisation per body, one solve per node), then the complementarity problem

    g = g0 - (u_pin - u_bush) . n >= 0,   lambda >= 0,   lambda g = 0,   sum lambda n_x = P' / 2

by a primal-dual active set (the contact zone is found, not assumed: every candidate node up to
``candidate_deg`` may close, and the result is rejected if the outermost one does).

Sources: Johnson, Contact Mechanics (1985), 4.3 and 5.6 (Hertz's line contact, conformal contact of a
pin in a hole, after Persson 1964); Ciavarella & Decuzzi, Int. J. Solids Struct. 38 (2001) 4507 (the
frictionless pin in a plate with clearance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class PinBushing:
    """Geometry and materials of the plane-strain pin-in-bushing model (SI units)."""

    radius: float  # R, pin radius, m
    clearance: float  # c, m
    wall: float  # t, bushing wall thickness, m (outer radius R + c + t held by the housing)
    pin_modulus: float  # E_j, Pa
    pin_poisson: float
    bushing_modulus: float  # E_b, Pa
    bushing_poisson: float

    @property
    def effective_modulus(self) -> float:
        """E* = 1 / ((1 - nu_j^2) / E_j + (1 - nu_b^2) / E_b), Pa (plane strain)."""
        return 1.0 / ((1.0 - self.pin_poisson**2) / self.pin_modulus
                      + (1.0 - self.bushing_poisson**2) / self.bushing_modulus)

    @classmethod
    def from_joint(cls, joint, wall: float) -> "PinBushing":
        """The model of a :class:`weftsim.input.params.ClearanceJoint` with bushing wall ``wall`` (m)."""
        return cls(joint.journal_radius, joint.clearance, wall,
                   joint.journal_material.youngs_modulus, joint.journal_material.poisson_ratio,
                   joint.bearing_material.youngs_modulus, joint.bearing_material.poisson_ratio)


@dataclass(frozen=True)
class Mesh:
    """Refinement of the graded meshes: h0 at the contact arc, growing by ``grading`` per metre away."""

    h0: float  # m
    grading: float = 0.25
    h_max_ratio: float = 0.12  # largest element, as a fraction of R
    fine_deg: float = 100.0  # the arc kept at h0 (degrees from the load's line)
    candidate_deg: float = 150.0  # candidate contact nodes up to this angle


@dataclass
class Solution:
    """One FE solution: load per length, approach, contact zone, nodal pressures."""

    load_per_length: float  # P', N/m
    approach: float  # delta, m
    contact_half_angle: float  # rad, to the last closed node
    peak_pressure: float  # Pa
    angles: np.ndarray = field(repr=False)  # rad, the candidate nodes
    pressure: np.ndarray = field(repr=False)  # Pa at those nodes


def _size(h0: float, grading: float, h_max: float, distance: np.ndarray) -> np.ndarray:
    return np.minimum(h0 + grading * distance, h_max)


def _march(total: float, size) -> np.ndarray:
    """Positions 0 = s_0 < s_1 < ... < s_n = total with steps ~ size(s), rescaled to end at ``total``."""
    marks = [0.0]
    while marks[-1] < total:
        marks.append(marks[-1] + float(size(marks[-1])))
    s = np.asarray(marks)
    if len(s) > 2 and (s[-1] - total) > 0.5 * (s[-1] - s[-2]):
        s = s[:-1]
    return s * (total / s[-1]) if s[-1] > 0 else s


def _boundary_angles(radius: float, mesh: Mesh) -> np.ndarray:
    """Angles 0..pi of the surface nodes (shared by pin and bushing), fine up to ``fine_deg``."""
    fine = math.radians(mesh.fine_deg)
    h_max = mesh.h_max_ratio * radius

    def step(theta):
        return _size(mesh.h0, mesh.grading, h_max, np.array(max(0.0, theta - fine) * radius)) / radius

    return _march(math.pi, step)


def _ring_points(r: float, radius: float, mesh: Mesh, depth: float) -> np.ndarray:
    """Points on a ring of radius r (a depth ``depth`` below the contact surface), 0..pi."""
    fine = math.radians(mesh.fine_deg)
    h_max = mesh.h_max_ratio * radius

    def step(phi):
        arc = max(0.0, phi - fine) * r
        return _size(mesh.h0, mesh.grading, h_max, np.array(math.hypot(arc, depth))) / r

    phi = _march(math.pi, step)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi)])


def _triangulate(points: np.ndarray, keep, surface: int, plane: np.ndarray | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Delaunay triangles of ``points`` (of their images ``plane`` if given) whose centroid ``keep``
    accepts, and the points they use.

    A point no kept triangle uses (qhull leaves out a point nearly coincident with another, and a
    sliver may be all that touched it) is dropped and the triangles renumbered; the first ``surface``
    points (the contact nodes) must all be used, or the mesh is refused.
    """
    from scipy.spatial import Delaunay

    tri = Delaunay(points if plane is None else plane).simplices
    p = points[tri]
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    centroid = p.mean(axis=1)
    scale = np.max(np.abs(points)) ** 2
    tri = tri[(area > 1e-12 * scale) & keep(centroid)]
    used = np.zeros(len(points), bool)
    used[tri.ravel()] = True
    if not used[:surface].all():
        raise RuntimeError("the mesh lost a contact node (choose another h0)")
    number = np.cumsum(used) - 1
    return points[used], number[tri]


def pin_mesh(model: PinBushing, mesh: Mesh, theta: np.ndarray):
    """Half disk of the pin (its own centre at the origin); its first len(theta) points are the surface
    nodes on the rays ``theta`` from the bushing's centre, which sits at (-c, 0) in this frame."""
    R, c = model.radius, model.clearance
    # the point of the pin's circle on the ray theta from (-c, 0): x = -c + rho cos(theta), |x| = R
    rho = c * np.cos(theta) + np.sqrt(R**2 - (c * np.sin(theta)) ** 2)
    surface = np.column_stack([-c + rho * np.cos(theta), rho * np.sin(theta)])
    pts = [surface]
    h_max = mesh.h_max_ratio * R
    depth, r = 0.0, R
    while True:
        dr = float(_size(mesh.h0, mesh.grading, h_max, np.array(depth)))
        depth += dr
        r = R - depth
        if r < 0.6 * dr:
            break
        pts.append(_ring_points(r, R, mesh, depth))
    pts.append(np.zeros((1, 2)))
    points = np.vstack(pts)
    points[:, 1] = np.where(np.abs(points[:, 1]) < 1e-12 * R, 0.0, points[:, 1])
    return _triangulate(points, lambda x: np.ones(len(x), bool), len(theta))


def bushing_mesh(model: PinBushing, mesh: Mesh, theta: np.ndarray):
    """Half ring of the bushing (its centre at the origin); first len(theta) points: the bore's nodes."""
    Rb = model.radius + model.clearance
    Ro = Rb + model.wall
    pts = [np.column_stack([Rb * np.cos(theta), Rb * np.sin(theta)])]
    h_max = mesh.h_max_ratio * model.radius
    radii, depth = [], 0.0
    while True:
        depth += float(_size(mesh.h0, mesh.grading, h_max, np.array(depth)))
        if depth >= model.wall - 0.3 * float(_size(mesh.h0, mesh.grading, h_max, np.array(depth))):
            break
        radii.append(Rb + depth)
    radii.append(Ro)
    for r in radii:
        pts.append(_ring_points(r, model.radius, mesh, r - Rb))
    points = np.vstack(pts)
    points[:, 1] = np.where(np.abs(points[:, 1]) < 1e-12 * Rb, 0.0, points[:, 1])
    # triangulated in the plane (R_b theta, r), where the half ring is a rectangle (convex: no triangle spans
    # the bore, none is lost to it), the triangles then taken back with their corners
    plane = np.column_stack([Rb * np.arctan2(points[:, 1], points[:, 0]), np.hypot(points[:, 0], points[:, 1])])
    points, tri = _triangulate(points, lambda x: np.ones(len(x), bool), len(theta), plane)
    return points, tri, Ro


def _stiffness(points, tri, modulus, poisson):
    from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    m = MeshTri(points.T.copy(), tri.T.copy())
    basis = Basis(m, ElementVector(ElementTriP1()))
    K = asm(linear_elasticity(*lame_parameters(modulus, poisson)), basis)  # plane strain
    return m, basis, K.tocsc()


def _solve_columns(K, fixed, rhs):
    """K u = rhs (columns) with u = 0 on the ``fixed`` dofs; one sparse LU for all columns."""
    from scipy.sparse.linalg import splu

    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    lu = splu(K[free][:, free].tocsc())
    out = np.zeros((K.shape[0], rhs.shape[1]))
    out[free] = lu.solve(np.ascontiguousarray(rhs[free]))
    return out


class PinBushingFE:
    """The condensed FE model of one geometry and mesh: compliances at the candidate contact nodes."""

    def __init__(self, model: PinBushing, mesh: Mesh):
        self.model, self.mesh = model, mesh
        theta = _boundary_angles(model.radius, mesh)
        self.theta_all = theta
        cand = np.flatnonzero(theta <= math.radians(mesh.candidate_deg))
        self.theta = theta[cand]
        n = np.column_stack([np.cos(self.theta), np.sin(self.theta)])
        self.normal = n
        nc = len(cand)

        # pin: frame at its own centre; symmetry u_y = 0 on y = 0; anchor u_x = 0 at the centre
        pp, pt = pin_mesh(model, mesh, theta)
        pm, pb, Kp = _stiffness(pp, pt, model.pin_modulus, model.pin_poisson)
        dx, dy = pb.nodal_dofs
        on_axis = np.flatnonzero(np.abs(pp[:, 1]) == 0.0)
        centre = int(np.argmin(np.hypot(pp[:, 0], pp[:, 1])))
        fixed_p = np.concatenate([dy[on_axis], [dx[centre]]])
        rhs = np.zeros((Kp.shape[0], nc + 1))
        rhs[dx[cand], np.arange(nc)] = -n[:, 0]  # a unit contact force -n on the pin at node i
        rhs[dy[cand], np.arange(nc)] = -n[:, 1]
        from skfem import LinearForm, asm

        @LinearForm
        def body_x(v, w):
            return v.value[0]

        area = float(pm.p.shape[1] and np.sum(_areas(pp, pt)))
        rhs[:, nc] = asm(body_x, pb) / area  # uniform body force of 1 N/m in total along +x
        up = _solve_columns(Kp, fixed_p, rhs)
        mean_x = np.asarray(asm(body_x, pb)) / area  # <u_x> = mean_x . u
        self.pin_radial = up[dx[cand]] * n[:, :1] + up[dy[cand]] * n[:, 1:]  # (nc, nc + 1)
        self.pin_mean = mean_x @ up  # (nc + 1,)

        # bushing: outer boundary held (housing), symmetry u_y = 0 on y = 0
        bp, bt, Ro = bushing_mesh(model, mesh, theta)
        bm, bb, Kb = _stiffness(bp, bt, model.bushing_modulus, model.bushing_poisson)
        ex, ey = bb.nodal_dofs
        outer = np.flatnonzero(np.abs(np.hypot(bp[:, 0], bp[:, 1]) - Ro) < 1e-9 * Ro)
        axis_b = np.flatnonzero(np.abs(bp[:, 1]) == 0.0)
        fixed_b = np.unique(np.concatenate([ex[outer], ey[outer], ey[axis_b]]))
        rhs = np.zeros((Kb.shape[0], nc))
        rhs[ex[cand], np.arange(nc)] = n[:, 0]  # a unit force +n on the bushing's bore at node i
        rhs[ey[cand], np.arange(nc)] = n[:, 1]
        ub = _solve_columns(Kb, fixed_b, rhs)
        self.bush_radial = ub[ex[cand]] * n[:, :1] + ub[ey[cand]] * n[:, 1:]

        R, c = model.radius, model.clearance
        rho = c * np.cos(self.theta) + np.sqrt(R**2 - (c * np.sin(self.theta)) ** 2)
        self.gap0 = (R + c) - rho
        # the tributary arc of each bore node (half at the ends), for nodal pressure
        mids = np.concatenate([[0.0], 0.5 * (theta[1:] + theta[:-1]), [math.pi]])
        self.arc = (R + c) * (mids[1:] - mids[:-1])[cand]
        self.nodes = int(pp.shape[0] + bp.shape[0])

    def solve(self, load_per_length: float) -> Solution:
        """Frictionless contact at a load P' (N/m, the whole pin; the half model carries P'/2)."""
        half = 0.5 * load_per_length
        nc = len(self.theta)
        M = self.bush_radial - self.pin_radial[:, :nc]  # gap opening per unit contact force
        q = self.gap0 - half * self.pin_radial[:, nc]
        nx = self.normal[:, 0]
        active = np.zeros(nc, bool)
        active[:max(3, int(np.searchsorted(self.gap0, 1e-9 * self.model.radius)))] = True
        lam = np.zeros(nc)
        for _ in range(200):
            A = np.flatnonzero(active)
            k = len(A)
            sysm = np.zeros((k + 1, k + 1))
            sysm[:k, :k] = M[np.ix_(A, A)]
            sysm[:k, k] = -nx[A]
            sysm[k, :k] = nx[A]
            sol = np.linalg.solve(sysm, np.concatenate([-q[A], [half]]))
            lam = np.zeros(nc)
            lam[A] = sol[:k]
            s = sol[k]
            gap = q + M @ lam - s * nx
            negative = active & (lam < 0.0)
            closing = ~active & (gap < -1e-12 * self.model.clearance)
            if not negative.any() and not closing.any():
                break
            active[negative] = False
            active[closing] = True
        else:
            raise RuntimeError("the contact's active set did not settle in 200 iterations")
        if active[-1]:
            raise RuntimeError(f"contact reached the last candidate node ({self.mesh.candidate_deg} deg): "
                               "widen candidate_deg")
        approach = s + self.pin_mean[:nc] @ lam + half * self.pin_mean[nc]
        pressure = lam / self.arc
        last = int(np.flatnonzero(lam > 0.0)[-1])
        return Solution(load_per_length, float(approach), float(self.theta[last]), float(pressure.max()),
                        self.theta.copy(), pressure)


def _areas(points, tri):
    p = points[tri]
    return 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))


def hertz_line_contact(model: PinBushing, load_per_length: float) -> tuple[float, float]:
    """(b, p0) of Hertz's line contact of the pin in the bore: b = sqrt(4 P' R' / (pi E*)),
    p0 = 2 P' / (pi b), with R' = R R_b / (R_b - R) (Johnson 1985, eq. 4.43-4.45)."""
    R, Rb = model.radius, model.radius + model.clearance
    r_eff = R * Rb / (Rb - R)
    b = math.sqrt(4.0 * load_per_length * r_eff / (math.pi * model.effective_modulus))
    return b, 2.0 * load_per_length / (math.pi * b)
