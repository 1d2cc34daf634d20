"""The engine contract and the one registry of engines: every caller chooses an engine here, by name.

An engine is an object with a ``name`` and three methods (:class:`Engine`):

``select_path(scene) -> dict``
    ``{"model", "method", "reason"}``: the model and method :meth:`~Engine.solve` will run, and why.
``estimate(scene) -> Estimate``
    The run's wall-clock seconds and the bytes of its per-step table, from measured rates (the figure
    ``weftsim run`` shows before a long run), and whether it integrates a stiff joint law explicitly.
``solve(scene, progress=None, observe=None) -> RunResult``
    The engine's pure solve: the channels, the solver statistics, the status; no before-run checks and no
    vetting of the result (:func:`weftsim.api.simulate`, the one door, does both, once, for every engine).
    ``progress`` is called with the completed fraction in [0, 1]; ``observe``, when given, is called once
    after the run with the raw step rows behind ``result.steps`` (each engine documents its rows: the
    reference engine's ``(t, y, contact, impact)``, the Exudyn engine's ``(t, states, f_n, v_t)``).

The built-in engines, ``"reference"`` (the closed-form Lagrange cross-check) and ``"exudyn"`` (the Exudyn
multibody model), are imported on first use (``import weftsim`` stays light); ``"auto"`` is
:data:`DEFAULT_ENGINE`.  A plug-in engine registers the same way (:func:`register`), or is named as
``module:attribute`` (an :class:`Engine` object, or a ``solve(scene, progress=None)`` function), which
:func:`get` imports: a plug-in is code that runs, so only name modules you trust.

Example::

    import weftsim
    from weftsim import engines

    engines.names()                                     # ('exudyn', 'reference')
    engine = engines.get("reference")
    engine.select_path(weftsim.load_scene("ideal"))["model"]   # 'ideal joint'
"""

from __future__ import annotations

import importlib
import math
import os
import warnings
from typing import TYPE_CHECKING, Any, Callable, Protocol, runtime_checkable


from weftsim.errors import ArgumentError, EngineError, PlausibilityWarning, RunFailed, SceneError, closest
from weftsim.input.params import Scene
from weftsim.checks.contract import Estimate

if TYPE_CHECKING:
    from weftsim.post.results import RunResult

__all__ = ["AUTO", "BUILT_IN", "DEFAULT_ENGINE", "Engine", "Estimate", "FunctionEngine", "UNKNOWN", "get", "names",
           "register", "resolve", "simulate", "split", "unregister"]

DEFAULT_ENGINE = "exudyn"  # "auto": the Exudyn multibody model, the project's primary engine
AUTO = "auto"
# The built-in engines: name -> "module:attribute" of their Engine object, imported on first use.
BUILT_IN: dict[str, str] = {"exudyn": "weftsim.exudyn_engine.engine:ENGINE",
                            "reference": "weftsim.reference.engine:ENGINE"}


UNKNOWN = Estimate(math.nan, math.nan, False)


@runtime_checkable
class Engine(Protocol):
    """The engine contract (module docstring)."""

    name: str

    def select_path(self, scene: Scene) -> dict: ...

    def estimate(self, scene: Scene) -> Estimate: ...

    def solve(self, scene: Scene, progress: Callable[[float], None] | None = None,
              observe: Callable[..., None] | None = None) -> RunResult: ...


_REGISTERED: dict[str, Engine] = {}
_LOADED: dict[str, Engine] = {}


def _check_contract(name: str, engine: Any) -> None:
    missing = [m for m in ("select_path", "estimate", "solve") if not callable(getattr(engine, m, None))]
    if missing:
        raise EngineError(f"engine {name!r}: {type(engine).__name__} lacks {', '.join(missing)} of the engine "
                          f"contract (select_path(scene), estimate(scene), solve(scene, progress=None, "
                          f"observe=None)); see weftsim.engines")


def register(name: str, engine: Engine) -> None:
    """Register a plug-in engine under ``name``; :func:`get` and every command then find it.

    Raises :class:`~weftsim.errors.EngineError` when the name is taken, is ``"auto"``, is not an identifier,
    or the object lacks a method of the contract.
    """
    if not isinstance(name, str) or not name.isidentifier():
        raise EngineError(f"an engine's name must be an identifier (letters, digits, _), got {name!r}")
    if name == AUTO or name in BUILT_IN or name in _REGISTERED:
        raise EngineError(f"engine name {name!r} is taken; the engines are {', '.join((AUTO,) + names())}")
    _check_contract(name, engine)
    _REGISTERED[name] = engine


def unregister(name: str) -> None:
    """Remove a plug-in engine :func:`register` added (a built-in engine stays)."""
    _REGISTERED.pop(name, None)


def names() -> tuple[str, ...]:
    """The engine names :func:`get` knows (built-in, then registered), ``"auto"`` left out."""
    return tuple(BUILT_IN) + tuple(sorted(_REGISTERED))


def resolve(name: str, scene: Scene | None = None) -> str:
    """The engine ``name`` names: ``"auto"`` is :data:`DEFAULT_ENGINE`, or for a ``scene`` whose rapier tape runs
    flexible the reference engine (both model it: the reference engine takes 1/5 of Exudyn's time over the
    start-up, 0.7-1.4 x over two revolutions, docs/rapier-tape.md section 6); a ``module:attribute`` plug-in
    is itself; an unknown name is an EngineError naming the engines (and the closest one)."""
    if name == AUTO:
        if scene is not None and scene.rapier_tape is not None:
            from weftsim.model.tape_selection import tape_model

            if tape_model(scene) == "flexible":
                return "reference"
        return DEFAULT_ENGINE
    if isinstance(name, str) and (name in BUILT_IN or name in _REGISTERED or ":" in name):
        return name
    known = (AUTO,) + names()
    near = closest(name, known) if isinstance(name, str) else None
    raise EngineError(f"engine must be one of {', '.join(known)}, got {name!r}"
                      + (f"; did you mean {near}?" if near else ""))


def split(name: str) -> tuple[str, str]:
    """(module, attribute) of a ``module:attribute`` plug-in name; an EngineError if it is not one."""
    module, sep, attribute = name.partition(":")
    if not sep or not module or not attribute or not all(p.isidentifier() for p in module.split(".")) \
            or not attribute.isidentifier():
        raise EngineError(f"engine must be one of {', '.join((AUTO,) + names())} or module:attribute "
                          f"(e.g. mypackage.model:solve), got {name!r}")
    return module, attribute


class FunctionEngine:
    """A plug-in engine given as a bare ``solve(scene, progress=None)`` function: no path, no estimate."""

    def __init__(self, name: str, function: Callable[..., RunResult]):
        self.name, self.function = name, function

    def select_path(self, scene: Scene) -> dict:
        return {"model": "plug-in", "method": self.name, "reason": "a plug-in engine named by its solve function"}

    def estimate(self, scene: Scene) -> Estimate:
        return UNKNOWN

    def solve(self, scene: Scene, progress: Callable[[float], None] | None = None,
              observe: Callable[..., None] | None = None) -> RunResult:
        if observe is not None:
            raise EngineError(f"engine {self.name}: a plug-in solve function gives no step rows to observe")
        return self.function(scene, progress=progress)


def _import(name: str, target: str) -> Engine:
    module, attribute = split(target)
    try:
        imported = importlib.import_module(module)
    except SyntaxError as exc:
        raise EngineError(f"engine {name}: module {module} has a syntax error "
                          f"({exc.filename}, line {exc.lineno}: {exc.msg})") from None
    except Exception as exc:  # noqa: BLE001 - importing runs arbitrary code: any failure is the plug-in's
        raise EngineError(f"engine {name}: cannot import {module} ({type(exc).__name__}: {exc})") from None
    found = getattr(imported, attribute, None)
    if found is None:
        raise EngineError(f"engine {name}: module {module} has no function {attribute!r} (nor an engine object of "
                          "that name)")
    if all(callable(getattr(found, m, None)) for m in ("select_path", "estimate", "solve")):
        return found
    if callable(found):
        return FunctionEngine(name, found)
    raise EngineError(f"engine {name}: {module}.{attribute} is neither an engine nor a solve function")


def get(name: str) -> Engine:
    """The engine object of ``name`` (``"auto"``, a built-in or registered name, or ``module:attribute``)."""
    name = resolve(name)
    if name in _REGISTERED:
        return _REGISTERED[name]
    if name not in _LOADED:
        engine = _import(name, BUILT_IN.get(name, name))
        _check_contract(name, engine)
        _LOADED[name] = engine
    return _LOADED[name]


def _as_scene(scene: Scene | str | os.PathLike) -> Scene:
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, os.PathLike)):
        from weftsim.input.scene import load_scene

        return load_scene(scene, {}, overrides_from="overrides")
    raise SceneError(f"simulate: scene must be a Scene (weftsim.load_scene), a scene file or the name of a "
                     f"bundled scene, got {type(scene).__name__}")


def simulate(scene: Scene | str | os.PathLike, engine: str = "auto", *,
             progress: Callable[[float], None] | None = None, raise_on_failure: bool = False,
             on_warning: Callable[[str], None] | None = None,
             observe: Callable[..., None] | None = None) -> RunResult:
    """Simulate one scene with one engine: the one door every caller runs an engine through.

    The before-run design checks, the engine's pure solve (:func:`get`), then the vetting of the result
    (:func:`weftsim.checks.guards.vet_result`), once, outside the engines.  ``weftsim.simulate`` is this function.

    Parameters
    ----------
    scene : Scene, str or path-like
        A scene from :func:`weftsim.load_scene`, or what it takes (a file or a bundled name).
    engine : {"auto", "exudyn", "reference"} or a registered plug-in's name
        ``"exudyn"``: the Exudyn multibody model (the kinematic tree, or the rigid-body model where
        a scene needs it); ``"reference"``: the independent closed-form Lagrange engine (compiled
        DOP853); ``"auto"``: the default engine, :data:`DEFAULT_ENGINE`; a plug-in engine
        (:func:`register`, or ``"module:attribute"``).
    progress : callable, optional
        Called with the completed fraction in [0, 1] about 100 times per run.
    raise_on_failure : bool
        Raise :class:`weftsim.errors.RunFailed` (holding the partial result) when the run fails,
        instead of returning it with ``status == "failed"``.
    on_warning : callable, optional
        Called with each before-run plausibility warning (:func:`weftsim.plausibility_checks`), one sentence
        naming the scene key to change, before the engine starts.  Default: issued as a
        :class:`weftsim.errors.PlausibilityWarning` (Python's ``warnings``).  Every check, before and
        after the run, is in ``result.plausibility["checks"]``.
    observe : callable, optional
        Called once after the run with the engine's raw step rows behind ``result.steps`` (the reference
        engine: ``observe(t, y, contact, impact)``; the Exudyn engine, on its kinematic tree:
        ``observe(t, states, f_n, v_t)``), for analyses that need the state itself.

    Returns
    -------
    RunResult
        The channels on the output grid (``samples``) and at every accepted step (``steps``), the
        solver statistics, the status and message, the plausibility counts and the path taken.
        A failed run keeps what it computed up to the failure (``result.ok`` is False).

    Raises
    ------
    weftsim.errors.EngineError
        ``engine`` is not the name of an engine.
    weftsim.errors.SceneError
        ``scene`` is a file or name that does not load.
    weftsim.errors.RunFailed
        Only with ``raise_on_failure``: the run failed (``exc.result`` holds it).
    weftsim.errors.ArgumentError
        ``progress`` is neither None nor callable.

    Examples
    --------
    >>> import weftsim
    >>> result = weftsim.simulate("ideal", "reference", on_warning=print)
    >>> result.status, result.path["method"]
    ('success', 'closed form')
    """
    from weftsim.checks.design_checks import before_run, warnings_of
    from weftsim.checks.guards import vet_result

    chosen = get(engine)
    if progress is not None and not callable(progress):
        raise ArgumentError(f"simulate: progress must be None or a function called with the completed fraction "
                            f"(e.g. lambda f: print(f)), got {type(progress).__name__} {progress!r:.40}")
    scene = _as_scene(scene)
    from weftsim.model.exchange import exchange_of, exchange_problem, taker_source

    problem = exchange_problem(scene)  # e.g. an ideal taker of a tape that rapier_tape.model = 'auto' runs flexible
    if problem:
        raise SceneError(f"scene {scene.name}: {problem}")
    for attr, table in (("joint", "joint_e"), ("joint_f", "joint_f")):
        lub = getattr(scene, attr).lubrication
        if lub is not None and lub.elastic_film:
            raise SceneError(f"scene {scene.name}: {table}.lubrication.elastic_film = true is the steady elastic film "
                             f"of `weftsim bearing` only; the transient engines run the rigid film: set it false")
    if engine == AUTO:  # a flexible rapier tape runs on the reference engine (resolve)
        chosen = get(resolve(engine, scene))
    if any(getattr(scene, attr).lubrication is not None and getattr(scene, attr).lubrication.has_oil
           for attr in ("joint", "joint_f")):
        from weftsim.joint.bearing import resolve_scene

        scene = resolve_scene(scene)  # the oil's viscosity at the film temperature of this scene's operating point
    for text in warnings_of(before_run(scene)):
        if on_warning is None:
            warnings.warn(text, PlausibilityWarning, stacklevel=2)
        else:
            on_warning(text)
    second = exchange_of(scene) is not None and taker_source(scene) == "run"  # the taker's own run
    # The engine's pure solve, then the post-run criteria (energy balance, ...) that no single step shows,
    # once, for every engine.
    result = vet_result(chosen.solve(scene, progress=_part(progress, 0.0, 0.5 if second else 1.0), observe=observe))
    if exchange_of(scene) is not None:
        result = _with_exchange(result, chosen, _part(progress, 0.5, 1.0))
    if raise_on_failure and not result.ok:
        raise RunFailed(f"simulation failed: {result.message}", result)
    return result


def _part(progress: Callable[[float], None] | None, start: float, end: float) -> Callable[[float], None] | None:
    """``progress`` of one of the runs of a scene, mapped onto [start, end] of the whole."""
    if progress is None or (start, end) == (0.0, 1.0):
        return progress
    return lambda fraction: progress(start + (end - start) * fraction)


def _with_exchange(result: RunResult, chosen: Engine, progress: Callable[[float], None] | None) -> RunResult:
    """``result`` of the giver with the weft exchange's channels (:mod:`weftsim.model.exchange`): the taker from
    the giver's run, the closed form or its own run on the same engine (vetted as every run is).

    A taker run that fails fails the result, which keeps everything: the taker's channels hold its head up to
    where it stopped (NaN after), and the message names the taker.
    """
    from dataclasses import replace

    import numpy as np

    from weftsim.checks.guards import vet_result
    from weftsim.model.exchange import exchange_channels, taker_scene, taker_source
    from weftsim.model.channels import EXCHANGE_CHANNELS

    scene = result.scene
    source = taker_source(scene)
    samples = {k: v for k, v in result.samples.items() if k not in EXCHANGE_CHANNELS}
    steps = {k: v for k, v in result.steps.items() if k not in EXCHANGE_CHANNELS}
    taker = None
    if source == "run" and result.ok:
        taker = vet_result(chosen.solve(taker_scene(scene), progress=progress))
    tables = {}
    for name, table in (("samples", samples), ("steps", steps)):
        other = None if taker is None else getattr(taker, name)
        if source == "run" and taker is None:  # the giver failed: no taker run, no taker head (NaN)
            other = {key: np.zeros(0) for key in ("time_s", "rapier_displacement_m", "rapier_velocity_m_s")}
        tables[name] = {**table, **exchange_channels(scene, table, table if source == "giver" else other)}
    stats = {**result.solver_stats, "exchange_taker": source}
    changes: dict[str, Any] = {}
    if taker is not None:
        stats |= {"taker_steps": taker.solver_stats.get("steps"), "taker_wall_time_s": taker.wall_time_s,
                  "wall_time_s": result.wall_time_s + taker.wall_time_s}
        if not taker.ok and result.ok:
            changes = {"status": "failed", "message": f"the taker head's run (exchange.taker_clearance_mm) failed: "
                                                      f"{taker.message}"}
    return replace(result, samples=tables["samples"], steps=tables["steps"], solver_stats=stats, **changes)
