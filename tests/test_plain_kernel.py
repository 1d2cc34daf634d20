"""The reference engine's plain kernel (weftsim.physics.chain_f.PLAIN): which scenes take it, and that it
computes what the general kernel computes, to the bit (docs/performance.md, "The plain kernel")."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("numba")

from conftest import scene_of  # noqa: E402
from weftsim.joint import load  # noqa: E402
from weftsim.model.dynamics import pack_parameters  # noqa: E402
from weftsim.physics import chain as kc  # noqa: E402
from weftsim.physics import chain_f as kf  # noqa: E402
from weftsim.physics.python import specialize  # noqa: E402
from weftsim.reference import compiled, compiled_channels, compiled_run  # noqa: E402


def test_plain_scenes_are_dry_round_e_only_at_constant_speed():
    prm = pack_parameters(scene_of("reference"))
    assert kf.is_plain(prm)
    assert kf.is_plain(pack_parameters(scene_of("reference", {"joint_e.friction_coefficient": 0.1})))
    assert not kf.is_plain(pack_parameters(scene_of("loom_oiled")))  # a film
    worn = np.append(prm, [0.0, 0.0])  # anything after the chain's blocks is a wear table
    assert not kf.is_plain(worn)
    for slot, value in ((kc.DRIVE_LAW, kc.RUN_DOWN), (kc.DRIVE_LAW, kc.START_UP), (kf.TOPOLOGY, kf.F_ONLY),
                        (kf.TOPOLOGY, kf.E_AND_F), (kf.TOPOLOGY, kf.E_TAPE)):  # fmt: skip
        other = prm.copy()
        other[slot] = value
        assert not kf.is_plain(other), (slot, value)


def test_specialize_rebuilds_only_what_reads_a_bound_name():
    """chain reads the drive law through eccentricity (rebuilt, tagged) but not through elastic_force (shared)."""
    form = specialize(kc.chain, "probe", crank_rate=kc.constant_rate)
    names = form.py_func.__globals__
    assert form.py_func.__qualname__ == "chain.probe"
    assert names["crank_rate"] is kc.constant_rate
    assert names["eccentricity"] is not kc.eccentricity
    assert names["eccentricity"].py_func.__qualname__ == "eccentricity.probe"
    assert names["elastic_force"] is kc.elastic_force


@pytest.mark.parametrize("friction", [0.0, 0.1])
def test_plain_kernel_equals_the_general_one(monkeypatch, friction):
    """Rows, samples, statistics, channels and the joint's load of a dry run, plain against general, equal."""
    scene = scene_of("reference", {"joint_e.friction_coefficient": friction}, revolutions=0.5)
    prm = pack_parameters(scene)
    assert kf.is_plain(prm)
    plain = compiled_run.integrate_compiled(scene)
    steps = plain[0]
    fill_plain = compiled_channels.compiled_channels(scene, *steps)
    channels = dict(fill_plain)
    load_plain = load.joint_force_table(scene, prm, steps[0], steps[1], channels)
    monkeypatch.setattr(compiled_run, "advance_plain", compiled.advance)
    monkeypatch.setattr(compiled_channels, "_fill_plain", compiled_channels._fill)
    monkeypatch.setattr(load, "_joint_force_rows_plain", load.joint_force_rows)
    general = compiled_run.integrate_compiled(scene)
    assert plain[2]["steps"] > 100 and plain[2]["impacts"] > 0  # a run with contact
    for a, b in zip(plain[0] + plain[1], general[0] + general[1]):
        assert np.array_equal(a, b)
    drop = ("wall_time_s",)
    assert {k: v for k, v in plain[2].items() if k not in drop} == {k: v for k, v in general[2].items() if k not in drop}
    assert plain[3] == general[3]
    fill_general = compiled_channels.compiled_channels(scene, *general[0])
    assert fill_plain.keys() == fill_general.keys()
    for name in fill_plain:
        assert np.array_equal(fill_plain[name], fill_general[name]), name
    load_general = load.joint_force_table(scene, prm, steps[0], steps[1], channels)
    for name in load_plain:
        assert np.array_equal(load_plain[name], load_general[name]), name
