"""Design sweeps (``weftsim sweep``): a grid of scene variants run in parallel, resumably, tabulated.

- :mod:`.grid`: the ``--vary`` / ``--set`` grammar and the cells of a grid;
- :mod:`.plan`: the validated plan of a sweep (:func:`plan_sweep`);
- :mod:`.engines`: named and plug-in engines (a plug-in is code that runs);
- :mod:`.cell`: one cell solved in a worker from data, and its record on disk;
- :mod:`.pool`, :mod:`.worker`: the local process pool (workers die with the sweep) or a Dask cluster;
- :mod:`.lock`: one sweep at a time in a directory;
- :mod:`.store`: the sweep's directory (``sweep.json``, ``sweep.csv``);
- :mod:`.runner`: running a sweep (:func:`run_sweep`);
- :mod:`.plots`: the sweep figure.

See docs/sweeps.md.
"""

from weftsim.sweep.grid import SweepError
from weftsim.sweep.plan import LARGE_GRID_CELLS, SweepPlan, plan_sweep
from weftsim.sweep.runner import SweepReport, format_report, run_sweep

__all__ = ["LARGE_GRID_CELLS", "SweepError", "SweepPlan", "SweepReport", "format_report", "plan_sweep", "run_sweep"]
