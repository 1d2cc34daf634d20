"""``python -m weftsim.bench``."""

from weftsim.bench.measure import main

raise SystemExit(main())
