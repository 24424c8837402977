"""Building robots: profiles and public configs in simulation, start-up checks, autodetect."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import autodetect, from_config, from_profile
from poppy_core.emulator import VirtualBus, VirtualMotor, serve_link
from poppy_core.emulator.bus_servers import EmulatorServer
from poppy_core.errors import SetupError
from poppy_core.models import model_by_name
from poppy_core.robot import ReturnDelayIssue, load_profile

DATA = Path(__file__).parent / "data"
XL320 = model_by_name("XL-320")


def ergo_line(
    ids: list[int], *, delay_zero: bool = True, extra: tuple[VirtualMotor, ...] = ()
) -> VirtualBus:
    motors = []
    for motor_id in ids:
        motor = VirtualMotor(XL320, motor_id, 1_000_000)
        if delay_zero:
            motor.table.set("return_delay_time", 0)
        motors.append(motor)
    return VirtualBus([*motors, *extra], 2)


@pytest.fixture
def served() -> Iterator[list[EmulatorServer]]:
    servers: list[EmulatorServer] = []
    yield servers
    for server in servers:
        server.stop()


def serve(servers: list[EmulatorServer], bus: VirtualBus) -> str:
    server = serve_link(bus)
    servers.append(server)
    return str(server.url)


@pytest.mark.parametrize("name", ["ergo-jr", "torso", "humanoid"])
def test_profiles_build_virtual_robots(name: str) -> None:
    config = load_profile(name)
    with from_profile(name, sim=True) as robot:
        assert [m.name for m in robot.motors] == [
            n for c in config.controllers for n in config.motors_of_controller(c)
        ]
        assert set(robot.sync_stats()) == set(config.controllers)
        for group in config.motorgroups:
            assert [m.name for m in getattr(robot, group)] == config.resolve_group(group)
        first = robot.motors[0]
        assert first.model.name == model_by_name(config.motors[first.name].type).name


@pytest.mark.parametrize("name", ["poppy_ergo_jr", "poppy_torso", "poppy_humanoid"])
def test_public_configs_build_virtual_robots(name: str) -> None:
    with from_config(DATA / f"{name}.json", sim=True) as robot:
        robot.power_up()
        target = {m.name: sum(m.angle_limit) / 2 for m in robot.motors}
        robot.goto_position(target, 0.3, wait=True)
        assert robot.sync_stats()  # loops ran without raising


def test_angle_limits_are_written_as_the_config_gives_them() -> None:
    """A config's angle_limit is in the motor frame (pypot's): the EEPROM gets it as it is,
    the motor shows it in the user frame (m2 is indirect)."""
    with from_profile("ergo-jr", sim=True) as robot:
        table = robot.emulators["my_dxl_controller"].bus.motor(2).table
        assert table.get_si("min_position_limit") == pytest.approx(-90, abs=0.3)
        assert table.get_si("max_position_limit") == pytest.approx(125, abs=0.3)
        assert robot.m2.angle_limit == (-125.0, 90.0)


def test_missing_motors_are_listed(served: list[EmulatorServer]) -> None:
    url = serve(served, ergo_line([1, 2, 3, 4]))
    before = set(threading.enumerate())
    with pytest.raises(SetupError) as info:
        from_profile("ergo-jr", port=url, sensors=False)
    message = str(info.value)
    assert "m5 (id 5)" in message and "m6 (id 6)" in message and "m4" not in message
    assert url in message and "1000000 bps" in message
    assert "\n" not in message
    assert set(threading.enumerate()) - before == set()


def test_wrong_model_is_reported(served: list[EmulatorServer]) -> None:
    other = VirtualMotor(model_by_name("XL430-W250"), 6, 1_000_000)
    url = serve(served, ergo_line([1, 2, 3, 4, 5], extra=(other,)))
    with pytest.raises(SetupError, match=r"m6 \(id 6\) is XL430-W250, config says XL-320"):
        from_profile("ergo-jr", port=url, sensors=False)


def test_not_strict_starts_missing_motors_offline(served: list[EmulatorServer]) -> None:
    url = serve(served, ergo_line([1, 2, 3, 4, 5]))
    with from_profile("ergo-jr", port=url, sensors=False, strict=False) as robot:
        assert not robot.m6.online and robot.m5.online
        assert robot.sync_stats()["my_dxl_controller"].offline == ["m6"]


def test_return_delay_reported_then_fixed_with_consent(served: list[EmulatorServer]) -> None:
    bus = ergo_line([1, 2, 3, 4, 5, 6], delay_zero=False)
    url = serve(served, bus)
    with from_profile("ergo-jr", port=url, sensors=False):
        pass
    assert all(m.table.get("return_delay_time") == 250 for m in bus.motors)
    shown: list[list[ReturnDelayIssue]] = []

    def consent(issues: list[ReturnDelayIssue]) -> bool:
        shown.append(issues)
        return True

    with from_profile("ergo-jr", port=url, sensors=False, fix_return_delay=consent):
        pass
    assert [i.motor for i in shown[0]] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert shown[0][0].delay_us == 500
    assert all(m.table.get("return_delay_time") == 0 for m in bus.motors)


def test_eeprom_written_at_start_up_on_stiff_motors_which_stay_stiff(
    served: list[EmulatorServer], caplog: pytest.LogCaptureFixture
) -> None:
    bus = ergo_line([1, 2, 3, 4, 5, 6], delay_zero=False)
    for motor in bus.motors[:3]:  # the XL-320 locks its EEPROM while its torque is on
        motor.table.set("torque_enable", 1)
    url = serve(served, bus)
    config = load_profile("ergo-jr")
    with (
        caplog.at_level("WARNING"),
        from_profile("ergo-jr", port=url, sensors=False, fix_return_delay=True) as robot,
    ):
        assert [m.compliant for m in robot.motors] == [False] * 3 + [True] * 3
    assert [r.getMessage() for r in caplog.records if r.levelname == "WARNING"] == []
    assert [m.table.get("return_delay_time") for m in bus.motors] == [0] * 6
    assert [m.table.get("torque_enable") for m in bus.motors] == [1] * 3 + [0] * 3
    limits = [tuple(config.motors[f"m{m.id}"].angle_limit) for m in bus.motors]
    read = [
        tuple(
            round(XL320.register(n).to_si(m.table.get(n)), 0)
            for n in ("min_position_limit", "max_position_limit")
        )
        for m in bus.motors
    ]
    assert read == [tuple(round(v, 0) for v in pair) for pair in limits]


def test_return_delay_advice_names_the_python_argument(
    served: list[EmulatorServer], caplog: pytest.LogCaptureFixture
) -> None:
    url = serve(served, ergo_line([1, 2, 3, 4, 5, 6], delay_zero=False))
    with caplog.at_level("WARNING"), from_profile("ergo-jr", port=url, sensors=False):
        pass
    advice = [r.getMessage() for r in caplog.records if "return delay" in r.getMessage()]
    assert len(advice) == 1 and "fix_return_delay=True" in advice[0]
    assert "poppy motor" not in advice[0]  # a shell command is no advice in a Python program


def test_auto_port_finds_the_bus(served: list[EmulatorServer]) -> None:
    empty = serve(served, VirtualBus([], 2))
    url = serve(served, ergo_line([1, 2, 3, 4, 5, 6]))
    with from_profile("ergo-jr", ports=[empty, url], sensors=False) as robot:
        assert robot.buses["my_dxl_controller"].port == url
    with pytest.raises(SetupError, match="searched"):
        from_profile("ergo-jr", ports=[empty], sensors=False)


def test_autodetect_builds_what_it_finds(served: list[EmulatorServer]) -> None:
    url = serve(served, ergo_line([2, 5]))
    with autodetect(url, baudrates=[1_000_000], protocols=[2]) as robot:
        assert [m.name for m in robot.motors] == ["m2", "m5"]
        assert robot.m5.model.name == "XL-320"
        assert robot.m5.angle_limit == pytest.approx((-150, 149.7), abs=0.1)
        assert robot.to_config()["motors"]["m2"]["id"] == 2
    with pytest.raises(SetupError):
        autodetect(serve(served, VirtualBus([], 2)), baudrates=[1_000_000], protocols=[2])
