"""Exit statuses of the ``weftsim`` command: defined in :mod:`weftsim.errors` (beside the errors that carry
them, at the bottom of the house), re-exported here for the command line and older imports."""

from weftsim.errors import EXIT_DISAGREE, EXIT_FAILED, EXIT_OK, EXIT_PARTIAL, EXIT_USAGE

__all__ = ["EXIT_OK", "EXIT_USAGE", "EXIT_FAILED", "EXIT_DISAGREE", "EXIT_PARTIAL"]
