"""The paper's studies, one command each: ``weftsim study NAME`` (see docs/paper-comparison.md).

===============  =====================================================================  ========
name             what                                                                   paper
===============  =====================================================================  ========
``contact-law``  K(delta) of the law; K and D along a revolution, c = 0.01 mm, 500 rpm  Fig. 7-9
``clearance``    c = 0.01, 0.25, 0.50 mm at 400 rpm, with the ideal joint               Fig. 12
``speed``        300, 500, 800 rpm at c = 0.25 mm; amplitude ratios; spectrum           Fig. 13
``engines``      reference vs exudyn, c = 0.50 mm at 400 rpm                            Fig. 16
===============  =====================================================================  ========

Each writes into its output directory PNG figures named ``study-*.png``, CSV files of
the plotted curves and a JSON file of every number it prints (``<name>.json``).
Scenes come from ``models/`` (``models/paper/`` for the paper's cases).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from weftsim.studies import clearance, contact_law, engines, speed
from weftsim.studies.common import SimulationFailed, StudyError
from weftsim.studies.spectrum import Spectrum, acceleration_spectrum, amplitude_spectrum

__all__ = ["STUDIES", "run_study", "format_study", "StudyError", "SimulationFailed", "Spectrum",
           "acceleration_spectrum", "amplitude_spectrum"]

# name -> (run(outdir, models, revolutions, force, progress) -> report, format_report(report) -> str)
STUDIES: dict[str, tuple[Callable[..., dict], Callable[[dict], str]]] = {
    "contact-law": (contact_law.run, contact_law.format_report),
    "clearance": (clearance.run, clearance.format_report),
    "speed": (speed.run, speed.format_report),
    "engines": (engines.run, engines.format_report),
}


def run_study(name: str, outdir: str | Path | None = None, models: str | Path = "models",
              revolutions: float | None = None, force: bool = False, progress: bool = True) -> dict:
    """Run one study by name into ``outdir`` (default ``out/study-<name>``); returns its report (JSON content).

    Raises
    ------
    StudyError
        Unknown name, missing scene file or bad revolutions.
    SimulationFailed
        A simulation of the study failed (a subclass of StudyError).
    """
    if name not in STUDIES:
        raise StudyError(f"unknown study {name!r}; choose one of {', '.join(STUDIES)} (or all)")
    run, _ = STUDIES[name]
    return run(Path(outdir) if outdir is not None else Path("out") / f"study-{name}", models=models,
               revolutions=revolutions, force=force, progress=progress)


def format_study(name: str, report: dict) -> str:
    """What ``weftsim study NAME`` prints for a report."""
    return STUDIES[name][1](report)
