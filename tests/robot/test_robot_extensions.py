"""The Robot's generic registry: attached objects as attributes, primitives, close callbacks."""

from __future__ import annotations

import pytest

from poppy_core.errors import ConfigError
from poppy_core.models import model_by_name
from poppy_core.robot import Motor, Robot


class Alive:
    """Anything with ``is_alive`` can be attached as a primitive."""

    def __init__(self, alive: bool) -> None:
        self.alive = alive

    def is_alive(self) -> bool:
        return self.alive


def hand_built() -> Robot:
    model = model_by_name("AX-12A")
    return Robot([Motor("m1", model, 1), Motor("m2", model, 2)], groups={"arm": ["m1", "m2"]})


def test_attached_objects_are_attributes() -> None:
    robot = hand_built()
    marker = object()
    robot.attach("camera", marker)
    assert robot.camera is marker
    assert robot.extensions == {"camera": marker}
    assert "camera" in dir(robot)
    assert robot.primitives == []  # plain extensions are not primitives
    with pytest.raises(AttributeError):
        robot.nothing_here  # noqa: B018
    robot.close()


@pytest.mark.parametrize(
    "name", ["m1", "arm", "close", "motors", "extensions", "config", "_hidden", "not valid"]
)
def test_names_that_cannot_be_attached(name: str) -> None:
    robot = hand_built()
    with pytest.raises(ConfigError):
        robot.attach(name, object())
    robot.close()


def test_primitives_and_active_primitives() -> None:
    robot = hand_built()
    idle, busy = Alive(False), Alive(True)
    robot.attach_primitive(idle, "idle")
    robot.attach_primitive(busy, "busy")
    robot.attach_primitive(busy, "busy")  # attaching again keeps one entry
    assert robot.primitive_names == ["idle", "busy"]
    assert robot.primitives == [idle, busy]
    assert robot.active_primitives == [busy]
    assert robot.busy is busy
    robot.close()


def test_close_callbacks_run_once_newest_first() -> None:
    robot = hand_built()
    calls: list[str] = []
    robot.on_close(lambda: calls.append("first"))
    robot.on_close(lambda: calls.append("second"))

    def broken() -> None:
        raise RuntimeError("cleanup failed")

    robot.on_close(broken)  # logged, does not stop the others
    robot.close()
    robot.close()
    assert calls == ["second", "first"]
