"""Sphinx configuration of the weftsim documentation site (``scripts/build_docs.sh``).

The Markdown pages of ``docs/`` are read as they are (myst-parser, equations in ``$...$`` and
``$$...$$`` rendered by MathJax), the API reference comes from the numpydoc docstrings (autodoc +
napoleon, one page per area with autosummary tables), the scene-key reference is written from the
schema at every build (``docs/_scene_keys.py``), and the gallery runs every ``examples/plot_*.py`` at
build time (sphinx-gallery), offering each as a Python script and a Jupyter notebook.

Links into the numpy, pandas, xarray, scipy and matplotlib docs (intersphinx) need their inventories
from the internet: set ``WEFTSIM_DOCS_INTERSPHINX=1`` where the build has network access. Without it
the build stays offline and those names are shown as plain code.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the checkout's weftsim, also when it is not installed
sys.path.insert(0, str(Path(__file__).resolve().parent))  # _gallery.py, the gallery's figure scraper
# Exudyn must never open a window while the gallery runs (docs/clearance-joint.md).
os.environ.setdefault("EXUDYN_SUPPRESS_UI_WINDOW_OPEN", "1")

import weftsim  # noqa: E402
from _scene_keys import write_page  # noqa: E402

# The scene-key reference, from weftsim.input.schema.SCHEMA (rewritten only when the schema changed).
write_page(Path(__file__).resolve().parent)

project = "weftsim"
author = "the weftsim authors"
copyright = "the weftsim authors, MIT licence"
release = weftsim.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax from the site itself, not a CDN: the equations show without a network (issue 35;
    # scripts/check_offline_math.py checks the built pages).
    "sphinx-mathjax-offline",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "data", "sg_execution_times.rst", "*/sg_execution_times.rst"]  # left by builds before they were off

# Markdown: headings get anchors so that pages can link to sections (physics.md#3-contact-force-laws).
myst_heading_anchors = 3
# $...$ inline and $$...$$ display maths (amsmath: align and friends), rendered by the site's own MathJax.
myst_enable_extensions = ["dollarmath", "amsmath"]

# The docstrings are numpydoc; napoleon reads them without demanding numpydoc's full section set.
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" as fields: dataclass fields are not described twice
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
# The API pages' summary tables (autosummary) list what each page documents; the pages themselves are
# written by hand (docs/api/*.rst), so no stub files are generated.
autosummary_generate = False

# Offline by default (the build must work without network access); WEFTSIM_DOCS_INTERSPHINX=1 links
# numpy, pandas, xarray, scipy and matplotlib names to their own documentation.
if os.environ.get("WEFTSIM_DOCS_INTERSPHINX") == "1":
    extensions.append("sphinx.ext.intersphinx")
    intersphinx_mapping = {
        "python": ("https://docs.python.org/3", None),
        "numpy": ("https://numpy.org/doc/stable", None),
        "scipy": ("https://docs.scipy.org/doc/scipy", None),
        "pandas": ("https://pandas.pydata.org/docs", None),
        "xarray": ("https://docs.xarray.dev/en/stable", None),
        "matplotlib": ("https://matplotlib.org/stable", None),
    }

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",  # every plot_*.py runs at build time
    "ignore_pattern": r"(__init__|flores_mechanism)\.py",  # a module the examples import, not a page
    "abort_on_example_error": True,
    "download_all_examples": True,
    "remove_config_comments": True,
    "within_subsection_order": "_gallery.LoomFirstSortKey",  # the loom run first, then by file name
    "show_memory": False,
    # No sg_execution_times pages: their table loads jQuery and DataTables from CDNs (the site must work offline,
    # scripts/check_offline_math.py); the build log gives the examples' times.
    "write_computation_times": False,
    "matplotlib_animations": True,
    "image_scrapers": ("matplotlib", "_gallery.weftsim_figures"),
    "capture_repr": ("_repr_html_",),  # no "<Figure size ...>" lines under the code
}

html_theme = "furo"
html_title = f"weftsim {release}"
html_static_path: list[str] = []
