"""Sensors over REST: pypot's routes, frames as images, the MJPEG stream, cards (ideal Ergo Jr:
a blank camera and a marker detector)."""

from __future__ import annotations

import time

import httpx
import numpy as np
import pytest

from tests.helpers.server import Served
from tests.helpers.waiting import http_timeout

cv2 = pytest.importorskip("cv2")


def test_pypot_sensor_routes(client: httpx.Client) -> None:
    assert client.get("/sensors/list.json").json() == {"sensors": ["camera", "marker_detector"]}
    assert client.get("/sensors/camera/registers/list.json").json() == {
        "registers": ["frame", "resolution", "fps"]
    }
    assert client.get("/sensors/camera/registers/resolution/value.json").json() == {
        "resolution": [640, 480]
    }
    frame = client.get("/sensors/camera/registers/frame/value.json").json()["frame"]
    assert frame["shape"] == [480, 640, 3] and frame["png"] == "/sensors/camera/frame.png"
    markers = client.get("/sensors/marker_detector/registers/markers/value.json")
    assert markers.json() == {"markers": []}


def test_unknown_sensors_and_registers_are_404_in_pypots_shape(client: httpx.Client) -> None:
    for path in (
        "/sensors/lidar/registers/list.json",
        "/sensors/camera/registers/x/value.json",
        "/sensors/lidar/frame.png",
        "/sensors/camera/frame.gif",
    ):
        answer = client.get(path)
        assert answer.status_code == 404, path
        assert set(answer.json()) == {"error", "tip", "details"}
    refused = client.post("/sensors/camera/registers/fps/value.json", content="30")
    assert refused.status_code == 400 and "read-only" in refused.json()["error"]


@pytest.mark.parametrize(("ext", "kind"), [("png", "image/png"), ("jpg", "image/jpeg")])
def test_frames_are_images(client: httpx.Client, ext: str, kind: str) -> None:
    for path in (f"/sensors/camera/frame.{ext}", f"/api/v1/sensors/camera/frame.{ext}"):
        answer = client.get(path)
        assert answer.status_code == 200 and answer.headers["content-type"] == kind
        image = cv2.imdecode(np.frombuffer(answer.content, np.uint8), cv2.IMREAD_COLOR)
        assert image.shape == (480, 640, 3)


def test_cards(client: httpx.Client) -> None:
    assert client.get("/sensors/code/list.json").json() == {"codes": []}
    assert client.get("/sensors/code/caribou.json").json() == {"found": False}
    # pypot's name of lapin's card (its rest.py and snap.py list both, its demo project's menu
    # offers rabbit)
    assert client.get("/sensors/code/rabbit.json").json() == {"found": False}
    unknown = client.get("/sensors/code/nope.json")
    assert unknown.status_code == 404 and "caribou, tetris, lapin" in unknown.json()["tip"]
    assert client.get("/api/v1/markers/cards/lapin").json() == {"card": "lapin", "found": False}
    assert client.get("/api/v1/markers").json() == []


def test_v1_sensors_describe_and_report_health(client: httpx.Client) -> None:
    listed = client.get("/api/v1/sensors").json()
    assert [s["name"] for s in listed] == ["camera", "marker_detector"]
    assert listed[0]["type"] == "DummyCamera" and listed[0]["health"]["ok"] is True
    camera = client.get("/api/v1/sensors/camera").json()
    assert camera["registers"]["resolution"] == [640, 480]
    assert set(client.get("/api/v1/sensors/health").json()) == {"camera", "marker_detector"}
    assert client.get("/api/v1/sensors/lidar").status_code == 404
    paths = client.get("/openapi.json").json()["paths"]
    assert "/api/v1/sensors/{sensor}/stream.mjpg" in paths


def test_the_mjpeg_stream_sends_jpeg_parts(served: Served) -> None:
    with (
        httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as http,
        http.stream("GET", "/api/v1/sensors/camera/stream.mjpg", params={"fps": 30}) as answer,
    ):
        assert answer.status_code == 200
        assert answer.headers["content-type"] == "multipart/x-mixed-replace; boundary=frame"
        received = b""
        for chunk in answer.iter_bytes():
            received += chunk
            if received.count(b"--frame") >= 2:
                break
    first = received.split(b"--frame")[1]
    headers, _, body = first.partition(b"\r\n\r\n")
    assert b"Content-Type: image/jpeg" in headers
    assert body.startswith(b"\xff\xd8")  # a JPEG


def test_a_stream_of_no_camera_is_404(client: httpx.Client) -> None:
    assert client.get("/api/v1/sensors/marker_detector/stream.mjpg").status_code == 404


def test_the_mjpeg_stream_waits_between_tries_of_a_camera_failed_for_good(
    served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    from poppy_core.errors import SensorError
    from tests.helpers.waiting import eventually

    camera = next(s for s in served.robot.sensors if s.name == "camera")
    tries: list[int] = []

    async def failed_for_good(after: int = 0, timeout_s: float = 0.0) -> object:
        tries.append(after)
        raise SensorError("camera 'camera': unplugged for good", sensor="camera")

    monkeypatch.setattr(camera, "wait_frame", failed_for_good)
    with (
        httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as http,
        http.stream("GET", "/api/v1/sensors/camera/stream.mjpg", params={"fps": 30}) as answer,
    ):
        assert answer.status_code == 200
        assert eventually(lambda: len(tries) >= 2, 10.0)
        first = len(tries)
        time.sleep(1.0)  # a second with the stream open
        # a floor of 0.5 s between tries: 2 or 3 in that second (load can only make it fewer);
        # without one, thousands
        assert len(tries) - first <= 5
