"""Running and guarding a run, for both engines.

:mod:`weftsim.checks.guards` holds the run-time failure criteria of the scene's ``[limits]``,
:mod:`weftsim.checks.design_checks` the checks before and after a run (is this a machine a designer would
build?), :mod:`weftsim.checks.plausibility` the plausibility of a finished run's contact history and
:mod:`weftsim.checks.progress` the progress lines and run-time estimates on stderr.
"""
