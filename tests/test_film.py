"""The oil-film kernel (weftsim.physics.film) against closed forms of the short and long bearing."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from weftsim.joint import reynolds
from weftsim.physics.film import (MODEL_FINITE, MODEL_LONG, MODEL_SHORT, MODEL_SHORT_HALF, _long_pressure, film_force,
                                 finite_force, long_force, short_force, sommerfeld_angle)
from weftsim.joint.reynolds import RAIMONDI_BOYD, equilibrium, steady_load

VISCOSITY, RADIUS, LENGTH, CLEARANCE = 0.1, 0.01, 0.02, 2e-5  # Pa s, m, m, m: a pin of B/D = 1


@pytest.mark.parametrize("eps", [0.05, 0.3, 0.5, 0.9, 0.99])
def test_short_bearing_rotation_is_ocvirks_closed_form(eps):
    """Ocvirk (NACA TN 2808): F_r = -eta U L^3 eps^2 / (c^2 (1-eps^2)^2),
    F_t = eta U L^3 pi eps / (4 c^2 (1-eps^2)^1.5)."""
    omega = 100.0
    fy, fz, _, _ = film_force(eps * CLEARANCE, 0.0, 0.0, 0.0, omega, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY,
                              MODEL_SHORT)
    speed = RADIUS * omega
    radial = -VISCOSITY * speed * LENGTH**3 * eps**2 / (CLEARANCE**2 * (1 - eps**2) ** 2)
    ahead = VISCOSITY * speed * LENGTH**3 * math.pi * eps / (4 * CLEARANCE**2 * (1 - eps**2) ** 1.5)
    # Same closed form by another route (Sommerfeld's substitution): round-off only.
    assert fy == pytest.approx(radial, rel=1e-9)
    assert fz == pytest.approx(ahead, rel=1e-9)


@pytest.mark.parametrize("eps", [0.0, 0.3, 0.8])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_short_bearing_squeeze_both_directions_with_cavitation(eps, sign):
    """Pure squeeze along e: F = -eta L^3 R v / c^3 times the integral of cos^2 / H^3 over the side it moves towards."""
    rate = sign * 1e-4
    fy, fz, _, _ = film_force(eps * CLEARANCE, 0.0, rate, 0.0, 0.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY,
                              MODEL_SHORT)
    lo, hi = (-0.5 * math.pi, 0.5 * math.pi) if sign > 0 else (0.5 * math.pi, 1.5 * math.pi)
    integral = quad(lambda p: math.cos(p) ** 2 / (1 - eps * math.cos(p)) ** 3, lo, hi, epsabs=0, epsrel=1e-12)[0]
    expected = -VISCOSITY * LENGTH**3 * RADIUS * rate / CLEARANCE**3 * integral
    assert fy == pytest.approx(expected, rel=1e-9)  # closed form vs adaptive quadrature: round-off
    assert abs(fz) <= 1e-12 * abs(fy)  # symmetric film: no force across the line of motion


@pytest.mark.parametrize("eps", [0.0, 0.3, 0.8])
@pytest.mark.parametrize("rate", [1e-4, -1e-4])
@pytest.mark.parametrize("omega", [0.0, 100.0, -100.0])
def test_short_half_film_is_the_multibody_papers_closed_form(eps, rate, omega):
    """MODEL_SHORT_HALF: Flores, Ambrosio, Claro, Lankarani (2006) short-bearing forces, wedge + squeeze on the
    fixed half film: F_r = -(eta R L^3 / (2 c^2)) (2 eps^2 |w| / (1-eps^2)^2 + pi (1+2 eps^2) deps / (1-eps^2)^2.5),
    F_t = (eta R L^3 / (2 c^2)) (pi eps w / (2 (1-eps^2)^1.5) + 4 eps deps sign(w) / (1-eps^2)^2), w = omega."""
    e = eps * CLEARANCE
    fy, fz, _, _ = film_force(e, 0.0, rate, 0.0, omega, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_SHORT_HALF)
    deps = rate / CLEARANCE
    side = 1.0 if omega >= 0.0 else -1.0  # the half film of the wedge flips with the sense of rotation
    k = 1 - eps**2
    base = VISCOSITY * RADIUS * LENGTH**3 / (2 * CLEARANCE**2)
    radial = -base * (2 * eps**2 * abs(omega) / k**2 + math.pi * (1 + 2 * eps**2) * deps / k**2.5)
    ahead = base * (math.pi * eps * omega / (2 * k**1.5) + side * 4 * eps * deps / k**2)
    scale = base * (abs(omega) + abs(deps)) / k**2.5
    assert fy == pytest.approx(radial, abs=1e-12 * scale)  # closed form by another route: round-off
    assert fz == pytest.approx(ahead, abs=1e-12 * scale)


def test_zero_viscosity_gives_no_force_and_no_torque():
    assert film_force(1e-5, 3e-6, 0.01, -0.02, 50.0, -3.0, CLEARANCE, RADIUS, LENGTH, 0.0, MODEL_SHORT) == (
        0.0, 0.0, 0.0, 0.0)


def test_centred_journal_is_finite_and_continuous():
    at_zero = film_force(0.0, 0.0, 1e-4, 2e-4, 30.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_SHORT)
    near = film_force(1e-14, 0.0, 1e-4, 2e-4, 30.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_SHORT)
    assert all(math.isfinite(v) for v in at_zero)
    assert at_zero == pytest.approx(near, rel=1e-6)  # eps = 5e-10 away: the force is smooth in e


def test_torques_balance_the_moment_of_the_film_force():
    """The film has no angular momentum: torque_j + torque_b + (e x F)_x = 0."""
    ey, ez = 8e-6, -5e-6
    fy, fz, tj, tb = film_force(ey, ez, 2e-3, 1e-3, 80.0, -10.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_SHORT)
    assert tj + tb + (ey * fz - ez * fy) == pytest.approx(0.0, abs=1e-12 * abs(tj))
    assert tj < 0.0  # the journal spins faster than the bearing: the film brakes it


# --- the long bearing (Sommerfeld, Gumbel) -------------------------------------------------------

@pytest.mark.parametrize("eps", [0.0, 0.1, 0.5, 0.9, 0.99])
def test_long_bearing_rotation_is_the_half_sommerfeld_closed_form(eps):
    """Half-Sommerfeld long bearing: F_r = -12 eta U L (R/c)^2 eps^2 / ((2+eps^2)(1-eps^2)),
    F_t = 6 pi eta U L (R/c)^2 eps / ((2+eps^2) sqrt(1-eps^2)) (Pinkus and Sternlicht 1961)."""
    omega = 100.0
    fy, fz, _, _ = film_force(eps * CLEARANCE, 0.0, 0.0, 0.0, omega, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY,
                              MODEL_LONG)
    base = VISCOSITY * RADIUS * omega * LENGTH * (RADIUS / CLEARANCE) ** 2 / (2 + eps**2)
    # 24-point Gauss on the pressure lobe: measured 2e-6 at eps = 0.99, 1e-9 at 0.9, round-off below.
    assert fy == pytest.approx(-12 * base * eps**2 / (1 - eps**2), rel=1e-5, abs=1e-9 * base)
    assert fz == pytest.approx(6 * math.pi * base * eps / math.sqrt(1 - eps**2), rel=1e-5)


@pytest.mark.parametrize("eps", [0.01, 0.5, 0.9])
def test_long_bearing_squeeze_approach_and_separation(eps):
    """P = (6/eps)(1/H^2 - 1/(1+eps)^2) >= 0 approaching: F = -12 pi eta L R (R/c)^2 v / (c (1-eps^2)^1.5);
    separating the same film is all below ambient and Gumbel's condition leaves no force."""
    rate = 1e-4
    approach = film_force(eps * CLEARANCE, 0.0, rate, 0.0, 0.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_LONG)
    separate = film_force(eps * CLEARANCE, 0.0, -rate, 0.0, 0.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY,
                          MODEL_LONG)
    closed = -12 * math.pi * VISCOSITY * LENGTH * RADIUS * (RADIUS / CLEARANCE) ** 2 * rate / (
        CLEARANCE * (1 - eps**2) ** 1.5)
    assert approach[0] == pytest.approx(closed, rel=1e-6)  # Gauss quadrature: measured < 1e-7
    assert separate[:2] == (0.0, 0.0)


@pytest.mark.parametrize(("eps", "xi"), [(0.6, 2.0), (0.95, -2.5), (0.3, 1.0), (0.8, -0.3)])
def test_long_bearing_any_squeeze_angle_is_the_positive_part_of_its_pressure(eps, xi):
    """The root search and Gauss sums against adaptive quadrature of max(P, 0) n over phi."""
    def pressure(phi):
        return max(_long_pressure(sommerfeld_angle(phi, eps), eps, xi), 0.0)

    expected = [-2.0 * quad(lambda p: pressure(p) * trig(p), -math.pi, math.pi, limit=400, points=[0.0])[0]
                for trig in (math.cos, math.sin)]
    got = long_force(eps, xi, 1.0)
    # Quadrature of a kinked integrand: agreement measured 3e-10 of the force's size.
    assert math.hypot(got[0] - expected[0], got[1] - expected[1]) < 1e-7 * math.hypot(*expected)


# --- the finite bearing -----------------------------------------------------------------------------

RB_ROWS = [(width, *row) for width, rows in RAIMONDI_BOYD.items() for row in rows]


@pytest.mark.parametrize(("width", "eps", "sommerfeld", "attitude"), RB_ROWS)
def test_finite_bearing_steady_load_matches_raimondi_and_boyd(width, eps, sommerfeld, attitude):
    """Equilibrium under the table's Sommerfeld number: eccentricity ratio and attitude angle of
    Raimondi and Boyd (1958; values as in Shigley's Mechanical Engineering Design)."""
    got_eps, got_attitude = equilibrium(sommerfeld, width, MODEL_FINITE)
    # 5 %: the bound.  Measured worst: 0.8 % in eps, 1.0 % in attitude (docs/lubrication.md).
    assert got_eps == pytest.approx(eps, rel=0.05)
    assert got_attitude == pytest.approx(attitude, rel=0.05)


@pytest.mark.parametrize("eps", [0.1, 0.5, 0.9])
def test_finite_bearing_tends_to_the_short_bearing_as_it_narrows(eps):
    """Reynolds' equation at B/D = 0.05 and 0.025 approaches Ocvirk's bearing (any squeeze direction)."""
    for xi in (-0.5 * math.pi, 0.0, math.pi, 2.0):
        errors = []
        for width in (0.05, 0.025):
            finite = reynolds.solve(eps, xi, width, 60, 16)[:2]
            short = short_force(eps, xi, width)
            errors.append(math.hypot(finite[0] - short[0], finite[1] - short[1]) / math.hypot(*short))
        assert errors[1] < errors[0]  # the width correction shrinks ...
        # ... to the grid's floor: measured 0.1-0.5 % at B/D = 0.025 (1.7 % at 0.05, eps = 0.9).
        assert errors[1] < 0.01


def test_short_bearing_overestimates_the_finite_load_as_published():
    """At B/D = 1 Ocvirk's load is about 1.7x the finite bearing's at eps = 0.5 and 5.7x at 0.9."""
    ratios = [steady_load(eps, 1.0, MODEL_FINITE)[0] / steady_load(eps, 1.0, MODEL_SHORT)[0] for eps in (0.5, 0.9)]
    # Load ratio = inverse Sommerfeld ratio; 10 %: the published figures are given to two digits.
    assert ratios == pytest.approx([1.7, 5.7], rel=0.1)


def test_load_per_length_grows_towards_the_long_limit_with_width():
    """f / (B/D) rises monotonically with B/D (side leakage falls) and stays below the full-Sommerfeld film."""
    eps = 0.6
    per_length = [math.hypot(*finite_force(eps, -0.5 * math.pi, w)) / w for w in (0.25, 0.5, 1.0, 2.0, 4.0)]
    assert all(b > a for a, b in zip(per_length, per_length[1:]))
    full = math.hypot(*reynolds.solve(eps, -0.5 * math.pi, 40.0, 120, 16, cavitation=False)[:2]) / 40.0
    assert per_length[-1] < full


@pytest.mark.parametrize(("eps", "xi", "width"), [(0.3, 0.0, 1.0), (0.3, math.pi, 1.0), (0.85, 0.0, 1.0),
                                                  (0.85, math.pi, 1.0), (0.55, -1.7, 0.6), (0.93, 2.4, 1.3),
                                                  (0.7, -1.2, 2.6)])
def test_finite_table_reproduces_fresh_solves_between_its_nodes(eps, xi, width):
    """The kernel's interpolated force against a fresh Reynolds solve (squeeze both ways, mixed)."""
    exact = reynolds.film(eps, xi, width)
    got = finite_force(eps, xi, width)
    # Measured worst over random points below eps = 0.97: 0.2 %; 1 % bound.
    assert math.hypot(got[0] - exact[0], got[1] - exact[1]) < 0.01 * math.hypot(*exact)


@pytest.mark.parametrize("model", [MODEL_FINITE, MODEL_SHORT, MODEL_LONG, MODEL_SHORT_HALF])
def test_every_model_is_finite_near_the_centre_and_silent_without_oil(model):
    """At the centre the film is the one of a journal leaving it along its squeeze velocity V."""
    args = (1e-4, 2e-4, 30.0, -5.0, CLEARANCE, RADIUS, LENGTH)
    centre = film_force(0.0, 0.0, *args, VISCOSITY, model)
    near = film_force(1e-13, 2e-13, *args, VISCOSITY, model)  # along V = (1e-4, 2e-4) (omega_m x e ~ 1e-12)
    assert all(math.isfinite(v) for v in centre)
    assert centre == pytest.approx(near, rel=1e-6)  # eps = 1e-8 away from the centre
    assert film_force(5e-6, 1e-6, *args, 0.0, model) == (0.0, 0.0, 0.0, 0.0)
    assert all(math.isfinite(v) for v in film_force(0.999 * CLEARANCE, 0.0, *args, VISCOSITY, model))


@pytest.mark.parametrize("model", [MODEL_FINITE, MODEL_SHORT, MODEL_LONG, MODEL_SHORT_HALF])
def test_petroff_torque_of_the_centred_journal(model):
    """Centred journal: no pressure torque, the shear torque is Petroff's 2 pi eta R^3 L omega / c."""
    omega = 50.0
    _, _, tj, tb = film_force(0.0, 0.0, 0.0, 0.0, omega, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, model)
    petroff = 2 * math.pi * VISCOSITY * RADIUS**3 * LENGTH * omega / CLEARANCE
    assert (tj, tb) == pytest.approx((-petroff, petroff), rel=1e-12)


def test_finite_force_is_the_same_film_for_any_frame():
    """Rotating the whole picture rotates the force; swapping spin for translation (Booker) changes nothing."""
    e, angle = 0.6 * CLEARANCE, 0.7
    base = film_force(e, 0.0, 1e-3, 2e-3, 40.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_FINITE)
    ca, sa = math.cos(angle), math.sin(angle)
    turned = film_force(e * ca, e * sa, 1e-3 * ca - 2e-3 * sa, 1e-3 * sa + 2e-3 * ca, 40.0, 0.0, CLEARANCE, RADIUS,
                        LENGTH, VISCOSITY, MODEL_FINITE)
    assert turned[0] == pytest.approx(base[0] * ca - base[1] * sa, rel=1e-9)
    assert turned[1] == pytest.approx(base[0] * sa + base[1] * ca, rel=1e-9)
    # omega_m x e = 20 * (0, e): the same squeeze velocity with the journal still and moving instead.
    still = film_force(e, 0.0, 1e-3, 2e-3 - 20.0 * e, 0.0, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY, MODEL_FINITE)
    assert still[:2] == pytest.approx(base[:2], rel=1e-12)


@pytest.mark.parametrize("model", [MODEL_FINITE, MODEL_SHORT, MODEL_LONG, MODEL_SHORT_HALF])
def test_the_film_only_dissipates(model):
    """Power into journal and bearing, F . e_dot + torque_j omega_j + torque_b omega_b, is never positive.

    It equals F . V (V Booker's squeeze velocity) minus the Couette shear's eta R^3 B (omega_j - omega_b)^2
    2 pi / (c sqrt(1 - eps^2)); F . V = -(1/12 eta) integral h^3 |grad p|^2 for a film that solves
    Reynolds' equation where it carries pressure.
    """
    rng = np.random.default_rng(3)
    for _ in range(500):
        eps, angle = rng.uniform(0.0, 0.98), rng.uniform(-math.pi, math.pi)
        ey, ez = eps * CLEARANCE * math.cos(angle), eps * CLEARANCE * math.sin(angle)
        vy, vz = rng.normal(0.0, 1e-3, 2)
        omega_j, omega_b = rng.normal(0.0, 50.0, 2)
        fy, fz, tj, tb = film_force(ey, ez, vy, vz, omega_j, omega_b, CLEARANCE, RADIUS, LENGTH, VISCOSITY, model)
        power = fy * vy + fz * vz + tj * omega_j + tb * omega_b
        assert power < 0.0


@pytest.mark.parametrize(("k", "i", "j"), [(4, 10, 0), (4, 20, 24), (2, 27, 48), (7, 5, 30)])
def test_stored_table_is_the_solver_of_this_code_at_its_nodes(k, i, j):
    """The shipped film_table.npz is what weftsim.joint.reynolds gives today (rebuild it after changing the solver)."""
    from weftsim.physics import film

    eps, xi, width = film.table_eccentricities()[i], film.table_angles()[j], film.table_widths()[k]
    stored = film.FINITE_TABLE[k + 1, i + 1, j + 1] / film.table_scale(eps, width)
    fresh = reynolds.film(float(eps), float(xi), float(width))
    # The same computation (sparse direct solves): round-off only.
    assert stored == pytest.approx(fresh, rel=1e-9, abs=1e-12 * math.hypot(*fresh))
