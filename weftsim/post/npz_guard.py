"""Opening an NPZ archive weftsim wrote earlier (a result, a wear state) as untrusted input.

A disk, a copy or a person may have damaged or crafted it, so the archive is checked from what
costs nothing to read before any array is: the path (present, a regular file, not empty, a ZIP
archive), the ZIP directory (only the expected members, none twice, none encrypted, the declared
uncompressed sizes within the memory available and not a ZIP bomb), and each array's NumPy
header (a few hundred bytes: dtype, shape, and the bytes they imply equal to the member's
declared size).  A member is never inflated past its declared size (:mod:`zipfile` stops there and
checks the CRC), so after these checks reading an array allocates only what its header says.

Every refusal is one :class:`weftsim.errors.OutputError` line: ``{path}: cannot be read as {what}: ...``.
"""

from __future__ import annotations

import math
import os
import stat
import zipfile
import zlib
from pathlib import Path

import numpy as np

from weftsim.errors import OutputError

# A float64 channel of a result compresses about 1.4:1 (measured: 206 kB of arrays in a 152 kB file);
# a channel that stays 0 (the contact of a run that never touches) compresses far better, but the
# time and the rapier's channels never do, and a wear state is stored uncompressed.  An archive
# declaring more than this many times its own size is a ZIP bomb or a damaged directory.
MAX_INFLATION = 200.0
# Below this declared total the inflation bound is not applied (a small archive may compress well).
INFLATION_FLOOR_BYTES = 64 * 2**20
# Exceptions a damaged archive raises while a member is read (truncated, bad CRC, bad deflate data, ...).
DAMAGE = (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, NotImplementedError, RuntimeError)


def fail(path: Path, what: str, text: str) -> OutputError:
    """The one-line refusal of ``path`` as ``what`` (e.g. "a weftsim result")."""
    return OutputError(f"{path}: cannot be read as {what}: {text}")


def size_text(n: float) -> str:
    """A byte count for a person: 3 significant digits and a decimal unit."""
    for unit in ("bytes", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000
    raise AssertionError("unreachable")


def open_archive(path: Path, what: str, directory_hint: str) -> zipfile.ZipFile:
    """The ZIP archive at ``path``, or an OutputError saying what the path is instead.

    ``directory_hint``: what to say when ``path`` is a directory (e.g. "give the result.npz file in it").
    """
    try:
        info = path.stat()
    except FileNotFoundError:
        raise OutputError(f"{path}: file not found") from None
    except OSError as exc:
        raise fail(path, what, exc.strerror or str(exc)) from None
    except ValueError as exc:  # a NUL character in the path
        raise fail(path, what, f"no such path ({exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise fail(path, what, f"it is a directory ({directory_hint})")
    if not stat.S_ISREG(info.st_mode):
        raise fail(path, what, "it is not a regular file")
    if info.st_size == 0:
        raise fail(path, what, "the file is empty (0 bytes: a process killed while writing it, or a failed copy)")
    try:
        with path.open("rb") as handle:
            head = handle.read(6)
        if head == b"\x93NUMPY":
            raise fail(path, what, "it is a single NumPy array (.npy), not the NPZ archive weftsim writes")
        return zipfile.ZipFile(path)
    except OutputError:
        raise
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError) as exc:
        raise fail(path, what, f"not an NPZ (ZIP) archive, or a truncated one ({exc})") from None
    except OSError as exc:
        raise fail(path, what, exc.strerror or str(exc)) from None


def _array_header(archive: zipfile.ZipFile, member: zipfile.ZipInfo) -> tuple[tuple[int, ...], np.dtype, int]:
    """(shape, dtype, header bytes) of one ``.npy`` member, read from its first bytes only."""
    with archive.open(member) as handle:
        version = np.lib.format.read_magic(handle)
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(handle)
        elif version == (2, 0):
            shape, _, dtype = np.lib.format.read_array_header_2_0(handle)
        else:
            raise ValueError(f"NumPy format version {version} is not one weftsim writes")
        return tuple(shape), dtype, handle.tell()


def available_memory() -> int | None:
    """Bytes of memory a new allocation can get without swapping (Linux MemAvailable), or None."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def array_headers(path: Path, archive: zipfile.ZipFile, expected: set[str], what: str
                  ) -> dict[str, tuple[tuple[int, ...], np.dtype]]:
    """The archive's members checked as the module docstring says; name (no ``.npy``) -> (shape, dtype).

    ``expected``: the array names that may occur, each at most once.
    """
    infos = archive.infolist()
    names = [info.filename for info in infos]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise fail(path, what, f"the archive holds {', '.join(twice[:3])} more than once (a damaged or crafted file)")
    unknown = sorted(n for n in names if not n.endswith(".npy") or n[:-4] not in expected)
    if unknown:
        shown = ", ".join(repr(n) for n in unknown[:3]) + (f" and {len(unknown) - 3} more" if len(unknown) > 3 else "")
        raise fail(path, what, f"the archive holds {shown}, which weftsim does not write")
    if any(info.flag_bits & 0x1 for info in infos):
        raise fail(path, what, "the archive is encrypted; weftsim writes none")
    declared = sum(info.file_size for info in infos)
    file_size = path.stat().st_size
    if declared > INFLATION_FLOOR_BYTES and declared > MAX_INFLATION * file_size:
        raise fail(path, what, f"its {size_text(file_size)} declare {size_text(declared)} of arrays, more than "
                               f"{MAX_INFLATION:g} times the file (a ZIP bomb or a damaged archive); nothing was read")
    available = available_memory()
    if available is not None and declared > available:
        raise fail(path, what, f"its arrays need {size_text(declared)} of memory, more than the "
                               f"{size_text(available)} available; nothing was read")
    headers = {}
    for info in infos:
        name = info.filename[:-4]
        try:
            shape, dtype, header = _array_header(archive, info)
        except (*DAMAGE, SyntaxError, TypeError) as exc:
            raise fail(path, what, f"array {name!r} has no valid NumPy header ({exc})") from None
        count = math.prod(shape)
        if dtype.hasobject:
            raise fail(path, what, f"array {name!r} holds Python objects ({dtype}); weftsim writes numbers and text")
        if header + count * dtype.itemsize != info.file_size:
            raise fail(path, what, f"array {name!r} claims shape {shape} of {dtype} "
                                   f"({size_text(count * dtype.itemsize)}), but its member holds "
                                   f"{size_text(max(info.file_size - header, 0))} (a damaged or crafted file)")
        headers[name] = (shape, dtype)
    return headers


def read_array(archive: zipfile.ZipFile, name: str) -> np.ndarray:
    """The array ``name`` (checked by :func:`array_headers`); a damaged member raises one of :data:`DAMAGE`."""
    with archive.open(f"{name}.npy") as handle:
        return np.lib.format.read_array(handle, allow_pickle=False)
