"""`poppy tui --serve` serves the app to a browser on loopback (textual-serve)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request

from tests.helpers.cli import command_env
from tests.helpers.processes import start
from tests.helpers.waiting import scaled


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def test_tui_serve_answers_a_browser_on_loopback() -> None:
    port = _free_port()
    proc = start(
        [sys.executable, "-m", "poppy_cli", "tui", "--serve", "--sim", "--http-port", str(port)],
        dict(os.environ, **command_env()),
    )
    try:
        page = ""
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2) as answer:
                    assert answer.status == 200
                    page = answer.read().decode()
                    break
            except OSError:
                time.sleep(0.2)
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        assert "poppy" in page  # the page textual-serve builds for our app (title "poppy")
        # only loopback by default: nothing listens on the machine's other addresses
        listeners = subprocess.run(
            ["ss", "-ltnH", f"sport = :{port}"], capture_output=True, text=True, check=False
        ).stdout
        if listeners.strip():
            assert all("127.0.0.1:" in line for line in listeners.splitlines() if line.strip())
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=scaled(10))
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        for stream in (proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()
