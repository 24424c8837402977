"""In MuJoCo, the Ergo Jr's head turns to a marker card seen by its simulated camera."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("mujoco")
pytest.importorskip("cv2")

from sim_helpers import ahead_of_camera, ready_to_look

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def ergo() -> Iterator[Any]:
    from poppy_core import from_profile

    with from_profile("ergo-jr", sim="mujoco") as robot:
        yield ready_to_look(robot)


def seen(robot: Any) -> tuple[float, float] | None:
    markers = [m for m in robot.marker_detector.detect() if m.id == 7]
    return markers[0].position if markers else None


def test_marker_follow_brings_the_card_to_the_middle(ergo: Any) -> None:
    sim = ergo.simulation
    sim.add_marker("card", 7, ahead_of_camera(sim, 0.3, 0.07), size=0.05)
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
