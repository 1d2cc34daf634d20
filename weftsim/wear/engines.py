"""The engine an update's simulation runs on (``weftsim wear --engine``): the wear of one worn geometry.

Both engines give the same thing, :class:`~weftsim.wear.archard.RunWear` per update and the response
of the steady revolutions, through the same Archard rows and deposit
(:func:`weftsim.wear.archard.rows_from_contact`, :func:`~weftsim.wear.archard.wear_from_rows`):

- ``"reference"``: :func:`weftsim.wear.extrapolate.simulate_update` (the reference engine's step rows;
  the dry law's F_N from the kernel at its states, modes and held impact velocities);
- ``"exudyn"``: the Exudyn engine's kinematic tree on the worn geometry
  (:func:`solve_worn`, the same kernel's worn clearance in its contact),
  Archard's integral over its own contact channels at its accepted steps: the normal force F_N and the
  sliding velocity v_T its force callback applied, the contact angles in the bearing's and the journal's
  frame from its joint coordinates.

The cycle extrapolation (:mod:`.extrapolate`) is the same for both; only the simulation differs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import WearError
from weftsim.wear.worn_run import solve_worn

if TYPE_CHECKING:
    from collections.abc import Callable

    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult
    from weftsim.wear.archard import RunWear

ENGINES = ("reference", "exudyn")


def simulator(engine: str) -> Callable | None:
    """The ``simulate`` of :func:`weftsim.wear.extrapolate.predict` for ``engine``: None (its default, the
    reference engine's :func:`~weftsim.wear.extrapolate.simulate_update`) or :func:`exudyn_update`."""
    if engine == "reference":
        return None
    if engine == "exudyn":
        return exudyn_update
    raise WearError(f"--engine must be one of {', '.join(ENGINES)}, got {engine!r}")


def engine_update(scene: Scene, bearing: np.ndarray, journal: np.ndarray, engine: str = "reference"
                  ) -> tuple[RunWear, dict]:
    """(wear of the steady revolutions, response) of ``scene`` on the worn geometry, simulated on ``engine``."""
    from weftsim.wear import extrapolate

    return (simulator(engine) or extrapolate.simulate_update)(scene, bearing, journal)


def _quiet(text: str) -> None:
    """An update's before-run warnings: the wear command reports the design checks of the scene once."""


def exudyn_update(scene: Scene, bearing: np.ndarray, journal: np.ndarray) -> tuple[RunWear, dict]:
    """:func:`engine_update` on the Exudyn engine (module docstring); raises
    :class:`~weftsim.wear.extrapolate.UpdateFailed` when every attempt of the run fails."""
    from weftsim.exudyn_engine.worn import ATTEMPTS
    from weftsim.checks.guards import stop_requested
    from weftsim.model.dynamics import pack_parameters
    from weftsim.wear.archard import rows_from_contact, wear_from_rows
    from weftsim.wear.extrapolate import UpdateFailed, WearInterrupted, wear_response, worn_scene

    w = scene.joint.wear
    run_scene = worn_scene(scene, bearing, journal, w.settle_revolutions + w.revolutions_per_update)
    for attempt in range(len(ATTEMPTS)):
        result, (t, states, f_n, v_t), rtol = solve_worn(run_scene, attempt)
        if result.ok:
            break
        if stop_requested() is not None or result.solver_stats.get("failure") == "interrupted":
            raise WearInterrupted(result.message)
    else:
        raise UpdateFailed(f"the Exudyn simulation on the worn geometry failed (also at relative tolerance "
                           f"{ATTEMPTS[1][1]:g} and on the implicit tree): {result.message}")
    keep = t >= w.settle_revolutions * scene.drive.period
    rows = np.zeros((int(keep.sum()), 6))
    # The callback's v_T where it applied a dry contact; elsewhere (a lubricated joint's asperities alone) the
    # sliding velocity at the state, as on the reference engine
    sliding = np.ascontiguousarray(np.where(f_n[keep] > 0.0, v_t[keep], np.nan))
    rows_from_contact(pack_parameters(run_scene), np.ascontiguousarray(t[keep]), np.ascontiguousarray(states[keep]),
                      np.ascontiguousarray(f_n[keep]), sliding, rows)  # fmt: skip
    wear = wear_from_rows(run_scene.joint, t[keep], rows)
    return wear, wear_response(scene, wear, result.steps, rtol)
