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


def test_tracker_holds_impact_velocity_until_separation_and_floors_it():
    tr = OnsetTracker(C, 1e-4)
    tr.accept(1e-6, -1e-7, 0.4)
    tr.accept(2e-6, 1e-7, 0.2)  # onset half-way: v_imp = 0.3, t = 1.5e-6
    assert tr.first_contact_time == pytest.approx(1.5e-6, rel=1e-12)  # round-off only
    assert tr.held == pytest.approx(0.3, rel=1e-12)
    tr.accept(3e-6, 2e-7, -0.1)  # still in contact: held value kept
    assert tr.callback_state[0] == pytest.approx(0.3, rel=1e-12)
    tr.accept(4e-6, -1e-8, -0.2)  # separation
    tr.accept(5e-6, 1e-8, -1e-9)  # grazing re-entry with non-positive rate: floored
    assert tr.held == 1e-4
    assert tr.contact_events == 2
    hist = tr.history()
    np.testing.assert_array_equal(hist["in_contact"], [0, 0, 1, 1, 0, 1])


STATES = [  # (e, e_dot, [v_held, delta0, rate0]): free, onset inside the step, held contact, centred
    ([1e-4, 5e-5, 0.0], [0.1, 0.0, 0.0], [1e-4, -C, 0.0]),
    ([C * 1.0004, 0.0, 0.0], [0.2, 0.05, 0.0], [1e-4, -2e-8, 0.25]),
    ([0.0, -C * 1.002, 0.0], [0.01, -0.03, 0.0], [0.2, 3e-7, 0.05]),
    ([0.0, -C * 1.002, 0.0], [0.01, 0.8, 0.0], [0.2, 3e-7, 0.05]),  # separating fast: clamped to 0
    ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1e-4, -C, 0.0]),
]


def _reference_force(law, e, e_dot, mem):
    """The callback's contract written with the numpy law and the onset module."""
    delta, rate = penetration_state(e[0], e[1], e_dot[0], e_dot[1], C)
    if delta <= 0.0:
        return np.zeros(2)
    v = mem[0] if mem[1] > 0.0 else onset_velocity(mem[1], mem[2], delta, rate)
    f = float(law.normal_force(delta, rate, max(v, JOINT.min_impact_velocity)))
    return f * np.array(e[:2]) / math.hypot(e[0], e[1])


@pytest.mark.parametrize("name", sorted(LAWS))
def test_python_and_symbolic_routes_equal_the_law(name):
    law = make_law(dataclasses.replace(JOINT, law=name))
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    py = callbacks.make_python_force(law, C, JOINT.min_impact_velocity)
    sym = callbacks.make_symbolic_force(mbs, law, C, JOINT.min_impact_velocity)
    for e, e_dot, mem in STATES:
        want = _reference_force(law, e, e_dot, mem)
        got_py = np.array(py(mbs, 0.0, 0, e, e_dot, mem, [0.0] * 3, [0.0] * 3)[:2])
        got_sym = np.array(sym.Evaluate(mbs, 0.0, 0, e, e_dot, mem, [0.0] * 3, [0.0] * 3)[:2])
        scale = max(np.abs(want).max(), 1.0)
        # Same formula in three codes: only round-off differences (forces up to ~1e4 N here).
        np.testing.assert_allclose(got_py, want, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(got_sym, want, rtol=0, atol=1e-12 * scale)


def test_numba_route_equals_python():
    pytest.importorskip("numba")
    law = make_law(JOINT)
    py = callbacks.make_python_force(law, C, JOINT.min_impact_velocity)
    nb = callbacks.make_numba_force(law, C, JOINT.min_impact_velocity)
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
