"""The command line's grammar, shared by every subcommand: the parser, the scene flags, the output flags.

``SCENE`` is a scene file or the name of a bundled scene; ``--set KEY=VALUE`` (repeatable) overrides any
scene key in the file's units, and ``--revolutions``, ``--speed-rpm``, ``--clearance-mm`` and ``--law`` are
its shorthands.  A subcommand adds them with :func:`add_scene_flags` and gets its validated scene from
:func:`scene_from_args`; ``-o`` comes from :func:`add_output_flags` and resolves with
:func:`output_directory` to ``out/<scene name>/<what>``.  The parser (:class:`Parser`) prints one-line
errors with the closest spelling of a mistyped flag or command.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, NoReturn

from weftsim.errors import WeftsimError, closest
from weftsim.errors import EXIT_USAGE

if TYPE_CHECKING:
    from weftsim.input.params import Scene


class CliError(WeftsimError):
    """An error of the command line itself, to print as one line, with an exit status."""

    def __init__(self, message: str, status: int = EXIT_USAGE) -> None:
        super().__init__(message)
        self.exit_status = status

    @property
    def status(self) -> int:
        return self.exit_status


class VersionAction(argparse.Action):
    """``--version``: the versions line (read from package metadata only when asked), then exit 0."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from weftsim.post.provenance import version_line

        print(version_line())
        parser.exit()


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (the usage stays behind --help), no abbreviated flags
    (``--speed 400`` must not silently mean ``--speed-rpm``) and the closest spelling of a
    mistyped flag or command (``did you mean --clearance-mm?``)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self._argv: list[str] = []

    def parse_args(self, args: list[str] | None = None,  # type: ignore[override]
                   namespace: argparse.Namespace | None = None) -> argparse.Namespace:
        self._argv = list(sys.argv[1:] if args is None else args)  # for the suggestion of error()
        return super().parse_args(args, namespace)

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}{self._suggestion(message)} "
                              f"(see '{self.prog} --help')\n")

    def _command_parser(self) -> argparse.ArgumentParser:
        """The subcommand's parser when the arguments name one (its flags are the ones to suggest)."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                for word in self._argv:
                    if word in action.choices:
                        return action.choices[word]
        return self

    def _suggestion(self, message: str) -> str:
        """``; did you mean --clearance-mm?`` for an unknown flag or an invalid choice, else ''."""
        choice = re.search(r"invalid choice: '(.*?)' \(choose from (.*)\)", message)
        if choice:
            options = re.findall(r"'([^']*)'", choice.group(2))
            near = closest(choice.group(1), options)
            return f"; did you mean {near}?" if near else ""
        unknown = re.search(r"unrecognized arguments: (.*)", message)
        if not unknown:
            return ""
        flags = [action_flag for action in self._command_parser()._actions for action_flag in action.option_strings]
        hints = []
        for word in unknown.group(1).split():
            if word.startswith("--"):
                near = closest(word.partition("=")[0], flags)
                if near:
                    hints.append(f"did you mean {near} for {word.partition('=')[0]}?")
        return "; " + "; ".join(hints) if hints else ""


def positive(kind: Callable[[str], float]) -> Callable[[str], float]:
    """An argparse type: ``kind(text)``, finite and > 0, or an error naming what was given."""

    def parse(text: str) -> float:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not math.isfinite(value) or value <= 0:
            raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
        return value

    return parse


def non_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


SCENE_HELP = "scene file (TOML) or the name of a bundled scene ('weftsim scenes' lists them), e.g. reference"
# The shorthand flags, by the load_scene flag (weftsim.api.SCENE_FLAGS) each sets: (type, help).
SHORTHANDS: dict[str, tuple[Any, str]] = {
    "revolutions": (positive(float), "crank revolutions to simulate (drive.revolutions)"),
    "speed_rpm": (positive(float), "crank speed, rpm (drive.speed_rpm)"),
    "clearance_mm": (non_negative, "radial clearance at E, mm; 0 = ideal joint (joint_e.clearance_mm)"),
    "law": (str, "contact force law (joint_e.law)"),
}


def add_scene_flags(parser: argparse.ArgumentParser, shorthands: tuple[str, ...] = tuple(SHORTHANDS),
                    positional: bool = True) -> None:
    """Add the scene grammar every command shares: ``SCENE``, ``--set KEY=VALUE`` and the shorthands.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A subcommand's parser (``weftsim wear``, ``weftsim animate``, ...).
    shorthands : tuple of str
        Which of ``revolutions``, ``speed_rpm``, ``clearance_mm``, ``law`` the command takes (all by
        default; a command where one means nothing leaves it out rather than ignore it).
    positional : bool
        Add the ``scene`` argument (a command with its own positional, as ``sweep``, adds it itself).

    :func:`scene_from_args` turns the parsed arguments into the validated scene.
    """
    if positional:
        parser.add_argument("scene", help=SCENE_HELP)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="set",
                        help="override any scene key in file units, e.g. --set joint_e.restitution=0.8 "
                        "(a dotted key, or its last part where unique: restitution); repeatable")
    for flag in shorthands:
        kind, text = SHORTHANDS[flag]
        parser.add_argument("--" + flag.replace("_", "-"), type=kind, help=text)


def set_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The ``--set`` overrides as dotted scene keys (file units)."""
    texts = getattr(args, "set", None) or []
    if not texts:  # the sweep's grammar (and its package, ~0.04 s of a run) only for a --set
        return {}
    from weftsim.sweep.grid import parse_set

    overrides: dict[str, Any] = {}
    for text in texts:
        key, value = parse_set(text)
        if key in overrides:
            raise CliError(f"--set: key '{key}' is given twice; give it once")
        overrides[key] = value
    return overrides


def shorthand_values(args: argparse.Namespace) -> dict[str, Any]:
    return {flag: getattr(args, flag) for flag in SHORTHANDS if getattr(args, flag, None) is not None}


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The validated scene of ``args.scene`` with the ``--set`` overrides and the shorthand flags.

    Raises :class:`weftsim.errors.SceneError` (or SweepError for a malformed ``--set``) with the
    line to print; a key set both by ``--set`` and by its shorthand flag is refused.
    """
    from weftsim.api import scene_overrides
    from weftsim.input.scene import load_scene

    from weftsim.input.joint_keys import inheritance_note, wear_only_keys, wear_only_message

    overrides = scene_overrides(set_overrides(args), where="command line", **shorthand_values(args))
    command = getattr(args, "command", None) or "run"
    idle = wear_only_keys(overrides) if command != "wear" else []
    if idle:
        raise CliError(wear_only_message(idle[0], command))
    scene = load_scene(args.scene, overrides)
    note = inheritance_note(scene)
    if note:  # one line on stderr: what joint F took from E (stdout stays the report's)
        print(f"weftsim {getattr(args, 'command', None) or 'scene'}: {note}", file=sys.stderr, flush=True)
    return scene


def add_output_flags(parser: argparse.ArgumentParser, default: str) -> None:
    """``-o/--output`` (its help naming ``default``, e.g. ``"out/<scene name>/wear"``) and ``--force``;
    :func:`output_directory` resolves them."""
    parser.add_argument("-o", "--output", default=None, help=f"output directory (default: {default})")
    parser.add_argument("--force", action="store_true",
                        help="write into an output directory that holds files weftsim did not write")


def models_directory(args: argparse.Namespace) -> Path:
    """``--models``, or the directory of the bundled scenes."""
    from weftsim.input.scene import bundled_directory

    if args.models is not None:
        return Path(args.models)
    directory = bundled_directory()
    if directory is None:
        raise CliError("this installation has no bundled scenes; pass the directory of the scene files with --models")
    return directory


# How the shorthand flags show in the name of a default output directory (out/loom-c0.25mm-800rpm/exudyn/).
DIRECTORY_LABELS = {"joint_e.clearance_mm": "c{}mm", "drive.speed_rpm": "{}rpm", "drive.revolutions": "{}rev",
                    "joint_e.law": "{}"}


def overrides_tag(overrides: dict[str, Any]) -> str:
    """What tells a default output directory of a scene with ``overrides`` from the scene's own: the shorthand
    values (``c0.25mm-800rpm-3rev``), and ``set`` with 8 hex digits of the other keys' values (``--set``);
    empty without overrides (``name`` names the directory itself)."""
    import hashlib
    import json

    given = {k: v for k, v in overrides.items() if v is not None and k != "name"}
    parts = [form.format(f"{given.pop(key):g}" if isinstance(given[key], float) else given.pop(key))
             for key, form in DIRECTORY_LABELS.items() if key in given]
    if given:
        digest = hashlib.sha1(json.dumps(given, sort_keys=True, default=str).encode()).hexdigest()[:8]
        parts.append(f"set{digest}")
    return "-".join(parts)


def command_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The overrides the command line gives (``--set`` and the shorthand flags) as dotted keys."""
    from weftsim.api import SCENE_FLAGS

    return {**set_overrides(args), **{SCENE_FLAGS[flag]: value for flag, value in shorthand_values(args).items()}}


def output_directory(args: argparse.Namespace, scene: Scene, *parts: str) -> Path:
    """``-o``, or ``out/<scene name>/<parts>`` (``parts``: the engine, ``"compare"``, ...): every command's
    results of one scene under one directory, each in its own.  With overrides on the command line the
    scene's directory is ``out/<scene name>-<tag>`` (:func:`overrides_tag`: ``out/loom-c0.25mm/exudyn``), so a
    run with other settings never lands on another's results.  A name that would leave ``out/`` is refused."""
    if args.output:
        return Path(args.output)
    name = scene.name
    if name in (".", "..") or "/" in name or "\\" in name or (os.altsep and os.altsep in name):
        raise CliError(f"the scene's key 'name' = {name!r} cannot name the default output directory "
                       "out/<name>: it must be one plain file name (no '/' or '\\', not '.' or '..'); "
                       "change it or choose the output directory with -o")
    tag = overrides_tag(command_overrides(args))
    return Path("out", f"{name}-{tag}" if tag else name, *parts)
