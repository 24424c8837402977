"""What the page's header and panels say about the robot: its name, its cameras, its Jupyter."""

from __future__ import annotations

import asyncio
import time
from typing import Any

from poppy_core.robot import Robot
from poppy_core.sensors import Camera

NOTEBOOK_PORT = 8888
"""Where ``poppy notebook`` (and the robot's Jupyter service) listens."""
NOTEBOOK_PATH = "/notebooks/discover-your-robot.ipynb"
"""The notebook the page links to (``poppy notebook`` puts it in its folder)."""
PROBE_TIMEOUT_S = 0.5
PROBE_FRESH_S = 3.0
"""A Jupyter found (or not) is asked again after this long (the page reads about every 5 s)."""
IDEAL_SIM_NO_CAMERA = (
    "No camera: a robot simulated with ideal servos has no scene to see "
    "(`poppy serve --sim mujoco` renders what its camera sees)"
)
NO_CAMERA = "No camera: this robot has none"


def robot_name(robot: Robot, served_name: str | None) -> tuple[str, str]:
    """The robot's name (``--name``, or as renamed from the page; else its profile's) and
    its creature."""
    profile = robot.config.profile if robot.config is not None else None
    creature = (profile.kind or profile.name) if profile else "custom"
    own = profile.name if profile else "robot"
    return served_name or own, creature


def camera_views(robot: Robot) -> tuple[list[dict[str, str]], str]:
    """The cameras with a picture to show (name and label), and what the panel says without
    one. A ``DummyCamera`` (ideal simulation: black frames) is no picture."""
    views: list[dict[str, str]] = []
    dummies = 0
    for sensor in robot.sensors:
        if not isinstance(sensor, Camera):
            continue
        kind = type(sensor).__name__
        if kind == "DummyCamera":
            dummies += 1
            continue
        if kind == "SimCamera":
            label = f"{sensor.name}: simulated by MuJoCo, from where the real one sits"
        else:
            label = f"{sensor.name}: {kind}"
        views.append({"name": sensor.name, "label": label})
    if views:
        return views, ""
    return views, IDEAL_SIM_NO_CAMERA if dummies else NO_CAMERA


async def jupyter_answers(host: str, port: int) -> bool:
    """True when a Jupyter server answers ``GET /api`` (unauthenticated: its version) on
    ``host``:``port``: the address the page's browser reached this server at."""
    try:
        reader, writer = await asyncio.wait_for(
            asyncio.open_connection(host, port), PROBE_TIMEOUT_S
        )
    except (OSError, TimeoutError):
        return False
    try:
        name = f"[{host}]" if ":" in host else host
        writer.write(f"GET /api HTTP/1.0\r\nHost: {name}:{port}\r\n\r\n".encode())
        await writer.drain()
        answer = await asyncio.wait_for(_read_some(reader, 16_384), PROBE_TIMEOUT_S)
    except (OSError, TimeoutError):
        return False
    finally:
        writer.close()
    head, _, body = answer.partition(b"\r\n\r\n")
    return (
        head.startswith(b"HTTP/1.") and b" 200 " in head.split(b"\r\n")[0] and b'"version"' in body
    )


async def _read_some(reader: asyncio.StreamReader, most: int) -> bytes:
    """What the peer sends until it closes (HTTP/1.0), at most ``most`` bytes."""
    answer = b""
    while len(answer) < most:
        chunk = await reader.read(most - len(answer))
        if not chunk:
            break
        answer += chunk
    return answer


async def notebook(state: Any, host: str | None) -> dict[str, Any] | None:
    """The Jupyter link's port and path when a Jupyter answers on ``host`` (kept for
    ``PROBE_FRESH_S``), else None: the page links to no dead port."""
    port: int = getattr(state, "web_notebook_port", NOTEBOOK_PORT)
    if not host or not port:
        return None
    cache: dict[tuple[str, int], tuple[float, bool]] = state.web_notebook_seen
    now = time.monotonic()
    seen = cache.get((host, port))
    if seen is None or now - seen[0] > PROBE_FRESH_S:
        seen = (now, await jupyter_answers(host, port))
        cache[(host, port)] = seen
    return {"port": port, "path": NOTEBOOK_PATH} if seen[1] else None
