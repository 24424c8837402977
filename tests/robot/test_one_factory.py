"""One way to build a robot: the package's faces (autodetect too) attach the creature."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import autodetect, from_config, from_profile
from poppy_core.creatures import Dance
from poppy_core.emulator import build_bus_from_spec, ergo_jr_bus, serve_link
from poppy_core.errors import ConfigError
from poppy_core.robot import load_profile, with_ports


def test_from_profile_attaches_the_creature() -> None:
    with from_profile("ergo-jr", sim=True, sensors=False) as robot:
        assert robot.creature is not None and robot.creature.kind == "ergo-jr"
        assert isinstance(robot.dance, Dance)
        assert robot.emulators["my_dxl_controller"].url.startswith("emu://")


def test_creature_false_builds_a_bare_robot() -> None:
    with from_config(load_profile("ergo-jr"), sim=True, sensors=False, creature=False) as robot:
        assert getattr(robot, "creature", None) is None
        assert not hasattr(robot, "dance")


def test_a_bare_robot_still_has_pypots_primitive_manager() -> None:
    with from_config(load_profile("ergo-jr"), sim=True, sensors=False, creature=False) as robot:
        assert robot._primitive_manager is robot.primitive_manager


def test_with_ports_replaces_the_one_port_or_refuses_in_one_line() -> None:
    config = with_ports(load_profile("ergo-jr"), "/dev/ttyACM7", source="command line")
    assert config.controllers["my_dxl_controller"].port == "/dev/ttyACM7"
    with pytest.raises(ConfigError, match="one port given but this robot has 2 controllers"):
        with_ports(load_profile("humanoid"), "/dev/ttyACM7")


@pytest.fixture
def ergo_line_url(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Iterator[str]:
    """An Ergo Jr's six XL-320 on the in-process link (and no user profile to compare with)."""
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    with serve_link(ergo_jr_bus()) as server:
        yield server.url


def test_autodetect_attaches_the_creature_of_the_profile_it_finds(ergo_line_url: str) -> None:
    with autodetect(
        ergo_line_url, baudrates=[1_000_000], protocols=[2], start_defaults=False
    ) as robot:
        assert robot.creature is not None and robot.creature.kind == "ergo-jr"
        assert isinstance(robot.dance, Dance)
        assert robot.buses["my_dxl_controller"].port == ergo_line_url
        assert robot.m2.orientation == "indirect"  # the profile's, not a bare m<id>
        assert robot.m3.angle_limit == pytest.approx((-90, 90))
        assert [m.name for m in robot.base] == ["m1", "m2", "m3"]


def test_autodetect_with_creature_false_builds_the_bare_robot(ergo_line_url: str) -> None:
    with autodetect(ergo_line_url, baudrates=[1_000_000], protocols=[2], creature=False) as robot:
        assert getattr(robot, "creature", None) is None
        assert not hasattr(robot, "dance")
        assert list(robot.buses) == ["controller_1"]
        assert robot.m3.angle_limit == pytest.approx((-150, 149.7), abs=0.1)


def test_autodetect_of_motors_no_profile_has_is_bare(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", "/nonexistent-poppy-test")
    with (
        serve_link(build_bus_from_spec("XL-320:1-5", protocol=2)) as server,
        autodetect(server.url, baudrates=[1_000_000], protocols=[2]) as robot,
    ):
        assert getattr(robot, "creature", None) is None
        assert [m.name for m in robot.motors] == ["m1", "m2", "m3", "m4", "m5"]
