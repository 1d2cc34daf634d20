"""Exit statuses of the ``weftsim`` command, shared by the CLI and the commands it calls."""

EXIT_OK = 0
EXIT_USAGE = 2  # bad scene, flag or output directory
EXIT_FAILED = 3  # the simulation itself failed (partial results written)
EXIT_DISAGREE = 4  # compare: engines disagree beyond the scene's tolerance
EXIT_PARTIAL = 5  # compare: what was compared agrees, but the core checks could not be compared (run too short)
