"""Snap! served by the robot (headless Chromium) against a served virtual Ergo Jr.

Snap! gets to the robot as a user's does: `poppy snap download --from URL` from a loopback server,
then `/app/snap.html` served from the installed copy. A fake release (a snap.html whose script
opens the ``#open:`` blocks and calls one route) checks that path with Chromium alone; the
generated projects need a real Snap!: set ``POPPY_TEST_SNAP_DIR`` to the folder holding its
``snap.html`` (unzipped from https://github.com/jmoenig/Snap/releases), which the test packs and
downloads as a release; those tests are skipped without it. Snap! opens each project with
``snap.html#run:URL`` (open it and press the green flag); the test watches the robot move as
the scripts say.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import from_profile
from poppy_core.motion import list_moves
from poppy_core.robot import Robot
from poppy_core.server.snap import SnapServer, start_snap_server
from poppy_core.server.snap.release import installed, release_digest
from tests.helpers.cli import run_poppy
from tests.helpers.snap_release import Files, make_release, release_server, zip_folder
from tests.helpers.waiting import scaled
from tests.server.snap_helpers import near, wait_until

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
SNAP_DIR = os.environ.get("POPPY_TEST_SNAP_DIR", "")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="needs chromium")
needs_snap = pytest.mark.skipif(
    not (Path(SNAP_DIR) / "snap.html").is_file(),
    reason="the generated projects need a real Snap!: set POPPY_TEST_SNAP_DIR to its folder",
)


def download(folder: Path, version: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """`poppy snap download` of ``folder`` packed as a release on a loopback server; its copy."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    files = Files({"/snap.zip": zip_folder(folder, top=f"Snap-{version}")})
    with release_server(files) as base:
        args = ["snap", "download", version, "--from", f"{base}/snap.zip"]
        done = run_poppy(*args, "--sha256", release_digest(folder))
    assert done.code == 0, done.stderr
    copy = installed(version)
    assert copy is not None
    return copy.path


def serve_snap(robot: Robot, snap_dir: Path) -> SnapServer:
    return start_snap_server(robot, port=0, snap_dir=snap_dir)


@pytest.fixture
def served(
    moves_folder: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> Iterator[tuple[Robot, SnapServer]]:
    """A virtual Ergo Jr, the downloaded Snap! served by its Snap! server (one origin)."""
    snap_dir = download(Path(SNAP_DIR), "real", tmp_path, monkeypatch)
    robot = from_profile("ergo-jr", sim=True)
    server = serve_snap(robot, snap_dir)
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
        proc.wait(timeout=scaled(20))
        shutil.rmtree(str(proc.args[-2]).removeprefix("--user-data-dir="), ignore_errors=True)


def run_project(server: SnapServer, name: str, started: list[subprocess.Popen[bytes]]) -> None:
    """Open project ``name`` in Snap! and press the green flag (``#run:``)."""
    open_page(f"{server.url}/app/snap.html#run:{server.url}/snap/{name}", started)


def open_page(url: str, started: list[subprocess.Popen[bytes]]) -> None:
    """Open ``url`` in a headless Chromium of its own."""
    assert CHROMIUM is not None
    profile = tempfile.mkdtemp(prefix="poppy-chromium-")
    args = [CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu"]
    args += [f"--user-data-dir={profile}", url]
    started.append(subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))


def test_the_downloaded_snap_opens_the_poppy_blocks_and_moves_the_robot(
    moves_folder: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    browser: list[subprocess.Popen[bytes]],
) -> None:
    """The page's Snap! link (``editor_url``) on a downloaded (fake) release: the blocks load
    from ``#open:`` and a route they name moves m1."""
    fake = make_release(tmp_path / "release")
    snap_dir = download(fake.folder, fake.version, tmp_path, monkeypatch)
    with from_profile("ergo-jr", sim=True) as robot:
        server = serve_snap(robot, snap_dir)
        try:
            assert server.editor_url.startswith(f"{server.url}/app/snap.html#open:")
            assert robot.m1.compliant
            open_page(server.editor_url, browser)
            assert wait_until(lambda: not robot.m1.compliant, 60)
            assert wait_until(lambda: near(robot.m1.present_position, 25, 3), 30)
        finally:
            server.stop()


@needs_snap
def test_first_steps_stiffens_lights_and_moves(
    served: tuple[Robot, SnapServer], browser: list[subprocess.Popen[bytes]]
) -> None:
    robot, server = served
    run_project(server, "first-steps", browser)
    assert wait_until(lambda: robot.m1.led == "green" and not robot.m1.compliant, 60)
    assert wait_until(lambda: near(robot.m1.present_position, 30, 3), 30)
    assert wait_until(lambda: near(robot.m1.present_position, -30, 3), 30)
    assert wait_until(lambda: robot.m1.led == "off", 30)


@needs_snap
def test_record_replay_in_french_saves_the_move_in_the_library(
    served: tuple[Robot, SnapServer], browser: list[subprocess.Popen[bytes]]
) -> None:
    robot, server = served
    run_project(server, "record-replay-fr", browser)
    assert wait_until(lambda: robot.m1.compliant, 60)
    assert wait_until(lambda: "my-move" in [e.name for e in list_moves()], 60)
    assert wait_until(lambda: not robot.m1.compliant, 30)


@needs_snap
def test_ik_drawing_moves_the_tip(
    served: tuple[Robot, SnapServer], browser: list[subprocess.Popen[bytes]]
) -> None:
    robot, server = served
    start = [float(v) for v in robot.chain.position]
    run_project(server, "ik-drawing", browser)
    assert wait_until(lambda: abs(float(robot.chain.position[0]) - start[0]) > 0.005, 60)
