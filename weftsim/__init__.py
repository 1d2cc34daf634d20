"""weftsim: the weft insertion mechanism of a rapier loom with a clearance joint at E.

A spatial linkage (spherical 4R, planar four-bar, sector gear, pinion and rapier rack) whose
revolute joint E between the cross rocker and the connecting rod has a radial clearance,
after Li Bo et al. (2020); the physics is written down in docs/physics.md.  Two independent
engines solve the same scene: ``"exudyn"`` (Exudyn multibody model) and ``"reference"``
(closed-form Lagrange equations).

Python interface
----------------
load_scene(scene, overrides=None, **flags)
    A scene file or bundled scene name, with overrides in file units.
simulate(scene, engine="auto")
    Run one engine; returns a :class:`RunResult` (``to_pandas()``, ``samples``, ``steps``).  The one door:
    before-run checks, the engine's solve, the vetting of its result.
estimate(scene, engine="auto"), select_path(scene, engine="auto")
    What a run will cost, and which model and method it takes.  The engines and a plug-in's registration:
    :mod:`weftsim.engines`.
bearing(scene, joint="e", load_kn=None, journal_rpm=None)
    The steady plain-bearing check of an oiled joint: Sommerfeld number, eccentricity, film ratio, friction,
    power loss, film temperature, regime and the Stribeck curve (docs/lubricated-joint.md).
plausibility_checks(scene)
    The checks that need no simulation: reflected mass, pin pressure, p x v, clearance ratio,
    rapier acceleration against their limits (docs/plausibility.md).
save_result(result, path), load_result(path)
    Lossless NPZ (``weftsim run`` writes ``result.npz``).
load_sweep(directory)
    A ``weftsim sweep`` directory as an xarray Dataset over its varied keys.
kinematics(scene), compare(scene, outdir), sweep(scene, vary, outdir), wear(scene, hours, outdir)
    The commands ``weftsim kinematics | compare | sweep | wear`` as functions (the commands are thin shells
    over them).
optimize(scene, vary, objectives, outdir, constraints=...)
    ``weftsim optimize``: the design keys that minimise one or two objectives under the loom's constraints.
bundled_scenes()
    Names of the scenes installed with weftsim.
WeftsimError
    Base class of every error raised on purpose (SceneError, OutputError, EngineError, ...).

Example::

    import weftsim

    scene = weftsim.load_scene("reference", clearance_mm=0.5, revolutions=1)
    for engine in ("reference", "exudyn"):
        table = weftsim.simulate(scene, engine).to_pandas()
"""

from weftsim.cli.startup import guard_command_start

guard_command_start()  # before the imports below: a Ctrl-C while they load is one line (weftsim.cli.startup)

from weftsim.version import __version__  # noqa: E402, F401 (weftsim.__version__)
from weftsim.api import (
    DEFAULT_ENGINE,
    ENGINE_NAMES,
    bearing,
    bundled_scenes,
    compare,
    estimate,
    kinematics,
    load_result,
    load_scene,
    load_sweep,
    optimize,
    plausibility_checks,
    save_result,
    select_path,
    simulate,
    sweep,
    wear,
)
from weftsim.errors import (  # noqa: E402
    ArgumentError,
    EngineError,
    MissingExtra,
    OptimizeError,
    OutputError,
    PlausibilityWarning,
    RunFailed,
    SceneError,
    SweepError,
    WearError,
    WeftsimError,
    WriteFailed,
)
from weftsim.input.params import Scene  # noqa: E402
from weftsim.post.results import CHANNELS, RunResult  # noqa: E402

__all__ = [
    "ArgumentError",
    "CHANNELS",
    "DEFAULT_ENGINE",
    "ENGINE_NAMES",
    "EngineError",
    "MissingExtra",
    "OptimizeError",
    "OutputError",
    "PlausibilityWarning",
    "RunFailed",
    "RunResult",
    "Scene",
    "SceneError",
    "SweepError",
    "WearError",
    "WeftsimError",
    "WriteFailed",
    "bearing",
    "bundled_scenes",
    "compare",
    "estimate",
    "kinematics",
    "load_result",
    "load_scene",
    "load_sweep",
    "optimize",
    "plausibility_checks",
    "save_result",
    "select_path",
    "simulate",
    "sweep",
    "wear",
]
