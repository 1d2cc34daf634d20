"""The paper's studies, one command each: ``weftsim study NAME`` (see docs/paper-comparison.md).

===============  =====================================================================  ========
name             what                                                                   paper
===============  =====================================================================  ========
``contact-law``  K(delta) of the law; K and D along a revolution, c = 0.01 mm, 500 rpm  Fig. 7-9
``clearance``    c = 0.01, 0.25, 0.50 mm at 400 rpm, with the ideal joint               Fig. 12
``speed``        300, 500, 800 rpm at c = 0.25 mm; amplitude ratios; spectrum           Fig. 13
``engines``      reference vs exudyn, c = 0.50 mm at 400 rpm                            Fig. 16
``regime``       lubricated E: min film ratio, peak force over speed x clearance x oil  -
``exchange``     weft exchange: overlap, speed, head errors over clearance x speed      -
===============  =====================================================================  ========

Each writes into its output directory PNG figures named ``study-*.png``, CSV files of
the plotted curves and a JSON file of every number it prints (``<name>.json``).
Scenes come from ``models/`` (``models/paper/`` for the paper's cases), or each case is run on a scene
given (``weftsim study clearance loom``): that scene with the keys the case sets.  ``overrides`` (scene keys in
file units) apply to every run of a study, except the keys the study sets itself (its ``SETS``: the
clearance of the clearance study, the speed of the speed study, the paper's case of the contact-law study).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from weftsim.studies import clearance, common, contact_law, engines, exchange, regime, speed
from weftsim.studies.common import SimulationFailed, StudyError
from weftsim.studies.spectrum import Spectrum, acceleration_spectrum, amplitude_spectrum

__all__ = ["STUDIES", "run_study", "check_overrides", "format_study", "StudyError", "SimulationFailed", "Spectrum",
           "acceleration_spectrum", "amplitude_spectrum"]

# name -> (run(outdir, models, revolutions, force, progress, overrides) -> report, format_report(report) -> str)
STUDIES: dict[str, tuple[Callable[..., dict], Callable[[dict], str]]] = {
    "contact-law": (contact_law.run, contact_law.format_report),
    "clearance": (clearance.run, clearance.format_report),
    "speed": (speed.run, speed.format_report),
    "engines": (engines.run, engines.format_report),
    "regime": (regime.run, regime.format_report),
    "exchange": (exchange.run, exchange.format_report),
}
# name -> the scene keys the study sets itself (refused as overrides), with why
SETS: dict[str, dict[str, str]] = {"contact-law": contact_law.SETS, "clearance": clearance.SETS, "speed": speed.SETS,
                                   "engines": engines.SETS, "regime": regime.SETS, "exchange": exchange.SETS}


def check_overrides(name: str, overrides: dict | None = None, revolutions: float | None = None) -> None:
    """Raise :class:`StudyError` where study ``name`` refuses ``overrides`` (before anything runs, so that
    ``weftsim study all`` stops before its first study rather than in the middle)."""
    if name not in STUDIES:
        raise StudyError(f"unknown study {name!r}; choose one of {', '.join(STUDIES)} (or all)")
    common.study_overrides(name, SETS[name], revolutions, 1.0, overrides)


def run_study(name: str, outdir: str | Path | None = None, models: str | Path = "models",
              revolutions: float | None = None, force: bool = False, progress: bool = True,
              overrides: dict | None = None, scene: str | Path | None = None) -> dict:
    """Run one study by name into ``outdir`` (default ``out/study-<name>``); returns its report (JSON content).

    ``overrides``: scene keys in file units (e.g. ``{"joint_e.restitution": 0.8}``) applied to every
    run of the study; a key the study sets itself is refused (:func:`check_overrides`).
    ``scene``: a scene file or bundled name to run the study's cases on (default: the paper's reference
    scene and its case files in ``models``): each case is that scene with the keys the case sets
    (the clearance of the clearance study, ...).  The report records the scene, the overrides and the
    command line (``base_scene``, ``overrides``, ``command``); the directory holds ``scene.toml``.

    Raises
    ------
    StudyError
        Unknown name, missing scene file, bad revolutions or an override of a key the study sets.
    SimulationFailed
        A simulation of the study failed (a subclass of StudyError).
    """
    if name not in STUDIES:
        raise StudyError(f"unknown study {name!r}; choose one of {', '.join(STUDIES)} (or all)")
    run, _ = STUDIES[name]
    return run(Path(outdir) if outdir is not None else Path("out") / f"study-{name}", models=models,
               revolutions=revolutions, force=force, progress=progress, overrides=overrides, scene=scene)


def format_study(name: str, report: dict) -> str:
    """What ``weftsim study NAME`` prints for a report."""
    return STUDIES[name][1](report)
