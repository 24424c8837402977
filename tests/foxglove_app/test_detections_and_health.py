"""Detections (markers, faces) as annotations over the camera's image, and health as log lines:
a camera showing an ArUco marker, recorded to MCAP and read back; health lines by level."""

from __future__ import annotations

import io
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

pytest.importorskip("foxglove")
pytest.importorskip("mcap_protobuf")
pytest.importorskip("cv2")

import foxglove
from foxglove.messages import LogLevel, PointsAnnotationType
from mcap.reader import make_reader
from mcap.records import Schema
from mcap_protobuf.decoder import DecoderFactory

from poppy_core.sensors.camera import DummyCamera
from poppy_core.sensors.detector import MarkerDetector
from poppy_core.sensors.faces import Face
from poppy_core.sensors.markers import marker_image
from poppy_core.server.foxglove import FoxglovePublisher
from poppy_core.server.foxglove.robot_messages import health_lines, image_annotations
from tests.helpers.waiting import eventually


class MarkerCamera(DummyCamera):
    """A camera looking at ArUco marker 7 on a white table."""

    def __init__(self) -> None:
        super().__init__("camera", (320, 240))
        frame = np.full((240, 320, 3), 255, dtype=np.uint8)
        marker = marker_image(7, size_px=120)
        frame[40 : 40 + marker.shape[0], 60 : 60 + marker.shape[1]] = marker[..., None]
        self._frame = frame

    def grab(self) -> np.ndarray:
        return self._frame


def decoded(message: Any) -> Any:
    """An SDK message as its protobuf (encoded, then decoded with its own schema)."""
    sdk = message.get_schema()
    schema = Schema(id=1, name=sdk.name, encoding=sdk.encoding, data=sdk.data)
    decode = DecoderFactory().decoder_for("protobuf", schema)
    assert decode is not None
    return decode(message.encode())


def robot_of(*sensors: Any) -> Any:
    """What the publisher reads of a robot: no motor, no model, these sensors."""
    return SimpleNamespace(
        motors=[],
        sensors=list(sensors),
        config=None,
        health=dict,
        sensor_health=lambda: {s.name: s.health() for s in sensors},
    )


def test_a_seen_marker_is_an_outline_and_its_id_over_the_image() -> None:
    camera = MarkerCamera()
    detector = MarkerDetector("marker_detector", [camera], 20.0)
    context = foxglove.Context()
    stream = io.BytesIO()
    publisher = FoxglovePublisher(robot_of(camera, detector), context, "jr1", state_rate_hz=20)
    writer = foxglove.open_mcap(stream, context=context)
    try:
        detector.start()
        publisher.start()
        assert eventually(lambda: bool(detector.found()), 20.0)
        assert eventually(lambda: publisher._detected.get("camera", (0, []))[1] != [], 20.0)
    finally:
        publisher.close()
        writer.close()
        detector.close()
        camera.close()
    stream.seek(0)
    reader = make_reader(stream)
    annotations = []
    for schema, channel, message in reader.iter_messages():
        if channel.topic == "/camera/detections":
            decode = DecoderFactory().decoder_for(channel.message_encoding, schema)
            assert decode is not None
            annotations.append(decode(message.data))
    seen = [a for a in annotations if a.points]
    assert seen, "no annotation of the marker"
    [outline] = seen[-1].points
    assert outline.type == PointsAnnotationType.LineLoop.value
    xs = [p.x for p in outline.points]
    ys = [p.y for p in outline.points]
    assert len(outline.points) == 4
    assert min(xs) >= 60 and max(xs) <= 210 and min(ys) >= 40 and max(ys) <= 190
    assert [t.text for t in seen[-1].texts] == ["aruco 7"]


def test_a_face_is_its_box() -> None:
    face = Face(rect=(10, 20, 30, 30), center=(25.0, 35.0), position=(0.0, 0.0), camera="c")
    annotations = decoded(image_annotations([face], 1_800_000_000.0))
    [box] = annotations.points
    assert [(p.x, p.y) for p in box.points] == [(10, 20), (40, 20), (40, 50), (10, 50)]
    assert [t.text for t in annotations.texts] == ["face"]


def test_health_lines_say_each_part_at_its_level() -> None:
    buses = {
        "a": {"label": "ttyUSB0", "connected": False, "offline": []},
        "b": {"label": "ttyUSB1", "connected": True, "offline": ["m3"]},
        "c": {"label": "ttyUSB2", "connected": True, "offline": []},
    }
    sensors = {"camera": {"ok": False, "last_error": "unplugged"}, "imu": {"ok": True}}
    lines = {line.text: line.level for line in health_lines(buses, sensors)}
    assert lines == {
        "bus ttyUSB0: disconnected": LogLevel.Error,
        "bus ttyUSB1: offline motors: m3": LogLevel.Warning,
        "bus ttyUSB2: ok": LogLevel.Info,
        "sensor camera: unplugged": LogLevel.Warning,
        "sensor imu: ok": LogLevel.Info,
    }


def test_the_state_loop_survives_a_tick_that_raises() -> None:
    """Health that fails three times (a bus driver's bug) is logged and retried with backoff:
    the loop goes on publishing joint states."""
    failures = iter([True, True, True])

    def health() -> dict[str, Any]:
        if next(failures, False):
            raise RuntimeError("the bus's health broke")
        return {}

    robot = robot_of()
    robot.health = health
    context = foxglove.Context()
    stream = io.BytesIO()
    publisher = FoxglovePublisher(robot, context, "jr1", state_rate_hz=50)
    writer = foxglove.open_mcap(stream, context=context)
    try:
        publisher.start()
        assert eventually(lambda: publisher.state_loop.failures >= 3, 30.0)
        published = publisher.published
        assert eventually(lambda: publisher.published > published + 5, 30.0)
        assert publisher.running and not publisher.state_loop.failing
    finally:
        publisher.close()
        writer.close()


class NotLookedYet(MarkerDetector):
    """A detector started whose first look has not come (its camera is slow to open): reading
    what it found would wait for it."""

    @property
    def running(self) -> bool:
        return True

    def health(self) -> Any:
        return replace(super().health(), age_s=None)

    def found(self) -> list[Any]:
        raise AssertionError("the state loop waited for a detector's first look")


def test_a_detector_that_has_not_looked_yet_holds_no_joint_state_back() -> None:
    camera = DummyCamera("camera", (64, 48))
    detector = NotLookedYet("marker_detector", [camera], 5.0)
    context = foxglove.Context()
    stream = io.BytesIO()
    publisher = FoxglovePublisher(robot_of(camera, detector), context, "jr1", state_rate_hz=50)
    writer = foxglove.open_mcap(stream, context=context)
    try:
        publisher.start()
        assert eventually(lambda: publisher.published >= 20, 30.0)
        assert publisher.running and publisher.state_loop.failures == 0
    finally:
        publisher.close()
        writer.close()
        camera.close()
