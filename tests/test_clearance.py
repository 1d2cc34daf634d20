"""Physics checks of the planar clearance-joint force (weftsim.joint.clearance, docs/physics.md section 2)."""

import dataclasses

import numpy as np
import pytest

from weftsim.joint.clearance import (
    clearance_contact,
    clearance_force,
    contact_geometry,
    make_clearance_kernel,
    tangential_velocity,
)
from weftsim.joint.contact import make_law
from weftsim.input.params import LOOM_JOINT_E

RNG = np.random.default_rng(7)
JOINT = dataclasses.replace(LOOM_JOINT_E, friction_coefficient=0.1)  # reference joint, c = 0.25 mm, with friction
FRICTIONLESS = dataclasses.replace(JOINT, friction_coefficient=0.0)


def random_states(n, joint):
    """Eccentricities around the clearance circle (free flight and contact) and rates."""
    angle = RNG.uniform(-np.pi, np.pi, n)
    radius = joint.clearance + RNG.uniform(-2e-5, 2e-5, n)
    ecc = radius[:, None] * np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    rate = RNG.uniform(-0.5, 0.5, (n, 2))
    v_t = RNG.uniform(-4e-4, 4e-4, n)  # spans the friction ramp 1e-4..2e-4 m/s
    v_imp = RNG.uniform(1e-4, 1.0, n)
    return ecc, rate, v_t, v_imp


def test_penetration_and_rate_match_the_geometry():
    ecc, rate, _, _ = random_states(50, JOINT)
    delta, delta_dot, n = contact_geometry(ecc, rate, JOINT.clearance)
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0, rtol=0.0, atol=1e-15)  # unit normal, round-off
    h = 1e-9  # s; |e| is smooth away from e = 0: FD error ~h * rate^2 / |e| ~ 1e-6 relative
    d_plus, _, _ = contact_geometry(ecc + h * rate, rate, JOINT.clearance)
    d_minus, _, _ = contact_geometry(ecc - h * rate, rate, JOINT.clearance)
    np.testing.assert_allclose((d_plus - d_minus) / (2 * h), delta_dot, rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(delta, np.linalg.norm(ecc, axis=-1) - JOINT.clearance, rtol=0, atol=1e-18)


@pytest.mark.parametrize("joint", [FRICTIONLESS, JOINT], ids=["frictionless", "friction"])
def test_force_pulls_the_journal_back_to_the_bearing_centre(joint):
    law = make_law(joint)
    ecc, rate, v_t, v_imp = random_states(400, joint)
    r = clearance_contact(ecc, rate, v_t, v_imp, law, joint)
    contact = r.normal_force > 0.0
    assert contact.sum() > 50 and (~contact).sum() > 50
    radial = np.einsum("...i,...i->...", r.force_on_journal, r.normal)
    np.testing.assert_allclose(radial, -r.normal_force, rtol=1e-14, atol=0.0)  # exact split in n, t
    assert np.all(radial[contact] < 0.0)
    assert np.all(r.force_on_journal[~contact] == 0.0)
    # friction never exceeds mu F_N and opposes the relative sliding of the journal
    assert np.all(np.abs(r.friction_force) <= joint.friction_coefficient * r.normal_force * (1 + 1e-15))
    assert np.all(r.friction_force * v_t <= 0.0)


def test_friction_is_full_coulomb_beyond_the_ramp():
    law = make_law(JOINT)
    ecc = np.array([JOINT.clearance + 2e-6, 0.0])
    for v_t, expected_sign in ((1e-3, -1.0), (-1e-3, 1.0), (5e-5, 0.0)):
        r = clearance_contact(ecc, (0.1, 0.0), v_t, 0.1, law, JOINT)
        assert r.friction_force == pytest.approx(expected_sign * 0.1 * r.normal_force, rel=1e-15)
        # t = (0, 1) here, so friction is along y only
        assert r.force_on_journal[1] == r.friction_force


def test_newton_third_law_and_moment_balance():
    law = make_law(JOINT)
    ecc, rate, v_t, v_imp = random_states(300, JOINT)
    r = clearance_contact(ecc, rate, v_t, v_imp, law, JOINT)
    np.testing.assert_array_equal(r.force_on_bearing, -r.force_on_journal)
    # Both forces act at Q: the journal's moment about P_b (M_j + e x f_j) cancels the bearing's.
    e_cross_f = ecc[:, 0] * r.force_on_journal[:, 1] - ecc[:, 1] * r.force_on_journal[:, 0]
    total = r.moment_on_journal + e_cross_f + r.moment_on_bearing
    scale = JOINT.bearing_radius * np.abs(r.force_on_journal).sum(axis=-1) + 1e-300
    assert np.all(np.abs(total) <= 1e-14 * scale)  # round-off of products of ~R_b F magnitude
    # Moments come from the contact point: Q - P_b = R_b n, Q - P_j = (R_b - |e|) n.
    q = r.contact_offset
    m_b = q[:, 0] * r.force_on_bearing[:, 1] - q[:, 1] * r.force_on_bearing[:, 0]
    assert np.all(np.abs(r.moment_on_bearing - m_b) <= 1e-14 * scale)  # cancelling products, round-off


def test_centred_journal_gives_no_force_and_no_nan():
    law = make_law(JOINT)
    zero = np.zeros(2)
    r = clearance_contact(zero, (0.3, -0.2), 1.0, 0.5, law, JOINT)
    for value in r:
        assert np.all(np.isfinite(value))
    assert r.normal_force == 0.0 and np.all(r.force_on_journal == 0.0)
    assert r.penetration == -JOINT.clearance and r.penetration_rate == 0.0
    batch = np.array([[0.0, 0.0], [JOINT.clearance + 1e-6, 0.0]])
    r2 = clearance_contact(batch, np.ones((2, 2)), [0.0, 0.0], [1.0, 1.0], law, JOINT)
    assert np.all(np.isfinite(r2.force_on_journal)) and r2.normal_force[1] > 0.0
    kernel = make_clearance_kernel(law, JOINT)
    out = kernel(0.0, 0.0, 0.3, -0.2, 1.0, 0.5)
    assert out == (0.0, 0.0, 0.0, -JOINT.clearance, 0.0, 0.0, 0.0)
    assert np.all(tangential_velocity(zero, (1.0, 2.0), 3.0, (0.0, 0.0), 4.0, JOINT.bearing_radius) == 0.0)


def test_short_form_matches_the_full_result():
    law = make_law(JOINT)
    ecc, rate, v_t, v_imp = random_states(20, JOINT)
    force, f_n, delta, delta_dot = clearance_force(ecc, rate, v_t, v_imp, law, JOINT)
    r = clearance_contact(ecc, rate, v_t, v_imp, law, JOINT)
    for a, b in ((force, r.force_on_journal), (f_n, r.normal_force), (delta, r.penetration),
                 (delta_dot, r.penetration_rate)):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("law_name", ["variable_kd", "flores", "elastic_foundation"])
@pytest.mark.parametrize("jit", [False, True], ids=["math", "numba"])
def test_scalar_kernel_equals_numpy(law_name, jit):
    if jit:
        pytest.importorskip("numba")
    joint = dataclasses.replace(JOINT, law=law_name)
    law = make_law(joint)
    ecc, rate, v_t, v_imp = random_states(300, joint)
    r = clearance_contact(ecc, rate, v_t, v_imp, law, joint)
    kernel = make_clearance_kernel(law, joint, jit=jit)
    out = np.array([kernel(*e, *ed, vt, vi) for e, ed, vt, vi in zip(ecc, rate, v_t, v_imp)])
    expected = np.column_stack([r.force_on_journal, r.normal_force, r.penetration, r.penetration_rate,
                                r.moment_on_journal, r.moment_on_bearing])
    # Same formulas; hypot vs sqrt of squares and libm vs LLVM differ by a few ulps.
    scale = np.abs(expected).max(axis=0)
    assert np.all(np.abs(out - expected) <= 1e-13 * scale)


def test_tangential_velocity_of_the_contact_points():
    r_b = JOINT.bearing_radius
    ecc = np.array([0.0, JOINT.clearance + 1e-6])  # n = +y, t = -x
    # journal spinning about its own centre, bearing at rest: v_T = w_j (R_b - |e|) = w_j (R_j - delta)
    v = tangential_velocity(ecc, (0.0, 0.0), 0.0, (0.0, 0.0), 10.0, r_b)
    assert v == pytest.approx(10.0 * (JOINT.journal_radius - 1e-6), rel=1e-14)
    # general case against v_Q = v_P + w x (Q - P), Q = P_b + R_b n
    for _ in range(20):
        e = RNG.normal(size=2) * 1e-4
        vb, vj = RNG.normal(size=2), RNG.normal(size=2)
        wb, wj = RNG.normal(size=2) * 20
        n = e / np.linalg.norm(e)
        t = np.array([-n[1], n[0]])
        q_b = r_b * n  # relative to P_b
        q_j = q_b - e  # relative to P_j
        v_qb = vb + wb * np.array([-q_b[1], q_b[0]])
        v_qj = vj + wj * np.array([-q_j[1], q_j[0]])
        assert tangential_velocity(e, vb, wb, vj, wj, r_b) == pytest.approx((v_qj - v_qb) @ t, rel=1e-12)


def test_the_kernel_clearance_geometry_is_what_every_form_evaluates():
    """The clearance geometry is written once, in the kernel (issue 32): the compiled
    :func:`weftsim.physics.joint.contact_geometry` gives delta = |e| - c and delta_dot = d|e|/dt (a central
    difference of |e(t)| along a curved path with h = 1e-4 |e| / |e_dot|: truncation ~ 1e-9 and round-off
    ~ 1e-12 relative, so 1e-6 is far above both), the array form
    above is it element for element (bit for bit: generated from its source), and the force kernel reports
    the same penetration and rate."""
    from weftsim.physics import joint as kernel

    rng = np.random.default_rng(7)
    prm = kernel.joint_parameters(JOINT, make_law(JOINT))
    for _ in range(20):
        e0, v, a = rng.normal(0.0, 3e-4, 2), rng.normal(0.0, 0.5, 2), rng.normal(0.0, 50.0, 2)

        def e(t):
            return e0 + v * t + 0.5 * a * t * t

        h = 1e-4 * np.hypot(*e0) / np.hypot(*v)
        delta, rate, nx, ny = kernel.contact_geometry(*e0, *v, JOINT.clearance)
        assert delta == pytest.approx(np.hypot(*e0) - JOINT.clearance, rel=1e-15, abs=1e-18)
        fd = (np.hypot(*e(h)) - np.hypot(*e(-h))) / (2 * h)
        assert rate == pytest.approx(fd, rel=1e-6, abs=1e-9)
        assert (nx, ny) == pytest.approx(tuple(e0 / np.hypot(*e0)), rel=1e-15)
        d_arr, r_arr, n_arr = contact_geometry(e0, v, JOINT.clearance)
        assert (float(d_arr), float(r_arr), *map(float, n_arr)) == (delta, rate, nx, ny)
        out = kernel.clearance_force(prm, *e0, *v, 0.0, 1.0)
        assert (out[4], out[5]) == (delta, rate)
    assert kernel.contact_geometry(0.0, 0.0, 1.0, 2.0, JOINT.clearance) == (-JOINT.clearance, 0.0, 0.0, 0.0)
