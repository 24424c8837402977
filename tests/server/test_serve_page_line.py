"""``poppy serve --sim`` prints the robot's page (with its 3D view) after its other lines."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import httpx

from tests.helpers.cli import command_env
from tests.helpers.processes import reap
from tests.helpers.waiting import http_timeout

POPPY = [sys.executable, "-m", "poppy_cli"]
WAIT_S = 60.0


def test_serve_sim_prints_the_page_with_the_3d_view() -> None:
    env = dict(os.environ, **command_env({"COLUMNS": "300"}))
    command = [*POPPY, "serve", "--http", "--http-port", "0", "--sim", "--profile", "ergo-jr"]
    proc = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    try:
        assert proc.stdout is not None
        lines = [proc.stdout.readline().strip() for _ in range(3)]
        assert lines[0].startswith("http://127.0.0.1:") and lines[1].startswith("docs: ")
        assert lines[2] == f"page: {lines[0]}/ (with the 3D view)"
        with httpx.Client(timeout=http_timeout(10.0)) as client:
            assert 'id="view3d"' in client.get(f"{lines[0]}/").text
            assert client.get(f"{lines[0]}/api/v1/model").status_code == 200
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=WAIT_S) == 0
    finally:
        reap(proc)
