"""A robot whose camera is unplugged or busy starts: the camera is lost, then opened when it can."""

from __future__ import annotations

import json
import logging
import os
import shutil
import signal
import subprocess
import sys
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import from_config, from_profile
from poppy_core.pypot import PoppyErgoJr
from poppy_core.robot import Robot, RobotConfig, load_profile, with_ports
from poppy_core.sensors import Camera
from poppy_core.sensors.opencv_capture import OpenCVCamera
from tests.helpers.bus import emulate_bus
from tests.helpers.cli import command_env
from tests.helpers.waiting import eventually, http_timeout, scaled
from tests.sensors.test_camera import Unpluggable

cv2 = pytest.importorskip("cv2")


@pytest.fixture
def ergo_url() -> Iterator[str]:
    """An emulated Ergo Jr bus (six XL-320) on the in-process link."""
    with emulate_bus("XL-320:1-6") as (_bus, url):
        yield url


def camera_warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [
        r.getMessage()
        for r in caplog.records
        if r.levelno >= logging.WARNING and "camera" in r.getMessage()
    ]


def plug_in(video: Path, device: Path) -> None:
    """The device appears at once, whole (a copy renamed into place)."""
    part = device.with_suffix(".part")
    shutil.copyfile(video, part)
    os.replace(part, device)


def ergo_jr_on(url: str, device: Path) -> Robot:
    data = with_ports(load_profile("ergo-jr"), url).to_dict()
    data["sensors"]["camera"]["index"] = str(device)
    return from_config(RobotConfig.from_dict(data, source="test"), fix_return_delay=True)


def test_a_robot_whose_camera_is_missing_starts_and_opens_it_when_plugged(
    ergo_url: str, video_file: Path, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    device = tmp_path / "video0.avi"
    with caplog.at_level(logging.WARNING), ergo_jr_on(ergo_url, device) as robot:
        health = robot.sensor_health()["camera"]
        assert not health.connected and not health.ok
        assert f"{device} does not exist" in health.last_error
        detector = robot.sensor_health()["marker_detector"]  # blind while its camera is lost
        assert not detector.ok and f"camera 'camera' lost: {device} does not exist" in (
            detector.last_error
        )
        robot.m1.compliant = False  # the motors work meanwhile
        (warning,) = camera_warnings(caplog)
        assert "is not available" in warning and str(device) in warning
        plug_in(video_file, device)
        assert eventually(lambda: robot.sensor_health()["camera"].connected, timeout_s=20)
        assert robot.sensor_health()["marker_detector"].ok  # back with its camera
        camera = robot.sensor("camera")
        assert isinstance(camera, Camera)
        first = camera.latest()
        assert first.image.shape == (480, 640, 3)  # the profile's resolution, asked of the file
        assert camera.next_frame(first.number).number > first.number  # frames flow
        assert robot.marker_detector.markers == []
        assert len(camera_warnings(caplog)) == 2  # lost at start, then back
        assert "is back" in camera_warnings(caplog)[1]


def test_a_camera_back_before_first_use_grabs_nothing_until_read(
    video_file: Path, caplog: pytest.LogCaptureFixture
) -> None:
    cable = Unpluggable(video_file)
    cable.plugged.clear()  # busy in another program: it exists but does not open
    with caplog.at_level(logging.WARNING, logger="poppy_core.sensors"):
        camera = OpenCVCamera("camera", "/dev/null", 50.0, opener=cable, retry_open=True)
    with camera:
        assert not camera.health().connected
        assert "another program" in camera.health().last_error
        cable.plugged.set()  # the other program let go
        assert eventually(lambda: camera.health().connected and not camera.running)
        assert camera.health().age_s is None  # reopened, but nothing read: nothing grabbed
        assert camera.next_frame(0).number >= 1 and camera.running
    assert len(camera_warnings(caplog)) == 2


def test_a_missing_camera_read_says_why_in_one_line(tmp_path: Path) -> None:
    device = tmp_path / "none.avi"
    with OpenCVCamera("camera", str(device), retry_open=True) as camera:
        with pytest.raises(Exception, match="does not exist") as caught:
            camera.latest(timeout_s=0.5)
        assert "\n" not in str(caught.value)


def test_the_profile_camera_unplugged_starts_the_robot_and_the_creature(
    ergo_url: str, caplog: pytest.LogCaptureFixture
) -> None:
    if os.path.exists("/dev/video0"):
        pytest.skip("this machine has a /dev/video0: the profile's camera is plugged in")
    with caplog.at_level(logging.WARNING):
        with from_profile("ergo-jr", port=ergo_url, fix_return_delay=True) as robot:
            assert not robot.sensor_health()["camera"].connected
        robot = PoppyErgoJr(port=ergo_url)
        try:
            assert not robot.sensor_health()["camera"].connected
            assert "marker_follow" in [p.name for p in robot.primitives]
        finally:
            robot.close()
    assert all("/dev/video0 does not exist" in w for w in camera_warnings(caplog))
    assert len(camera_warnings(caplog)) == 2  # one per robot


def test_poppy_serve_starts_without_its_camera_and_the_page_says_so(tmp_path: Path) -> None:
    if os.path.exists("/dev/video0"):
        pytest.skip("this machine has a /dev/video0: the profile's camera is plugged in")
    env = dict(os.environ, **command_env(), POPPY_MOVES_DIR=str(tmp_path))
    with emulate_bus("XL-320:1-6", via="tcp") as (_bus, url):
        args = ["serve", "--http", "--http-port", "0", "--profile", "ergo-jr", "--port", url]
        proc = subprocess.Popen(
            [sys.executable, "-m", "poppy_cli", *args],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            assert proc.stdout is not None
            http_url = proc.stdout.readline().strip()
            assert http_url.startswith("http://127.0.0.1:"), proc.communicate(timeout=scaled(30))
            with urllib.request.urlopen(f"{http_url}/api/v1/web/about", timeout=20) as answer:
                sensors = json.load(answer)["sensors"]
            camera, detector = sensors["camera"], sensors["marker_detector"]
            assert camera["connected"] is False and camera["ok"] is False
            assert "/dev/video0 does not exist" in camera["last_error"]
            assert detector["ok"] is False and "camera 'camera' lost" in detector["last_error"]
            with urllib.request.urlopen(f"{http_url}/motors/list.json", timeout=20) as answer:
                assert json.load(answer)["motors"] == [f"m{i}" for i in range(1, 7)]
        finally:
            proc.send_signal(signal.SIGTERM)
            _, err = proc.communicate(timeout=scaled(60))
    assert proc.returncode == 0, err
    lines = [line for line in err.splitlines() if "camera" in line]
    assert len(lines) == 1 and "is not available" in lines[0], err


def test_the_mjpeg_stream_of_an_absent_camera_is_503_at_once(
    ergo_url: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import httpx

    from tests.helpers.server import serve_robot

    device = tmp_path / "video0.avi"  # never plugged in
    robot = ergo_jr_on(ergo_url, device)
    camera = robot.sensor("camera")
    assert isinstance(camera, Camera)
    # were the stream to wait for a first frame, it would wait a minute: longer than the client
    monkeypatch.setattr(camera, "latest", lambda timeout_s=60.0: Camera.latest(camera, 60.0))
    served = serve_robot(robot)
    url = next(served).url
    try:
        with httpx.Client(base_url=url, timeout=http_timeout(30.0)) as http:
            answer = http.get("/api/v1/sensors/camera/stream.mjpg")
        assert answer.status_code == 503, answer.text
        detail = answer.json()["detail"]
        assert "not available" in detail and "does not exist" in detail and "\n" not in detail
    finally:
        served.close()
