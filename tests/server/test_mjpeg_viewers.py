"""Many MJPEG viewers at once: one JPEG per frame for all of them, no thread of the pool held
per viewer (a REST call still answers while they wait or watch), a viewer that leaves is
released and ends no other viewer's stream."""

from __future__ import annotations

import asyncio
import threading
from collections.abc import AsyncIterator, Iterator
from types import SimpleNamespace
from typing import Any, cast
from urllib.parse import urlsplit

import httpx
import pytest

from poppy_core.errors import SensorError
from poppy_core.sensors import DummyCamera
from poppy_core.server.routers import v1_sensors
from poppy_core.server.sensors import SensorService
from tests.helpers.server import Served
from tests.helpers.waiting import eventually, http_timeout

cv2 = pytest.importorskip("cv2")

STREAM = "/api/v1/sensors/camera/stream.mjpg"
POOL = 40
"""The threads of the pool the routes run blocking work in (Starlette's default limit)."""


async def open_viewer(url: str, fps: float) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    """A viewer of the stream that has read the headers of its first JPEG part."""
    reader, writer = await ask_stream(url, fps)
    await asyncio.wait_for(reader.readuntil(b"Content-Type: image/jpeg"), 60.0)
    return reader, writer


async def ask_stream(url: str, fps: float) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    """A viewer that has asked for the stream (read nothing yet)."""
    where = urlsplit(url)
    reader, writer = await asyncio.open_connection(where.hostname, where.port)
    writer.write(f"GET {STREAM}?fps={fps:g} HTTP/1.1\r\nHost: {where.netloc}\r\n\r\n".encode())
    await writer.drain()
    return reader, writer


async def count_parts(reader: asyncio.StreamReader, parts: int) -> int:
    """Read until ``parts`` more JPEG parts came; how many bytes that took."""
    read = 0
    for _ in range(parts):
        chunk = await asyncio.wait_for(reader.readuntil(b"Content-Type: image/jpeg"), 60.0)
        read += len(chunk)
    return read


@pytest.fixture
def frozen(served: Served, monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """The served camera with its thread stuck in ``grab``: no new frame until the test ends."""
    camera = next(s for s in served.robot.sensors if s.name == "camera")
    camera.latest(30.0)
    stuck = threading.Event()
    release = threading.Event()
    black = camera.grab()

    def grab() -> Any:
        stuck.set()
        release.wait(120.0)
        return black

    monkeypatch.setattr(camera, "grab", grab)
    assert stuck.wait(30.0)
    try:
        yield camera
    finally:
        release.set()


def test_many_viewers_share_one_jpeg_per_frame(
    served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    encodes: list[int] = []
    real = cv2.imencode

    def spy(ext: str, image: Any, params: Any = ()) -> Any:
        encodes.append(1)
        return real(ext, image, params)

    viewers = 12

    async def watch() -> int:
        opened = await asyncio.gather(*(open_viewer(served.url, 60) for _ in range(viewers)))
        monkeypatch.setattr(cv2, "imencode", spy)
        await asyncio.gather(*(count_parts(reader, 5) for reader, _ in opened))
        monkeypatch.setattr(cv2, "imencode", real)
        for _, writer in opened:
            writer.close()
        return viewers * 5

    parts = asyncio.run(watch())
    # each frame is encoded once for all the viewers waiting for it (a viewer that misses a
    # frame under load only makes fewer parts); one encoding per part would be 60 here
    assert 0 < len(encodes) <= parts // 3


def test_viewers_waiting_for_frames_hold_no_thread_of_the_pool(
    served: Served, frozen: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(v1_sensors, "FRAME_WAIT_S", 90.0)  # each waits for the next frame long
    viewers = POOL + 10

    async def scenario() -> tuple[int, int]:
        opened = await asyncio.gather(*(open_viewer(served.url, 15) for _ in range(viewers)))
        async with httpx.AsyncClient(base_url=served.url, timeout=http_timeout(30.0)) as http:
            # both run in the pool: with a thread held per viewer they would wait 90 s
            described = await http.get("/api/v1/sensors/camera")
            snapshot = await http.get("/api/v1/sensors/camera/frame.jpg")
        for _, writer in opened:
            writer.close()
        return described.status_code, len(snapshot.content) if snapshot.is_success else 0

    status, jpeg = asyncio.run(scenario())
    assert status == 200 and jpeg > 0


def test_a_viewer_that_leaves_is_released(served: Served, frozen: Any) -> None:
    viewers = 5

    async def scenario() -> tuple[bool, bool]:
        opened = await asyncio.gather(*(open_viewer(served.url, 15) for _ in range(viewers)))
        all_wait = await asyncio.to_thread(
            eventually, lambda: frozen.async_waiters() == viewers, 30.0
        )
        for _, writer in opened:
            writer.close()
        # released while the camera still gives no frame: the stream was cancelled, not
        # woken by a frame or its 5 s wait
        gone = await asyncio.to_thread(eventually, lambda: frozen.async_waiters() == 0, 30.0)
        return all_wait, gone

    assert asyncio.run(scenario()) == (True, True)


def test_many_viewers_of_a_live_camera_get_parts_while_rest_calls_answer(served: Served) -> None:
    viewers = POOL + 10

    async def scenario() -> tuple[list[int], list[int]]:
        opened = await asyncio.gather(*(open_viewer(served.url, 15) for _ in range(viewers)))
        async with httpx.AsyncClient(base_url=served.url, timeout=http_timeout(30.0)) as http:
            watched = asyncio.gather(*(count_parts(reader, 3) for reader, _ in opened))
            answers = [
                await http.get("/api/v1/sensors/camera"),
                await http.get("/api/v1/motors"),
                await http.get("/api/v1/sensors/camera/frame.jpg"),
            ]
            read = await watched
        for _, writer in opened:
            writer.close()
        return read, [a.status_code for a in answers]

    read, statuses = asyncio.run(scenario())
    assert len(read) == viewers and all(n > 0 for n in read)
    assert statuses == [200, 200, 200]


def test_a_viewer_leaving_while_its_frame_is_encoded_ends_no_other_stream(
    served: Served, frozen: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the flake of stop 34 (a stream's headers, then its end before the first part): a viewer
    # that left while awaiting another's encoding cancelled that shared encoding, so every
    # reader of the frame (a frozen camera: every later viewer) got a cancelled one
    monkeypatch.setattr(v1_sensors, "MJPEG_QUALITY", 79)  # a quality no test encoded yet
    entered = threading.Event()
    go = threading.Event()
    real_encode = frozen.encode

    def held_encode(image: Any, ext: str, quality: int) -> bytes:
        entered.set()
        assert go.wait(120.0)
        return bytes(real_encode(image, ext, quality))

    asked: list[int] = []
    cancelled: list[int] = []
    real_encoded_async = frozen.encoded_async

    async def counted(*args: Any, **kwargs: Any) -> bytes:
        asked.append(1)
        try:
            return bytes(await real_encoded_async(*args, **kwargs))
        except asyncio.CancelledError:
            cancelled.append(1)
            raise

    monkeypatch.setattr(frozen, "encode", held_encode)
    monkeypatch.setattr(frozen, "encoded_async", counted)

    async def scenario() -> tuple[bool, bool, int, int]:
        first, first_writer = await ask_stream(served.url, 15)  # it encodes the frame (held)
        assert await asyncio.to_thread(entered.wait, 60.0)
        _, leaving = await ask_stream(served.url, 15)  # it awaits that encoding, then leaves
        asked_both = await asyncio.to_thread(eventually, lambda: len(asked) == 2, 30.0)
        leaving.close()
        left = await asyncio.to_thread(eventually, lambda: len(cancelled) == 1, 30.0)
        go.set()
        await asyncio.wait_for(first.readuntil(b"Content-Type: image/jpeg"), 60.0)
        later, writer = await open_viewer(served.url, 15)  # the same frame, asked afresh
        jpeg = await asyncio.wait_for(later.readuntil(b"\xff\xd9"), 60.0)
        writer.close()
        first_writer.close()
        return asked_both, left, len(jpeg), len(cancelled)

    asked_both, left, jpeg, leavers = asyncio.run(scenario())
    assert asked_both and left and jpeg > 0 and leavers == 1


def test_the_viewers_the_snapshots_ros2_and_foxglove_share_one_encoding_of_a_frame() -> None:
    calls: list[tuple[str, int]] = []

    class Counted(DummyCamera):
        def encode(self, image: Any, ext: str, quality: int) -> bytes:
            calls.append((ext, quality))
            return super().encode(image, ext, quality)

    camera = Counted("camera", (64, 48))
    camera.update()
    frame = camera.latest()
    snapshot = SensorService(cast(Any, SimpleNamespace(sensors=[camera]))).image("camera", "jpg")
    viewer = asyncio.run(camera.encoded_async(frame, ".jpg", v1_sensors.MJPEG_QUALITY))
    published = camera.encoded(frame, ".jpg")  # what ROS 2 and Foxglove ask
    assert snapshot == viewer == published and snapshot.startswith(b"\xff\xd8")
    assert len(calls) == 1


def test_a_viewer_of_a_lost_camera_that_leaves_is_released(
    served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    camera = next(s for s in served.robot.sensors if s.name == "camera")
    tries: list[int] = []
    ended: list[bool] = []

    async def lost(after: int = 0, timeout_s: float = 0.0) -> Any:
        tries.append(after)
        raise SensorError("camera 'camera' gave no new frame in 5 s", sensor="camera")

    real_mjpeg = v1_sensors.mjpeg

    async def watched(*args: Any) -> AsyncIterator[bytes]:
        try:
            async for part in real_mjpeg(*args):
                yield part
        finally:
            ended.append(True)

    monkeypatch.setattr(camera, "wait_frame", lost)
    monkeypatch.setattr(v1_sensors, "mjpeg", watched)

    async def scenario() -> tuple[bool, bool]:
        _, writer = await ask_stream(served.url, 15)
        waiting = await asyncio.to_thread(eventually, lambda: len(tries) >= 2, 30.0)
        writer.close()  # no part was sent meanwhile: the stream notices the client left
        released = await asyncio.to_thread(eventually, lambda: ended == [True], 30.0)
        return waiting, released

    assert asyncio.run(scenario()) == (True, True)
