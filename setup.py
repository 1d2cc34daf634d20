"""Build configuration that pyproject.toml cannot state: the scene files of ``models/`` are
installed as the package data ``weftsim.scenes``, so ``weftsim run reference`` works from any
directory after ``pip install``.  The scene files stay in ``models/`` at the repository root, where
the documentation and the tests name them; everything else is in pyproject.toml.
"""

from setuptools import find_packages, setup

setup(
    packages=find_packages(include=["weftsim", "weftsim.*"]) + ["weftsim.scenes"],
    package_dir={"weftsim.scenes": "models"},
)
