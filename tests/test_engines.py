"""The engine contract and its registry (issue 32): one module names the engines, a plug-in registers the
same way, and ``simulate`` is the one door (before-run checks, the engine's pure solve, vetting once).

The toy engine below is a real engine of the ideal mechanism: the closed form of the crank side
(:func:`weftsim.model.ideal.ideal_channels`, the shared model), evaluated on the output grid.  On an ideal
scene the reference engine runs the same closed form, so the two must agree bit for bit; a toy that
returned anything else would fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import weftsim
from weftsim import engines
from weftsim.errors import EngineError, SceneError


class ToyEngine:
    """The ideal mechanism in closed form, as a plug-in engine (module docstring)."""

    name = "toy"

    def __init__(self):
        self.calls = []

    def select_path(self, scene):
        return {"model": "ideal joint", "method": "closed form (toy)", "reason": "a plug-in of the tests"}

    def estimate(self, scene):
        return engines.Estimate(0.0, 0.0, False)

    def solve(self, scene, progress=None, observe=None):
        from weftsim.model.ideal import ideal_channels
        from weftsim.post.results import RunResult, angle_grid

        self.calls.append(scene.name)
        grid = angle_grid(scene.drive.end_time, scene.drive.speed, scene.output.sample_angle)
        samples = ideal_channels(grid, scene)
        if observe is not None:
            observe(grid)
        if progress is not None:
            progress(1.0)
        result = RunResult(scene, "toy", "success", "", samples, samples, {"wall_time_s": 0.0},
                           {"first_contact_time_s": None})
        object.__setattr__(result, "path", self.select_path(scene))
        return result


@pytest.fixture
def toy():
    engine = ToyEngine()
    engines.register("toy", engine)
    yield engine
    engines.unregister("toy")


def test_a_plug_in_engine_registers_and_runs_through_the_one_door(toy):
    """The toy is found by name, its result is vetted by ``simulate`` (the design checks before and after the run
    are attached, which the toy's own solve never does) and equals the reference engine's closed form bit for bit."""
    scene = weftsim.load_scene("ideal", revolutions=0.5)
    assert "toy" in engines.names() and engines.get("toy") is toy
    seen = []
    result = weftsim.simulate(scene, "toy", on_warning=seen.append, observe=lambda grid: seen.append(grid.size))
    assert toy.calls == [scene.name] and result.ok and result.engine == "toy"
    assert {c["name"] for c in result.plausibility["checks"]} >= {"rapier_acceleration"}
    reference = weftsim.simulate(scene, "reference", on_warning=lambda text: None)
    for channel in ("driving_torque_Nm", "rapier_acceleration_m_s2", "rapier_velocity_m_s"):
        np.testing.assert_array_equal(result.samples[channel], reference.samples[channel])
    assert seen[-1] == result.samples["time_s"].size
    assert weftsim.select_path(scene, "toy")["method"] == "closed form (toy)"
    assert weftsim.estimate(scene, "toy").run_time_s == 0.0
    with pytest.raises(weftsim.OutputError, match="plug-in engine 'toy' cannot be saved"):
        weftsim.save_result(result, "unused.npz")


def test_the_door_runs_the_before_run_checks_for_every_engine(toy):
    """A scene outside the design range warns before the engine starts, on a plug-in as on the built-ins."""
    scene = weftsim.load_scene("ideal", {"limits.max_rapier_acceleration_m_s2": 100.0}, revolutions=0.25)
    seen = []
    weftsim.simulate(scene, "toy", on_warning=seen.append)
    assert any("limits.max_rapier_acceleration_m_s2" in text for text in seen)


def test_the_engines_solve_is_pure_and_the_door_vets_it():
    """The engine object's solve returns the result unvetted (no plausibility block); simulate adds it, once."""
    scene = weftsim.load_scene("reference", revolutions=0.05)
    raw = engines.get("reference").solve(scene)
    assert raw.plausibility in (None, {}) or "checks" not in raw.plausibility
    vetted = weftsim.simulate(scene, "reference", on_warning=lambda text: None)
    assert "checks" in vetted.plausibility
    np.testing.assert_array_equal(raw.steps["contact_force_N"], vetted.steps["contact_force_N"])


def test_registry_refuses_what_is_not_an_engine():
    with pytest.raises(EngineError, match="taken"):
        engines.register("reference", ToyEngine())
    with pytest.raises(EngineError, match="taken"):
        engines.register("auto", ToyEngine())
    with pytest.raises(EngineError, match="identifier"):
        engines.register("my engine", ToyEngine())
    with pytest.raises(EngineError, match="lacks estimate"):
        engines.register("half", type("Half", (), {"select_path": lambda s, x: {}, "solve": lambda s, x: None})())
    with pytest.raises(EngineError, match="did you mean reference"):
        engines.get("refrence")
    with pytest.raises(EngineError, match="cannot import"):
        engines.get("no_such_module_xyz:solve")
    assert "half" not in engines.names()


def test_a_plug_in_given_as_module_and_function_is_wrapped():
    """``module:function`` (the sweep's plug-in form) is a solve function wrapped into the contract."""
    engine = engines.get("test_sweep:fake_solve")
    scene = weftsim.load_scene("reference", revolutions=0.25)
    assert engine.select_path(scene)["model"] == "plug-in" and math.isnan(engine.estimate(scene).run_time_s)
    assert engine.solve(scene).ok


def test_auto_is_the_default_engine_and_estimates_come_from_the_engine():
    assert engines.resolve("auto") == weftsim.DEFAULT_ENGINE == "exudyn"
    scene = weftsim.load_scene("reference", revolutions=1)
    ref, exu = weftsim.estimate(scene, "reference"), weftsim.estimate(scene, "exudyn")
    # the rates of the engines' modules (weftsim.reference.engine, weftsim.exudyn_engine.engine), per revolution
    assert ref.run_time_s == pytest.approx(0.008) and exu.run_time_s == pytest.approx(0.10)
    assert not ref.stiff_explicit and ref.step_bytes > 0.0
    with pytest.raises(SceneError):
        weftsim.estimate(object(), "reference")
