"""The result of one simulation, shared by both engines.

A :class:`RunResult` holds named channels (units in their names) twice: on the
uniform crank-angle output grid (``samples``) and at every accepted solver step
(``steps``).  Peaks and statistics are taken from ``steps`` because an impact
lasts about 0.1 ms, a fraction of a degree, and falls between output samples.

:func:`save_npz` / :func:`weftsim.post.result_file.read_npz` keep a result losslessly (both tables bit for bit,
the scene in SI units, the solver statistics, events, plausibility and path), so
the per-step data behind the peaks can be studied after the run; ``weftsim run``
writes it as ``result.npz`` beside ``channels.csv``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from weftsim.errors import ArgumentError, require
from weftsim.input.params import Scene
# The channel tables live in weftsim.model.channels (below the joint modules that compute them); re-exported here.
from weftsim.model.channels import (  # noqa: F401
    CHANNELS, JOINT_F_CHANNELS, LUBRICATION_CHANNELS, LUBRICATION_CHANNELS_F, JOINT_FORCE_CHANNELS,
    JOINT_FORCE_CHANNELS_F, LOAD_FALLBACK, TAPE_CHANNELS, EXCHANGE_CHANNELS, JOINT_E_NAME, CONTACT_CHANNELS,
    PEAK_CHANNELS,
    PEAK_CHANNELS_F, PEAK_CHANNELS_LUBRICATION, PEAK_CHANNELS_LUBRICATION_F, PEAK_CHANNELS_TAPE,
    OPTIONAL_GROUPS, optional_channels,
)

if TYPE_CHECKING:
    import pandas

STATUSES = ("success", "failed")
ENGINES = ("reference", "exudyn")  # the built-in engines, what a result file records (weftsim.engines names them)


def _as_channels(data: dict[str, np.ndarray], what: str) -> dict[str, np.ndarray]:
    missing = [name for name in CHANNELS if name not in data]
    if missing:
        raise ValueError(f"{what} lacks channels {missing}; every engine must provide all of {list(CHANNELS)}")
    names = CHANNELS
    for group, label in ((JOINT_F_CHANNELS, "joint F"), (LUBRICATION_CHANNELS, "lubrication"),
                         (LUBRICATION_CHANNELS_F, "joint F lubrication"), (JOINT_FORCE_CHANNELS, "joint E load"),
                         (JOINT_FORCE_CHANNELS_F, "joint F load"), (TAPE_CHANNELS, "rapier tape"),
                         (EXCHANGE_CHANNELS, "weft exchange")):
        given = [name for name in group if name in data]
        if given:
            if len(given) != len(group):
                raise ValueError(f"{what} has {label} channels {given} but not all of {list(group)}")
            names = names + group
    lengths = {name: np.shape(data[name]) for name in names}
    n = len(np.asarray(data["time_s"]))
    bad = {name: shape for name, shape in lengths.items() if shape != (n,)}
    if bad:
        raise ValueError(f"{what}: channels must be 1-D of length {n} like time_s, got {bad}")
    out = {}
    for name in names:
        arr = np.array(data[name], dtype=float)
        arr.setflags(write=False)
        out[name] = arr
    return out


@dataclass(frozen=True)
class RunResult:
    """Outcome of one engine run on one scene.

    Attributes
    ----------
    scene : Scene
        The scene that produced it (after command-line overrides).
    engine : str
        ``"reference"`` (closed-form Lagrange) or ``"exudyn"``.
    status : str
        ``"success"`` or ``"failed"``; a failed run keeps what it computed up to the failure.
    message : str
        Empty on success; otherwise what failed, at which time and crank angle, and what to try.
    samples, steps : dict of str to ndarray
        All :data:`CHANNELS`, on the uniform output grid and at every accepted solver step, and
        :data:`JOINT_F_CHANNELS` when the scene has a clearance at F.
    solver_stats : dict
        Steps, rejected steps, function evaluations, contact events, ``wall_time_s``, ...
    events : dict
        E.g. ``first_contact_time_s`` (true onset, located within the step) or None.
    plausibility : dict
        Counts of a broken contact history and the law-range warnings
        (:meth:`weftsim.checks.plausibility.Plausibility.as_dict`; not for the ideal mechanism), the design
        checks before and after the run (``checks``, :mod:`weftsim.checks.design_checks`) and every after-run
        ``warnings``, filled by :func:`weftsim.checks.guards.vet_result`; empty for a result no engine vetted.
    path : dict
        The model and method that ran and why (``{"model": ..., "method": ..., "reason": ...}``):
        what the engine's automatic selection chose for this scene, or what the scene forced.
    """

    scene: Scene
    engine: str
    status: str
    message: str
    samples: dict[str, np.ndarray]
    steps: dict[str, np.ndarray]
    solver_stats: dict = field(default_factory=dict)
    events: dict = field(default_factory=dict)
    plausibility: dict = field(default_factory=dict)
    path: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.engine not in ENGINES and not (isinstance(self.engine, str) and self.engine.isidentifier()):
            raise ValueError(f"engine must be one of {ENGINES} or a plug-in engine's name (an identifier), "
                             f"got {self.engine!r}")
        if self.status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {self.status!r}")
        object.__setattr__(self, "samples", _as_channels(self.samples, "samples"))
        object.__setattr__(self, "steps", _as_channels(self.steps, "steps"))

    @property
    def ok(self) -> bool:
        return self.status == "success"

    @property
    def first_contact_angle_deg(self) -> float | None:
        """Crank angle of the first contact onset, deg, or None if the journal never touched."""
        t = self.events.get("first_contact_time_s")
        if t is None:
            return None
        return math.degrees(self.scene.drive.speed * t)

    @property
    def path_text(self) -> str:
        """One line: ``model, method (reason)``, or empty when the engine did not say."""
        if not self.path:
            return ""
        what = ", ".join(str(self.path[k]) for k in ("model", "method") if self.path.get(k))
        reason = self.path.get("reason")
        return f"{what} ({reason})" if reason else what

    @property
    def channel_names(self) -> tuple[str, ...]:
        """The channels this result holds: :data:`CHANNELS`, then joint F's when F has a clearance."""
        return tuple(self.samples)

    @property
    def has_joint_f(self) -> bool:
        """True when the result holds joint F's channels (the scene has a clearance at F)."""
        return JOINT_F_CHANNELS[0] in self.samples

    @property
    def wall_time_s(self) -> float:
        """Wall-clock time of the solve, s (NaN when the engine did not record it)."""
        return float(self.solver_stats.get("wall_time_s", float("nan")))

    def to_pandas(self, which: Literal["samples", "steps"] = "samples") -> pandas.DataFrame:
        """One table of the run as a :class:`pandas.DataFrame`, one column per channel.

        Parameters
        ----------
        which : {"samples", "steps"}
            ``"samples"``: the uniform crank-angle output grid (the rows of ``channels.csv``);
            ``"steps"``: every accepted solver step, where the peaks are taken (an impact of
            ~0.1 ms falls between output samples).

        Returns
        -------
        pandas.DataFrame
            Columns :attr:`channel_names` (SI units, named in the column names) as float64, a
            ``RangeIndex``; ``attrs`` hold the scene name, engine, status and ``which``.

        Raises
        ------
        weftsim.errors.MissingExtra
            pandas is not installed (it comes with the optional extra ``weftsim[data]``).
        """
        if which not in ("samples", "steps"):
            raise ArgumentError(f"to_pandas: which must be 'samples' or 'steps', got {which!r}")
        pd = require("pandas", "data", "RunResult.to_pandas")
        table = self.samples if which == "samples" else self.steps
        frame = pd.DataFrame({name: np.array(table[name]) for name in self.channel_names})
        frame.attrs.update({"scene": self.scene.name, "engine": self.engine, "status": self.status, "table": which})
        return frame


def empty_channels(joint_f: bool = False, scene: Scene | None = None) -> dict[str, np.ndarray]:
    """All channels with no rows (``joint_f``: with joint F's; ``scene``: the channels it has), for a run
    that failed before its first step."""
    if scene is not None:
        return {name: np.zeros(0) for name in scene_channels(scene)}
    return {name: np.zeros(0) for name in CHANNELS + (JOINT_F_CHANNELS if joint_f else ())}


def scene_channels(scene: Scene) -> tuple[str, ...]:
    """The channels a run of ``scene`` has: :data:`CHANNELS`, joint F's with a clearance at F, the
    lubrication channels of each lubricated loose joint and the load of each loose joint."""
    names = CHANNELS
    if not scene.joint_f.is_ideal:
        names += JOINT_F_CHANNELS
    if not scene.joint.is_ideal and scene.joint.is_lubricated:
        names += LUBRICATION_CHANNELS
    if not scene.joint_f.is_ideal and scene.joint_f.is_lubricated:
        names += LUBRICATION_CHANNELS_F
    if not scene.joint.is_ideal:
        names += JOINT_FORCE_CHANNELS
    if not scene.joint_f.is_ideal:
        names += JOINT_FORCE_CHANNELS_F
    if scene.rapier_tape is not None:
        from weftsim.model.tape_selection import tape_model

        if tape_model(scene) == "flexible":
            names += TAPE_CHANNELS
    if scene.exchange is not None and scene.exchange.enabled:  # the weft exchange (weftsim.model.exchange)
        names += EXCHANGE_CHANNELS
    return names


def angle_grid(end_time: float, omega: float, step_angle: float) -> np.ndarray:
    """Times of a uniform crank-angle grid from t = 0 to end_time inclusive, s.

    The last point is end_time itself if the grid does not land on it.
    """
    dt = step_angle / omega
    n = int(math.floor(end_time / dt * (1.0 + 1e-12)))
    t = np.arange(n + 1) * dt
    if end_time - t[-1] > 1e-9 * dt:
        t = np.append(t, end_time)
    return t


# Format tag of a saved result; weftsim.post.result_file.read_npz refuses others (a later layout gets a new number).
NPZ_FORMAT = "weftsim-result/1"


def _plain(value: Any) -> Any:
    """A dataclass, numpy scalar or array, tuple or Path as JSON-ready Python values (floats exact)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    return value


def save_npz(result: RunResult, path: str | os.PathLike) -> Path:
    """Write ``result`` to one NPZ file from which :func:`weftsim.post.result_file.read_npz` rebuilds it
    exactly (reading it as untrusted input).

    The file holds ``samples/<channel>`` and ``steps/<channel>`` (float64 arrays, bit for bit)
    and ``meta``: one JSON text with the format tag, the scene (SI values of
    :class:`weftsim.input.params.Scene`), engine, status, message, solver statistics, events,
    plausibility and path.  No pickled objects, so reading a file runs no code.

    Returns
    -------
    Path
        ``path``, written as given (no suffix is added; ``.npz`` is the customary one).
    """
    path = Path(path)
    meta = {"format": NPZ_FORMAT, "scene": _plain(result.scene), "engine": result.engine, "status": result.status,
            "message": result.message, "solver_stats": _plain(result.solver_stats), "events": _plain(result.events),
            "plausibility": _plain(result.plausibility), "path": _plain(result.path)}
    arrays = {f"{table}/{name}": getattr(result, table)[name] for table in ("samples", "steps")
              for name in result.channel_names}
    # allow_nan: NaN and inf statistics come back as they were (Python's JSON reads its own NaN back).
    arrays["meta"] = np.array(json.dumps(meta, allow_nan=True))
    with path.open("wb") as file:
        np.savez_compressed(file, **arrays)
    return path
