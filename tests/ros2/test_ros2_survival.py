"""The ROS 2 node keeps serving through a raising publish tick, and each refusal is one typed
event (``Refusal``) that listeners (/rosout) receive."""

from __future__ import annotations

import logging
from typing import Any

import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")

from poppy_core.server.ros2 import node as node_module
from poppy_core.server.ros2.refusal_log import Refusal
from tests.helpers.waiting import eventually
from tests.ros2.test_ros2_node import TRAJECTORY, Node, _trajectory


def test_a_refusal_is_one_typed_event_handed_to_listeners(node: Node) -> None:
    ros2 = node.servers.ros2
    assert ros2 is not None
    heard: list[Refusal] = []
    ros2.refusals.listen(heard.append)
    node.robot.compliant = True
    node.client.publish("/joint_trajectory", TRAJECTORY, _trajectory(["m1"], [(0.2, [0.3])]))
    assert eventually(lambda: len(heard) == 1, 10.0)
    (refusal,) = heard
    assert refusal.kind == "topic" and refusal.where.endswith("joint_trajectory")
    assert "m1" in refusal.reason and "compliant" in refusal.reason
    assert ros2.refusals.count == 1 and ros2.commands.refused == 1


def test_a_raising_publish_tick_is_logged_once_and_the_node_recovers(
    node: Node, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    ros2 = node.servers.ros2
    assert ros2 is not None
    real = node_module.messages.joint_state
    failing = [True]

    def flaky(*args: Any, **kwargs: Any) -> Any:
        if failing[0]:
            raise RuntimeError("a joint went missing")
        return real(*args, **kwargs)

    caplog.set_level(logging.WARNING, logger="poppy_core.schedule")
    monkeypatch.setattr(node_module.messages, "joint_state", flaky)
    assert eventually(lambda: ros2.state_loop.failures >= 3, 10.0)
    assert ros2.running and ros2.state_loop.failing  # alive: `poppy serve` stays up
    published = ros2.published
    failing[0] = False
    assert eventually(lambda: ros2.published >= published + 5, 10.0)
    assert not ros2.state_loop.failing
    warned = [r for r in caplog.records if "a tick failed" in r.getMessage()]
    assert len(warned) == 1 and "a joint went missing" in warned[0].getMessage()
