"""What an engine of the contract returns before it runs, and the engine object built from its functions.

The contract itself and the registry are :mod:`weftsim.engines` (above the engines); what the engines need
of it sits here, below them, so that an engine's ``engine`` module imports nothing above its floor.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult


@dataclass(frozen=True)
class Estimate:
    """What a run of one scene on one engine will cost, before it starts (measured rates, within ~3x).

    Attributes
    ----------
    run_time_s : float
        Wall-clock seconds of the run (NaN: unknown, e.g. a plug-in without an estimate).
    step_bytes : float
        Bytes of the per-step table (``result.npz``, and about as much memory while held).
    stiff_explicit : bool
        The run integrates a stiff joint law (friction's ramp, an oil film) with an explicit method.
    """

    run_time_s: float
    step_bytes: float
    stiff_explicit: bool = False


@dataclass(frozen=True)
class BoundEngine:
    """An engine of the contract made of three functions: ``select_path(scene)``, ``estimate(scene)`` and
    ``solve(scene, progress=None, observe=None)`` (the built-in engines are two of these)."""

    name: str
    path_of: Callable[[Scene], dict]
    estimate_of: Callable[[Scene], Estimate]
    solve_of: Callable[..., RunResult]

    def select_path(self, scene: Scene) -> dict:
        return self.path_of(scene)

    def estimate(self, scene: Scene) -> Estimate:
        return self.estimate_of(scene)

    def solve(self, scene: Scene, progress: Callable[[float], None] | None = None,
              observe: Callable[..., None] | None = None) -> RunResult:
        return self.solve_of(scene, progress=progress, observe=observe)
