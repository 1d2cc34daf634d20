"""The reference engine's object in the engine registry (:mod:`weftsim.engines`): its path, estimate and solve.

The estimate's rates were measured by ``weftsim bench --targets`` on ``models/reference.toml`` at 400 rpm,
c = 0.25 mm (issue 12, medians of 5 in one warm process, the 2-core machine otherwise idle; the start-up
of imports, model build and numba cache is not included).  Other scenes differ by the number of impacts and
the step a contact needs: the estimate is meant to tell seconds from hours, within ~3x.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING

from weftsim.model.stiffness import stiff_joints
from weftsim.reference import compiled_method, effective_rtol, select_path, solve, switches_by_sliding
from weftsim.checks.contract import Estimate
from weftsim.checks.progress import NPZ_BYTES_PER_ROW, STEP_ROWS_PER_REVOLUTION

if TYPE_CHECKING:
    from weftsim.input.params import Scene

# Wall-clock seconds per crank revolution (module docstring).
SECONDS_PER_REVOLUTION = {
    "reference scipy": 0.8,  # DOP853 at rtol 1e-9 on the compiled right-hand side: 0.78-0.89 s (1st revolution)
    "reference numba": 0.008,  # numba_DOP853 at rtol 1e-5 (the default): 79 ms for 10 revolutions
    # numba_DOP853_RODAS4 at rtol 1e-6, the default with friction (issue 23): 2.3-3.1x the dry default in the
    # same process (c = 0.5 mm, mu = 0.15; docs/performance.md "Friction"), so 3x the figure above.
    "reference numba implicit": 0.024,
    # ... with dry friction at E alone RODAS4 only near the friction ramp, at rtol 1e-7 (issue 36): 1.6x the dry
    # default on that scene (CPU, one process), 1.4-2.1x on the loom at c = 0.02 and 0.1 mm.
    "reference numba sliding": 0.016,
}
# Steps of the Runge-Kutta paths grow about as rtol^(-1/4) on this contact (the compiled DOP853: 0.08 s per
# revolution at rtol 1e-9, 10x its cost at 1e-5); the figures above are at these tolerances.
REFERENCE_RTOL = {"reference scipy": 1e-9, "reference numba": 1e-5, "reference numba implicit": 1e-6,
                  "reference numba sliding": 1e-7}
# An explicit method on a stiff joint law (friction's ramp, an oil film) steps at its stability limit, ~1e-9 s
# where the journal sticks: one revolution of c = 0.5 mm, 400 rpm, mu = 0.15 took 1661x the dry run with
# numba_DOP853 (issue 23).  Applied to a path that integrates such a joint explicitly.
EXPLICIT_STIFF_FACTOR = 1500.0
# Recorded step rows per revolution of the implicit path with friction, ~13 000 (3 200 steps); the dry
# default's is weftsim.checks.progress.STEP_ROWS_PER_REVOLUTION.
IMPLICIT_STEP_ROWS_PER_REVOLUTION = 1.3e4
# The flexible rapier tape (RODAS4 throughout): loom_tape, 600 rpm, c = 0.02 mm, two revolutions, 27.0 s of CPU and
# 1 115 914 steps under the cylindrical contact law (its start-up impacts excite the tape's upper modes; 3 December
# 2026, one process, load average 7-10; the worn joints' 17.3 s and 12.4 s at 0.1 and 0.25 mm take fewer steps):
# per revolution, 13.5 s and ~6e5 step rows (docs/rapier-tape.md, section 6).
FLEXIBLE_TAPE_SECONDS_PER_REVOLUTION = 13.5
FLEXIBLE_TAPE_STEP_ROWS_PER_REVOLUTION = 6e5


def _path(scene: Scene) -> tuple[str, bool]:
    """(key of :data:`SECONDS_PER_REVOLUTION`, whether a stiff joint is integrated explicitly)."""
    method = compiled_method(scene) or scene.reference_solver.method
    if method == "numba_DOP853_RODAS4" and switches_by_sliding(scene):
        return "reference numba sliding", False
    if "RODAS4" in method:
        return "reference numba implicit", False
    path = "reference numba" if method.startswith("numba") else "reference scipy"
    implicit_scipy = method in ("Radau", "BDF", "LSODA")
    return path, bool(stiff_joints(scene)) and not implicit_scipy


def estimate(scene: Scene) -> Estimate:
    """The run's cost (:class:`weftsim.engines.Estimate`): 0 for the closed-form ideal joint; else the path's
    rate at its tolerance, x :data:`EXPLICIT_STIFF_FACTOR` on an explicit path with a stiff joint law
    (:func:`weftsim.model.stiffness.stiff_joints`); the step rows per revolution likewise."""
    if scene.rapier_tape is not None:
        from weftsim.model.tape_selection import rigid_scene

        if rigid_scene(scene).rapier_tape is not None:  # the flexible tape
            revolutions = scene.drive.revolutions
            return Estimate(revolutions * FLEXIBLE_TAPE_SECONDS_PER_REVOLUTION,
                            revolutions * FLEXIBLE_TAPE_STEP_ROWS_PER_REVOLUTION * NPZ_BYTES_PER_ROW, False)
        scene = rigid_scene(scene)
    if scene.is_ideal:
        return Estimate(0.0, 0.0, False)
    revolutions = scene.drive.revolutions
    path, explicit_stiff = _path(scene)
    scale = (REFERENCE_RTOL[path] / effective_rtol(scene)) ** 0.25
    factor = EXPLICIT_STIFF_FACTOR if explicit_stiff else 1.0
    seconds = revolutions * SECONDS_PER_REVOLUTION[path] * scale * factor
    rows = IMPLICIT_STEP_ROWS_PER_REVOLUTION if path == "reference numba implicit" else STEP_ROWS_PER_REVOLUTION
    return Estimate(seconds, rows * factor * revolutions * NPZ_BYTES_PER_ROW, explicit_stiff)


# The engine's object in the registry: its three functions under the contract's names (weftsim.engines.simulate
# calls them directly).
ENGINE = SimpleNamespace(name="reference", select_path=select_path, estimate=estimate, solve=solve)
