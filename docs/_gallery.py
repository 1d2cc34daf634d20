"""The gallery's image scraper for weftsim's figures (named in ``docs/conf.py``; a module of its own
because Sphinx keeps its configuration picklable)."""

from __future__ import annotations

# The figures already shown, per example file (held, so that a freed figure's id is never reused).
_shown: dict[str, list] = {}


def weftsim_figures(block, block_vars, gallery_conf):
    """sphinx-gallery image scraper for the figures of :mod:`weftsim.post.plots`.

    weftsim draws on plain ``matplotlib.figure.Figure`` objects, never through pyplot (so that a run
    does not pay pyplot's import), which the gallery's own matplotlib scraper cannot see. This one
    saves every Figure that a code block left in a global variable of the example, once each, and
    shows every animation file (a ``Path`` to an existing ``.gif``) the same way.
    """
    import shutil
    from pathlib import Path

    from matplotlib.figure import Figure
    from sphinx_gallery.scrapers import figure_rst

    seen = _shown.setdefault(block_vars["src_file"], [])
    paths = []
    for value in list(block_vars["example_globals"].values()):
        if isinstance(value, Figure) and not any(value is shown for shown in seen):
            seen.append(value)
            path = next(block_vars["image_path_iterator"])
            value.savefig(path, dpi=110)
            paths.append(path)
        elif isinstance(value, Path) and value.suffix == ".gif" and value.is_file() and value not in seen:
            seen.append(value)
            path = str(Path(next(block_vars["image_path_iterator"])).with_suffix(".gif"))
            shutil.copyfile(value, path)
            paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])




class LoomFirstSortKey:
    """The gallery's order (``within_subsection_order`` in ``docs/conf.py``): the loom's run first, the
    showcase of the bundled ``loom`` scene, then the other examples by file name."""

    FIRST = "plot_loom_run.py"

    def __init__(self, src_dir):
        self.src_dir = src_dir

    def __call__(self, filename):
        return (filename != self.FIRST, filename)

    def __repr__(self):
        return f"<{type(self).__name__}>"
