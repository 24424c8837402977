"""`poppy dataset record` on a terminal: lerobot-record's keys (→ ends the episode or the reset,
← records it again, Esc stops) and the live line (episode i/N, time, frames, dropped)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from poppy_cli.commands.dataset.live import ENTER, ESC, LEFT, RIGHT, parse_keys
from tests.helpers.cli import no_user_settings
from tests.helpers.terminal import Terminal
from tests.helpers.waiting import scaled

RIGHT_KEY, LEFT_KEY, ESC_KEY = b"\x1b[C", b"\x1b[D", b"\x1b"
NEVER = "\0"


def shows_again(terminal: Terminal, text: str, seen: int, timeout_s: float = 60) -> str:
    """What the terminal shows once ``text`` is on it more than ``seen`` times."""
    deadline = time.monotonic() + scaled(timeout_s)
    while terminal.shown.count(text) <= seen and time.monotonic() < deadline:
        terminal.read_until(NEVER, timeout_s=0.3)
    assert terminal.shown.count(text) > seen, terminal.text[-2000:]
    return terminal.text


def test_keys_are_read_from_what_a_terminal_sends() -> None:
    assert parse_keys(b"\x1b[C\x1b[D\x1bOC\x1bOD") == [RIGHT, LEFT, RIGHT, LEFT]
    assert parse_keys(b"\x1b") == [ESC]
    assert parse_keys(b"\x1b\x1b[C") == [ESC, RIGHT]
    assert parse_keys(b"x\r\x1b[A\x1b[15~") == [ENTER]  # up arrow and F5 are no keys here


@pytest.mark.slow
def test_right_left_and_esc_drive_the_episodes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    no_user_settings(tmp_path, monkeypatch, moves=True)
    root = tmp_path / "ds"
    terminal = Terminal(
        "dataset",
        "record",
        "poppy/keys",
        "--root",
        str(root),
        "--profile",
        "ergo-jr",
        "--sim",
        "--primitive",
        "dance",
        "--no-cameras",
        "--episodes",
        "3",
        "--episode-s",
        "120",
        "--reset-s",
        "120",
        "--fps",
        "10",
        "--task",
        "keys",
    )
    try:
        assert "Esc stops" in terminal.read_until("Esc stops")
        live = shows_again(terminal, "episode 1/3  ", 0)  # the live line
        assert " frames  0 dropped" in live[live.index("episode 1/3  ") :], live[-2000:]
        terminal.type(RIGHT_KEY)  # the episode ends, saved
        assert "episode 0 saved" in shows_again(terminal, "before episode 2/3 (", 0)
        terminal.type(RIGHT_KEY)  # the reset ends
        shows_again(terminal, "episode 2/3  ", 0)
        terminal.type(LEFT_KEY)  # dropped, recorded again after a reset
        shown = shows_again(terminal, "before episode 2/3 (", 1)
        assert "episode 2/3 dropped: recording it again" in shown, shown[-2000:]
        terminal.type(RIGHT_KEY)
        seen = terminal.shown.count("episode 2/3  ")
        shows_again(terminal, "episode 2/3  ", seen)
        terminal.type(ESC_KEY)  # saved, and the recording stops
        assert terminal.wait(timeout_s=60) == 0, terminal.text[-2000:]
    finally:
        terminal.close()
    text = terminal.text
    assert "episode 1 saved" in text and "episode 3/3" not in text, text[-2000:]
    assert "recorded 2 episode(s)" in text and "Traceback" not in text
    info = json.loads((root / "meta/info.json").read_text())
    assert info["total_episodes"] == 2
