"""Design sweeps (``weftsim sweep``): a grid of scene variants run in parallel, resumably, tabulated.

- :mod:`.grid`: the ``--vary`` / ``--set`` grammar and the cells of a grid;
- :mod:`.cell`: one cell run in a worker and its record on disk;
- :mod:`.store`: the sweep's directory (``sweep.json``, ``sweep.csv``);
- :mod:`.runner`: planning and running a sweep (:func:`plan_sweep`, :func:`run_sweep`);
- :mod:`.plots`: the sweep figure.

See docs/sweeps.md.
"""

from weftsim.sweep.grid import SweepError
from weftsim.sweep.runner import SweepPlan, SweepReport, format_report, plan_sweep, run_sweep

__all__ = ["SweepError", "SweepPlan", "SweepReport", "format_report", "plan_sweep", "run_sweep"]
