"""Command-line refusals that must come before any simulation (issue 24): a DISPLAY with no server behind it
(the renderer aborted the process natively), an unbounded --frames, an animation path that cannot be written."""

import socket
from pathlib import Path

import pytest

from weftsim.cli.commands import EXIT_USAGE, main
from weftsim.post.display import unreachable_display

UNUSED_DISPLAY = 987  # an X display number nothing on a test machine serves


def _one_error_line(capsys, *words):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("weftsim animate: error: "), err
    for word in words:
        assert word in err[0], err[0]
    return err[0]


@pytest.fixture
def no_x_server():
    if Path(f"/tmp/.X11-unix/X{UNUSED_DISPLAY}").exists():
        pytest.skip(f"display :{UNUSED_DISPLAY} exists here")
    return f":{UNUSED_DISPLAY}"


@pytest.fixture
def no_solve(monkeypatch):
    """Fail the test if the command gets as far as solving the scene; returns the stand-in."""
    def solve(*args, **kwargs):
        raise AssertionError("the scene was solved before the refusal")

    monkeypatch.setattr("weftsim.cli.commands._solve", solve)
    return solve


def test_a_display_with_no_server_is_refused_before_the_solve(monkeypatch, tmp_path, capsys, no_x_server,
                                                              no_solve):
    pytest.importorskip("exudyn")
    monkeypatch.setenv("DISPLAY", no_x_server)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("EXUDYN_SUPPRESS_UI_WINDOW_OPEN", raising=False)
    monkeypatch.setattr("sys.platform", "linux")
    monkeypatch.setattr("weftsim.exudyn_engine.viewer.record_solution", no_solve)
    target = tmp_path / "solution.txt"
    assert main(["animate", "reference", "--viewer", "-o", str(target)]) == EXIT_USAGE
    _one_error_line(capsys, f"no X server answers at DISPLAY='{no_x_server}'", "writes a GIF instead")
    assert not target.exists()


def test_a_listening_socket_counts_as_a_display(tmp_path):
    """A server behind the display (here a bare listening socket) passes; without it each kind is named."""
    path = tmp_path / "xsock:0"  # an X display given as a socket path (XQuartz's form)
    assert "nothing listens on" in unreachable_display({"DISPLAY": str(path)})
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as server:
        server.bind(str(path))
        server.listen(1)
        assert unreachable_display({"DISPLAY": str(path)}) is None
    wayland = {"WAYLAND_DISPLAY": "wayland-test", "XDG_RUNTIME_DIR": str(tmp_path)}
    assert "no Wayland compositor answers" in unreachable_display(wayland)
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as server:
        server.bind(str(tmp_path / "wayland-test"))
        server.listen(1)
        assert unreachable_display(wayland) is None
    assert "not of the form" in unreachable_display({"DISPLAY": "garbage"})


def test_a_million_frames_are_refused_naming_the_limit(tmp_path, capsys, no_solve):
    assert main(["animate", "reference", "--frames", "1000000", "-o", str(tmp_path / "a.gif")]) == EXIT_USAGE
    _one_error_line(capsys, "--frames must be a whole number from 2 to 1440", "got 1000000")
    assert not (tmp_path / "a.gif").exists()


@pytest.mark.parametrize("make, words", [
    (lambda d: (d / "f").write_text("a file"), ["is a file, not a directory"]),
    (lambda d: (d / "f").mkdir() or (d / "f" / "a.gif").mkdir(), ["it is a directory"]),
])
def test_an_animation_path_that_cannot_be_written_fails_before_the_solve(tmp_path, capsys, no_solve, make, words):
    make(tmp_path)
    assert main(["animate", "reference", "-o", str(tmp_path / "f" / "a.gif")]) == EXIT_USAGE
    _one_error_line(capsys, *words)
