"""In MuJoCo, the Ergo Jr's head turns to a marker card seen by its simulated camera."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

pytest.importorskip("mujoco")
pytest.importorskip("cv2")

from poppy_core.errors import ConfigError, SensorError

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def ergo() -> Iterator[Any]:
    from poppy_core.creatures import from_profile

    with from_profile("ergo-jr", sim="mujoco") as robot:
        try:
            robot.camera.latest(timeout_s=30)
        except (SensorError, ConfigError) as exc:
            pytest.skip(f"no OpenGL for offscreen rendering here ({exc}); `make sim-deps`")
        robot.compliant = False
        robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.5, wait=True)
        time.sleep(0.5)
        yield robot


def seen(robot: Any) -> tuple[float, float] | None:
    markers = [m for m in robot.marker_detector.detect() if m.id == 7]
    return markers[0].position if markers else None


def test_marker_follow_brings_the_card_to_the_middle(ergo: Any) -> None:
    import mujoco

    sim = ergo.simulation
    with sim.lock:
        camera = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
        axes = np.asarray(sim.data.cam_xmat[camera]).reshape(3, 3)
        where = np.asarray(sim.data.cam_xpos[camera])
    look, right = -axes[:, 2], axes[:, 0]
    card = where + 0.3 * look + 0.07 * right
    sim.add_marker("card", 7, (float(card[0]), float(card[1]), float(card[2])), size=0.05)
    deadline = time.monotonic() + 20
    while seen(ergo) is None and time.monotonic() < deadline:
        time.sleep(0.1)
    start = seen(ergo)
    assert start is not None and abs(start[0]) > 0.25  # seen, on one side
    names = ergo.primitive_names
    assert "marker_follow" in names and "tracking_feedback" in names
    ergo.marker_follow.marker = 7
    ergo.marker_follow.start()
    try:
        deadline = time.monotonic() + 60
        now = seen(ergo)
        while time.monotonic() < deadline and (now is None or max(map(abs, now)) > 0.12):
            time.sleep(0.2)
            now = seen(ergo)
    finally:
        ergo.marker_follow.stop()
    assert now is not None and max(map(abs, now)) <= 0.12, (start, now)
    assert ergo.marker_follow.error is None
