"""Which Exudyn model and method a scene runs on (``RunResult.path``).

Today this reports what the scene's keys force (``exudyn_solver.model``); the automatic
selection of issue 12 replaces it.
"""

from __future__ import annotations

from weftsim.params import Scene


def select_path(scene: Scene) -> dict:
    """``{"model", "method", "reason"}`` of the run :func:`weftsim.exudyn_engine.solve` makes of ``scene``."""
    s = scene.exudyn_solver
    if s.model == "kinematic_tree":
        return {"model": "kinematic_tree", "method": f"{s.explicit_method} rtol {s.relative_tolerance:g}",
                "reason": "scene key solver.exudyn.model"}
    return {"model": "rigid_body", "method": f"generalized-alpha h {s.step_size:g} s",
            "reason": "scene key solver.exudyn.model"}
