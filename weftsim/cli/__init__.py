"""The command line: ``weftsim scenes | kinematics | run | animate | compare | sweep | study | bench | wear``.

:mod:`weftsim.cli.commands` holds the subcommands and ``main`` (the ``weftsim`` console script; also
``python -m weftsim.cli`` and ``python -m weftsim``), :mod:`weftsim.cli.grammar` the parser and the flags they
share and :mod:`weftsim.errors` the exit statuses.  Thin: it parses, calls the Python interface
(:mod:`weftsim.api`) and reports.
"""
