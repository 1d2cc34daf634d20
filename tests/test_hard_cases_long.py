"""Hard cases (issue 7, part 1), continued: long runs without drift, and lasting contact with
grazing impacts, where the floor on the impact velocity (``joint.min_impact_velocity``) is what
keeps the contact damping finite.  Figures in docs/hard-cases.md.

Long runs: the reference engine runs 50 revolutions (~1 min); Exudyn runs 4 (~30 s: 50 would take
~7 min at its 2e-6 s step) and is compared with the reference engine's long-run statistics.  The
impact sequence after the start-up is chaotic (docs/physics.md section 6), so "no drift" is judged on
per-revolution statistics, not on one revolution matching the next.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from weftsim import exudyn_engine, reference
from weftsim.post.analysis import channel_statistics, energy_balance, peaks
from weftsim.joint.contact import make_law
from weftsim.input.params import Drive, ExudynSolver, Material, Scene
from weftsim.post.results import CHANNELS
from conftest import door

RPM = math.pi / 30.0
STEEL = Scene()
LONG_REVOLUTIONS = 50
EXUDYN_REVOLUTIONS = 4
RMS_CHANNELS = ("contact_force_N", "rapier_acceleration_m_s2", "driving_torque_Nm")


def revolutions(scene: Scene, n: float, **joint) -> Scene:
    return dataclasses.replace(scene, joint=dataclasses.replace(scene.joint, **joint),
                               drive=dataclasses.replace(scene.drive, revolutions=n))  # fmt: skip


def per_revolution(result, first: int = 1) -> dict[str, np.ndarray]:
    """RMS of each channel of RMS_CHANNELS, KE at the start and stroke of every revolution from ``first``."""
    st, period = result.steps, result.scene.drive.period
    n = int(round(result.scene.drive.revolutions))
    out = {name: [] for name in RMS_CHANNELS + ("kinetic_energy_at_start_J", "stroke_m")}
    for k in range(first, n):
        keep = (st["time_s"] >= k * period - 1e-12) & (st["time_s"] <= (k + 1) * period + 1e-12)
        for name in RMS_CHANNELS:
            out[name].append(channel_statistics(st["time_s"][keep], st[name][keep])["rms"])
        out["kinetic_energy_at_start_J"].append(st["kinetic_energy_J"][keep][0])
        s = st["rapier_displacement_m"][keep]
        out["stroke_m"].append(s.max() - s.min())
    return {k: np.array(v) for k, v in out.items()}


def assert_finite_and_bounded(result) -> None:
    assert result.ok, result.message
    assert all(np.all(np.isfinite(result.steps[name])) for name in CHANNELS)
    bound = result.scene.limits.max_penetration * result.scene.joint.journal_radius  # weftsim.checks.guards
    assert result.steps["penetration_m"].max() < bound


# --- Long runs ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def long_reference():
    return door("reference")(revolutions(STEEL, LONG_REVOLUTIONS))


@pytest.mark.slow
def test_fifty_revolutions_without_drift(long_reference):
    r = long_reference
    assert_finite_and_bounded(r)
    balance = energy_balance(r)
    # 100 rtol KE_max (5e-5 J) as for one revolution: the error does not grow with the ~700 impacts
    # (measured 7e-6 J against 380 J dissipated).
    assert abs(balance["residual_J"]) < 100 * r.scene.reference_solver.rtol * r.steps["kinetic_energy_J"].max()
    rev = per_revolution(r)  # revolutions 2..50: the start-up impact of revolution 1 left out
    half = len(rev["stroke_m"]) // 2
    for name in RMS_CHANNELS:
        early, late = rev[name][:half].mean(), rev[name][half:].mean()
        # Per-revolution RMS scatter ~5 % (chaotic impact sequence), so two 24-revolution means differ
        # by ~1.5 % (1 SE) by chance; 5 % is ~3.4 SE.  Measured 2.2-2.4 %.  A drift of the steady cycle
        # (energy pumped in, a creeping journal) would show as a trend here.
        assert late == pytest.approx(early, rel=0.05), name
    # The mechanism's energy at the start of every revolution (theta = 0 mod 360) does not accumulate.
    # It scatters from revolution to revolution with the vibration the last impacts left in the chain:
    # measured s = 0.46 J (4.8 %) about 9.63 J under the max_approach rule (0.7 % under the onset rule,
    # whose slow onsets overdamped every lasting contact).  A drift shows as a difference of the two
    # halves' means beyond chance: their chance difference has standard error s sqrt(2 / n) (1.4 % here;
    # measured 2.6 %); 4 of it.
    ke = rev["kinetic_energy_at_start_J"]
    chance = ke.std(ddof=1) * np.sqrt(2.0 / half)
    assert abs(ke[half:].mean() - ke[:half].mean()) < 4.0 * chance
    # The rapier stroke (1.0578 m with the journal offset; ideal 1.052348 m) varies between revolutions
    # only by where the journal sits in its clearance at the stroke's ends: each end moves by at most
    # (d5 d7 / d6) (c + delta_max) / L_FG (the journal displaced along the sector arm's tangent), 5.5 mm
    # for the reference scene (0.675 m x 0.42 mm / 50 mm = 5.7 mm).  Measured 2.3 mm (0.25 mm under the
    # onset rule).
    geo, joint = r.scene.geometry, r.scene.joint
    lever = geo.rapier_ratio * (joint.clearance + r.steps["penetration_m"].max()) / geo.l_fg
    assert rev["stroke_m"].max() - rev["stroke_m"].min() < lever
    print(f"\nreference {LONG_REVOLUTIONS} revolutions: {r.solver_stats['steps']} steps, "
          f"{r.solver_stats['impacts']} impacts, wall {r.wall_time_s:.1f} s, energy residual "
          f"{balance['residual_J']:.3g} J of {balance['dissipated_energy_J']:.4g} J dissipated, max penetration "
          f"{r.steps['penetration_m'].max() * 1e6:.1f} um; RMS halves "
          + ", ".join(f"{n} {rev[n][:half].mean():.4g}/{rev[n][half:].mean():.4g}" for n in RMS_CHANNELS))


@pytest.mark.slow
def test_exudyn_steady_running_matches_the_long_reference_run(long_reference):
    rigid = dataclasses.replace(STEEL, exudyn_solver=ExudynSolver(model="rigid_body"))
    r = door("exudyn")(revolutions(rigid, EXUDYN_REVOLUTIONS))
    assert_finite_and_bounded(r)
    balance = energy_balance(r)
    # Trapezoid sums and the integrator's damping at each impact (tests/test_exudyn_engine.py): 1e-3 of
    # the dissipated energy; measured ~1e-5 of it per revolution.
    assert abs(balance["residual_J"]) < 1e-3 * balance["dissipated_energy_J"]
    ex, ref = per_revolution(r), per_revolution(long_reference)
    for name in RMS_CHANNELS:
        # Mean of 3 steady revolutions against the 49 of the reference: per-revolution scatter 5 %, so
        # the 3-revolution mean has ~3 % standard error; 10 % is ~3 of it.
        assert ex[name].mean() == pytest.approx(ref[name].mean(), rel=0.10), name
    # Energy at every revolution start within the reference engine's steady band: 4 of its measured
    # revolution-to-revolution standard deviation (0.46 J about 9.63 J) from its mean.
    band = 4.0 * ref["kinetic_energy_at_start_J"].std(ddof=1)
    assert np.abs(ex["kinetic_energy_at_start_J"] - ref["kinetic_energy_at_start_J"].mean()).max() < band
    print(f"\nexudyn {EXUDYN_REVOLUTIONS} revolutions: {r.solver_stats['steps']} steps, wall {r.wall_time_s:.1f} s, "
          f"energy residual {balance['residual_J']:.3g} J of {balance['dissipated_energy_J']:.4g} J; RMS "
          + ", ".join(f"{n} {ex[n].mean():.4g} (reference {ref[n].mean():.4g})" for n in RMS_CHANNELS))


# --- Lasting contact and grazing impacts: the floor on the impact velocity ---------------

# At 20 rpm the inertial loads are 400x smaller than at 400 rpm: after the start-up bounces the
# journal rests on the bearing wall (lasting contact) and touches it again gently, some onsets at a
# tangency of delta(t) with 0, i.e. with an impact velocity of practically zero.
CREEP = dataclasses.replace(STEEL, drive=Drive(speed=20.0 * RPM, revolutions=0.1))
FLOORS = (1e-6, 1e-5, 1e-4, 1e-3)  # m/s; the default is 1e-4


def onsets(result) -> np.ndarray:
    """Indices of the steps at which a contact starts."""
    contact = result.steps["in_contact"] > 0
    return np.flatnonzero(contact[1:] & ~contact[:-1]) + 1


def damping(result) -> np.ndarray:
    """D = xi F_el(delta) / v_imp at every step in contact (0 elsewhere), N s/m (paper Eq. 19)."""
    st, law = result.steps, make_law(result.scene.joint)
    inside = st["in_contact"] > 0
    held = np.where(inside, st["impact_velocity_m_s"], 1.0)
    return np.where(inside, law.hysteresis * law.elastic_force(np.maximum(st["penetration_m"], 0.0)) / held, 0.0)


def figures(result) -> dict[str, float]:
    p = peaks(result, 0) if result.scene.drive.revolutions >= 1 else None
    st = result.steps
    out = {
        "contact_force_N": float(st["contact_force_N"].max()),
        "rapier_acceleration_m_s2": float(np.abs(st["rapier_acceleration_m_s2"]).max()),
        "driving_torque_Nm": float(np.abs(st["driving_torque_Nm"]).max()),
        "penetration_m": float(st["penetration_m"].max()),
        "dissipated_energy_J": float(st["dissipated_energy_J"][-1]),
    }
    if p is not None:  # first-revolution peaks
        out.update({f"rev1_max_{k}": v["max"] for k, v in p.items()})
    return out


def contact_depths(result) -> np.ndarray:
    """Largest penetration of each contact (from an onset to the next separation), m."""
    st = result.steps
    contact = st["in_contact"] > 0
    separations = np.flatnonzero(contact[:-1] & ~contact[1:]) + 1
    depths = []
    for start in onsets(result):
        later = separations[separations > start]
        end = int(later[0]) if later.size else contact.size
        depths.append(st["penetration_m"][start:end].max())
    return np.array(depths)


# A contact whose penetration never exceeds this is a tangency of delta(t) with 0, not an impact: its
# elastic force, and the damping force proportional to it, are ~0 whatever the held velocity.  In the
# creep window 1e-15 m is 30x the deepest tangency measured (3.0e-17 m, round-off of the 0.25 mm
# clearance) and 1e-9 of the shallowest real re-contact (0.92 um).
TANGENCY_DEPTH = 1e-15


@pytest.mark.slow
def test_impact_velocity_floor_keeps_damping_finite_and_results_do_not_hinge_on_it():
    """Every floor keeps the held velocity, so the damping, finite; a floor changes the results only
    where real onsets are slower than it.  Which onsets are slow depends on the event location and the
    held-velocity rule (the engine of issue 7 found two real onsets at 5.7e-4 and 6.0e-4 m/s and 9
    tangencies below 1e-6 m/s; with the largest-approach rule and the corrected event location of issue
    11 every onset is above 1.5e-3 m/s), so the test reads them from the run instead of naming them."""
    runs = {v: door("reference")(revolutions(CREEP, 0.1, min_impact_velocity=v)) for v in FLOORS}
    for v, r in runs.items():
        assert_finite_and_bounded(r)
        st = r.steps
        inside = st["in_contact"] > 0
        # The held impact velocity never goes below the floor, so D = xi F_el / v_imp stays finite.
        assert np.all(st["impact_velocity_m_s"][inside] >= v)
        assert np.all(np.isfinite(damping(r)))
        assert len(onsets(r)) > 40  # the gentle re-contacts of a journal resting on the wall (measured 49-63)
    lowest = runs[FLOORS[0]]
    rates = lowest.steps["impact_velocity_m_s"][onsets(lowest)]  # approach rates, held at 1e-6 if slower
    real = contact_depths(lowest) > TANGENCY_DEPTH
    base = figures(lowest)
    for v in FLOORS[1:]:
        if not np.any(real & (rates < v)):
            # Below every real onset: only tangencies are held at the floor, and the results are the same
            # to round-off (measured identical).
            for key, value in figures(runs[v]).items():
                assert value == pytest.approx(base[key], rel=1e-9), (v, key)
        else:
            # Above some real onsets: their damping is lower (measured at 1e-3 m/s with the engine of issue
            # 7: dissipated energy -5.8 %), but the peaks, set by faster impacts, stay within 0.1 %
            # (measured unchanged).
            # Results hinge on v_min once it exceeds real onset velocities: keep it below the slowest one.
            for key in ("contact_force_N", "rapier_acceleration_m_s2", "driving_torque_Nm", "penetration_m"):
                assert figures(runs[v])[key] == pytest.approx(base[key], rel=1e-3), (v, key)
            assert figures(runs[v])["dissipated_energy_J"] != base["dissipated_energy_J"]
    # The default floor, 1e-4 m/s, must be below every real onset of this gentle case.
    assert not np.any(real & (rates < 1e-4))


@pytest.mark.slow
def test_floor_acts_only_from_the_first_onset_slower_than_it():
    """E = 1000 GPa, one revolution at 400 rpm: the re-contacts after the start-up impact come at
    mm/s.  A floor below the slowest onset leaves the run bit for bit unchanged; a floor above it holds
    that onset at the floor and changes the run from there on only.

    Which onset is the slowest, and how slow, depends on the event location and the held-velocity
    rule (measured 6.5e-4 m/s at ~300 deg in issue 7, 2.0e-3 m/s at 285 deg and 5.0e-3 m/s at 282 deg
    with later versions of the reference engine), so the test finds it in the run instead of naming it.
    """
    stiff = revolutions(STEEL, 1.0, journal_material=Material(1000e9, 0.3), bearing_material=Material(1000e9, 0.3))
    low = door("reference")(revolutions(stiff, 1.0, min_impact_velocity=1e-5))
    assert_finite_and_bounded(low)
    slowest = float(low.steps["impact_velocity_m_s"][onsets(low)].min())
    # Floors a decade apart: one below the slowest onset and the first one above it.  The start-up impact
    # comes at 0.18 m/s, so 0.1 m/s is the highest floor that can only touch the re-contacts.
    floors = (1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
    assert 1e-5 < slowest < floors[-1], slowest
    below = max(v for v in floors if v < slowest)
    above = min(v for v in floors if v > slowest)
    unchanged = door("reference")(revolutions(stiff, 1.0, min_impact_velocity=below))
    assert figures(unchanged) == figures(low)
    high = door("reference")(revolutions(stiff, 1.0, min_impact_velocity=above))
    assert_finite_and_bounded(high)
    floored = [i for i in onsets(high) if high.steps["impact_velocity_m_s"][i] == above]
    assert floored, f"expected the onset at {slowest:.3g} m/s to be held at the floor {above:g} m/s"
    t_floor = high.steps["time_s"][floored[0]]
    n = int(np.searchsorted(low.steps["time_s"], t_floor))
    # Identical up to that onset (same steps, same states) ...
    for name in CHANNELS:
        np.testing.assert_array_equal(high.steps[name][:n], low.steps[name][:n], err_msg=name)
    # ... where the raw onset velocity (held unfloored with the low floor) was below the floor ...
    assert low.steps["impact_velocity_m_s"][n] < above
    # ... and from where the run differs (a lower contact damping D = xi F_el / v_imp).
    assert high.steps["dissipated_energy_J"][-1] != low.steps["dissipated_energy_J"][-1]


@pytest.mark.slow
def test_exudyn_grazing_window_agrees_with_reference_and_ignores_the_floor():
    """The creep-speed window on Exudyn (step 1e-5 s: the 20 rpm impacts are ~20x slower than at
    400 rpm): the same peaks as the reference engine, and no change between floors 1e-6 and 1e-3."""
    runs = {}
    for v in (1e-6, 1e-3):
        scene = revolutions(CREEP, 0.1, min_impact_velocity=v)
        runs[v] = door("exudyn")(dataclasses.replace(scene, exudyn_solver=ExudynSolver(
            model="rigid_body", step_control="fixed", step_size=1e-5)))
        assert_finite_and_bounded(runs[v])
        inside = runs[v].steps["in_contact"] > 0
        assert np.all(runs[v].steps["impact_velocity_m_s"][inside] >= v)
        assert np.all(np.isfinite(damping(runs[v])))
    a, b = figures(runs[1e-6]), figures(runs[1e-3])
    for key in a:
        # Measured identical: every Exudyn onset in this window is faster than 1e-3 m/s (its fixed
        # step does not see the tangencies the event-driven reference engine locates).
        assert a[key] == pytest.approx(b[key], rel=1e-6), key
    ref = figures(door("reference")(CREEP))
    for key in ("contact_force_N", "rapier_acceleration_m_s2", "driving_torque_Nm", "penetration_m"):
        # Gentle impacts, converged at both engines' settings: measured within 0.2 % (torque).
        assert a[key] == pytest.approx(ref[key], rel=0.01), key
