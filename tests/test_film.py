"""The oil-film kernel (weftsim.kernel.film) against closed forms of the short and long bearing."""

import math

import pytest
from scipy.integrate import quad

from weftsim.kernel.film import MODEL_SHORT, film_force

VISCOSITY, RADIUS, LENGTH, CLEARANCE = 0.1, 0.01, 0.02, 2e-5  # Pa s, m, m, m: a pin of B/D = 1


@pytest.mark.parametrize("eps", [0.05, 0.3, 0.5, 0.9, 0.99])
def test_short_bearing_rotation_is_ocvirks_closed_form(eps):
    """Ocvirk (NACA TN 2808): F_r = -eta U L^3 eps^2 / (c^2 (1-eps^2)^2), F_t = eta U L^3 pi eps / (4 c^2 (1-eps^2)^1.5)."""
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
