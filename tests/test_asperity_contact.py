"""The asperities of a lubricated joint lose energy as the joint's solids do and hand their load to the dry law
(issue 30, point 3; docs/lubricated-joint.md).

Kernel: beyond |e| = c the solids carry max(F_a(c), F_el) elastically and the share's potential is its integral;
a free impact into an oil-free rough layer rebounds with the joint's restitution (within the layer and through it
into the dry law), and its energy closes (kinetic + stored + dissipated).  Runs: no oil and smooth surfaces, with
the asperities on, is the dry loom.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from weftsim.input.params import ClearanceJoint, Lubrication
from weftsim.joint.contact import make_law
from weftsim.physics.asperity import H_CUTOFF, asperity_load
from weftsim.physics.joint import ASPERITY_COEF, CLEARANCE, COEF, KIND, clearance_force_at, joint_parameters
from weftsim.physics.laws import elastic_energy, elastic_force
from weftsim.physics.lubricated import L_DISSIPATED, L_FX, asperity_share, lubricated_force

C, SIGMA = 0.1e-3, 0.4e-6


def _prm(sigma: float = SIGMA, law: str = "variable_kd", restitution: float = 0.9) -> np.ndarray:
    """The loom's joint E (30 mm pin, 30 mm bushing) at c = 0.1 mm, no oil (viscosity 0), rough."""
    joint = ClearanceJoint(clearance=C, journal_radius=15e-3, bearing_length=30e-3, law=law, restitution=restitution,
                           lubrication=Lubrication(viscosity=0.0, roughness=sigma))
    return joint_parameters(joint, make_law(joint))


def _dry(prm: np.ndarray) -> np.ndarray:
    out = prm.copy()
    out[ASPERITY_COEF] = 0.0  # the same joint without asperities: its dry law alone
    return out


@pytest.mark.parametrize("law", ["variable_kd", "lankarani_nikravesh", "elastic_foundation"])
def test_beyond_c_the_dry_law_takes_the_asperities_load_over(law):
    prm = _prm(law=law)
    f_c = asperity_load(prm[ASPERITY_COEF], SIGMA, C, C, 15e-3, 30e-3)[0]
    assert f_c > 0.0
    for delta in np.geomspace(1e-10, 1e-4, 40):
        share = asperity_share(prm, C, C + delta)[0]
        f_el = elastic_force(prm[KIND], prm[COEF], C, delta)
        # The solids carry max(F_a(c), F_el) elastically: never more than the dry law once it carries F_a(c).
        assert share + f_el == pytest.approx(max(f_c, f_el), rel=1e-12)
    assert asperity_share(prm, C, C + 1e-4)[0] == 0.0


@pytest.mark.parametrize("law", ["variable_kd", "lankarani_nikravesh", "elastic_foundation"])
def test_the_asperity_share_has_its_potential(law):
    """dU_s/d|e| = F_s across the layer, the edge at c and the hand-over (trapezoid on a fine grid)."""
    prm = _prm(law=law)
    ecc = C - H_CUTOFF * SIGMA + np.linspace(0.0, 1.0, 20001) ** 2 * (H_CUTOFF * SIGMA + 30e-6)
    share = np.array([asperity_share(prm, C, e) for e in ecc])
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (share[1:, 0] + share[:-1, 0]) * np.diff(ecc))])
    # Trapezoid error (h^2/12) |F''| on the steep layer: measured 2e-7 of the final potential.
    np.testing.assert_allclose(share[:, 1] - share[0, 1], integral, rtol=1e-5, atol=1e-5 * share[-1, 1])


def _impact(prm: np.ndarray, v0: float, asperities: bool = True, mass: float = 2.0):
    """A journal of ``mass`` kg flying at v0 into the still bearing's wall along y, no oil: (restitution,
    largest relative energy error, deepest |e| - c).  The dry law holds the onset's rate, as the engines do."""
    c = prm[CLEARANCE]
    start = c - 1.05 * H_CUTOFF * SIGMA

    def force(x, v):
        lub = lubricated_force(prm, c, x, 0.0, v, 0.0, 0.0, 0.0) if asperities else (0.0,) * 10
        dry = clearance_force_at(prm, c, 0.0, x, 0.0, v, 0.0, 0.0, v0)[0] if x > c else 0.0
        return lub[L_FX] + dry, lub[L_DISSIPATED], dry

    def rhs(t, y):
        f, dissipated, dry = force(y[0], y[1])
        f_el = elastic_force(prm[KIND], prm[COEF], c, y[0] - c)
        dry_loss = -dry * y[1] - f_el * y[1] if y[0] > c else 0.0  # the dry law's damping work
        return [y[1], f / mass, dissipated + dry_loss]

    leave = lambda t, y: y[0] - start  # noqa: E731 - back out of the layer
    leave.terminal, leave.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1.0), [start, v0, 0.0], method="LSODA", rtol=1e-10, atol=[1e-15, 1e-12, 1e-16],
                    events=leave, max_step=2e-6)
    stored = np.array([asperity_share(prm, c, x)[1] if asperities else 0.0 for x in sol.y[0]])
    stored += np.array([elastic_energy(prm[KIND], prm[COEF], c, x - c) for x in sol.y[0]])
    total = 0.5 * mass * sol.y[1] ** 2 + stored + sol.y[2]
    error = float(np.max(np.abs(total - total[0])) / total[0])
    return -sol.y[1, -1] / v0, error, float(sol.y[0].max() - c)


@pytest.mark.parametrize("law", ["variable_kd", "lankarani_nikravesh"])
@pytest.mark.parametrize("v0", [0.003, 0.03, 0.3, 3.0])
def test_a_free_impact_into_the_rough_layer_has_the_laws_restitution(law, v0):
    """0.003 m/s stays in the layer (|e| < c), 0.03 m/s just reaches the dry law, the faster ones go through it
    into the bulk.  The rough joint rebounds as the dry joint does (its law's own restitution, 0.913 for
    variable_kd with e = 0.9), within 5 % (measured 0.6-1.5 %: the layer's loop returns exactly e^2 of its work)."""
    prm = _prm(law=law)
    rough, _, depth = _impact(prm, v0)
    dry = _impact(_dry(prm), v0, asperities=False)[0]
    assert rough == pytest.approx(dry, rel=0.05)
    if v0 == 0.003:
        assert depth < 0.0  # the layer alone stopped it: its loop, not the dry law's damping, set the rebound
        assert rough == pytest.approx(0.9, rel=1e-3)  # (1 - kappa) / (1 + kappa) = e^2 exactly


def test_energy_closes_through_the_dissipating_asperities():
    """Kinetic + stored (asperity share and dry law) + dissipated (hysteresis and the dry law's damping) stays
    the impact's kinetic energy (measured 2e-9 at rtol 1e-10), and the layer dissipates: it is not elastic."""
    prm = _prm()
    for v0 in (0.003, 0.3):
        restitution, error, _ = _impact(prm, v0)
        assert error < 1e-6
        assert restitution < 0.95


def test_the_smooth_limit_has_no_asperity_load_to_speak_of():
    """F_a(c) falls as sqrt(sigma): at sigma = 1 nm the layer carries 39 N at c (0.1 % of the dry loom's
    32.1 kN impacts at c = 0.1 mm), and the dry law has taken it over 2 um beyond c (variable_kd, the softest
    law at small penetrations: F_el ~ delta^2)."""
    rough, smooth = _prm(), _prm(sigma=1e-9)
    f_rough = asperity_share(rough, C, C)[0]
    f_smooth = asperity_share(smooth, C, C)[0]
    assert f_smooth == pytest.approx(f_rough * math.sqrt(1e-9 / SIGMA), rel=0.05)
    assert asperity_share(smooth, C, C + 2e-6)[0] == 0.0


# --- the loom ------------------------------------------------------------------------------------------------

NO_OIL = {"joint_e.clearance_mm": 0.1, "joint_e.law": "variable_kd",  # explicit: the loom's default law may change
          "joint_e.lubrication.viscosity_mpa_s": 1e-9}


@pytest.fixture(scope="module")
def dry_loom():
    """The dry loom whose contact has the boundary friction the oil-free joint's solids carry (mu_b, the
    lubrication's default: in oil the solids' contact is boundary-lubricated, weftsim.physics.joint)."""
    import weftsim
    from weftsim.input.params import Lubrication

    dry = {k: v for k, v in NO_OIL.items() if "lubrication" not in k}
    dry["joint_e.friction_coefficient"] = Lubrication(viscosity=0.0).boundary_friction_coefficient
    return weftsim.simulate(weftsim.load_scene("loom", dry), engine="reference")


@pytest.mark.parametrize(("roughness_um", "bound"), [(0.001, 0.02), (0.4, 0.05)])
def test_no_oil_is_the_dry_loom(dry_loom, roughness_um, bound):
    """The loom at 600 rpm, c = 0.1 mm, no oil (1e-9 mPa s) with the asperities on: smooth surfaces (1 nm) are the
    dry joint with the solids' friction mu_b = 0.1, revolution 2's peaks within 2 % (measured 0.04 % on the rapier
    acceleration, 0.08 % on the torque and the joint's load: -6828.8 against -6831.2 m/s2, 33.93 against 33.96 kN);
    real roughness (0.4 um) a rough dry joint close to it (the issue asks no number: measured 2.5 % on the
    acceleration, 2.6 % on the load; 5 % here).  The former continuation of the asperities beyond c gave 40 464
    and 10 161 m/s2; the hand-over to a dry law without the boundary friction gave 6 436 m/s2, the frictionless
    dry loom's 6 446, where the dry loom with mu_b gives 6 831."""
    import weftsim
    from weftsim.post.analysis import peaks

    run = weftsim.simulate(weftsim.load_scene("loom", {**NO_OIL, "joint_e.lubrication.roughness_um": roughness_um}),
                           engine="reference")
    assert run.ok and dry_loom.ok, (run.message, dry_loom.message)
    got, dry = peaks(run, 1), peaks(dry_loom, 1)
    for name in ("rapier_acceleration_m_s2", "driving_torque_Nm"):
        for side in ("min", "max"):
            assert got[name][side] == pytest.approx(dry[name][side], rel=bound), (name, side)
    assert got["joint_force_N"]["max"] == pytest.approx(dry["joint_force_N"]["max"], rel=bound)
    # The energy closes with the dissipating asperities (the reference engine integrates their loss as a state):
    # measured 1e-6 of the largest kinetic energy; the dry run's own residual at rtol 1e-5 is ~3e-6.
    s = run.steps
    balance = (s["kinetic_energy_J"] + s["potential_energy_J"] + s["contact_energy_J"] + s["dissipated_energy_J"]
               - s["driving_work_J"])  # fmt: skip
    assert np.max(np.abs(balance - balance[0])) < 2e-4 * np.max(s["kinetic_energy_J"])


def test_no_oil_is_the_dry_loom_on_the_looms_own_law():
    """The same limit on the law `weftsim run loom` uses (the cylindrical law, the loom's default): smooth
    surfaces without oil are the dry joint with mu_b in revolution 2's statistics within 2 %.  Not its peaks: on this
    law at c = 0.1 mm revolution 2's peaks are not reproducible (the dry joint alone, reference engine, rtol 1e-7,
    1e-9, 1e-10, 1e-11: rapier acceleration maximum 15 106, 16 043, 14 473, 14 116 m/s2; no oil, smooth: 15 298-16 132),
    while the statistics are: RMS rapier acceleration 2 557-2 574 dry against 2 563-2 586 without oil, RMS joint
    load 13 570-13 653 N against 13 596-13 708 N (0.04-1.1 % apart at each tolerance; 0.3 % at the defaults)."""
    import weftsim
    from weftsim.input.params import Lubrication
    from weftsim.post.analysis import statistics

    base = {"joint_e.clearance_mm": 0.1}
    dry = weftsim.simulate(weftsim.load_scene("loom", {
        **base, "joint_e.friction_coefficient": Lubrication(viscosity=0.0).boundary_friction_coefficient}),
        engine="reference")
    smooth = weftsim.simulate(weftsim.load_scene("loom", {
        **base, "joint_e.lubrication.viscosity_mpa_s": 1e-9, "joint_e.lubrication.roughness_um": 0.001}),
        engine="reference")
    assert dry.ok and smooth.ok, (dry.message, smooth.message)
    assert dry.scene.joint.law == smooth.scene.joint.law == "cylindrical"
    got, want = statistics(smooth), statistics(dry)
    for name in ("rapier_acceleration_m_s2", "driving_torque_Nm", "joint_force_N"):
        assert got[name]["rms"] == pytest.approx(want[name]["rms"], rel=0.02), name
    assert got["joint_force_N"]["mean"] == pytest.approx(want["joint_force_N"]["mean"], rel=0.02)
