"""The Python interface of weftsim: load a scene, simulate it, keep and load results.

The functions here are what ``import weftsim`` exports and what the command line calls,
so a script and ``weftsim run`` take the same path::

    import weftsim

    scene = weftsim.load_scene("reference", clearance_mm=0.5)  # a bundled scene, c = 0.5 mm at E
    result = weftsim.simulate(scene, engine="reference")     # closed-form Lagrange engine
    table = result.to_pandas()                                  # needs the extra weftsim[data]

Scenes are given in the units of the scene files (mm, deg, rpm: the unit is part of each
key's name, docs/physics.md and the README's scene reference); everything inside weftsim,
results included, is SI.  Errors are :class:`weftsim.errors.WeftsimError` subclasses whose
message is the line the command line prints.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from weftsim import engines
from weftsim.errors import ArgumentError, OutputError, SceneError, closest
from weftsim.input.params import Scene
from weftsim.post.results import RunResult

if TYPE_CHECKING:
    import xarray

# Engine names :func:`simulate` accepts (the built-in ones; a plug-in registered with
# :func:`weftsim.engines.register` is accepted too).  "auto" is the default engine, the Exudyn multibody
# model (the project's primary engine; the reference engine is its independent cross-check).
ENGINE_NAMES: tuple[str, ...] = (engines.AUTO,) + tuple(engines.BUILT_IN)
DEFAULT_ENGINE = engines.DEFAULT_ENGINE

# The shorthands of the command line (--clearance-mm, --speed-rpm, --revolutions, --law) and of
# load_scene's keyword flags, and the scene keys they set (file units).
SCENE_FLAGS: dict[str, str] = {
    "clearance_mm": "joint_e.clearance_mm",
    "speed_rpm": "drive.speed_rpm",
    "revolutions": "drive.revolutions",
    "law": "joint_e.law",
}


def scene_overrides(overrides: Mapping[str, Any] | None = None, where: str = "overrides",
                    **flags: Any) -> dict[str, Any]:
    """One dict of dotted scene keys from ``overrides`` and the shorthand ``flags`` (:data:`SCENE_FLAGS`).

    A flag that is None is not given.  Raises :class:`SceneError` for an unknown flag (with the
    closest one) or a key given both ways.
    """
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ArgumentError(f"{where}: overrides must be a mapping of dotted scene keys to values, e.g. "
                            f"{{'joint_e.clearance_mm': 0.5}}, got {type(overrides).__name__} {overrides!r:.40}")
    merged = dict(overrides or {})
    for flag, value in flags.items():
        key = SCENE_FLAGS.get(flag)
        if key is None:
            near = closest(flag, SCENE_FLAGS)
            mean = f"did you mean {near}? " if near else ""
            raise SceneError(f"{where}: unknown scene flag {flag!r}; {mean}the flags are {', '.join(SCENE_FLAGS)}; "
                             "set any other key with overrides={'section.key': value}")
        if value is None:
            continue
        if merged.get(key) is not None:
            raise SceneError(f"{where}: key '{key}' is given twice, by the flag {flag} = {value!r} and as "
                             f"{key} = {merged[key]!r}; give it once")
        merged[key] = value
    return merged


def load_scene(scene: str | os.PathLike, overrides: Mapping[str, Any] | None = None, **flags: Any) -> Scene:
    """Read, merge, override and validate a scene.

    Parameters
    ----------
    scene : str or path-like
        A scene file (TOML), or the name of a bundled scene (:func:`bundled_scenes`, e.g.
        ``"reference"`` or ``"paper/clearance_0p50mm_400rpm"``).  A string names a file when a
        regular file exists at that path, a bundled scene otherwise.
    overrides : mapping, optional
        Dotted scene keys and values in the units of the file, applied after it, e.g.
        ``{"joint_e.clearance_mm": 0.5, "solver.reference.rtol": 1e-8}``.
    **flags
        The command line's shorthands: ``clearance_mm`` (radial clearance at E, mm; 0 is the ideal
        joint), ``speed_rpm`` (crank speed, rpm), ``revolutions`` (crank revolutions), ``law``
        (contact force law, a name of :data:`weftsim.joint.contact.LAWS`).

    Returns
    -------
    Scene
        The validated scene in SI units (:class:`weftsim.input.params.Scene`, frozen).

    Raises
    ------
    weftsim.errors.SceneError
        The file or name, a key or a value is not acceptable; the message names the file, the
        key, the bad value and what is allowed (and the closest key or scene name for a typo).
    """
    from weftsim.input.scene import load_scene as load_file

    return load_file(scene, scene_overrides(overrides, **flags), overrides_from="overrides")


def bundled_scenes() -> list[str]:
    """Names of the scenes installed with weftsim, for :func:`load_scene` and ``weftsim run NAME``.

    ``"reference"`` is the reference mechanism of docs/physics.md section 1 (c = 0.25 mm at E,
    400 rpm), ``"ideal"`` the same with an ideal joint, ``"paper/..."`` the paper's clearance and
    speed cases.  ``weftsim scenes`` lists them with their descriptions.
    """
    from weftsim.input.scene import bundled_scenes as names

    return names()


def resolve_engine(engine: str, scene: Scene | None = None) -> str:
    """The engine ``engine`` names: ``"auto"`` is :data:`DEFAULT_ENGINE` (the reference engine for a ``scene``
    whose rapier tape runs flexible); an unknown name is an EngineError (:func:`weftsim.engines.resolve`)."""
    return engines.resolve(engine, scene)


def select_path(scene: Scene, engine: str = "auto") -> dict[str, str]:
    """The model and method ``engine`` runs ``scene`` on, and why: ``{"model", "method", "reason"}``.

    >>> import weftsim
    >>> weftsim.select_path(weftsim.load_scene("ideal"), "reference")["model"]
    'ideal joint'
    """
    return engines.get(engines.resolve(engine, scene)).select_path(scene)


def estimate(scene: Scene | str | os.PathLike, engine: str = "auto") -> engines.Estimate:
    """What a run of ``scene`` on ``engine`` will cost before it starts (:class:`weftsim.engines.Estimate`:
    wall-clock seconds and bytes of the step table, from measured rates, within ~3x).

    >>> import weftsim
    >>> weftsim.estimate("ideal", "reference").run_time_s   # the closed form: nothing to integrate
    0.0
    """
    scene = _as_scene(scene)
    return engines.get(engines.resolve(engine, scene)).estimate(scene)


def _as_scene(scene: Scene | str | os.PathLike) -> Scene:
    return engines._as_scene(scene)


# The one door (defined beside the engine registry, below the commands that run many simulations).
simulate = engines.simulate


def bearing(scene: Scene | str | os.PathLike, joint: str = "e", load_kn: float | None = None,
            journal_rpm: float | None = None, stribeck: bool = True) -> dict:
    """The steady plain-bearing check of a lubricated joint (``weftsim bearing``; docs/lubricated-joint.md).

    Parameters
    ----------
    scene : Scene, str or path-like
        A scene whose joint ``joint`` has a clearance and oil (``[joint_e.lubrication]`` with ``oil`` or
        ``viscosity_mpa_s``).
    joint : {"e", "f"}
    load_kn, journal_rpm : float, optional
        Another operating point: the bearing alone under this load (kN), its journal turning at this speed (rpm)
        in a still bushing.  Each defaults to the ideal mechanism's mean; without either, the mechanism's mean
        and peak load at its mean sliding speed.
    stribeck : bool
        Add the Stribeck curve (friction coefficient against journal speed at the first point's load).

    Returns
    -------
    dict
        ``points`` (``mean`` and ``peak``, or ``given``): Sommerfeld number, eccentricity ratio, attitude angle,
        minimum film and film ratio, friction torque and coefficient, power loss, flows, the film temperature and
        its heat balance, the regime; ``stribeck``: the curve; the joint's geometry and oil (SI units in the keys).

    Raises
    ------
    weftsim.errors.SceneError
        One line: an ideal or dry joint, a load or speed not > 0, a heat balance without a solution.
    """
    from weftsim.joint.bearing import bearing as check

    import math

    scene = _as_scene(scene)
    for value, name in ((load_kn, "load_kn (--load-kn, kN)"), (journal_rpm, "journal_rpm (--journal-rpm)")):
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if value is not None and not (number and math.isfinite(value) and value > 0.0):
            raise SceneError(f"bearing: {name} must be a finite number > 0, got {value!r}")
    return check(scene, joint, None if load_kn is None else 1e3 * load_kn, journal_rpm, stribeck)


def plausibility_checks(scene: Scene | str | os.PathLike) -> list[dict]:
    """The plausibility checks of a scene that need no simulation (docs/plausibility.md).

    Each is a dict: ``name``, ``table`` (the joint's scene table, or None), ``value`` and ``limit``
    (SI, ``unit``), ``key`` (the scene key of the limit), ``verdict`` ("ok", "warning", "no_limit",
    "info"), further ``numbers`` and the warning ``message``.  A run adds the after-run checks in
    ``result.plausibility["checks"]``.
    """
    from weftsim.checks.design_checks import before_run

    return [check.as_dict() for check in before_run(_as_scene(scene))]


def save_result(result: RunResult, path: str | os.PathLike) -> Path:
    """Save a result losslessly to one NPZ file (``weftsim run`` writes ``result.npz``).

    Both tables (output samples and every solver step) are kept bit for bit, with the scene, the
    status, the solver statistics, the plausibility counts and the path; :func:`load_result`
    rebuilds an equal :class:`RunResult`.  Returns the path, written as given (atomically: an
    interrupted save leaves the previous file or none, never a truncated one).

    Raises
    ------
    weftsim.errors.ArgumentError
        ``result`` is not a :class:`RunResult` or ``path`` not a path.
    weftsim.errors.OutputError
        The file cannot be written.
    """
    from weftsim.post.results import save_npz

    if not isinstance(result, RunResult):
        raise ArgumentError(f"save_result: result must be a RunResult (from weftsim.simulate or load_result), "
                            f"got {type(result).__name__}")
    if not isinstance(path, (str, os.PathLike)):
        raise ArgumentError(f"save_result: path must be a file path, got {type(path).__name__}")
    from weftsim.post.output import write_atomic
    from weftsim.post.results import ENGINES

    if result.engine not in ENGINES:
        raise OutputError(f"save_result: the result of the plug-in engine {result.engine!r} cannot be saved: the "
                          f"result file records the built-in engines ({', '.join(ENGINES)}) only; keep its "
                          "tables with result.to_pandas() or numpy")

    try:  # atomic: a run killed while saving leaves the previous file (or none), never a truncated one
        def write(tmp: Path) -> None:
            save_npz(result, tmp)

        write_atomic(Path(path), write)
        return Path(path)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {exc.strerror or exc}") from None
    except ValueError as exc:  # a NUL character in the path
        raise OutputError(f"cannot write {path!r}: {exc}") from None


def load_result(path: str | os.PathLike) -> RunResult:
    """The :class:`RunResult` saved by :func:`save_result` (or ``weftsim run``'s ``result.npz``).

    Raises
    ------
    weftsim.errors.OutputError
        The file is missing, unreadable, not a weftsim result, or damaged or edited so that it no longer
        is one (each checked before anything is allocated: :mod:`weftsim.post.result_file`).
    weftsim.errors.ArgumentError
        ``path`` is not a path.
    """
    from weftsim.post.result_file import read_npz

    if not isinstance(path, (str, os.PathLike)):
        raise ArgumentError(f"load_result: path must be a file path, got {type(path).__name__}")
    return read_npz(path)


def load_sweep(directory: str | os.PathLike) -> xarray.Dataset:
    """A sweep directory (``weftsim sweep``) as a labelled grid.

    Returns
    -------
    xarray.Dataset
        One dimension per varied key (named as in the cell names, e.g. ``clearance_mm``; its
        ``scene_key`` attribute is the dotted key), coordinates the values in file units; data
        variables the table columns of ``sweep.csv`` (peaks of the first and last revolution and
        99th percentiles of driving torque, rapier acceleration and the contact force at E
        (``contact_force_N_*``) and at F (``contact_force_f_N_*``), wall time, first contact angle)
        and ``status`` (``"success"``, ``"failed"`` or ``"not run"``).  Values of cells not run, or
        without the number (a joint ideal in that cell has no contact force), are NaN.

    Raises
    ------
    weftsim.errors.SweepError
        The directory holds no sweep (no ``sweep.json``) or a damaged one.
    weftsim.errors.MissingExtra
        xarray is not installed (it comes with the optional extra ``weftsim[data]``).
    """
    from weftsim.sweep.store import load_grid

    if not isinstance(directory, (str, os.PathLike)):
        raise ArgumentError(f"load_sweep: directory must be a path, got {type(directory).__name__}")
    return load_grid(Path(directory))


# The columns of weftsim.kinematics (and of `weftsim kinematics`'s kinematics.csv), in order.
KINEMATICS_COLUMNS = ("crank_angle_deg", "rapier_displacement_m", "rapier_velocity_m_s", "rapier_acceleration_m_s2",
                      "rocker_angle_deg", "rocker_arm_angle_deg", "sector_angle_deg", "rod_angle_deg",
                      "transmission_angle_deg")


def kinematics(scene: Scene | str | os.PathLike) -> dict[str, Any]:
    """The ideal mechanism's motion over one crank revolution, on the scene's output grid (no simulation).

    Returns the columns of :data:`KINEMATICS_COLUMNS` (``weftsim kinematics`` writes them to
    ``kinematics.csv``) as arrays: the crank angle, deg; the rapier's displacement s, m, velocity
    omega s', m/s, and acceleration omega^2 s'', m/s2, at the scene's constant crank speed omega; the
    members' angles, deg, and the transmission angle at F, deg (docs/physics.md, the linkage's closure).

    >>> import weftsim
    >>> k = weftsim.kinematics("reference")
    >>> round(float(k["rapier_displacement_m"].max() - k["rapier_displacement_m"].min()), 3)   # the stroke, m
    1.052
    """
    import math

    import numpy as np

    from weftsim.mechanism.kinematics import linkage_state

    scene = _as_scene(scene)
    rows = int(round(2.0 * math.pi / scene.output.sample_angle)) + 1
    theta = np.linspace(0.0, 2.0 * math.pi, rows)
    state = linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    w = scene.drive.speed
    return {
        "crank_angle_deg": np.degrees(theta),
        "rapier_displacement_m": state.rapier_displacement,
        "rapier_velocity_m_s": w * state.d_rapier_displacement,
        "rapier_acceleration_m_s2": w * w * state.dd_rapier_displacement,
        "rocker_angle_deg": np.degrees(state.phi),
        "rocker_arm_angle_deg": np.degrees(state.theta_oe),
        "sector_angle_deg": np.degrees(state.theta_fg),
        "rod_angle_deg": np.degrees(state.theta_ef),
        "transmission_angle_deg": np.degrees(state.transmission_angle),
    }


def compare(scene: Scene | str | os.PathLike, outdir: str | os.PathLike, *, force: bool = False,
            solve: Callable[[Scene, str], RunResult] | None = None) -> dict:
    """Run both engines on ``scene`` and compare them (``weftsim compare``): both runs' files, ``compare.json``
    and the overlay figure ``compare.png`` in ``outdir``.

    Returns the report (``compare.json``'s content: each channel's first-revolution peaks on both engines,
    their difference against the scene's tolerance, ``agree``); :func:`weftsim.post.compare.verdict` gives the
    command's exit status from it.  ``solve(scene, engine)`` runs one engine (default :func:`simulate`, its
    before-run warnings left to the result's checks; the command passes one with progress on stderr).
    """
    from weftsim.post.compare import run_compare

    def quiet(scene: Scene, engine: str) -> RunResult:
        return simulate(scene, engine, on_warning=lambda text: None)

    report, _, _ = run_compare(_as_scene(scene), Path(outdir), solve=solve or quiet, force=force)
    return report


def sweep(scene: str | os.PathLike, vary: list[str], outdir: str | os.PathLike, **options: Any) -> Any:
    """A parameter sweep (``weftsim sweep``), each cell through :func:`simulate`: :func:`weftsim.sweep.sweep`
    (``weftsim.sweep`` is that function too: the subpackage is callable)."""
    from weftsim.sweep import sweep as run

    return run(Path(scene) if not isinstance(scene, str) else scene, vary, Path(outdir), **options)


def optimize(scene: str | os.PathLike, vary: list[str], objectives: list[str], outdir: str | os.PathLike,
             **options: Any) -> Any:
    """A design optimisation (``weftsim optimize``): :func:`weftsim.optimize.optimize` (``weftsim.optimize`` is that
    function too: the subpackage is callable)."""
    from weftsim.optimize import optimize as run

    return run(Path(scene) if not isinstance(scene, str) else scene, vary, objectives, Path(outdir), **options)


def wear(scene: Scene | str | os.PathLike, hours: float, outdir: str | os.PathLike, **options: Any) -> dict:
    """The wear of the scene's worn joint(s) over ``hours`` (``weftsim wear``): :func:`weftsim.wear.wear`
    (``weftsim.wear`` is that function too: the subpackage is callable)."""
    from weftsim.wear import wear as run

    return run(_as_scene(scene), hours, Path(outdir), **options)
