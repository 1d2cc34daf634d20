"""The Exudyn engine's object in the engine registry (:mod:`weftsim.engines`): its path, estimate and solve.

The estimate's rates were measured by ``weftsim bench --targets`` on ``models/reference.toml`` at 400 rpm,
c = 0.25 mm (issue 12, medians of 5 in one warm process, the 2-core machine otherwise idle; the start-up is
not included): within ~3x on other scenes, enough to tell seconds from hours.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING

from weftsim.exudyn_engine.selection import adaptive, select_model, select_path, step_plan, tree_solver
from weftsim.errors import SceneError
from weftsim.exudyn_engine.solver import check_settings, solve, tape_problem
from weftsim.model.stiffness import stiff_joints
from weftsim.checks.contract import Estimate
from weftsim.checks.progress import NPZ_BYTES_PER_ROW, STEP_ROWS_PER_REVOLUTION

if TYPE_CHECKING:
    from weftsim.input.params import Scene

SECONDS_PER_REVOLUTION = {
    "exudyn kinematic_tree": 0.10,  # the default path (DOPRI5 rtol 1e-6, numba route): 0.97-1.02 s for 10
    "exudyn rigid_body adaptive": 1.95,  # local error 3e-10 m: 1.94-2.00 s (1st revolution)
}
# The kinematic tree under solver.exudyn.tree_solver = "explicit" on a stiff joint law steps at its stability
# limit: one revolution of c = 0.5 mm, 400 rpm, mu = 0.15 took 1437x the dry run (issue 23).
EXUDYN_STIFF_FACTOR = 1400.0
# The implicit paths with friction (issue 23, same scene, medians of 3 in one process): the kinematic tree on
# generalized-alpha with error control 4.3-5.0x its dry run (CPU), the rigid-body model 25x its frictionless
# span (docs/performance.md, "Exudyn engine with friction").
EXUDYN_IMPLICIT_STIFF_FACTOR = 5.0
EXUDYN_RIGID_BODY_STIFF_FACTOR = 25.0
# The rigid-body model takes fixed steps: its cost is per step (5.5 s for the 75 000 steps of one revolution
# at 400 rpm with h = 2e-6 s, 73 us a step; 16.6 s for 3 revolutions).
EXUDYN_SECONDS_PER_STEP = 7.3e-5
# The flexible tape on the tree (DOPRI5 at the tape's stability limit through the impacts): loom_tape at 600 rpm,
# c = 0.02 mm, two revolutions: 19.2 s of CPU and 82 531 stored steps (docs/rapier-tape.md section 6), per revolution.
TAPE_SECONDS_PER_REVOLUTION = 9.6
TAPE_STEP_ROWS_PER_REVOLUTION = 41_300


def tree_explicit(scene: Scene) -> bool:
    """True when ``scene`` runs on the kinematic tree with its explicit solver."""
    return select_model(scene)[0] == "kinematic_tree" and tree_solver(scene) == "explicit"


def run_time(scene: Scene) -> float:
    """Estimated wall-clock seconds of the run (module docstring and the factors above)."""
    revolutions = scene.drive.revolutions
    stiff = bool(stiff_joints(scene))
    if select_model(scene)[0] == "kinematic_tree":
        factor = (EXUDYN_STIFF_FACTOR if tree_explicit(scene) else EXUDYN_IMPLICIT_STIFF_FACTOR) if stiff else 1.0
        return revolutions * SECONDS_PER_REVOLUTION["exudyn kinematic_tree"] * factor
    if adaptive(scene):
        factor = EXUDYN_RIGID_BODY_STIFF_FACTOR if stiff else 1.0
        return revolutions * SECONDS_PER_REVOLUTION["exudyn rigid_body adaptive"] * factor
    return step_plan(scene)[1] * EXUDYN_SECONDS_PER_STEP  # the fixed steps it will take (longer for an ideal joint)


def estimate(scene: Scene) -> Estimate:
    """The run's cost (:class:`weftsim.engines.Estimate`): :func:`run_time`, and step rows in proportion to it
    (the engine's steps cost about the same everywhere).

    Raises :class:`weftsim.errors.SceneError` for settings the engine refuses to run
    (:func:`weftsim.exudyn_engine.solver.check_settings`, e.g. a fixed step in the rigid-body model's
    round-off): the command line asks for the estimate before the run, so such a scene is refused there in
    one line (exit 2) instead of being estimated (a 1e-9 s step: ~73 s and ~829 MB announced) and then
    failing at its first step with incomplete result files.  ``solve`` still returns the same failure."""
    if scene.rapier_tape is not None:
        from weftsim.model.tape_selection import rigid_scene

        if rigid_scene(scene).rapier_tape is not None:  # the flexible tape on the tree (solver._solve_tape_scene)
            problem = tape_problem(scene)
            if problem is not None:
                raise SceneError(problem)
            revolutions = scene.drive.revolutions
            return Estimate(revolutions * TAPE_SECONDS_PER_REVOLUTION,
                            revolutions * TAPE_STEP_ROWS_PER_REVOLUTION * NPZ_BYTES_PER_ROW, False)
        scene = rigid_scene(scene)  # the tape as the rigid rapier: the rigid loom's run
    problem = check_settings(scene)
    if problem is not None:
        raise SceneError(problem)
    seconds = run_time(scene)
    rows = STEP_ROWS_PER_REVOLUTION * seconds / SECONDS_PER_REVOLUTION["exudyn kinematic_tree"]
    return Estimate(seconds, rows * NPZ_BYTES_PER_ROW, bool(stiff_joints(scene)) and tree_explicit(scene))


# The engine's object in the registry: its three functions under the contract's names (weftsim.engines.simulate
# calls them directly).
ENGINE = SimpleNamespace(name="exudyn", select_path=select_path, estimate=estimate, solve=solve)
