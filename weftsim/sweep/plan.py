"""Planning a sweep: the grid, the engine check and the validated scene of every cell, nothing run.

Planning is linear in the number of cells and reads the scene file once: each cell's scene
is the base scene with the cell's keys applied (:func:`weftsim.input.scene.apply_overrides`, about
1 ms a cell), not a fresh read of the file.  A grid of more than :data:`LARGE_GRID_CELLS`
cells is refused unless asked for (``--yes``), so a typo such as ``speed_rpm=100:1000:1000000``
costs one line, not hours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from weftsim.sweep.cell import normalise
from weftsim.sweep.engines import check_engine
from weftsim.sweep.grid import Axis, Cell, SweepError, grid_cells, grid_size, parse_set, parse_vary, value_count

if TYPE_CHECKING:
    from weftsim.input.params import Scene

# Beyond this many cells a sweep must be asked for with --yes.  The README's clearance x speed map
# has 121 cells; 2000 cells of the reference engine at 2 revolutions are about an hour on 2 cores.
LARGE_GRID_CELLS = 2000
# No sweep beyond this many cells, even with --yes: a million directories of runs (months of the
# reference engine on 2 cores), and the grid arrays of load_sweep must fit in memory.
MAX_GRID_CELLS = 1_000_000
CELL_NAME_CHECK = "command line"  # where a cell's bad value is said to come from (as for `run` flags)


@dataclass(frozen=True)
class PlannedCell:
    """A cell of a validated plan: its name and parameters, and its scene overrides (file units)."""

    cell: Cell
    overrides: dict


@dataclass(frozen=True)
class SweepPlan:
    """A validated sweep: base scene, grid and the planned cells (nothing run, nothing written).

    The cells' scenes are not stored (a large grid would hold thousands of them): :meth:`scene`
    rebuilds one from the base scene and the cell's overrides when it is needed.
    """

    scene_path: str
    engine: str
    axes: tuple[Axis, ...]
    fixed: dict
    base_keys: dict
    cells: tuple[PlannedCell, ...]
    base: Scene  # the base scene (after --set), from which each cell's scene is rebuilt
    notes: tuple[str, ...] = ()  # lines for the user: what joint F takes from E (weftsim.input.joint_keys)

    @property
    def axis_names(self) -> list[str]:
        return [axis.name for axis in self.axes]

    def scene(self, planned: PlannedCell) -> Scene:
        """The cell's validated scene."""
        from weftsim.input.scene import apply_overrides

        return apply_overrides(self.base, planned.overrides, CELL_NAME_CHECK, refuse_ideal_keys=False)

    def scene_keys(self, planned: PlannedCell) -> dict:
        """The cell's resolved scene as stored in ``cell.json`` and compared on resume."""
        from weftsim.input.scene import to_file_keys

        return normalise(to_file_keys(self.scene(planned)))


def refused_settings(engine: str, scene: Scene) -> str | None:
    """Why the named engine refuses to run the scene's settings (its estimate's SceneError, what ``weftsim run``
    refuses before the run), or None; a plug-in engine's settings are its own (None)."""
    from weftsim import engines
    from weftsim.input.scene import SceneError

    if engine != engines.AUTO and engine not in engines.names():
        return None
    try:
        engines.get(engines.resolve(engine, scene)).estimate(scene)
    except SceneError as exc:
        return str(exc)
    return None


def plan_sweep(scene_path: str | Path, vary: list[str], fixed: list[str] | tuple = (),
               engine: str = "reference", allow_large: bool = False, allow_cwd_engine: bool = False,
               announce: Callable[[str], None] | None = None) -> SweepPlan:
    """Parse ``--vary``/``--set`` texts, check the engine and validate the scene of every cell.

    Parameters
    ----------
    allow_large : bool
        Plan a grid of more than :data:`LARGE_GRID_CELLS` cells (``--yes``).
    allow_cwd_engine : bool
        Allow a plug-in engine module from the current directory (see :mod:`weftsim.sweep.engines`).
    announce : callable, optional
        Called with one line before a large grid is validated (the command line prints it).

    Raises
    ------
    SweepError
        Bad grid text or engine, a grid too large without ``allow_large``, or any cell whose scene
        is invalid (all such cells are named).
    weftsim.input.scene.SceneError
        The base scene itself is invalid.
    """
    from weftsim.input.joint_keys import (ideal_joint_keys, ideal_key_message, inheritance_note, wear_only_keys,
                                    wear_only_message)
    from weftsim.input.scene import SceneError, apply_overrides, load_scene, to_file_keys

    # Counted from the text first: a range of 10^8 values is refused before any of them is built.
    size = math.prod(value_count(text) for text in vary)
    if size > MAX_GRID_CELLS:
        raise SweepError(f"the grid has {size:,} cells, more than the {MAX_GRID_CELLS:,} a sweep can hold (a directory "
                         "a cell, also with --yes): check the --vary counts")
    if size > LARGE_GRID_CELLS and not allow_large:
        raise SweepError(f"the grid has {size:,} cells, more than {LARGE_GRID_CELLS:,}: check the --vary counts, "
                         "or pass --yes to plan and run them all")
    axes = tuple(parse_vary(text) for text in vary)
    fixed_overrides = dict(parse_set(text) for text in fixed)
    wear_only = wear_only_keys([axis.key for axis in axes] + list(fixed_overrides))
    if wear_only:
        raise SweepError(wear_only_message(wear_only[0], "sweep"))
    size = grid_size(axes)
    cells = grid_cells(axes, fixed_overrides)
    check_engine(engine, allow_cwd_engine)
    base = load_scene(scene_path, fixed_overrides, refuse_ideal_keys=False)  # checked over the cells below
    if announce and size > LARGE_GRID_CELLS // 10:
        announce(f"sweep: validating the scenes of {size:,} cells (about 1 ms each)")
    planned: list[PlannedCell] = []
    problems: dict[str, list[str]] = {}
    notes: list[str] = []
    idle_everywhere: set[str] | None = None  # keys at a joint that is ideal in every cell so far
    for cell in cells:
        candidate = PlannedCell(cell, {**cell.overrides, "name": f"{base.name}[{cell.name}]"})
        try:
            scene = apply_overrides(base, candidate.overrides, CELL_NAME_CHECK, refuse_ideal_keys=False)
        except SceneError as exc:
            problems.setdefault(str(exc), []).append(cell.name)
            continue
        problem = refused_settings(engine, scene)
        if problem is not None:
            problems.setdefault(problem, []).append(cell.name)
            continue
        idle = set(ideal_joint_keys(scene, cell.overrides))
        idle_everywhere = idle if idle_everywhere is None else idle_everywhere & idle
        note = inheritance_note(scene)
        if note and not notes:
            notes.append(note)
        planned.append(candidate)
    if idle_everywhere and not problems:
        # A key of a joint that is ideal in every cell changes nothing: the cells would be identical
        # copies.  Refused with the line `run --set` gives for it (a key that matters in some cells is kept).
        key = sorted(idle_everywhere)[0]
        raise SweepError(f"{ideal_key_message(key, CELL_NAME_CHECK)} (in every cell of the sweep)")
    if problems:
        lines = [f"{message} (cell{'s' if len(names) > 1 else ''} {', '.join(names[:3])}"
                 f"{f' and {len(names) - 3} more' if len(names) > 3 else ''})" for message, names in problems.items()]
        bad = sum(len(n) for n in problems.values())
        raise SweepError(f"{bad} of {len(cells)} cells are invalid, nothing was run: " + "; ".join(lines))
    return SweepPlan(str(scene_path), engine, axes, fixed_overrides, normalise(to_file_keys(base)), tuple(planned),
                     base, tuple(notes))
