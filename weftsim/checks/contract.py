"""What an engine of the contract returns before it runs (:class:`Estimate`).

The contract itself and the registry are :mod:`weftsim.engines` (above the engines); what the engines need
of it sits here, below them, so that an engine's ``engine`` module imports nothing above its floor.
"""

from __future__ import annotations

from dataclasses import dataclass


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
