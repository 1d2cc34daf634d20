"""The version of weftsim (``weftsim.__version__``) and the directory of its package, in a module of its own so
that a submodule can read them without importing the package's interface (:mod:`weftsim.api`), which imports
the submodules."""

from pathlib import Path

__version__ = "0.1.0"


def package_directory() -> Path:
    """The directory of the weftsim package (``.../weftsim``), the same from any of its modules however deep
    it sits (the bundled scenes and the git checkout are found from it)."""
    return Path(__file__).resolve().parent
