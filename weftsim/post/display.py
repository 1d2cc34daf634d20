"""Is a window server behind ``DISPLAY`` / ``WAYLAND_DISPLAY``?  Asked before a renderer is started.

Exudyn's renderer (GLFW) aborts the whole process natively ("terminate called without an active
exception") when ``DISPLAY`` names an X server that is not there, so ``weftsim animate --viewer``
connects to the server's socket first and refuses with one line when nothing answers.

An X display ``[host]:number[.screen]`` is served on the local socket ``/tmp/.X11-unix/X<number>``
(on Linux also the same name in the abstract namespace) when ``host`` is empty or ``unix``, on
TCP port 6000 + number of ``host`` otherwise, and on the socket named by the whole text when it is a
path (macOS XQuartz: ``/private/tmp/.../org.xquartz:0``).  A Wayland display is the socket
``$XDG_RUNTIME_DIR/$WAYLAND_DISPLAY`` (or the absolute path it gives).  Only a connection is
opened and closed; nothing is sent.
"""

from __future__ import annotations

import os
import re
import socket
from collections.abc import Mapping

X_SOCKET_DIRECTORY = "/tmp/.X11-unix"
X_TCP_BASE_PORT = 6000
CONNECT_TIMEOUT_S = 2.0  # a TCP display (SSH forwarding) answers in milliseconds; a dead host must not hang
_X_DISPLAY = re.compile(r"^(?P<host>.*):(?P<number>\d+)(?:\.\d+)?$")


def _unix_connects(address: str) -> bool:
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as sock:
        sock.settimeout(CONNECT_TIMEOUT_S)
        try:
            sock.connect(address)
        except OSError:
            return False
        return True


def _tcp_connects(host: str, port: int) -> bool:
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S):
            return True
    except (OSError, ValueError):
        return False


def x_server_problem(display: str) -> str | None:
    """Why the X server of ``display`` cannot be reached (one phrase), or None when it answers."""
    match = _X_DISPLAY.match(display)
    if match is None:
        return f"DISPLAY={display!r} is not of the form [host]:number[.screen]"
    host, number = match["host"], int(match["number"])
    if host.startswith("/"):  # a socket path (XQuartz's launchd socket)
        candidates = [display]
    elif host in ("", "unix"):
        path = f"{X_SOCKET_DIRECTORY}/X{number}"
        candidates = ["\0" + path, path] if hasattr(socket, "AF_UNIX") else []
    else:
        if _tcp_connects(host, X_TCP_BASE_PORT + number):
            return None
        return f"no X server answers at DISPLAY={display!r} (TCP port {X_TCP_BASE_PORT + number} of {host})"
    if any(_unix_connects(address) for address in candidates):
        return None
    where = candidates[-1] if candidates else display
    return f"no X server answers at DISPLAY={display!r} (nothing listens on {where})"


def wayland_problem(name: str, environ: Mapping[str, str]) -> str | None:
    """Why the Wayland compositor ``name`` cannot be reached (one phrase), or None when it answers."""
    path = name if name.startswith("/") else os.path.join(environ.get("XDG_RUNTIME_DIR", ""), name)
    if not os.path.isabs(path):
        return f"WAYLAND_DISPLAY={name!r} without XDG_RUNTIME_DIR names no socket"
    return None if _unix_connects(path) else f"no Wayland compositor answers at {path}"


def unreachable_display(environ: Mapping[str, str]) -> str | None:
    """None when the display that ``environ`` names answers; else why not (X first, then Wayland)."""
    problems = []
    if environ.get("DISPLAY"):
        problem = x_server_problem(environ["DISPLAY"])
        if problem is None:
            return None
        problems.append(problem)
    if environ.get("WAYLAND_DISPLAY"):
        problem = wayland_problem(environ["WAYLAND_DISPLAY"], environ)
        if problem is None:
            return None
        problems.append(problem)
    return "; ".join(problems) or None
