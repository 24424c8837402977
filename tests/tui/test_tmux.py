"""The TUI in a real terminal (tmux): it starts on a pty bus, scans it and shows the motors."""

from __future__ import annotations

import shutil
import subprocess
import time
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core.emulator import EmulatorServer, build_bus_from_spec, serve_pty

ROOT = Path(__file__).resolve().parents[2]
POPPY = ROOT / ".venv" / "bin" / "poppy"
TMUX = shutil.which("tmux")

pytestmark = pytest.mark.skipif(TMUX is None or not POPPY.exists(), reason="needs tmux")


@pytest.fixture
def pty_server() -> Iterator[EmulatorServer]:
    """Three XL-320 (ids 1-3, protocol 2, 1 Mbps) on a pty: the TUI runs in another process."""
    with serve_pty(build_bus_from_spec("XL-320:1-3", protocol=2, baudrate=1_000_000)) as server:
        yield server


def capture(session: str) -> str:
    assert TMUX is not None
    return subprocess.run(
        [TMUX, "capture-pane", "-p", "-t", session], capture_output=True, text=True, check=False
    ).stdout


def wait_screen(session: str, text: str, timeout_s: float = 15.0) -> str:
    end = time.monotonic() + timeout_s
    screen = ""
    while time.monotonic() < end:
        screen = capture(session)
        if text in screen:
            return screen
        time.sleep(0.2)
    raise AssertionError(f"{text!r} never showed:\n{screen}")


def test_tui_in_tmux_shows_found_motors(pty_server: EmulatorServer) -> None:
    assert TMUX is not None
    session = f"poppy-{uuid.uuid4().hex[:8]}"
    command = f"{POPPY} tui --port {pty_server.url} --baud 1000000 --protocol 2"
    subprocess.run(
        [TMUX, "new-session", "-d", "-s", session, "-x", "100", "-y", "30", command], check=True
    )
    try:
        screen = wait_screen(session, "id 3")
        assert "id 1" in screen and "id 2" in screen and "XL-320" in screen
        subprocess.run([TMUX, "send-keys", "-t", session, "F3"], check=True)
        wait_screen(session, "goto")
        subprocess.run([TMUX, "send-keys", "-t", session, "q"], check=True)
        end = time.monotonic() + 5
        while time.monotonic() < end:
            alive = subprocess.run(
                [TMUX, "has-session", "-t", session], capture_output=True, check=False
            )
            if alive.returncode != 0:
                break
            time.sleep(0.1)
        assert alive.returncode != 0, "q did not quit"
    finally:
        subprocess.run([TMUX, "kill-session", "-t", session], capture_output=True, check=False)
