"""``python -m weftsim.cli``: the ``weftsim`` command."""

import sys

from weftsim.cli.commands import main

sys.exit(main())
