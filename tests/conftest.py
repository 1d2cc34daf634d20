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


# The short runs that compile the kernels every engine path uses: the reference integrator's plain kernel (a dry
# scene: weftsim.physics.chain_f.PLAIN) and its general one (one specialisation of
# weftsim.reference.compiled.advance holding every law, friction and film, compiled by the oiled loom), their
# channels and joint rows, and the Exudyn tree's force.
WARM_UP = (("reference", "reference"), ("loom_oiled", "reference"), ("loom", "exudyn"))


def _kernels_cached() -> bool:
    """Whether numba's cache (weftsim's keyed folder, or the user's NUMBA_CACHE_DIR) holds the integrator."""
    import weftsim.physics  # noqa: F401  # sets numba's cache folder (weftsim.physics.compiled_cache)
    from numba.core import config

    return any(Path(config.CACHE_DIR).rglob("compiled.advance-*.nbi"))


def pytest_sessionstart(session) -> None:
    """Compile the kernels once before pytest-xdist starts its workers, when the cache is empty (a fresh clone).

    Otherwise every worker, and every weftsim process a test starts before one of them has written the cache,
    compiles the same kernels at once (~90 s of CPU each on a fresh clone: docs/performance.md, "The test
    suite's time").  Runs in xdist's controller only (this hook precedes xdist's, which starts the workers);
    a warm cache costs one directory scan.  A warm-up that fails is left to the tests to report."""
    if not session.config.pluginmanager.has_plugin("dsession") or _kernels_cached():  # no workers to start
        return
    for name, engine in WARM_UP:
        try:
            weftsim.simulate(scene_of(name, revolutions=0.01), engine, on_warning=quiet)
        except Exception as error:  # noqa: BLE001  # the tests that run this scene say what is wrong
            print(f"conftest: warming numba's cache with {name} on {engine} failed: {error}")


# The longest test files, longest first (the fresh-clone parallel run of 3 December 2026, load ~7: the sum
# of their tests' times over ~4.3, the run's wall-to-CPU ratio, in CPU s: 83, 65, 62, 61, 58, 57, 47, 41, 41,
# 37).  pytest-xdist's loadfile hands out files in collection order (--no-loadscope-reorder, pyproject.toml);
# in xdist's default order, most tests first, the wear files of few long tests came last and one worker ran
# them while the other had finished.  Given first, the short files fill the end.
LONGEST_FIRST = ("test_wear_life.py", "test_hostile_ensemble.py", "test_wear_exudyn.py", "test_exudyn_engine.py",
                 "test_wear_ensemble.py", "test_reference_integrate.py", "test_cylindrical.py",
                 "test_sweep_faults.py", "test_lubricated_steps.py", "test_rapier_tape.py")


def pytest_collection_modifyitems(session, config, items) -> None:
    """The files of :data:`LONGEST_FIRST` first, in that order; the rest, and the tests within each file, as
    collected (a stable sort, the same on every worker, as xdist requires)."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


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
