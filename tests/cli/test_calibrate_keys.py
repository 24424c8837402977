"""`poppy calibrate` on a terminal: Enter goes on and a single q cancels (no Enter after it)."""

from __future__ import annotations

import io
import os
import sys
import termios
from pathlib import Path

import pytest

from poppy_cli.commands.calibrate import RichAnswers
from tests.helpers.cli import POPPY
from tests.helpers.processes import read_until, start_on_pty
from tests.helpers.waiting import scaled


def _env(tmp_path: Path) -> dict[str, str]:
    """A terminal of 120 columns, no colour, no user profile or port, config under tmp_path."""
    return dict(
        os.environ,
        COLUMNS="120",
        NO_COLOR="1",
        XDG_CONFIG_HOME=str(tmp_path / "xdg"),
        POPPY_PROFILE="",
        POPPY_PORT="",
    )


def test_enter_then_a_single_q_cancels_and_the_terminal_is_restored(tmp_path: Path) -> None:
    env = _env(tmp_path)
    proc, parent, child = start_on_pty(
        [*POPPY, "calibrate", "--sim", "--profile", "ergo-jr", "--motors", "m1"], env
    )
    try:
        shown = read_until(parent, "q to cancel")
        assert "reference posture" in shown, shown
        os.write(parent, b"\r")  # Enter: the posture is taken
        shown = read_until(parent, "q to cancel")
        assert "slowly" in shown, shown
        os.write(parent, b"q")  # one key, no Enter
        shown = read_until(parent, "nothing was written", timeout_s=30)
        assert "calibration cancelled" in shown, shown
        assert proc.wait(timeout=scaled(30)) == 1
        lflag = termios.tcgetattr(child)[3]
        assert lflag & termios.ECHO and lflag & termios.ICANON  # back as it was
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(parent)
        os.close(child)
    assert not (tmp_path / "xdg" / "poppy" / "profiles").exists()


def test_q_at_the_posture_cancels_at_once(tmp_path: Path) -> None:
    env = _env(tmp_path)
    proc, parent, child = start_on_pty([*POPPY, "calibrate", "--sim", "--profile", "ergo-jr"], env)
    try:
        read_until(parent, "q to cancel")
        os.write(parent, b"q")
        shown = read_until(parent, "nothing was written", timeout_s=30)
        assert "calibration cancelled" in shown, shown
        assert proc.wait(timeout=scaled(30)) == 1
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(parent)
        os.close(child)


@pytest.mark.parametrize(
    ("piped", "answer"),
    [("\n", True), ("n\n", False), ("y\r\n", True), ("maybe\n\n", True), ("", False)],
)
def test_a_calibration_question_takes_the_lines_piped_to_it(
    monkeypatch: pytest.MonkeyPatch, piped: str, answer: bool
) -> None:
    """Enter on a pipe is the default (yes), as on a terminal; the end of input is no. Rich
    takes a stream's line as it is, and a line still ending in its newline was never an answer:
    the question was asked again for every Enter piped (the README tour's `poppy calibrate`
    through pipes asked until it was killed)."""
    monkeypatch.setattr(sys, "stdin", io.StringIO(piped))
    assert RichAnswers().confirm("Record these zeros anyway?") is answer
