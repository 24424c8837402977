"""Many MJPEG viewers while `play` and `save` are timed: a script run by ``bench/camera_bench.py``.

Run as ``python bench/camera_viewers.py VIEWERS FPS SECONDS`` with the poppy to measure first
on ``PYTHONPATH`` (this checkout, or an older one: it uses only routes and calls both have). It
serves an ideal Ergo Jr (a blank 640×480 camera at 30 fps) on loopback, starts a second process
holding ``VIEWERS`` MJPEG streams at ``FPS``, and once each got a frame, records, saves, plays
and stops a move over REST in a loop for ``SECONDS``, timing ``save`` and ``play``. Prints one
JSON line: the latencies (ms), the JPEG parts each viewer got per second, the load average.
"""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys
import time
from urllib.parse import urlsplit

STREAM = "/api/v1/sensors/camera/stream.mjpg"
PART = b"--frame\r\n"
CAMERA_FPS = 30.0


async def _viewer(
    url: str, fps: float, counts: list[int], index: int, ready: asyncio.Event
) -> None:
    where = urlsplit(url)
    reader, writer = await asyncio.open_connection(where.hostname, where.port)
    writer.write(f"GET {STREAM}?fps={fps:g} HTTP/1.1\r\nHost: {where.netloc}\r\n\r\n".encode())
    await writer.drain()
    tail = b""
    try:
        while True:
            chunk = await reader.read(65536)
            if not chunk:
                return
            seen = tail + chunk
            counts[index] += seen.count(PART)
            tail = seen[-(len(PART) - 1) :]
            if counts[index] and not ready.is_set() and all(counts):
                ready.set()
    finally:
        writer.close()


async def _viewers(url: str, count: int, fps: float, seconds: float) -> None:
    counts = [0] * count
    ready = asyncio.Event()
    tasks = [asyncio.ensure_future(_viewer(url, fps, counts, i, ready)) for i in range(count)]
    if count:
        await asyncio.wait_for(ready.wait(), 120.0)
    print("ready", flush=True)
    start = list(counts)
    began = time.monotonic()
    await asyncio.sleep(seconds)
    elapsed = time.monotonic() - began
    rates = [(n - s) / elapsed for n, s in zip(counts, start, strict=True)] or [0.0]
    print(json.dumps({"viewer_fps": rates}), flush=True)
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)


def _timed_moves(url: str, seconds: float) -> dict[str, list[float]]:
    import httpx

    timings: dict[str, list[float]] = {"save": [], "play": []}
    deadline = time.monotonic() + seconds
    with httpx.Client(base_url=url, timeout=60.0) as http:
        n = 0
        while time.monotonic() < deadline:
            move = f"bench{n % 4}"
            n += 1
            http.post(f"/api/v1/moves/{move}/record", json={}).raise_for_status()
            time.sleep(0.2)
            for what, body in (("save", None), ("play", {"speed": 4.0})):
                began = time.perf_counter()
                answer = http.post(f"/api/v1/moves/{move}/{what}", json=body)
                timings[what].append((time.perf_counter() - began) * 1000)
                answer.raise_for_status()
            time.sleep(0.1)
            http.post(f"/api/v1/moves/{move}/stop").raise_for_status()
    return timings


def measure(viewers: int, fps: float, seconds: float) -> dict[str, object]:
    """The measurement (this process serves; a child process views)."""
    import tempfile

    os.environ["POPPY_MOVES_DIR"] = tempfile.mkdtemp(prefix="poppy-bench-moves-")
    from poppy_core import from_config
    from poppy_core.robot import RobotConfig, load_profile
    from poppy_core.server import ServerThread, create_app

    data = load_profile("ergo-jr").to_dict()
    data["sensors"]["camera"].update({"fps": CAMERA_FPS})
    config = RobotConfig.from_dict(data, source="bench")
    with from_config(config, sim=True) as robot:
        server = ServerThread(create_app(robot)).start()
        try:
            child = subprocess.Popen(
                [
                    sys.executable,
                    __file__,
                    "--view",
                    server.url,
                    str(viewers),
                    str(fps),
                    str(seconds),
                ],
                stdout=subprocess.PIPE,
                text=True,
            )
            assert child.stdout is not None
            first = child.stdout.readline().strip()
            if first != "ready":
                child.kill()
                raise RuntimeError(f"the viewers did not all get a frame ({first!r})")
            load = os.getloadavg()[0]
            timings = _timed_moves(server.url, seconds)
            out, _ = child.communicate(timeout=120)
            rates = json.loads(out.strip().splitlines()[-1])["viewer_fps"]
        finally:
            server.stop()
    return {"viewers": viewers, "fps": fps, "load1": load, **timings, "viewer_fps": rates}


def main() -> None:
    if sys.argv[1] == "--view":
        url, count, fps, seconds = (
            sys.argv[2],
            int(sys.argv[3]),
            float(sys.argv[4]),
            float(sys.argv[5]),
        )
        asyncio.run(_viewers(url, count, fps, seconds))
        return
    viewers, fps, seconds = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    print(json.dumps(measure(viewers, fps, seconds)), flush=True)


if __name__ == "__main__":
    main()
