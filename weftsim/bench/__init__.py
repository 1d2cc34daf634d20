"""Work-precision benchmark (``weftsim bench``): every engine over its settings against a converged solution.

- :mod:`.measure`: the cases, the settings, the timing and error measurements;
- :mod:`.report`: the tables, figures, machine and versions.

See docs/performance.md.
"""

from weftsim.bench.measure import CASES, QUANTITY_CHANNELS, run_benchmark

__all__ = ["CASES", "QUANTITY_CHANNELS", "run_benchmark"]
