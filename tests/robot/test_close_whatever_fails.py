"""``Robot.close`` closes every part whatever fails first, each failure logged once.

Before, the first part whose close raised (a camera) ended ``close``: the sync loops went on
and the ports stayed open, so the next program could not open them.
"""

from __future__ import annotations

import logging
import threading

import pytest

from poppy_core import from_profile
from poppy_core.errors import SensorError


def _failing(what: str) -> object:
    def close() -> None:
        raise SensorError(f"{what} would not close")

    return close


def test_a_camera_that_fails_to_close_leaves_nothing_else_open(
    caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = from_profile("ergo-jr", sim=True)
    camera = robot.sensor("camera")
    camera.latest()  # its thread runs
    monkeypatch.setattr(camera, "close", _failing("the camera"))
    monkeypatch.setattr(robot.sensor("marker_detector"), "close", _failing("the detector"))
    emulator = robot.emulators["my_dxl_controller"]
    with caplog.at_level(logging.WARNING, logger="poppy_core"):
        robot.close()
    threads = [t.name for t in threading.enumerate()]
    assert not any(name.startswith("sync ") for name in threads), threads
    assert not any(bus.is_open for bus in robot.buses.values())
    assert not emulator.running
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert sum("sensor camera failed: the camera would not close" in w for w in warnings) == 1
    assert sum("sensor marker_detector failed" in w for w in warnings) == 1
    robot.close()  # again: nothing, nothing logged
    assert len([r for r in caplog.records if r.levelno == logging.WARNING]) == len(warnings)
