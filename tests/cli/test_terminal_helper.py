"""The pty helper of the CLI tests shows what a command printed as it was printed."""

from __future__ import annotations

import sys

import pytest

import tests.helpers.terminal as terminal_module
from tests.helpers.terminal import Terminal

# "µ" (2 bytes in UTF-8) written one byte at a time, with a pause between: two reads
SPLIT = (
    "import os, sys, time\n"
    "data = 'Set it to 0 µs? [Y/n]: '.encode()\n"
    "cut = data.index('µ'.encode()) + 1\n"
    "os.write(2, data[:cut]); time.sleep(0.5); os.write(2, data[cut:])\n"
)


def test_a_character_split_between_reads_is_shown_whole(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(terminal_module, "POPPY", [sys.executable, "-c", SPLIT])
    terminal = Terminal()
    try:
        shown = terminal.read_until("[Y/n]")
        assert terminal.wait() == 0
    finally:
        terminal.close()
    assert "Set it to 0 µs? [Y/n]" in shown, repr(shown)
