"""A sensor's loop on the Worker base: a loop that dies says so once, in the log and in health."""

from __future__ import annotations

import logging

import pytest

from poppy_core.sensors import Sensor
from tests.helpers.waiting import eventually


class _Fatal(BaseException):
    """Escapes the loop's own ``except Exception`` (as a bug in the loop itself would)."""


class _Dying(Sensor):
    def update(self) -> None:
        raise _Fatal("the loop itself broke")


def test_a_sensor_whose_loop_dies_shows_it_in_health_and_closes(
    caplog: pytest.LogCaptureFixture,
) -> None:
    sensor = _Dying("dying", 50.0)
    with caplog.at_level(logging.WARNING):
        sensor.start()
        assert eventually(lambda: not sensor.running)
        health = sensor.health()
        assert "the loop itself broke" in health.last_error and health.errors >= 1
        sensor.close()  # a dead loop does not stop the robot's close
    said = [r for r in caplog.records if "the loop itself broke" in r.getMessage()]
    assert len(said) == 1 and said[0].levelno == logging.WARNING
