"""The generated projects run in a real Snap! (headless Chromium) against a served virtual Ergo Jr.

Needs Debian's ``chromium`` and a Snap! copy: set ``POPPY_TEST_SNAP_DIR`` to the folder holding
``snap.html`` (unzipped from https://github.com/jmoenig/Snap/releases); skipped otherwise.
Snap! opens each project with ``snap.html#run:URL`` (open it and press the green flag); the test
watches the robot move as the scripts say.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core.creatures import from_profile
from poppy_core.motion import list_moves
from poppy_core.robot import Robot
from poppy_core.server.snap import SnapServer, start_snap_server
from tests.server.snap_helpers import near, wait_until

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
SNAP_DIR = os.environ.get("POPPY_TEST_SNAP_DIR", "")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None or not (Path(SNAP_DIR) / "snap.html").is_file(),
    reason="needs chromium and a Snap! copy in POPPY_TEST_SNAP_DIR",
)


@pytest.fixture
def served(moves_folder: str) -> Iterator[tuple[Robot, SnapServer]]:
    """A virtual Ergo Jr, Snap! served by its Snap! server (one origin)."""
    robot = from_profile("ergo-jr", sim=True)
    server = start_snap_server(robot, port=0, snap_dir=Path(SNAP_DIR))
    try:
        yield robot, server
    finally:
        server.stop()
        robot.close()


@pytest.fixture
def browser() -> Iterator[list[subprocess.Popen[bytes]]]:
    """Chromium processes started by a test, stopped after it."""
    started: list[subprocess.Popen[bytes]] = []
    yield started
    for proc in started:
        proc.terminate()
        proc.wait(timeout=20)
        shutil.rmtree(str(proc.args[-2]).removeprefix("--user-data-dir="), ignore_errors=True)


def run_project(server: SnapServer, name: str, started: list[subprocess.Popen[bytes]]) -> None:
    """Open project ``name`` in Snap! and press the green flag (``#run:``)."""
    assert CHROMIUM is not None
    url = f"{server.url}/app/snap.html#run:{server.url}/snap/{name}"
    profile = tempfile.mkdtemp(prefix="poppy-chromium-")
    args = [CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu"]
    args += [f"--user-data-dir={profile}", url]
    started.append(subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))


def test_first_steps_stiffens_lights_and_moves(
    served: tuple[Robot, SnapServer], browser: list[subprocess.Popen[bytes]]
) -> None:
    robot, server = served
    run_project(server, "first-steps", browser)
    assert wait_until(lambda: robot.m1.led == "green" and not robot.m1.compliant, 60)
    assert wait_until(lambda: near(robot.m1.present_position, 30, 3), 30)
    assert wait_until(lambda: near(robot.m1.present_position, -30, 3), 30)
    assert wait_until(lambda: robot.m1.led == "off", 30)


def test_record_replay_in_french_saves_the_move_in_the_library(
    served: tuple[Robot, SnapServer], browser: list[subprocess.Popen[bytes]]
) -> None:
    robot, server = served
    run_project(server, "record-replay-fr", browser)
    assert wait_until(lambda: robot.m1.compliant, 60)
    assert wait_until(lambda: "my-move" in [e.name for e in list_moves()], 60)
    assert wait_until(lambda: not robot.m1.compliant, 30)


def test_ik_drawing_moves_the_tip(
    served: tuple[Robot, SnapServer], browser: list[subprocess.Popen[bytes]]
) -> None:
    robot, server = served
    start = [float(v) for v in robot.chain.position]
    run_project(server, "ik-drawing", browser)
    assert wait_until(lambda: abs(float(robot.chain.position[0]) - start[0]) > 0.005, 60)
