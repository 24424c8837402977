"""A camera's frames encoded once for all their readers (threads and coroutines), and awaited
in an event loop without a thread."""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
from typing import Any

import pytest

from poppy_core.errors import SensorError
from poppy_core.sensors import DummyCamera

cv2 = pytest.importorskip("cv2")


@pytest.fixture
def encodes(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, int]]:
    """Every ``cv2.imencode`` made, as (format, JPEG quality or 0)."""
    made: list[tuple[str, int]] = []
    real = cv2.imencode

    def spy(ext: str, image: Any, params: Any = ()) -> Any:
        made.append((ext, int(params[1]) if len(params) else 0))
        return real(ext, image, params)

    monkeypatch.setattr(cv2, "imencode", spy)
    return made


def test_many_readers_of_a_frame_share_one_encoding(encodes: list[tuple[str, int]]) -> None:
    camera = DummyCamera("camera", (64, 48))
    camera.update()  # frame 1, by hand: no thread, so no frame comes meanwhile
    first = camera.latest()
    results: list[bytes] = []
    go = threading.Barrier(16)

    def read() -> None:
        go.wait()
        results.append(camera.encoded(first, ".jpg", 80))

    readers = [threading.Thread(target=read) for _ in range(16)]
    for reader in readers:
        reader.start()
    for reader in readers:
        reader.join(30)

    async def many() -> list[bytes]:
        return await asyncio.gather(*(camera.encoded_async(first, ".jpg", 80) for _ in range(50)))

    results += asyncio.run(many())
    assert len(results) == 66 and len(set(results)) == 1 and results[0].startswith(b"\xff\xd8")
    assert encodes == [(".jpg", 80)]
    camera.encoded(first, ".jpg", 50)  # another quality: its own encoding, once
    camera.encoded(first, ".jpg", 50)
    camera.encoded(first, ".png")
    assert encodes == [(".jpg", 80), (".jpg", 50), (".png", 0)]
    camera.update()  # frame 2: encoded again, once
    second = camera.latest()
    assert camera.encoded(second, ".jpg", 80) == camera.encoded(second, ".jpg", 80)
    camera.encoded(first, ".jpg", 80)  # an older frame still encodes (for its reader alone)
    assert encodes[3:] == [(".jpg", 80), (".jpg", 80)]


def test_a_failed_encoding_is_tried_again_by_the_next_reader() -> None:
    camera = DummyCamera("camera", (64, 48))
    camera.update()
    with pytest.raises(SensorError, match="unknown image format"):
        camera.encoded(camera.latest(), ".gif")
    with pytest.raises(SensorError, match="unknown image format"):
        camera.encoded(camera.latest(), ".gif")
    assert camera.encoded(camera.latest(), ".jpg").startswith(b"\xff\xd8")


def test_coroutines_await_the_next_frame_and_a_cancelled_one_is_released() -> None:
    camera = DummyCamera("camera", (64, 48), fps=20.0)

    async def scenario() -> tuple[int, int, int]:
        first = await camera.wait_frame(0, 30.0)
        later = await asyncio.gather(*(camera.wait_frame(first.number, 30.0) for _ in range(30)))
        assert {f.number for f in later} == {later[0].number} and later[0].number > first.number
        never = asyncio.ensure_future(camera.wait_frame(10**9, 60.0))
        for _ in range(1000):
            if camera.async_waiters() == 1:
                break
            await asyncio.sleep(0.01)
        waiting = camera.async_waiters()
        never.cancel()
        with pytest.raises(asyncio.CancelledError):
            await never
        return first.number, waiting, camera.async_waiters()

    with camera:
        number, waiting, after_cancel = asyncio.run(scenario())
    assert number >= 1 and waiting == 1 and after_cancel == 0


def test_waiting_for_a_frame_of_a_camera_failed_for_good_raises_at_once() -> None:
    camera = DummyCamera("camera", (64, 48))
    camera.fail("no such camera in the model")
    with pytest.raises(SensorError, match="no such camera"):
        asyncio.run(camera.wait_frame(0, 60.0))
    camera.close()


class CountingCamera(DummyCamera):
    """A camera double whose encoder counts its calls and can be held mid-encoding."""

    def __init__(self) -> None:
        super().__init__("camera", (64, 48))
        self.calls: list[tuple[int, str, int]] = []
        self.entered = threading.Event()
        self.go = threading.Event()
        self.go.set()
        self._calls_lock = threading.Lock()

    def encode(self, image: Any, ext: str, quality: int) -> bytes:
        with self._calls_lock:
            self.calls.append((int(image[0, 0, 0]), ext, quality))
        self.entered.set()
        assert self.go.wait(60.0)
        return f"{ext}:{quality}:{int(image[0, 0, 0])}".encode()

    def grab(self) -> Any:
        frame = self._black.copy()
        frame[0, 0, 0] = (1 if self._latest is None else self._latest.number + 1) % 256
        return frame


def test_a_double_counts_one_encode_per_frame_and_quality_for_many_consumers() -> None:
    camera = CountingCamera()
    for number in (1, 2, 3):
        camera.update()
        frame = camera.latest()
        assert frame.number == number
        results: list[bytes] = []
        go = threading.Barrier(12)

        def read(quality: int, frame: Any, go: Any, results: list[bytes]) -> None:
            go.wait()
            results.append(camera.encoded(frame, ".jpg", quality))

        readers = [
            threading.Thread(target=read, args=(80 if i % 2 else 50, frame, go, results))
            for i in range(12)
        ]
        for reader in readers:
            reader.start()

        async def many(frame: Any = frame) -> list[bytes]:
            return await asyncio.gather(
                *(camera.encoded_async(frame, ".jpg", 80 if i % 2 else 50) for i in range(40))
            )

        results += asyncio.run(many())
        for reader in readers:
            reader.join(30)
        assert sorted(set(results)) == [f".jpg:{q}:{number}".encode() for q in (50, 80)]
        assert len(results) == 52
    assert sorted(camera.calls) == [(n, ".jpg", q) for n in (1, 2, 3) for q in (50, 80)]


def test_a_reader_cancelled_while_its_frame_is_encoded_leaves_the_encoding_to_the_others() -> None:
    camera = CountingCamera()
    camera.update()
    frame = camera.latest()
    camera.go.clear()

    async def scenario() -> tuple[list[bytes], bytes]:
        readers = [asyncio.ensure_future(camera.encoded_async(frame, ".jpg", 80)) for _ in range(6)]
        assert await asyncio.to_thread(camera.entered.wait, 60.0)
        await asyncio.sleep(0)  # every reader has claimed or is waiting for the encoding
        for leaving in readers[:3]:  # the claimer and two waiters: their clients left
            leaving.cancel()
        camera.go.set()
        stayed = await asyncio.gather(*readers[3:])
        return stayed, await camera.encoded_async(frame, ".jpg", 80)  # a later reader too

    stayed, later = asyncio.run(scenario())
    assert stayed == [b".jpg:80:1"] * 3 and later == b".jpg:80:1"
    assert camera.calls == [(1, ".jpg", 80)]


def test_a_first_reader_cancelled_before_its_encoding_started_still_serves_the_others() -> None:
    camera = CountingCamera()
    camera.update()
    frame = camera.latest()
    busy = threading.Event()

    async def scenario() -> bytes:
        loop = asyncio.get_running_loop()
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            loop.set_default_executor(pool)
            blocker = loop.run_in_executor(None, busy.wait, 60.0)  # the one worker is taken
            first = asyncio.ensure_future(camera.encoded_async(frame, ".jpg", 80))
            other = asyncio.ensure_future(camera.encoded_async(frame, ".jpg", 80))
            await asyncio.sleep(0)  # both asked: the first's encoding waits for the worker
            first.cancel()
            busy.set()
            await blocker
            return await asyncio.wait_for(other, 60.0)

    assert asyncio.run(scenario()) == b".jpg:80:1"
    assert camera.calls == [(1, ".jpg", 80)]
