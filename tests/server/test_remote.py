"""``RemoteRobot`` mirrors ``Robot``: names, registers, gotos, compliance, primitives, moves."""

from __future__ import annotations

import time

import pytest

from poppy_core.errors import (
    CommunicationError,
    ConfigError,
    RegisterError,
    UnknownGroupError,
    UnknownMotorError,
    UnknownMoveError,
    UnknownNameError,
    UnknownPrimitiveError,
)
from poppy_core.remote import RemoteRobot
from poppy_core.remote.client import path_of
from tests.helpers.server import Served
from tests.helpers.waiting import eventually


@pytest.fixture
def remote(served: Served) -> RemoteRobot:
    return RemoteRobot(served.url)


def test_same_names_groups_and_registers(remote: RemoteRobot, served: Served) -> None:
    assert [m.name for m in remote.motors] == [m.name for m in served.robot.motors]
    assert {g: [m.name for m in ms] for g, ms in remote.motorgroups.items()} == {
        g: [m.name for m in ms] for g, ms in served.robot.motorgroups.items()
    }
    for local, distant in zip(served.robot.motors, remote.motors, strict=True):
        assert distant.registers == local.registers
        assert distant.id == local.id and distant.model.name == local.model.name
    assert remote.m1.present_temperature == served.robot.m1.present_temperature
    assert remote.m2.angle_limit == list(served.robot.m2.angle_limit)
    assert [m.name for m in remote.base] == ["m1", "m2", "m3"]


def test_registers_read_and_write(remote: RemoteRobot, served: Served) -> None:
    remote.m4.led = "yellow"
    assert served.robot.m4.led == "yellow" and remote.m4.led == "yellow"
    with pytest.raises(ConfigError, match=r"m4 is compliant .* make it stiff first"):
        remote.m4.goal_position = 10.0  # a compliant motor would not move: the server says so
    remote.m4.compliant = False
    remote.m4.goal_position = 1000.0  # beyond the angle limits: clamped, as the library does
    top = served.robot.m4.angle_limit[1]
    assert eventually(lambda: abs(served.robot.m4.goal_position - top) < 0.5)
    remote.m4.compliant = True
    with pytest.raises(RegisterError, match="read-only"):
        remote.m4.present_position = 3.0
    with pytest.raises(AttributeError):
        remote.m4.nope = 1
    with pytest.raises(ConfigError):
        remote.motor("m9")
    remote.m4.led = "off"


def test_goto_and_compliance_match_the_robot(remote: RemoteRobot, served: Served) -> None:
    remote.compliant = False
    assert served.robot.compliant is False and remote.compliant is False
    handle = remote.goto_position({"m1": 25, "m2": -15}, 0.4, wait=True)
    assert handle.done
    time.sleep(0.1)
    local = served.robot.goto_position({"m3": 10}, 0.3, wait=True)
    assert local.done
    assert eventually(lambda: abs(remote.m1.present_position - 25) <= 2)  # a read may lag a loop
    assert remote.m2.present_position == pytest.approx(-15, abs=2)
    moving = remote.m1.goto_position(0, 1.0)  # long enough to be seen running over HTTP
    assert not moving.done and moving.wait(5.0) and moving.done
    remote.compliant = True
    assert served.robot.compliant is True


def test_primitives_and_moves(remote: RemoteRobot, served: Served) -> None:
    assert remote.primitive_names == served.robot.primitive_names
    sinus = remote.primitive("sinus")
    sinus.set_property("amplitude", 3)
    assert sinus.get_property("amplitude") == 3
    sinus.start()
    assert sinus.is_alive() and [p.name for p in remote.active_primitives] == ["sinus"]
    sinus.stop()
    assert sinus.state == "stopped"
    remote.moves.record("remote_move", ["m1"])
    time.sleep(0.2)
    assert remote.moves.save("remote_move")["motors"] == ["m1"]
    assert "remote_move" in remote.moves.list()
    remote.moves.play("remote_move", speed=4)
    remote.moves.stop("remote_move")
    remote.moves.delete("remote_move")
    assert "remote_move" not in remote.moves.list()
    served.robot.compliant = True


def test_keep_alive_and_unreachable_server(remote: RemoteRobot) -> None:
    for _ in range(20):
        assert isinstance(remote.m1.present_position, float)
    assert len(remote._client._all) == 1
    with pytest.raises(CommunicationError):
        RemoteRobot("http://127.0.0.1:9", timeout_s=1.0)


def test_a_404_is_a_typed_unknown_name(remote: RemoteRobot) -> None:
    """The Python API over REST raises what the local robot raises for an unknown name."""
    client = remote._client
    with pytest.raises(UnknownMotorError) as motor:
        client.get(path_of("motors", "m9"))
    assert motor.value.kind == "motor" and motor.value.motor == "m9"
    with pytest.raises(UnknownGroupError):
        client.get(path_of("groups", "nope"))
    with pytest.raises(UnknownPrimitiveError):
        client.request("POST", path_of("primitives", "nope", "start"))
    with pytest.raises(UnknownMoveError):
        client.get(path_of("moves", "nope"))
    with pytest.raises(UnknownNameError):
        remote.primitive("nope")
    with pytest.raises(ConfigError) as register:  # an unknown register: not an unknown motor
        client.get(path_of("motors", "m1", "registers", "nope"))
    assert not isinstance(register.value, UnknownNameError)


def test_primitives_are_attributes_as_in_pypot(remote: RemoteRobot, served: Served) -> None:
    """pypot's ``robot.dance.start()`` on a served robot (the notebooks' call form)."""
    assert "dance" in served.robot.primitive_names
    remote.dance.start()
    assert eventually(lambda: served.robot.dance.is_alive(), 10)
    assert remote.dance.is_alive()
    remote.dance.stop()
    assert not served.robot.dance.is_alive()
    with pytest.raises(AttributeError, match="no motor, group or primitive 'nope'"):
        remote.nope  # noqa: B018


def test_from_remote_without_a_host_reaches_the_robot_of_the_environment(
    served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    from poppy_core.robot import from_remote

    monkeypatch.setenv("POPPY_ROBOT_URL", served.url)
    with from_remote() as robot:
        assert robot.url == served.url and [m.name for m in robot.motors][:1] == ["m1"]


def test_a_served_camera_s_frame_is_read_as_an_image(remote: RemoteRobot, served: Served) -> None:
    import cv2
    import numpy as np

    assert remote.camera_names() == ["camera"]
    camera = next(s for s in served.robot.sensors if s.name == "camera")
    expected = camera.latest(10.0).image
    png = remote.camera_image("camera", "png")
    assert png.startswith(b"\x89PNG")
    decoded = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    assert decoded.shape == expected.shape and (decoded == expected).all()
    with pytest.raises(ConfigError, match="Sensor 'nope' does not exist"):
        remote.camera_image("nope")
