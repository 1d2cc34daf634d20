"""``python -m weftsim``: the ``weftsim`` command."""

import sys

from weftsim.cli.commands import main

sys.exit(main())
