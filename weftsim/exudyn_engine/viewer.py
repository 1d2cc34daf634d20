"""Replay of an Exudyn run in Exudyn's own renderer: ``weftsim animate SCENE --viewer``.

The kinematic tree (:mod:`.tree`) integrates only the two coordinates behind the clearance and has
no bodies to draw, so the replay runs the rigid-body model (:func:`.mechanism.build_mechanism`,
generalized-alpha with the settings of :func:`.solver.simulation_settings`) and lets Exudyn write
its coordinates to a solution file, one row per output sample (``output.sample_deg`` of crank).
Exudyn's solution viewer (``mbs.SolutionViewer``, a renderer window and a dialog to play, stop or
scrub the rows) then shows the stored motion.  The bodies get simple graphics
(:func:`add_body_graphics`): shafts along the revolute axes, bars between the joint centres; the
clearance is drawn at its true size (a fraction of a millimetre: invisible at this scale).  The
``weftsim animate`` GIF draws it magnified.

Recording and showing are separate (:func:`record_solution`, :func:`show_solution`) so that the
recording can be checked without a display.  :func:`display_problem` says, before anything is
computed, why no window can open here.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import exudyn as exu
import exudyn.graphics as graphics

from weftsim.errors import RunFailed, WeftsimError
from weftsim.errors import EXIT_USAGE
from weftsim.exudyn_engine.mechanism import MechanismModel, build_mechanism
from weftsim.exudyn_engine.solver import adaptive, check_settings, simulation_settings, step_plan
from weftsim.exudyn_engine.step_control import StepController
from weftsim.input.params import Scene

# Exudyn reads this variable at import; any value but these blocks its windows (exudyn/__init__.py).
SUPPRESS_VARIABLE = "EXUDYN_SUPPRESS_UI_WINDOW_OPEN"
_NOT_SUPPRESSED = ("", "0", "False", "false")
# Drawing sizes, m: thin enough not to hide the 50 mm member FG, thick enough to see at the ~0.5 m
# extent of the linkage.
BAR_WIDTH = 0.012
SHAFT_RADIUS = 0.008
SHAFT_LENGTH = 0.08  # the crank, coupler and rocker shafts along their axes through O
TILES = 16  # facets of a cylinder
SECTOR_DISC_COLOR = [0.7, 0.7, 0.7, 0.25]  # RGBA: translucent, the rod and the pin F stay visible through it


class ViewerUnavailable(WeftsimError):
    """Exudyn's viewer cannot open a window here (no display, or windows suppressed)."""

    exit_status = EXIT_USAGE


def display_problem(environ: Mapping[str, str] | None = None, platform: str | None = None,
                    probe: bool | None = None) -> str | None:
    """Why no viewer window can open here (one line), or None.

    On Linux and the BSDs a window needs an X11 (``DISPLAY``) or Wayland (``WAYLAND_DISPLAY``) server;
    macOS and Windows always have a desktop.  ``EXUDYN_SUPPRESS_UI_WINDOW_OPEN`` (set by test and
    documentation builds) makes Exudyn skip every window, which would leave the viewer with nothing to do.
    ``probe`` (default: when ``environ`` is the process's own) also connects to the display's socket
    (:func:`weftsim.post.display.unreachable_display`): a ``DISPLAY`` with no server behind it makes the
    renderer abort the process natively.
    """
    probe = environ is None if probe is None else probe
    environ = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    instead = "`weftsim animate SCENE` (without --viewer) writes a GIF instead"
    if environ.get(SUPPRESS_VARIABLE, "") not in _NOT_SUPPRESSED:
        return f"Exudyn's windows are suppressed here ({SUPPRESS_VARIABLE} is set); {instead}"
    if platform.startswith(("linux", "freebsd", "openbsd", "netbsd")) and not (
            environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY")):
        return f"the Exudyn viewer needs a display (neither DISPLAY nor WAYLAND_DISPLAY is set); {instead}"
    if probe and platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        from weftsim.post.display import unreachable_display

        problem = unreachable_display(environ)
        if problem is not None:
            return f"the Exudyn viewer needs a display: {problem}; {instead}"
    return None


def _bar(length: float, color, start: float = 0.0) -> dict:
    """A bar along the body's local x from ``start`` to ``start + length`` (m)."""
    return graphics.Brick(centerPoint=[start + 0.5 * length, 0.0, 0.0], size=[abs(length), BAR_WIDTH, BAR_WIDTH],
                          color=color)


def _shaft(axis, color, length: float = SHAFT_LENGTH, radius: float = SHAFT_RADIUS, centre=(0.0, 0.0, 0.0)) -> dict:
    """A cylinder of ``length`` centred on ``centre`` along the unit vector ``axis`` (body frame)."""
    return graphics.Cylinder(pAxis=[c - 0.5 * length * a for c, a in zip(centre, axis)],
                             vAxis=[length * a for a in axis], radius=radius, color=color, nTiles=TILES)


def add_body_graphics(mbs, model: MechanismModel) -> None:
    """Give the bodies of a built mechanism simple graphics (their body frames, :mod:`.mechanism`).

    Crank 1: shaft along axis A (body z).  Coupler 2: a ball at O (its axes B and C both pass there).
    Rocker 3: shaft along axis D (body z), bar O-E (body x, length L_OE) and the joint E as a disc of the
    journal radius.  Rod 4: bar E-F (body x,
    centred on its middle).  Sector 5: bar G-F (body x, length L_FG) and a disc of the pitch radius d5.
    The reflected gears 6/7 and rapier 8 (``reflect_gears=True``) have no bodies to draw.
    """
    g = model.scene.geometry
    rod_half = 0.5 * g.l_ef
    shapes = {
        "crank": [_shaft([0.0, 0.0, 1.0], graphics.color.grey)],
        "coupler": [graphics.Sphere(point=[0.0, 0.0, 0.0], radius=2.0 * SHAFT_RADIUS, color=graphics.color.orange,
                                    nTiles=TILES)],
        "rocker": [_shaft([0.0, 0.0, 1.0], graphics.color.blue), _bar(g.l_oe, graphics.color.blue),
                   _shaft([0.0, 0.0, 1.0], graphics.color.red, length=2.0 * BAR_WIDTH,
                          radius=model.scene.joint.journal_radius, centre=(g.l_oe, 0.0, 0.0))],
        "rod": [_bar(g.l_ef, graphics.color.green, start=-rod_half)],
        "sector": [_bar(g.l_fg, graphics.color.steelblue),
                   graphics.Cylinder(pAxis=[0.0, 0.0, -0.5 * BAR_WIDTH], vAxis=[0.0, 0.0, 0.2 * BAR_WIDTH],
                                     radius=g.sector_pitch_radius, color=SECTOR_DISC_COLOR, nTiles=4 * TILES)],
    }
    for name, shape in shapes.items():
        if name in model.bodies:
            mbs.SetObjectParameter(model.bodies[name], "VgraphicsData", shape)


@dataclass
class Recording:
    """A rigid-body run stored for the viewer.

    ``system_container`` and ``mbs`` hold the model the solution file belongs to (the viewer draws
    its bodies at the stored coordinates); ``coordinates``: its ODE2 coordinates per row;
    ``rows``: rows written (the initial state and one per output sample).
    """

    path: Path
    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    model: MechanismModel
    coordinates: int
    rows: int
    wall_time_s: float


def expected_rows(scene: Scene) -> int:
    """Rows of the solution file: the initial state and one per output sample period over the run."""
    return int(round(scene.drive.end_time * scene.drive.speed / scene.output.sample_angle)) + 1


def record_solution(scene: Scene, path: str | Path) -> Recording:
    """Solve ``scene`` on the rigid-body model with graphics and write its coordinates to ``path``.

    The solution file is Exudyn's text format (``exudyn.utilities.LoadSolutionFile`` reads it): a
    header, then per row the time and the ODE2 coordinates, every ``output.sample_deg`` of crank
    (``solution.file.writePeriod``).  Velocities, accelerations and the constraints' algebraic
    coordinates are not written: the viewer only places the bodies.

    Raises
    ------
    RunFailed
        The scene's Exudyn settings are invalid or the solve failed (the message says where).
    """
    problem = check_settings(scene)
    if problem is not None:
        raise RunFailed(problem)
    path = Path(path)
    wall0 = time.perf_counter()
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    model = build_mechanism(mbs, scene)
    add_body_graphics(mbs, model)
    solver = exu.MainSolverImplicitSecondOrder()
    if adaptive(scene):
        StepController.for_mechanism(mbs, solver, model, scene).install()
    mbs.Assemble()
    for joint in model.clearances.values():
        joint.reset(mbs)
    settings = simulation_settings(scene, step_plan(scene)[1])
    output = settings.solution.file
    output.write = True
    output.name = str(path)
    output.writePeriod = scene.output.sample_angle / scene.drive.speed
    output.export.velocities = False
    output.export.accelerations = False
    output.export.algebraicCoordinates = False  # the constraint multipliers: nothing to draw
    output.writeInitialValues = True
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        ok = solver.SolveSystem(mbs, settings)  # type: ignore[call-arg, misc]  # exudyn stub: SolveSystem lacks self
    except exu.ExudynError as exc:
        lines = str(exc).strip().splitlines()
        last = lines[-1] if lines else type(exc).__name__
        raise RunFailed(f"the Exudyn solve for the viewer failed: {last}") from None
    if not ok:
        raise RunFailed(f"the Exudyn solve for the viewer stopped at t = {mbs.systemData.GetTime():.6g} s "
                        "(Newton did not converge); `weftsim run SCENE --engine exudyn` reports why")
    return Recording(path, container, mbs, model, len(mbs.systemData.GetODE2Coordinates()),
                     _count_rows(path), time.perf_counter() - wall0)


def _count_rows(path: Path) -> int:
    """Data rows of an Exudyn text solution file (comment lines start with '#')."""
    with open(path) as handle:
        return sum(1 for line in handle if line.strip() and not line.startswith("#"))


def show_solution(recording: Recording) -> None:
    """Open Exudyn's renderer and solution viewer on a recording; returns when the window is closed.

    Raises :class:`ViewerUnavailable` (before opening anything) where :func:`display_problem` finds
    no display.
    """
    problem = display_problem()
    if problem is not None:
        raise ViewerUnavailable(problem)
    from exudyn.utilities import LoadSolutionFile

    settings = recording.system_container.visualizationSettings
    settings.general.autoFitScene = True
    settings.openGL.advanced.initialZoom = 1.0  # openGL.initialZoom is its deprecated alias (Exudyn 1.13)
    settings.nodes.show = False
    settings.connectors.show = False
    settings.markers.show = False
    settings.loads.show = False  # the gravity arrows, longer than the linkage, would set the zoom
    settings.sensors.show = False
    with contextlib.redirect_stdout(sys.stderr):  # Exudyn's notes on loading; stdout stays the report's
        solution = LoadSolutionFile(str(recording.path), verbose=False)
    try:
        recording.mbs.SolutionViewer(solution, runMode=0, title=f"weftsim: {recording.model.scene.name}")
    finally:
        recording.system_container.renderer.Stop()


def period_label(scene: Scene) -> str:
    """The replayed span, for the command's report: crank revolutions and rows."""
    turns = scene.drive.revolutions
    return (f"{turns:g} revolution{'' if turns == 1 else 's'} at {scene.drive.speed * 30.0 / math.pi:g} rpm, "
            f"{expected_rows(scene)} frames {math.degrees(scene.output.sample_angle):g} deg apart")
