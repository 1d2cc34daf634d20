"""The flexible rapier tape (docs/rapier-tape.md): closed forms, limits and energy of the kernel's model.

The kernel's tape (weftsim.physics.tape) is checked where the physics has an answer: the first axial
frequency of a fixed free length with the head at its end (beta L tan beta L = M / m), the quasi-static
stretch under a constant wheel acceleration, the energy balance with the free length changing under the
tape, the rigid rapier as the limit of a stiff tape, and the scene table's rules.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from weftsim.api import load_scene, simulate
from weftsim.errors import SceneError
from weftsim.input.params import RapierTape
from weftsim.physics import tape as kt
from weftsim.model.tape import first_frequency, quasi_static, rigid_equivalent, ritz_matrices, tape_block
from weftsim.model.tape_selection import tape_check

TAPE = RapierTape()
# The loom_tape scene's free lengths: outermost (250 mm), mid stroke and innermost (250 + 1241 mm).
LENGTHS = (0.25, 0.87, 1.49)


def _kernel_parameters(tape: RapierTape) -> np.ndarray:
    """A parameter array holding only the tape block (the driven tape reads nothing else)."""
    scene = replace(load_scene("loom"), rapier_tape=tape)
    return np.concatenate([np.zeros(kt.TAPE), tape_block(scene, scene.geometry.rapier_ratio, 0.0)])


def _driven_rhs(prm, motion):
    n = int(prm[kt.TAPE + kt.MODES])

    def rhs(t, y):
        s, sd, sdd = motion(t)
        qdd = np.empty(n)
        kt.driven_tape(prm, s, sd, sdd, y[:n].copy(), y[n:2 * n].copy(), qdd)
        return np.concatenate([y[n:2 * n], qdd])

    return rhs


@pytest.mark.parametrize("free_length", LENGTHS)
def test_first_frequency_of_the_kernels_tape_meets_the_closed_form(free_length):
    """Mass and stiffness of the compiled kernel at a fixed free length: the first eigenfrequency against
    beta L tan(beta L) = M / m.  Measured 1e-8 to 5e-9 with 4 Ritz functions; the issue asks 0.5 %."""
    prm = _kernel_parameters(TAPE)
    n = TAPE.modes
    m_sq, m_qq, f_q = np.empty(n), np.empty((n, n)), np.empty(n)
    stiffness = np.empty((n, n))
    for j in range(n):  # f_q = -K q at rest (s' = q' = 0): K column by column
        q = np.zeros(n)
        q[j] = 1.0
        kt.tape_terms(prm, free_length, 0.0, q, np.zeros(n), m_sq, m_qq, f_q)
        stiffness[:, j] = -f_q
    from scipy.linalg import eigh

    omega = np.sqrt(eigh(stiffness, m_qq.copy(), eigvals_only=True))
    expected = first_frequency(TAPE, free_length)
    assert omega[0] / (2 * math.pi) == pytest.approx(expected, rel=5e-3)
    # The closed form's root: beta L tan(beta L) = M / m to round-off.
    x = 2 * math.pi * expected * free_length / math.sqrt(TAPE.axial_modulus / TAPE.density)
    assert x * math.tan(x) == pytest.approx(TAPE.mass_per_length * free_length / TAPE.head_mass, rel=1e-10)


def test_free_vibration_of_the_head_rings_at_the_first_frequency():
    """Time domain: the wheel held, the tape released from its first mode shape (no damping); the head's
    displacement crosses zero at the closed-form period (10 periods, crossings interpolated).  Measured
    within 2e-6 at 0.87 m."""
    tape = replace(TAPE, damping_time=0.0)
    prm = _kernel_parameters(tape)
    lam = LENGTHS[1]
    m = ritz_matrices(tape.modes)
    from scipy.linalg import eigh

    mass = tape.mass_per_length * lam * m["P"] + tape.head_mass * np.outer(m["h"], m["h"])
    _, shapes = eigh(tape.axial_stiffness / lam * m["S"], mass)
    q0 = 1e-5 * shapes[:, 0] / (m["h"] @ shapes[:, 0])
    period = 1.0 / first_frequency(tape, lam)
    # s = lam - L0 held still: the free length is lam.
    rhs = _driven_rhs(prm, lambda t: (lam - tape.free_length, 0.0, 0.0))
    sol = solve_ivp(rhs, (0.0, 10.25 * period), np.concatenate([q0, np.zeros(tape.modes)]), method="DOP853",
                    rtol=1e-10, atol=1e-16, dense_output=True)
    t = np.linspace(0.0, 10.25 * period, 20001)
    head = m["h"] @ sol.sol(t)[:tape.modes]
    down = np.nonzero((head[:-1] > 0.0) & (head[1:] <= 0.0))[0]
    crossings = t[down] - head[down] * (t[down + 1] - t[down]) / (head[down + 1] - head[down])
    assert np.diff(crossings).mean() == pytest.approx(period, rel=5e-3)


def test_constant_wheel_acceleration_stretches_the_tape_quasi_statically():
    """The wheel accelerating at a from rest, the free length growing from 0.25 m: the head lags the wheel by
    the stretch of the head's inertia m a L / EA plus the tape's own mu a L^2 / (2 EA); the axial force at
    the wheel is -(m + mu L) a, at the head -m a.  Measured within 3e-5 (the growing length's dynamic
    correction) at the end; the issue asks 1 %."""
    accel = 1000.0
    prm = _kernel_parameters(TAPE)
    n = TAPE.modes
    rhs = _driven_rhs(prm, lambda t: (0.5 * accel * t * t, accel * t, accel))
    y0 = np.concatenate([quasi_static(TAPE, TAPE.free_length, accel), np.zeros(n)])
    t_end = 0.02
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-9, atol=1e-15)
    s, sd = 0.5 * accel * t_end**2, accel * t_end
    lam = TAPE.free_length + s
    y = sol.y[:, -1]
    ea, mu, m = TAPE.axial_stiffness, TAPE.mass_per_length, TAPE.head_mass
    stretch = -(m * accel * lam + mu * accel * lam**2 / 2) / ea
    lag = ritz_matrices(n)["h"] @ y[:n]
    assert lag == pytest.approx(stretch, rel=1e-2)
    wheel, root, _, head_a = kt.driven_tape(prm, s, sd, accel, y[:n].copy(), y[n:].copy(), np.empty(n))[:4]
    assert root == pytest.approx(-(m + mu * lam) * accel, rel=1e-2)
    assert -m * head_a == pytest.approx(-m * accel, rel=1e-2)
    assert wheel == pytest.approx(-TAPE.mass * accel, rel=1e-2)  # the rigid rapier's -m8 s''


def test_energy_of_the_driven_tape_balances_with_the_length_changing():
    """The wheel swinging the free length from 0.25 to 1.45 m and back (s = 0.6 (1 - cos 2 pi 20 t), one cycle), damping
    and guide friction on: the wheel's work equals the change of the tape's kinetic and strain energy plus
    what damping and friction dissipated (1.6e-3 of the largest kinetic energy).  Measured residual 4e-15 of
    the largest kinetic energy (rtol 1e-8); an error in the terms of the moving free length (g_s, g_q)
    shows at order 1."""
    tape = replace(TAPE, guide_friction_coefficient=0.3)
    prm = _kernel_parameters(tape)
    n = tape.modes
    w = 2 * math.pi * 20.0

    def motion(t):
        return 0.6 * (1 - math.cos(w * t)), 0.6 * w * math.sin(w * t), 0.6 * w * w * math.cos(w * t)

    base = _driven_rhs(prm, motion)

    def rhs(t, y):
        s, sd, sdd = motion(t)
        out = kt.driven_tape(prm, s, sd, sdd, y[:n].copy(), y[n:2 * n].copy(), np.empty(n))
        return np.concatenate([base(t, y[:2 * n]), [-out[0] * sd, out[6]]])  # wheel's power, dissipated

    y0 = np.concatenate([quasi_static(tape, tape.free_length, 0.6 * w * w), np.zeros(n), [0.0, 0.0]])
    sol = solve_ivp(rhs, (0.0, 0.05), y0, method="DOP853", rtol=1e-8, atol=1e-13, dense_output=True)

    def energy(t):
        y = sol.sol(t)
        s, sd, _ = motion(t)
        out = kt.driven_tape(prm, s, sd, 0.0, y[:n].copy(), y[n:2 * n].copy(), np.empty(n))
        return out[4], out[5], y[2 * n], y[2 * n + 1]

    times = np.linspace(0.0, 0.05, 41)
    rows = np.array([energy(t) for t in times])
    kinetic, strain, work, dissipated = rows.T
    residual = work - (kinetic - kinetic[0]) - (strain - strain[0]) - dissipated
    assert dissipated[-1] > 1e-3 * kinetic.max()  # damping and friction did work
    assert np.abs(residual).max() < 1e-9 * kinetic.max()


@pytest.fixture(scope="module")
def short_runs():
    """loom_tape over the first 18 deg (the start-up impacts), its tape 1e4 and 1e5 x stiffer, and the same scene
    with tape and head as the rigid rapier; all on RODAS4 at rtol 1e-8 (the integrators then agree far below the
    model differences checked)."""
    solver = {"solver.reference.method": "numba_RODAS4", "solver.reference.rtol": 1e-8,
              "solver.reference.atol": 1e-11, "drive.revolutions": 0.05}
    scene = load_scene("loom_tape", solver)
    stiff = [replace(scene, rapier_tape=replace(scene.rapier_tape, axial_modulus=factor * scene.rapier_tape.axial_modulus))
             for factor in (1e4, 1e5)]
    return tuple(simulate(s, engine="reference") for s in stiff) + (simulate(rigid_equivalent(scene), engine="reference"),)


def test_a_stiffer_tape_tends_to_the_rigid_rapier_as_one_over_its_modulus(short_runs):
    """Every channel of the rigid rapier, the head's acceleration against the rigid rapier's, at every sample:
    the tape's compliance is the only difference, so it falls as 1 / E (the quasi-static stretch F / EA, as
    (f_impact / f1)^2).  Measured under the loom's cylindrical law, relative to each channel's peak: 1000 x
    stiffer 1.7e-3 (wheel acceleration, contact force), 3.0e-3 (torque), 2.6e-3 (head acceleration); 1e4 x
    1.7e-4, 3.0e-4, 2.6e-4; 1e5 x 1.6e-5, 2.7e-5, 2.5e-5 (ratios 10.0-10.8 per decade).  The law's short hard
    impacts excite the tape 11-37 times more than the former variable_kd's (1000 x: 5e-5, 8e-5, 2.4e-4), whose
    1000 x tape met 1e-3."""
    *tapes, rigid = (r.samples for r in short_runs)
    assert all(r.ok for r in short_runs)
    pairs = [(name, name) for name in ("rapier_displacement_m", "rapier_velocity_m_s", "rapier_acceleration_m_s2",
                                       "driving_torque_Nm", "contact_force_N", "penetration_m")]
    pairs += [("head_acceleration_m_s2", "rapier_acceleration_m_s2"), ("head_velocity_m_s", "rapier_velocity_m_s")]
    for flexible, stiff_name in pairs:
        scale = np.abs(rigid[stiff_name]).max()
        softer, stiffer = (np.abs(tape[flexible] - rigid[stiff_name]).max() / scale for tape in tapes)
        assert softer < 1e-3, flexible  # 1e4 x: within 0.1 % of the peak (measured at most 3.0e-4)
        # First order in 1 / E: ten times smaller for ten times the modulus (measured 10.0-10.8); a second
        # difference (the tape's mass placement, an integrator's error) would not fall with E.
        assert 5.0 < softer / stiffer < 20.0, (flexible, softer, stiffer)


def test_the_flexible_run_balances_its_energy():
    """Kinetic (with the tape's), potential (with its strain energy), contact and dissipated energy (with its
    damping) against the crank's work: measured 1e-10 of the largest kinetic energy at the default rtol."""
    result = simulate(load_scene("loom_tape", {"drive.revolutions": 0.05}), engine="reference")
    s = result.steps
    total = s["kinetic_energy_J"] + s["potential_energy_J"] + s["contact_energy_J"] + s["dissipated_energy_J"]
    residual = total - total[0] - s["driving_work_J"]
    assert np.abs(residual).max() < 1e-8 * s["kinetic_energy_J"].max()
    assert s["tape_strain_energy_J"].max() > 0.0
    # The strain energy is the tape's share of the potential energy: U = EA/(2 lam) q^T S q >= 0 at every step.
    assert s["tape_strain_energy_J"].min() >= 0.0


def test_the_rigid_route_is_the_rigid_rapier_bit_for_bit():
    """rapier_tape.model = 'rigid': the loom with m8 = tape + head, every channel bit for bit."""
    scene = load_scene("loom_tape", {"rapier_tape.model": "rigid", "drive.revolutions": 0.05})
    tape_run = simulate(scene, engine="reference")
    rigid_run = simulate(rigid_equivalent(scene), engine="reference")
    assert tape_run.scene.rapier_tape is not None and "rapier" in tape_run.path
    for name, values in rigid_run.samples.items():
        np.testing.assert_array_equal(tape_run.samples[name], values, err_msg=name)


def test_the_selection_scales_with_the_tapes_stiffness():
    """epsilon ~ (f_drive / f1)^2 ~ 1 / E: 1000 x stiffer, 1000 x smaller, but for the resonance factor
    1 / (1 - r^2) of the soft tape, at most 1 / (1 - 0.018) for its highest harmonic above round-off (k = 11,
    110 Hz against 823 Hz; measured ratio 0.99831e-3); at 600 rpm the loom's tape passes (6.5e-4), at 800
    rpm not (1.15e-3)."""
    scene = load_scene("loom_tape", {"rapier_tape.model": "auto"})
    check = tape_check(scene)
    stiff = tape_check(replace(scene, rapier_tape=replace(scene.rapier_tape, axial_modulus=1e14)))
    ratio = stiff["harmonic_error"] / check["harmonic_error"]
    assert 1e-3 * (1 - 0.018) < ratio < 1e-3
    assert check["model"] == "rigid" and check["first_frequency_hz"][0] < check["first_frequency_hz"][1]
    fast = tape_check(load_scene("loom_tape", {"rapier_tape.model": "auto", "drive.speed_rpm": 800.0}))
    assert fast["model"] == "flexible"


def test_an_empty_table_is_the_default_tape(tmp_path):
    path = tmp_path / "tape.toml"
    path.write_text('extends = "loom"\nname = "t"\n[rapier_tape]\n')
    assert load_scene(str(path)).rapier_tape == RapierTape()


def test_a_tape_shorter_than_the_stroke_is_refused():
    with pytest.raises(SceneError, match="rapier_tape.length_mm' must be at least"):
        load_scene("loom_tape", {"rapier_tape.length_mm": 1000.0})


def test_the_flexible_tape_without_a_clearance_fails_with_one_line():
    result = simulate(load_scene("loom_tape", {"joint_e.clearance_mm": 0.0}), engine="reference")
    assert not result.ok and "needs a clearance at E" in result.message and "\n" not in result.message


@pytest.mark.parametrize("free_length", LENGTHS)
def test_exudyns_ancf_tape_meets_the_same_closed_form(free_length):
    """The other engine's elements: the guided free length as 4 ANCF cables with the head as a mass point
    (weftsim.exudyn_engine.tape), first axial frequency against beta L tan(beta L) = M / m.  Measured within
    8e-10 (4 elements); the issue asks 0.5 %."""
    from weftsim.exudyn_engine.tape import axial_frequencies

    assert axial_frequencies(TAPE, free_length, elements=4)[0] == pytest.approx(first_frequency(TAPE, free_length),
                                                                                rel=5e-3)


def _pulse(t: float, peak: float = 2000.0, duration: float = 5e-4) -> tuple[float, float, float]:
    """The wheel's (s, s', s'') under a raised-cosine acceleration pulse of ``peak`` m/s^2 from rest."""
    w = 2 * math.pi / duration
    if t <= 0.0:
        return 0.0, 0.0, 0.0
    if t < duration:
        return (0.5 * peak * (t * t / 2 + (math.cos(w * t) - 1) / w**2), 0.5 * peak * (t - math.sin(w * t) / w),
                0.5 * peak * (1 - math.cos(w * t)))
    return 0.5 * peak * duration * (duration / 2 + t - duration), 0.5 * peak * duration, 0.0


def test_both_engines_agree_on_the_heads_acceleration_under_a_wheel_pulse():
    """The wheel jerked by a 2000 m/s^2, 0.5 ms pulse (an impact's time scale; the tape's first mode at 0.87 m
    rings at 1165 Hz), damping on: the head's acceleration peaks (+3229 / -3143 m/s^2, 1.6 x the wheel's) on the
    kernel's Ritz tape and on Exudyn's ANCF cables (4 elements, h = 1 us; 8 elements at 0.5 us move them by
    5e-6).  Measured 2.2e-4 and 0.9e-4 apart (the kernel's free length grows 0.2 % under the pulse, Exudyn's
    is fixed); the issue asks 1 %.
    """
    from weftsim.exudyn_engine.tape import driven_head_acceleration

    tape = replace(TAPE, free_length=0.87)
    end = 4e-3
    _, exudyn_head = driven_head_acceleration(tape, tape.free_length, lambda t: _pulse(t)[0], end, 1e-6)
    prm = _kernel_parameters(tape)
    n = tape.modes
    sol = solve_ivp(_driven_rhs(prm, _pulse), (0.0, end), np.zeros(2 * n), method="DOP853", rtol=1e-9, atol=1e-14,
                    dense_output=True, max_step=2.5e-5)
    head = []
    for t in np.linspace(0.0, end, 4001):
        y = sol.sol(t)
        head.append(kt.driven_tape(prm, *_pulse(t), y[:n].copy(), y[n:].copy(), np.empty(n))[3])
    head = np.array(head)
    assert head.max() > 1.5 * 2000.0  # the tape rings: the check is not the rigid rapier's
    assert head.max() == pytest.approx(exudyn_head.max(), rel=1e-2)
    assert head.min() == pytest.approx(exudyn_head.min(), rel=1e-2)


def test_without_the_table_the_rigid_rapier_is_untouched():
    """No [rapier_tape]: the kernel's parameters and state are the rigid chain's (no tape block, topology E_ONLY,
    6 states), the run has no tape channels and its path no tape verdict; the stored peaks of
    tests/test_regression.py hold the rigid rapier's numbers themselves."""
    from weftsim.model.dynamics import initial_state, pack_parameters
    from weftsim.physics import chain_f as kf
    from weftsim.post.results import TAPE_CHANNELS, scene_channels

    scene = load_scene("loom", {"drive.revolutions": 0.02})
    assert scene.rapier_tape is None
    prm = pack_parameters(scene)
    assert prm.size == kf.N_PARAMETERS and prm[kf.TOPOLOGY] == kf.E_ONLY and initial_state(scene).size == 6
    assert not set(TAPE_CHANNELS) & set(scene_channels(scene))
    result = simulate(scene, engine="reference")
    assert "rapier" not in result.path and not set(TAPE_CHANNELS) & set(result.samples)


def test_the_automatic_engine_of_a_flexible_tape_is_the_reference_engine():
    """engine 'auto' is the Exudyn engine, but a scene whose tape runs flexible goes to the reference engine
    (both model it, tests/test_exudyn_tape.py); a tape run as the rigid rapier stays on the default."""
    from weftsim import engines

    flexible = load_scene("loom_tape", {"drive.revolutions": 0.01})
    assert engines.resolve("auto", flexible) == "reference"
    assert engines.resolve("auto", load_scene("loom_tape", {"rapier_tape.model": "rigid"})) == engines.DEFAULT_ENGINE
    assert simulate(flexible).engine == "reference"
