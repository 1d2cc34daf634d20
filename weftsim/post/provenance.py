"""Where a result came from: the versions of weftsim and the packages that computed it, and the commit.

Read from the installed distributions' metadata (no package is imported for it) and, when weftsim
runs from a git checkout, from git; written into every ``summary.json`` so a result can be traced
and reproduced.
"""

from __future__ import annotations

import functools
import platform
import subprocess
from importlib import metadata

from weftsim.version import package_directory

PACKAGES = ("weftsim", "exudyn", "numpy", "scipy", "numba", "matplotlib")


@functools.lru_cache(maxsize=1)
def versions() -> dict[str, str | None]:
    """``{"python": ..., "weftsim": ..., "exudyn": ..., ...}``; None for a package that is not installed."""
    out: dict[str, str | None] = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


@functools.lru_cache(maxsize=1)
def commit() -> str | None:
    """The git commit of the weftsim source in use (``+dirty`` with uncommitted changes), or None when
    weftsim is not run from a git checkout (an installed wheel) or git is missing."""
    source = package_directory()
    try:
        head = subprocess.run(["git", "-C", str(source), "rev-parse", "HEAD"], capture_output=True, text=True,
                              timeout=5)  # fmt: skip
        if head.returncode != 0:
            return None
        status = subprocess.run(["git", "-C", str(source), "status", "--porcelain", "--", "."],
                                capture_output=True, text=True, timeout=5)  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + ("+dirty" if status.stdout.strip() else "")


def version_line() -> str:
    """``weftsim 0.1.0 (Python 3.11.7, exudyn 1.13.6, numpy ...)`` for ``weftsim --version``."""
    v = versions()
    others = ", ".join(f"{name} {v[name] or 'not installed'}" for name in PACKAGES[1:])
    return f"weftsim {v['weftsim']} (Python {v['python']}, {others})"
