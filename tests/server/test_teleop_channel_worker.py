"""A WebSocket's teleop channel runs on the worker base: an error in its loop is logged once,
the session stops holding, and closing (twice) joins and frees the motors."""

from __future__ import annotations

import logging
from typing import Any

import pytest

from poppy_core.motion.leases import MotorLeases
from poppy_core.motion.teleop.goal_stream import GoalStream
from poppy_core.robot import Robot
from poppy_core.server.teleop_channel import TeleopChannel, TeleopRegistry
from tests.helpers import eventually
from tests.helpers.fixtures import ergo_fixture

ergo = ergo_fixture(sensors=False)


def test_an_error_in_the_channel_loop_is_logged_once_and_the_motors_are_freed(
    ergo: Robot, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(self: GoalStream, goals: Any) -> None:
        raise RuntimeError("the goals would not go")

    monkeypatch.setattr(GoalStream, "push", broken)
    registry = TeleopRegistry(MotorLeases(ergo))
    sent: list[dict[str, Any]] = []
    channel = TeleopChannel(ergo, registry, sent.append)
    with caplog.at_level(logging.WARNING):
        answer = channel.handle({"type": "teleop.start", "motors": ["m1"]})
        assert answer is not None and answer["type"] == "teleop.started"
        channel.handle({"type": "teleop.goals", "positions": {"m1": 10.0}})
        session = channel.session
        assert session is not None
        assert eventually(lambda: session.state == "stopped", timeout_s=10.0)
    channel.close("the test ends")
    channel.close("again")  # twice is safe
    assert registry.states() == {}
    assert registry.leases.owners() == {}
    failed = [r for r in caplog.records if r.getMessage().startswith("teleop channel failed")]
    assert len(failed) == 1
