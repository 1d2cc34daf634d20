"""The reusable clearance joint of the Exudyn engine: onset capture, callback routes, symbolic laws."""

from __future__ import annotations

import dataclasses
import math

import exudyn as exu
import numpy as np
import pytest

from weftsim.contact import LAWS, make_law
from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.clearance_joint import add_clearance_joint, register_post_step
from weftsim.exudyn_engine.onset import OnsetTracker, onset_fraction, onset_velocity, penetration_state
from weftsim.params import ClearanceJoint

C = 0.25e-3
JOINT = ClearanceJoint(clearance=C)


def test_onset_interpolation_is_exact_for_linear_motion():
    # delta(t) = -1e-6 + 0.2 t crosses 0 at t = 5e-6; delta_dot is constant 0.2 in the step,
    # and a linearly varying rate is interpolated exactly too.
    d0, d1 = -1e-6, -1e-6 + 0.2 * 2e-5
    assert onset_fraction(d0, d1) == pytest.approx(0.25, rel=1e-12)  # round-off only
    assert onset_velocity(d0, 0.1, d1, 0.3) == pytest.approx(0.15, rel=1e-12)  # 0.1 + 0.25 * 0.2
    assert onset_fraction(1e-6, 2e-6) == 0.0  # already penetrated: the start of the step
    assert onset_fraction(-1e-6, -2e-6) == 1.0  # no crossing: the end of the step


def test_penetration_state_signs():
    delta, rate = penetration_state(3e-4, 4e-4, 0.3, 0.4, C)  # |e| = 5e-4 moving outwards at 0.5 m/s
    assert delta == pytest.approx(2.5e-4, rel=1e-12)  # round-off only
    assert rate == pytest.approx(0.5, rel=1e-12)
    assert penetration_state(0.0, 0.0, 1.0, 0.0, C) == (-C, 0.0)  # centred: free, no normal


def test_tracker_holds_impact_velocity_until_separation_onset_rule():
    tr = OnsetTracker(C, 1e-4, rule="onset")
    tr.accept(1e-6, -1e-7, 0.4)
    tr.accept(2e-6, 1e-7, 0.2)  # onset half-way: v_imp = 0.3, t = 1.5e-6
    assert tr.first_contact_time == pytest.approx(1.5e-6, rel=1e-12)  # round-off only
    assert tr.held == pytest.approx(0.3, rel=1e-12)
    tr.accept(3e-6, 2e-7, 0.5)  # approach rate grows past the onset value: "onset" keeps 0.3
    assert tr.callback_state[0] == pytest.approx(0.3, rel=1e-12)
    tr.accept(4e-6, -1e-8, -0.2)  # separation
    assert tr.counters()["separations"] == 1
    hist = tr.history()
    np.testing.assert_array_equal(hist["in_contact"], [0, 0, 1, 1, 0])
    np.testing.assert_allclose(hist["impact_velocity"], [0, 0, 0.3, 0.3, 0], rtol=1e-12)


def test_tracker_max_approach_holds_the_largest_rate_since_onset():
    tr = OnsetTracker(C, 1e-4)  # default rule "max_approach"
    tr.accept(1e-6, -1e-7, 0.4)
    tr.accept(2e-6, 1e-7, 0.2)  # onset at 0.3, end-of-step rate 0.2 lower: 0.3
    assert tr.held == pytest.approx(0.3, rel=1e-12)  # round-off only
    tr.accept(3e-6, 2e-7, 0.5)  # a driven contact pushes harder: held rises to 0.5
    assert tr.held == 0.5
    tr.accept(4e-6, 3e-7, 0.1)  # and never falls while the contact lasts
    assert tr.held == 0.5
    tr.accept(5e-6, -1e-8, 0.3)  # free again, already returning
    tr.accept(6e-6, 1e-8, 0.1)  # new contact: starts again from its own onset, below the old 0.5
    assert tr.held == pytest.approx(0.2, rel=1e-12)  # s = 0.5: 0.3 + 0.5 (0.1 - 0.3)
    assert tr.contact_events == 2 and tr.nonpositive_onsets == 0


def test_tracker_never_holds_a_nonpositive_onset_and_counts_it():
    # A graze inside the step: delta goes from -1e-8 to +1e-8 while the sampled rates say the
    # journal leaves at both ends; linear interpolation gives a negative "onset" rate.  The
    # secant rate (2e-8 m / 1e-6 s = 0.02 m/s) is a positive approach rate the step really had.
    for rule in ("max_approach", "onset"):
        tr = OnsetTracker(C, 1e-4, t0=4e-6, delta0=-1e-8, rate0=-0.2, rule=rule)
        tr.accept(5e-6, 1e-8, -1e-9)
        assert tr.nonpositive_onsets == 1 and tr.contact_events == 1
        assert tr.held == pytest.approx(0.02, rel=1e-9)  # secant: round-off of 2e-8 / 1e-6


def test_tracker_detects_a_separation_inside_one_step():
    # In contact at both ends, leaving at 0.1 m/s and returning at 0.1 m/s over 10 us: the cubic
    # through the ends dips to 1e-7 - 10e-6 * 0.1 / 4 = -1.5e-7 m, a whole free flight in the step.
    tr = OnsetTracker(C, 1e-4, t0=0.0, delta0=1e-7, rate0=-0.1)
    tr.accept(1e-5, 1e-7, 0.1)
    assert tr.missed_separations == 1
    tr.accept(2e-5, 1.5e-7, 0.001)  # a shallow in-contact step: no dip below 0
    assert tr.missed_separations == 1
    free = OnsetTracker(C, 1e-4, t0=0.0, delta0=-1e-7, rate0=0.1)
    free.accept(1e-5, -1e-7, -0.1)  # the mirror case: a whole contact inside one free step
    assert free.missed_contacts == 1 and free.contact_events == 0


def test_tracker_rejects_an_unknown_rule():
    with pytest.raises(ValueError, match="impact_velocity_rule"):
        OnsetTracker(C, 1e-4, rule="largest")


STATES = [  # (e, e_dot, [v_held, delta0, rate0]): free, onset inside the step, held contact, centred
    ([1e-4, 5e-5, 0.0], [0.1, 0.0, 0.0], [1e-4, -C, 0.0]),
    ([C * 1.0004, 0.0, 0.0], [0.2, 0.05, 0.0], [1e-4, -2e-8, 0.25]),
    ([0.0, -C * 1.002, 0.0], [0.01, -0.03, 0.0], [0.2, 3e-7, 0.05]),
    ([0.0, -C * 1.002, 0.0], [0.01, 0.8, 0.0], [0.2, 3e-7, 0.05]),  # separating fast: clamped to 0
    ([0.0, -C * 1.002, 0.0], [0.01, -0.9, 0.0], [0.2, 3e-7, 0.05]),  # approach 0.9 > held 0.2: rules differ
    ([C * 1.0004, 0.0, 0.0], [-0.02, 0.0, 0.0], [1e-4, -2e-8, -0.05]),  # graze: onset estimate < 0
    ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1e-4, -C, 0.0]),
]


def _reference_force(law, e, e_dot, mem, max_approach=True):
    """The callback's contract written with the numpy law and the onset module (SPEC rule)."""
    delta, rate = penetration_state(e[0], e[1], e_dot[0], e_dot[1], C)
    if delta <= 0.0:
        return np.zeros(2)
    v = mem[0] if mem[1] > 0.0 else onset_velocity(mem[1], mem[2], delta, rate)
    if mem[1] <= 0.0 and v <= 0.0:
        v = rate  # never a non-positive onset estimate
    if max_approach:
        v = max(v, rate)
    f = float(law.normal_force(delta, rate, max(v, JOINT.min_impact_velocity)))
    return f * np.array(e[:2]) / math.hypot(e[0], e[1])


@pytest.mark.parametrize("max_approach", [True, False], ids=["max_approach", "onset"])
@pytest.mark.parametrize("name", sorted(LAWS))
def test_python_and_symbolic_routes_equal_the_law(name, max_approach):
    law = make_law(dataclasses.replace(JOINT, law=name))
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    py = callbacks.make_python_force(law, C, JOINT.min_impact_velocity, max_approach=max_approach)
    sym = callbacks.make_symbolic_force(mbs, law, C, JOINT.min_impact_velocity, max_approach)
    for e, e_dot, mem in STATES:
        want = _reference_force(law, e, e_dot, mem, max_approach)
        got_py = np.array(py(mbs, 0.0, 0, e, e_dot, mem, [0.0] * 3, [0.0] * 3)[:2])
        got_sym = np.array(sym.Evaluate(mbs, 0.0, 0, e, e_dot, mem, [0.0] * 3, [0.0] * 3)[:2])
        scale = max(np.abs(want).max(), 1.0)
        # Same formula in three codes: only round-off differences (forces up to ~1e4 N here).
        np.testing.assert_allclose(got_py, want, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(got_sym, want, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("max_approach", [True, False], ids=["max_approach", "onset"])
def test_numba_route_equals_python(max_approach):
    pytest.importorskip("numba")
    law = make_law(JOINT)
    py = callbacks.make_python_force(law, C, JOINT.min_impact_velocity, max_approach=max_approach)
    nb = callbacks.make_numba_force(law, C, JOINT.min_impact_velocity, max_approach)
    for e, e_dot, mem in STATES:
        # Compiled vs interpreted math: round-off only.
        np.testing.assert_allclose(nb(None, 0.0, 0, e, e_dot, mem, None, None),
                                   py(None, 0.0, 0, e, e_dot, mem, None, None), rtol=1e-13, atol=1e-9)  # fmt: skip


def test_add_clearance_joint_rejects_ideal_and_friction():
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    with pytest.raises(ValueError, match="clearance"):
        add_clearance_joint(mbs, 0, 1, ClearanceJoint(clearance=0.0))
    with pytest.raises(NotImplementedError, match="friction"):
        add_clearance_joint(mbs, 0, 1, dataclasses.replace(JOINT, friction_coefficient=0.1))
    with pytest.raises(ValueError, match="callback"):
        add_clearance_joint(mbs, 0, 1, JOINT, callback="fortran")


def test_post_step_hooks_chain_with_a_users_function():
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    seen = []
    mbs.SetPostStepUserFunction(lambda mbs, t: seen.append("user") or True)
    register_post_step(mbs, lambda mbs, t: seen.append("a"))
    register_post_step(mbs, lambda mbs, t: seen.append("b"))
    assert mbs.GetPostStepUserFunction()["function"](mbs, 0.0) is True
    assert seen == ["user", "a", "b"]
