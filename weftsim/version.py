"""The version of weftsim (``weftsim.__version__``), in a module of its own so that a submodule can read it
without importing the package's interface (:mod:`weftsim.api`), which imports the submodules."""

__version__ = "0.1.0"
