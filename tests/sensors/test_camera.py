"""OpenCV cameras on a video file (a stand-in device), missing devices, a camera lost and back."""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from poppy_core.errors import SensorError
from poppy_core.sensors import DummyCamera, MarkerDetector, build_sensors, opencv_camera
from poppy_core.sensors.opencv_capture import OpenCVCamera, list_devices
from tests.helpers.configs import checked_sensors
from tests.helpers.waiting import eventually

cv2 = pytest.importorskip("cv2")


def test_a_video_file_is_a_camera(video_file: Path) -> None:
    with OpenCVCamera("camera", str(video_file), fps=50.0) as camera:
        assert camera.registers == ("frame", "resolution", "fps", "index")
        first = camera.latest()
        later = camera.next_frame(first.number + 3)
        assert first.image.shape == (120, 160, 3)
        assert camera.resolution == [160, 120]
        assert camera.fps == 50.0
        assert later.number > first.number
        frame = camera.frame
        frame[:] = 0  # a copy: drawing on it leaves the camera's frame alone
        assert camera.latest().image.flags.writeable is False


def test_frames_follow_the_video_and_loop(video_file: Path) -> None:
    with OpenCVCamera("camera", str(video_file), fps=100.0) as camera:
        seen = []
        number = 0
        for _ in range(30):
            frame = camera.next_frame(number)
            number = frame.number
            seen.append(round(float(frame.image.mean()) / 10))
        assert seen[:12] == sorted(seen[:12]) or 0 in seen[1:]  # rising, then back to 0
        assert max(seen) == 11 and seen.count(0) >= 2


def test_a_resolution_is_applied_to_a_file(video_file: Path) -> None:
    with OpenCVCamera("camera", str(video_file), resolution=(80, 60)) as camera:
        assert camera.latest().image.shape == (60, 80, 3)


@pytest.mark.parametrize(
    ("source", "words"),
    [
        ("/dev/video99", "/dev/video99 does not exist: plug the camera in"),
        (97, "/dev/video97 does not exist"),
        ("/nonexistent/clip.avi", "/nonexistent/clip.avi does not exist"),
    ],
)
def test_a_missing_device_is_one_line(source: Any, words: str) -> None:
    with pytest.raises(SensorError) as caught:
        OpenCVCamera("camera", source)
    message = str(caught.value)
    assert words in message and "\n" not in message
    assert message.startswith("camera 'camera': ")


def test_a_file_that_is_no_video_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "notes.avi"
    path.write_text("not a video")
    with pytest.raises(SensorError, match="OpenCV cannot read"):
        OpenCVCamera("camera", str(path))


class Unpluggable:
    """A real ``cv2.VideoCapture`` on the video file, with a cable to pull (same interface)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.plugged = threading.Event()
        self.plugged.set()
        self.opened = 0

    def __call__(self, source: Any) -> Any:
        cable = self

        class Capture:
            def __init__(self) -> None:
                self.inner = cv2.VideoCapture(str(cable.path))
                cable.opened += 1

            def isOpened(self) -> bool:
                return cable.plugged.is_set() and bool(self.inner.isOpened())

            def read(self) -> tuple[bool, Any]:
                if not cable.plugged.is_set():
                    return False, None
                return self.inner.read()

            def set(self, prop: int, value: float) -> bool:
                return bool(self.inner.set(prop, value))

            def release(self) -> None:
                self.inner.release()

        return Capture()


def test_a_lost_camera_warns_once_shows_in_health_and_resumes(
    video_file: Path, caplog: pytest.LogCaptureFixture
) -> None:
    cable = Unpluggable(video_file)
    with OpenCVCamera("camera", "/dev/video0", fps=50.0, opener=cable) as camera:
        before = camera.latest()
        assert camera.health().ok
        with caplog.at_level(logging.WARNING, logger="poppy_core.sensors"):
            cable.plugged.clear()
            deadline = time.monotonic() + 10
            while camera.health().connected and time.monotonic() < deadline:
                time.sleep(0.02)
            health = camera.health()
            assert not health.connected and not health.ok and health.losses == 1
            assert "gave no frame" in health.last_error
            time.sleep(0.8)  # several reconnection attempts fail meanwhile
            lost = [r for r in caplog.records if "lost" in r.getMessage()]
            assert len(lost) == 1
            assert camera.latest().number >= before.number  # the last frame is still there
            cable.plugged.set()
            resumed = camera.next_frame(camera.latest().number, timeout_s=10)
        assert resumed.number > before.number
        health = camera.health()
        assert health.connected and health.losses == 1 and health.as_dict()["ok"] is True
        assert any("is back" in r.getMessage() for r in caplog.records)
        assert cable.opened >= 2


def test_a_marker_detector_is_lost_while_its_camera_is_and_back_with_it(
    video_file: Path,
) -> None:
    cable = Unpluggable(video_file)
    with (
        OpenCVCamera("camera", "/dev/video0", fps=50.0, opener=cable) as camera,
        MarkerDetector("marker_detector", [camera], 20.0) as detector,
    ):
        assert detector.markers == [] and detector.health().ok
        cable.plugged.clear()
        assert eventually(lambda: not camera.health().connected, timeout_s=10)
        health = detector.health()
        assert not health.connected and not health.ok and health.running
        assert health.last_error.startswith("camera 'camera' lost: ")
        assert "gave no frame" in health.last_error
        assert health.as_dict()["ok"] is False
        cable.plugged.set()
        assert eventually(lambda: detector.health().ok, timeout_s=10)
        assert camera.health().connected and detector.markers == []


def test_dummy_camera_gives_black_frames() -> None:
    with DummyCamera("camera", (64, 48), fps=30) as camera:
        assert camera.frame.shape == (48, 64, 3)
        assert not camera.frame.any()
        assert camera.read("resolution") == [64, 48]
        with pytest.raises(SensorError, match="no register 'exposure'"):
            camera.read("exposure")


def test_a_sensor_starts_on_first_use_and_closes() -> None:
    camera = DummyCamera("camera", (32, 24))
    assert not camera.running and camera.health().age_s is None
    camera.latest()
    assert camera.running
    camera.close()
    assert not camera.running and camera.closed
    with pytest.raises(SensorError, match="closed"):
        camera.start()


def test_sections_build_cameras_from_files(video_file: Path) -> None:
    section = {
        "camera": {"type": "OpenCVCamera", "index": str(video_file), "fps": 30.0},
        "marker_detector": {"type": "MarkerDetector", "cameras": ["camera"], "freq": 10.0},
    }
    sensors = build_sensors(checked_sensors(section), opencv_camera)
    try:
        assert list(sensors) == ["camera", "marker_detector"]
        assert sensors["marker_detector"].read("markers") == []
    finally:
        for sensor in sensors.values():
            sensor.close()


def test_list_devices_reads_sysfs(tmp_path: Path) -> None:
    for index, name in ((2, "USB Camera: metadata"), (0, "USB Camera")):
        folder = tmp_path / f"video{index}"
        folder.mkdir()
        (folder / "name").write_text(name + "\n")
    assert list_devices(str(tmp_path)) == [
        {"device": "/dev/video0", "index": 0, "name": "USB Camera"},
        {"device": "/dev/video2", "index": 2, "name": "USB Camera: metadata"},
    ]
    assert list_devices(str(tmp_path / "none")) == []


def test_the_packages_camera_maker_stays_a_function_once_the_camera_module_is_loaded() -> None:
    # A submodule named like a name of its package replaces that name once imported: the
    # module that opens OpenCV devices is not called `opencv_camera`, the package's maker is.
    import poppy_core.sensors as sensors
    import poppy_core.sensors.opencv_capture  # noqa: F401

    assert callable(sensors.opencv_camera)
    assert sensors.opencv_camera is opencv_camera
