"""One run of a worn scene on the Exudyn engine with its step rows (:func:`solve_worn`), shared by the wear
updates (:mod:`weftsim.wear.engines`) and the stop-starts of the duty cycle (:mod:`weftsim.wear.duty`), which
must not import the updates' module (it imports the duty cycle).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult


def _quiet(text: str) -> None:
    """A run's before-run warnings: the wear command reports the design checks of the scene once."""


def solve_worn(scene: Scene, attempt: int = 0) -> tuple[RunResult, tuple, float]:
    """(result, (t, states, F_N, v_T), relative tolerance) of one attempt
    (:data:`weftsim.exudyn_engine.worn.ATTEMPTS`) on ``scene``, through :func:`weftsim.api.simulate`.

    The rows are the Exudyn engine's ``observe`` rows of its kinematic tree: times (n,) s, states (n, 4)
    [a, psi, a', psi'], the contact's F_N (N) and v_T (m/s) at every accepted step.
    """
    from weftsim.engines import simulate
    from weftsim.exudyn_engine.selection import tree_relative_tolerance
    from weftsim.exudyn_engine.worn import attempt_scene

    run_scene = attempt_scene(scene, attempt)
    rows: dict = {}
    result = simulate(run_scene, "exudyn", observe=lambda *a: rows.update(steps=a), on_warning=_quiet)
    if "steps" not in rows:  # refused before the run (settings): no rows
        rows["steps"] = (np.zeros(0), np.zeros((0, 4)), np.zeros(0), np.zeros(0))
    return result, rows["steps"], tree_relative_tolerance(run_scene)
