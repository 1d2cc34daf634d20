"""Running and guarding a run, for both engines.

:mod:`weftsim.run.guards` holds the run-time failure criteria of the scene's ``[limits]``,
:mod:`weftsim.run.design_checks` the checks before and after a run (is this a machine a designer would
build?), :mod:`weftsim.run.plausibility` the plausibility of a finished run's contact history and
:mod:`weftsim.run.progress` the progress lines and run-time estimates on stderr.
"""
