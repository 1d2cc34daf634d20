"""Fixtures the test files share (issue 32): the bundled scenes, the engines, and runs shared per session.

- :data:`ENGINES`: the built-in engines; the ``engine`` fixture runs a test once on each, so a check that
  should hold for every engine is written once (``tests/test_every_engine.py``);
- ``bundled``: the names of the bundled scenes (``weftsim scenes``);
- :func:`scene_of`: a bundled scene (or scene file) with file-unit overrides and the command line's
  shorthands, the one scene helper (``scene_of("reference", clearance_mm=0.5, revolutions=0.1)``);
- ``run_of`` (session-scoped): :func:`weftsim.simulate` of a scene on an engine, computed once per
  session for each (scene, engine, overrides): tests that look at the same short run share it instead of
  repeating it (the suite's time).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import weftsim

ENGINES: tuple[str, ...] = ("reference", "exudyn")
MODELS = Path(__file__).resolve().parent.parent / "models"


def scene_of(name: str, overrides: dict | None = None, **flags) -> weftsim.Scene:
    """A bundled scene or scene file with overrides (dotted keys, file units) and shorthands
    (``clearance_mm``, ``speed_rpm``, ``revolutions``, ``law``): :func:`weftsim.load_scene`."""
    return weftsim.load_scene(name, overrides, **flags)


def quiet(text: str) -> None:
    """``on_warning`` of a test run: the before-run warnings are in ``result.plausibility["checks"]``."""


@pytest.fixture(params=ENGINES)
def engine(request) -> str:
    """Each built-in engine in turn."""
    return request.param


@pytest.fixture(scope="session")
def bundled() -> list[str]:
    return weftsim.bundled_scenes()


@pytest.fixture(scope="session")
def run_of():
    """``run_of(name, engine, **flags)``: the result of one run, computed once per session."""
    cache: dict = {}

    def run(name: str, engine: str, overrides: dict | None = None, **flags) -> weftsim.RunResult:
        key = (name, engine, tuple(sorted((overrides or {}).items())), tuple(sorted(flags.items())))
        if key not in cache:
            cache[key] = weftsim.simulate(scene_of(name, overrides, **flags), engine, on_warning=quiet)
        return cache[key]

    return run


def door(engine: str):
    """``solve(scene, progress=None, observe=None, callback=None)`` of ``engine`` through the one door
    (:func:`weftsim.simulate`: before-run checks, the engine's pure solve, the vetting), for tests written
    against an engine's solve; ``callback`` (the Exudyn engine's clearance-force route) is set on the scene."""
    import dataclasses

    def solve(scene, progress=None, observe=None, callback=None):
        if callback is not None:
            scene = dataclasses.replace(scene, exudyn_solver=dataclasses.replace(scene.exudyn_solver,
                                                                                 callback=callback))
        return weftsim.simulate(scene, engine, progress=progress, observe=observe, on_warning=quiet)

    return solve
