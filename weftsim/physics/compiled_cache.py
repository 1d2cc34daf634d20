"""Where numba keeps the compiled physics: a folder keyed by the source of every compiled module.

numba's own cache (``cache=True``) checks only the time stamp of the file that defines a function, not of
the files whose functions and constants it compiled in.  The kernels read their parameters by indices
defined in other modules (:mod:`weftsim.physics.joint`'s block layout, the chain's slots): after an edit or
a ``git pull`` that changes one of those files, a kernel loaded from the cache would read its parameters at
the old indices and compute nonsense without a word (seen: a worn reference run with a "penetration" of
675 mm at t = 2e-14 s).  So the cache lives in a folder named by a digest of the source of every weftsim
module that numba compiles: a change to any of them starts a new folder, and nothing stale is ever loaded.

The folder is ``__pycache__/numba-<digest>`` beside the package where that is writable (an editable or
user install), else ``weftsim/numba-<digest>`` in the user's cache (``$XDG_CACHE_HOME`` or ``~/.cache``).
A ``NUMBA_CACHE_DIR`` set by the user wins (then the user keeps it fresh).  Folders of older sources are
left in place (another checkout may still use them); deleting them only costs a recompilation.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent


def source_digest(package: Path = PACKAGE) -> str:
    """SHA-256 (first 16 hex digits) over the path and text of every module of ``package`` that uses numba."""
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        text = path.read_bytes()
        if b"numba" in text:
            digest.update(str(path.relative_to(package)).encode() + b"\0" + text + b"\0")
    return digest.hexdigest()[:16]


def cache_folder(package: Path = PACKAGE) -> Path:
    """The folder for this source's compiled kernels (module docstring)."""
    name = f"numba-{source_digest(package)}"
    beside = package / "__pycache__"
    if os.access(beside if beside.exists() else package, os.W_OK):
        return beside / name
    home = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return home / "weftsim" / name


def use_keyed_cache() -> None:
    """Point numba's cache at :func:`cache_folder`, unless the user set ``NUMBA_CACHE_DIR``.

    Must run before the first ``@njit(cache=True)`` of weftsim is decorated (numba reads the folder then):
    ``weftsim.physics`` calls it on import, and every compiled module imports the physics first.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    from numba.core import config

    config.CACHE_DIR = str(cache_folder())  # type: ignore[attr-defined]  # set at run time
