"""The ROS 2 node publishes a camera while it runs and never starts it.

Before, the node's camera loop checked ``running``, then read with ``next_frame()``, which
starts the camera: a camera stopped between the two was opened again by the node.
"""

from __future__ import annotations

import threading
from types import SimpleNamespace

import pytest

from poppy_core.errors import SensorError
from poppy_core.sensors.camera import DummyCamera

pytest.importorskip("rosbags")

from poppy_core.server.ros2.node import Ros2Node


class StoppedAfterTheCheck(DummyCamera):
    """A camera the node finds running, then stopped before it reads (the user's stop landed
    between the two); its second check ends the node's loop."""

    def __init__(self, stopping: threading.Event) -> None:
        super().__init__("camera")
        self.stopping = stopping
        self.checks = 0
        self.grabs = 0

    @property
    def running(self) -> bool:
        self.checks += 1
        if self.checks > 1:
            self.stopping.set()
        return self.checks == 1

    def grab(self) -> object:
        self.grabs += 1
        return super().grab()


def test_the_node_does_not_start_a_camera_stopped_after_its_check() -> None:
    stopping = threading.Event()
    camera = StoppedAfterTheCheck(stopping)
    published: list[bytes] = []
    node = SimpleNamespace(
        _cameras=lambda: [camera], _publishers={"camera": SimpleNamespace(put=published.append)}
    )
    try:
        Ros2Node._camera_loop(node, stopping)  # type: ignore[arg-type]
        assert camera.grabs == 0 and published == []
        assert camera._thread is None  # never started
    finally:
        camera.close()


def test_next_frame_without_start_refuses_a_camera_not_running() -> None:
    camera = DummyCamera("camera")
    try:
        with pytest.raises(SensorError, match="not running"):
            camera.next_frame(start=False)
        assert not camera.running
        assert camera.next_frame().number >= 1  # a reader that may start it does
        assert camera.next_frame(after=-1, start=False).number >= 2
    finally:
        camera.close()
