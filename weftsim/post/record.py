"""What an output directory records about how it was made, and the check that keeps one scene's results
from silently replacing another's.

Every command that writes results records in its directory's manifest (``.weftsim-output.json``) the
full resolved scene (every key in file units, after ``extends``, ``--set`` and the shorthand flags:
``resolved_scene``) and the command line that made it (``command``), and writes the same scene as
``scene.toml``: a scene file of its own, ``weftsim run out/<scene>/<engine>/scene.toml`` runs it again.

Before writing, :func:`check_same_scene` refuses a directory whose manifest records a *different*
resolved scene (``weftsim run reference`` and then ``weftsim run reference --clearance-mm 0.5`` would
both write ``out/reference/exudyn/``): the message names the keys that differ, ``-o`` to write
elsewhere and ``--force`` to replace them.  A rerun of the same scene replaces its own results.
"""

from __future__ import annotations

import contextlib
import json
import math
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from weftsim.errors import OutputError

if TYPE_CHECKING:
    from weftsim.input.params import Scene

MANIFEST = ".weftsim-output.json"  # the manifest of every output directory (weftsim.post.output writes it)
SCENE_FILE = "scene.toml"
SHOWN_DIFFERENCES = 3  # keys named in the refusal; the rest are counted

_command: list[str] | None = None
_command_text: str | None = None  # set by written_by()


def set_command(argv: list[str]) -> None:
    """The arguments of the ``weftsim`` command running now (``weftsim.cli.commands.main`` sets them)."""
    global _command
    _command = list(argv)


@contextlib.contextmanager
def written_by(command: str):
    """Within the block, :func:`command_line` is ``command``: a sweep's worker process writes its cell's
    record with the command that started the sweep, not its own arguments."""
    global _command_text
    before, _command_text = _command_text, command
    try:
        yield
    finally:
        _command_text = before


def command_line() -> str:
    """The command that is writing: ``weftsim run reference --clearance-mm 0.5``, or for the Python
    interface the interpreter's own arguments (the script and its arguments)."""
    if _command_text is not None:
        return _command_text
    if _command is not None:
        return shlex.join(["weftsim", *_command])
    return shlex.join(sys.argv) if sys.argv and sys.argv[0] else "python"


def resolved_scene(scene: Scene) -> dict[str, Any]:
    """Every key of ``scene`` in file units, as JSON gives it back (lists, no None: a key the scene
    leaves out is left out)."""
    from weftsim.input.scene import to_file_keys

    keys = {k: v for k, v in to_file_keys(scene).items() if v is not None}
    return json.loads(json.dumps(keys, default=str))


def provenance(scene: Scene) -> dict[str, Any]:
    """The manifest fields of a directory holding results of ``scene``: ``resolved_scene`` and ``command``."""
    return {"resolved_scene": resolved_scene(scene), "command": command_line()}


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return json.dumps(str(value), ensure_ascii=False)  # a TOML basic string: JSON's escapes are TOML's


def scene_toml(scene: Scene) -> str:
    """``scene`` as a complete scene file (every key, file units) that loads back to the same scene."""
    keys = resolved_scene(scene)
    tables: dict[str, list[str]] = {}
    for path, value in keys.items():
        table, _, name = path.rpartition(".")
        tables.setdefault(table, []).append(f"{name} = {_toml_value(value)}")
    lines = [f"# The resolved scene of these results (every key, file units), written by: {command_line()}",
             "# Run it again with: weftsim run <this file>"]
    lines += tables.pop("", [])
    for table, entries in tables.items():
        lines += ["", f"[{table}]", *entries]
    return "\n".join(lines) + "\n"


def recorded_scene(outdir: str | Path) -> dict[str, Any] | None:
    """The resolved scene the manifest of ``outdir`` records, or None (no manifest, or one written before
    weftsim recorded scenes)."""
    try:
        data = json.loads((Path(outdir) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    scene = data.get("resolved_scene") if isinstance(data, dict) else None
    return scene if isinstance(scene, dict) else None


def differences(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """``key old -> new`` for every key whose value differs (a missing key shows as ``-``)."""
    out = []
    for key in sorted(set(old) | set(new)):
        if old.get(key) != new.get(key):
            out.append(f"{key} {_shown(old.get(key))} -> {_shown(new.get(key))}")
    return out


def _shown(value: Any) -> str:
    return "-" if value is None else _toml_value(value)


# The command that writes each kind of output directory (the manifest's "kind"), for the refusal below.
COMMAND_OF_KIND = {"run": "weftsim run", "compare": "weftsim compare", "kinematics": "weftsim kinematics",
                   "wear": "weftsim wear", "wear ensemble": "weftsim wear --uncertain", "study": "weftsim study",
                   "bench": "weftsim bench", "optimize": "weftsim optimize"}


def recorded_kind(outdir: str | Path) -> str | None:
    """The ``kind`` the manifest of ``outdir`` records (``"run"``, ``"wear"``, ...), or None."""
    path = Path(outdir) / MANIFEST
    if not path.is_file():  # also a pipe, whose reading would wait forever
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    kind = data.get("kind") if isinstance(data, dict) else None
    return kind if isinstance(kind, str) else None


def check_same_kind(outdir: str | Path, kind: str, force: bool = False) -> None:
    """Refuse to write results of ``kind`` into ``outdir`` when it holds another command's results (a wear
    prediction's ``wear_state.npz`` beside an ensemble's ``ensemble.json`` would replace each other).

    Raises
    ------
    OutputError
        Naming the command whose results are there, ``-o`` and ``--force`` (unless ``force``).
    """
    old = recorded_kind(outdir)
    if old is None or old == kind or force:
        return
    theirs = COMMAND_OF_KIND.get(old, repr(old))
    ours = COMMAND_OF_KIND.get(kind, repr(kind))
    raise OutputError(f"{outdir} holds the results of `{theirs}`, which `{ours}` would replace; choose another "
                      "directory with -o, or pass --force to replace them")


def check_same_scene(outdir: str | Path, scene: Scene, force: bool = False) -> None:
    """Refuse to write results of ``scene`` into ``outdir`` when it holds results of another scene.

    Raises
    ------
    OutputError
        Naming the keys that differ, ``-o`` and ``--force`` (unless ``force``: the caller means to replace them).
    """
    old = recorded_scene(outdir)
    if old is None or force:
        return
    new = resolved_scene(scene)
    if scene.joint_f.is_ideal:  # keys of an ideal F added to weftsim after ``old`` was written change nothing
        new = {k: v for k, v in new.items() if k in old or not k.startswith("joint_f.")}
    changed = differences(old, new)
    if not changed:
        return
    shown = ", ".join(changed[:SHOWN_DIFFERENCES])
    more = f" and {len(changed) - SHOWN_DIFFERENCES} more" if len(changed) > SHOWN_DIFFERENCES else ""
    raise OutputError(f"{outdir} holds the results of another scene ({shown}{more}); choose another "
                      "directory with -o, or pass --force to replace them")
